//! Field-by-field value checks for scene validation: each error names the file and the field
//! path that holds the value at fault.

use super::file::Triple;
use crate::error::{num, Error, Result};
use crate::model::Vec3;
use std::path::Path;

/// Most particles one scene may hold (a 3162×3162 cloth).
pub const MAX_PARTICLES: usize = 10_000_000;
/// Longest scene name in bytes: it becomes a directory name, which holds at most 255.
pub const MAX_NAME_BYTES: usize = 255;
/// Most steps one run may take.
pub const MAX_STEPS: u64 = 10_000_000_000;

/// Checks values of one scene file, naming the file in every error.
pub(super) struct Checker<'a> {
    /// The file the values come from.
    pub(super) file: &'a Path,
}

impl Checker<'_> {
    pub(super) fn err(&self, field: impl Into<String>, msg: impl Into<String>) -> Error {
        Error::invalid(self.file, field, msg)
    }
    pub(super) fn finite(&self, field: &str, x: f64) -> Result<f64> {
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be a finite number, got {}", num(x))))
        }
    }
    pub(super) fn positive(&self, field: &str, x: f64) -> Result<f64> {
        self.finite(field, x)?;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be > 0, got {}", num(x))))
        }
    }
    pub(super) fn non_negative(&self, field: &str, x: f64) -> Result<f64> {
        self.finite(field, x)?;
        if x >= 0.0 {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be >= 0, got {}", num(x))))
        }
    }
    pub(super) fn triple(&self, field: &str, t: Triple) -> Result<Vec3> {
        for (k, c) in t.iter().enumerate() {
            self.finite(&format!("{field}[{k}]"), *c)?;
        }
        Ok(Vec3::from(t))
    }
    pub(super) fn index(&self, field: &str, i: i64, n: usize) -> Result<usize> {
        if i < 0 || i as u64 >= n as u64 {
            Err(self.err(
                field,
                format!(
                    "particle index {i} does not exist (the scene has {n} particles, 0..{})",
                    n.saturating_sub(1)
                ),
            ))
        } else {
            Ok(i as usize)
        }
    }
    pub(super) fn pair(&self, field: &str, b: [i64; 2], n: usize) -> Result<(usize, usize)> {
        let i = self.index(&format!("{field}.between[0]"), b[0], n)?;
        let j = self.index(&format!("{field}.between[1]"), b[1], n)?;
        if i == j {
            return Err(self.err(
                format!("{field}.between[1]"),
                format!("joins particle {i} to itself"),
            ));
        }
        Ok((i, j))
    }
    pub(super) fn count(&self, field: &str, c: i64, min: i64) -> Result<usize> {
        if c < min || c as u64 > MAX_PARTICLES as u64 {
            Err(self.err(
                field,
                format!("must be between {min} and {MAX_PARTICLES}, got {c}"),
            ))
        } else {
            Ok(c as usize)
        }
    }
    pub(super) fn names(&self, field: &str, given: &[String], allowed: &[&str]) -> Result<()> {
        for (k, g) in given.iter().enumerate() {
            if !allowed.contains(&g.as_str()) {
                return Err(self.err(
                    format!("{field}[{k}]"),
                    format!(
                        "unknown value '{g}'; expected one of: {}",
                        allowed.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }
}
