//! The `springlab` command: a thin layer over the library (parse flags, run, exit code).

mod cli;

use std::process::ExitCode;

fn main() -> ExitCode {
    cli::main()
}
