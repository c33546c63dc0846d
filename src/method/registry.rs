//! The registry: every method springlab can run, with its facts and its constructor, in the
//! order reports list them. Built-ins come first; a library user adds their own with
//! [`Registry::with`], and every command that takes a registry then runs it like a built-in.

use super::info::{MethodInfo, Order};
use super::instance::Instance;
use super::options::{MethodOptions, OptionSpec};
use crate::error::{Error, Result};
use crate::integrate::Stepper;
use std::sync::Arc;

/// Builds a fresh, independent instance of a method.
pub type Constructor = dyn Fn(&MethodOptions) -> Box<dyn Stepper> + Send + Sync;

/// A method: its facts and how to make one.
#[derive(Clone)]
pub struct Method {
    /// The facts.
    pub info: MethodInfo,
    make: Arc<Constructor>,
}

impl std::fmt::Debug for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Method").field("info", &self.info).finish()
    }
}

impl Method {
    /// A method with `info` built by `make`.
    pub fn new(
        info: MethodInfo,
        make: impl Fn(&MethodOptions) -> Box<dyn Stepper> + Send + Sync + 'static,
    ) -> Self {
        Method {
            info,
            make: Arc::new(make),
        }
    }
    /// A fresh instance.
    pub fn create(&self, opts: &MethodOptions) -> Instance {
        Instance {
            info: self.info.clone(),
            stepper: (self.make)(opts),
        }
    }
}

/// An ordered set of methods with unique names; cheap to clone (shared).
#[derive(Clone, Debug)]
pub struct Registry {
    methods: Arc<Vec<Method>>,
}

impl Default for Registry {
    /// The built-in methods.
    fn default() -> Self {
        Registry::builtin()
    }
}

fn valid_flag(f: &str) -> bool {
    !f.is_empty()
        && !f.starts_with('-')
        && !f.ends_with('-')
        && !f.contains("--")
        && f.bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-')
}

fn valid_name(n: &str) -> bool {
    !n.is_empty()
        && n.bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_')
}

impl Registry {
    /// No methods at all (build up with [`Registry::with`]).
    pub fn empty() -> Self {
        Registry {
            methods: Arc::new(Vec::new()),
        }
    }

    /// This registry plus `m`, refused when its facts are inconsistent: a name or alias
    /// already taken or not snake_case, order 0, an empty summary, an option flag that is not
    /// kebab-case, whose default is below its least value or that another method declares
    /// differently.
    pub fn with(self, m: Method) -> Result<Self> {
        let info = &m.info;
        let refuse = |message: String| Error::Registration {
            name: info.name.to_string(),
            message,
        };
        for n in std::iter::once(&info.name).chain(info.aliases) {
            if !valid_name(n) {
                return Err(refuse(format!(
                    "'{n}' is not a valid name (lower-case letters, digits and '_')"
                )));
            }
            if let Some(other) = self.find(n) {
                return Err(refuse(format!(
                    "the name '{n}' is already taken by '{}'",
                    other.info.name
                )));
            }
        }
        if info.aliases.contains(&info.name) {
            return Err(refuse("an alias repeats the name".into()));
        }
        if info.order == Order::Finite(0) {
            return Err(refuse(
                "order 0 is not an order of accuracy (use Order::Finite(p ≥ 1) or Order::Exact)"
                    .into(),
            ));
        }
        if info.summary.trim().is_empty() {
            return Err(refuse("the summary is empty".into()));
        }
        for spec in info.options {
            if !valid_flag(spec.flag) {
                return Err(refuse(format!(
                    "option '--{}' is not a valid flag (lower-case words joined by '-')",
                    spec.flag
                )));
            }
            if let Err(why) = spec.check(&spec.default_value()) {
                return Err(refuse(format!(
                    "option '--{}': its default {why}",
                    spec.flag
                )));
            }
            let other = self
                .option_schema()
                .into_iter()
                .find(|(o, _)| o.flag == spec.flag);
            if let Some((o, by)) = other.filter(|(o, _)| o != spec) {
                return Err(refuse(format!(
                    "option '--{}' is declared differently by {} ({}, default {}, help \"{}\")",
                    o.flag,
                    by.join(", "),
                    o.kind.what(),
                    o.default_value(),
                    o.help
                )));
            }
            if info.options.iter().filter(|o| o.flag == spec.flag).count() > 1 {
                return Err(refuse(format!("option '--{}' is listed twice", spec.flag)));
            }
        }
        let mut v = (*self.methods).clone();
        v.push(m);
        Ok(Registry {
            methods: Arc::new(v),
        })
    }

    /// The method answering to `name` (its name or an alias).
    pub fn find(&self, name: &str) -> Option<&Method> {
        self.methods.iter().find(|m| m.info.answers_to(name))
    }

    /// The method answering to `name`, or an error listing every known name.
    pub fn get(&self, name: &str) -> Result<&Method> {
        self.find(name).ok_or_else(|| Error::UnknownMethod {
            name: name.to_string(),
            known: self.names().join(", "),
        })
    }

    /// The facts of `name`'s method.
    pub fn info(&self, name: &str) -> Result<&MethodInfo> {
        self.get(name).map(|m| &m.info)
    }

    /// A fresh instance of `name`'s method, refused (naming the flag) when one of the options
    /// it reads is below its least value.
    pub fn create(&self, name: &str, opts: &MethodOptions) -> Result<Instance> {
        let m = self.get(name)?;
        opts.check(m.info.options)?;
        Ok(m.create(opts))
    }

    /// The canonical name for `name` (resolving aliases).
    pub fn canonical(&self, name: &str) -> Option<&'static str> {
        self.find(name).map(|m| m.info.name)
    }

    /// Every method, in registration order.
    pub fn iter(&self) -> impl Iterator<Item = &Method> {
        self.methods.iter()
    }

    /// Every option the registered methods read, in registration order, each once with the
    /// canonical names of the methods that read it: the command line's method flags.
    pub fn option_schema(&self) -> Vec<(OptionSpec, Vec<&'static str>)> {
        let mut out: Vec<(OptionSpec, Vec<&'static str>)> = Vec::new();
        for m in self.methods.iter() {
            for spec in m.info.options {
                match out.iter_mut().find(|(o, _)| o.flag == spec.flag) {
                    Some((_, by)) => by.push(m.info.name),
                    None => out.push((*spec, vec![m.info.name])),
                }
            }
        }
        out
    }

    /// Whether option `flag` changes any of `methods` (names or aliases; a name it does not
    /// know reads nothing): what a recorded command writes and what the command line
    /// refuses. An empty list stands for every method, which reads every option.
    pub fn reads_option(&self, methods: &[String], flag: &str) -> bool {
        methods.is_empty()
            || methods.iter().any(|n| {
                self.find(n)
                    .is_some_and(|m| m.info.options.iter().any(|o| o.flag == flag))
            })
    }

    /// Every canonical name, in registration order.
    pub fn names(&self) -> Vec<&'static str> {
        self.methods.iter().map(|m| m.info.name).collect()
    }

    /// The canonical names of the methods that are not engines (springlab's own and users').
    pub fn native_names(&self) -> Vec<&'static str> {
        self.methods
            .iter()
            .filter(|m| !m.info.engine)
            .map(|m| m.info.name)
            .collect()
    }

    /// The canonical names of the engines (Rapier methods).
    pub fn engine_names(&self) -> Vec<&'static str> {
        self.methods
            .iter()
            .filter(|m| m.info.engine)
            .map(|m| m.info.name)
            .collect()
    }
}
