//! What every measuring command shares, declared once: which methods run, from which registry
//! and with which options, the runner's blow-up factor, whether progress is printed, and the
//! time budget. Each command's config holds one [`Common`] beside its own settings.

use crate::measure::command::CommandLine;
use crate::method::{MethodOptions, Registry};

/// The settings every measuring command shares.
#[derive(Debug, Clone)]
pub struct Common {
    /// Methods by name (empty: every one that applies to the scene and the command).
    pub methods: Vec<String>,
    /// The methods the names are looked up in (built-ins unless a library user added theirs).
    pub registry: Registry,
    /// Method options.
    pub options: MethodOptions,
    /// The runner's blow-up factor (see [`crate::run::RunPlan::blowup_factor`]).
    pub blowup_factor: f64,
    /// Print progress lines to stderr.
    pub progress: bool,
    /// Time budget in modelled seconds of runs (`None`: unlimited; `--budget`).
    pub budget_seconds: Option<f64>,
}

impl Common {
    /// Which of these methods apply to `sys` (every registered one when none is named):
    /// canonical names, split into (applicable, skipped with the reason).
    #[allow(clippy::type_complexity)]
    pub fn applicable(
        &self,
        sys: &crate::model::System,
    ) -> crate::error::Result<(Vec<String>, Vec<(String, String)>)> {
        crate::measure::case::applicable(&self.registry, sys, &self.methods, &self.options)
    }

    /// `line` with these settings' flags, as the command line takes them: `--methods` (the
    /// names `methods` the document lists), the options any of them reads, `--blowup-factor`
    /// and `--budget` when there is one. Every recorded command renders them here.
    pub fn recorded(&self, line: CommandLine, methods: &[String]) -> CommandLine {
        line.list("methods", methods)
            .method_options(&self.registry, methods, &self.options)
            .flag("blowup-factor", self.blowup_factor)
            .flag_opt("budget", self.budget_seconds)
    }
}

impl Default for Common {
    /// Every method of the built-in registry with default options, the default blow-up
    /// factor, no progress, no budget.
    fn default() -> Self {
        Common {
            methods: Vec::new(),
            registry: Registry::builtin(),
            options: MethodOptions::default(),
            blowup_factor: crate::run::DEFAULT_BLOWUP_FACTOR,
            progress: false,
            budget_seconds: None,
        }
    }
}
