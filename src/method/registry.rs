//! The registry: every method springlab can run, with its facts and its constructor, in the
//! order reports list them. Built-ins come first; a library user adds their own with
//! [`Registry::with`], and every command that takes a registry then runs it like a built-in.

use super::info::{MethodInfo, Order};
use crate::error::{Error, Result};
use crate::integrate::{Integrator, IntegratorOptions};
use std::sync::Arc;

/// Builds a fresh, independent instance of a method.
pub type Constructor = dyn Fn(&IntegratorOptions) -> Box<dyn Integrator> + Send + Sync;

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
        make: impl Fn(&IntegratorOptions) -> Box<dyn Integrator> + Send + Sync + 'static,
    ) -> Self {
        Method {
            info,
            make: Arc::new(make),
        }
    }
    /// A fresh instance.
    pub fn create(&self, opts: &IntegratorOptions) -> Box<dyn Integrator> {
        (self.make)(opts)
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

    /// springlab's own integrators and the Rapier backends.
    pub fn builtin() -> Self {
        static BUILTIN: std::sync::OnceLock<Registry> = std::sync::OnceLock::new();
        BUILTIN
            .get_or_init(|| {
                super::builtin::methods()
                    .into_iter()
                    .try_fold(Registry::empty(), Registry::with)
                    .expect("built-in methods have consistent facts")
            })
            .clone()
    }

    /// This registry plus `m`, refused when its facts are inconsistent: a name or alias
    /// already taken or not snake_case, order 0, an empty summary, or a constructor whose
    /// instances report another name.
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
        let made = m.create(&IntegratorOptions::default());
        if made.name() != info.name {
            return Err(refuse(format!(
                "its constructor makes an integrator named '{}'",
                made.name()
            )));
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
        self.find(name).ok_or_else(|| Error::UnknownIntegrator {
            name: name.to_string(),
            known: self.names().join(", "),
        })
    }

    /// The facts of `name`'s method.
    pub fn info(&self, name: &str) -> Result<&MethodInfo> {
        self.get(name).map(|m| &m.info)
    }

    /// A fresh instance of `name`'s method.
    pub fn create(&self, name: &str, opts: &IntegratorOptions) -> Result<Box<dyn Integrator>> {
        self.get(name).map(|m| m.create(opts))
    }

    /// The canonical name for `name` (resolving aliases).
    pub fn canonical(&self, name: &str) -> Option<&'static str> {
        self.find(name).map(|m| m.info.name)
    }

    /// Every method, in registration order.
    pub fn iter(&self) -> impl Iterator<Item = &Method> {
        self.methods.iter()
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

    /// The canonical names of the engines (Rapier backends).
    pub fn engine_names(&self) -> Vec<&'static str> {
        self.methods
            .iter()
            .filter(|m| m.info.engine)
            .map(|m| m.info.name)
            .collect()
    }
}
