//! The library's one error type: every variant carries the file, field or number at fault.

use std::path::PathBuf;

/// Everything that can go wrong in springlab, with enough context to fix it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The scenario file could not be read from disk.
    #[error("{file}: cannot read scenario: {source}")]
    Read {
        /// The file that failed.
        file: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The file is not valid TOML or does not match the scenario format.
    #[error("{file}{location}: {field}: {message}")]
    Parse {
        /// The file that failed.
        file: PathBuf,
        /// ` line L, column C` where TOML reports it, else empty.
        location: String,
        /// Dotted field path such as `spring[3].between[1]` (or `(document)`).
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A field parsed but its value is impossible (negative mass, missing particle, ...).
    #[error("{file}: {field}: {message}")]
    Invalid {
        /// The file that failed (or `<memory>` for scenes built in code).
        file: PathBuf,
        /// Dotted field path such as `spring[3].between[1]`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A method cannot handle this scene (say, constraints without projection).
    #[error("{method} cannot run scenario '{scenario}': {reason}")]
    Unsupported {
        /// Method name.
        method: String,
        /// Scenario name.
        scenario: String,
        /// Why not.
        reason: String,
    },
    /// An unknown method name was asked for.
    #[error("unknown method '{name}'; known: {known}")]
    UnknownMethod {
        /// The name given.
        name: String,
        /// Comma-separated list of valid names.
        known: String,
    },
    /// A command-line or API option has an impossible value.
    #[error("{option}: {message}")]
    BadOption {
        /// Option name, e.g. `--dt`.
        option: String,
        /// What is wrong.
        message: String,
    },
    /// Writing an output failed.
    #[error("{file}: cannot write: {source}")]
    Write {
        /// The file being written.
        file: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// Another springlab command holds the lock on the output folder (one writer per folder).
    #[error("{dir}: another springlab command is writing this folder or a folder inside it; wait for it to finish or write elsewhere with --out")]
    Busy {
        /// The output folder.
        dir: PathBuf,
    },
    /// Another springlab command writes a folder that holds this output folder.
    #[error("{dir}: another springlab command is writing {above}, which holds this folder; wait for it to finish or write elsewhere with --out")]
    BusyAbove {
        /// The output folder.
        dir: PathBuf,
        /// The folder above it that is being written.
        above: PathBuf,
    },
    /// A method could not be registered: its facts are inconsistent (order 0, a name taken).
    #[error("cannot register method '{name}': {message}")]
    Registration {
        /// The method's name.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// A numerical solve inside a step failed (for example Newton did not converge).
    #[error("step failed: {0}")]
    Step(String),
}

/// A number as messages print it: as typed when that is short (`0.01`, `250`, `1e-320`), else
/// in scientific form with five significant digits at most (`1.6667e-2`, `1e300`), so that no
/// message holds a number hundreds of digits long.
pub fn num(x: f64) -> String {
    const SHORT: usize = 12;
    let plain = format!("{x}");
    if plain.len() <= SHORT {
        return plain;
    }
    let exact = format!("{x:e}");
    if exact.len() <= SHORT {
        return exact;
    }
    let rounded = format!("{x:.4e}");
    match rounded.split_once('e') {
        Some((m, e)) if m.contains('.') => {
            format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
        }
        _ => rounded,
    }
}

/// A finite number with `sig` significant digits, as tables and notes print measured figures:
/// plain between 1e-3 and 1e5 (`0.0116`, `2706`), else scientific (`1.00e-6`); zero is `0`.
pub fn significant(v: f64, sig: usize) -> String {
    let sci = format!("{v:.prec$e}", prec = sig.saturating_sub(1));
    // The decade after rounding: 0.0099999 to three digits is 0.0100, not 0.01000.
    let rounded: f64 = sci.parse().unwrap_or(v);
    if v == 0.0 {
        "0".into()
    } else if (1e-3..1e5).contains(&rounded.abs()) {
        let digits = (sig as i32 - 1 - rounded.abs().log10().floor() as i32).max(0) as usize;
        format!("{v:.digits$}")
    } else {
        sci
    }
}

/// Shorthand for results carrying [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// Builds an [`Error::Invalid`] for a field of a file.
    pub fn invalid(
        file: impl Into<PathBuf>,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Error::Invalid {
            file: file.into(),
            field: field.into(),
            message: message.into(),
        }
    }
    /// Builds an [`Error::BadOption`].
    pub fn option(option: impl Into<String>, message: impl Into<String>) -> Self {
        Error::BadOption {
            option: option.into(),
            message: message.into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::significant;

    // Oracle: counting digits by hand. A value that rounds up into the next decade keeps
    // `sig` digits there (0.00999999… to three is 0.0100); its twins away from the edge keep
    // theirs; the plain range is decided after rounding (99 999.9 is 1.00e5).
    #[test]
    fn significant_digits_hold_across_a_decade_edge() {
        assert_eq!(significant(0.00999999987674645, 3), "0.0100");
        assert_eq!(significant(9.996, 3), "10.0");
        assert_eq!(significant(0.0116, 3), "0.0116");
        assert_eq!(significant(2706.0, 3), "2706");
        assert_eq!(significant(99999.9, 3), "1.00e5");
        assert_eq!(significant(1.234e-6, 3), "1.23e-6");
        assert_eq!(significant(0.0, 3), "0");
    }
}
