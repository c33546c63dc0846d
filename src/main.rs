//! The `springlab` command: a thin layer over the library (parse flags, run, exit code).

mod cli;

use std::process::ExitCode;

fn main() -> ExitCode {
    // Piping into `head` closes stdout early: end quietly as Unix tools do, instead of
    // panicking on the next print.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // Ctrl-C and SIGTERM remove what was being written and say what was kept.
    springlab::output::interrupt::install();
    cli::main()
}
