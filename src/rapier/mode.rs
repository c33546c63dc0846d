//! The two Rapier backends: which joint family carries the scene's springs, and each one's
//! method name (the registry registers them under these names).

/// CLI name of the impulse-joint backend.
pub const IMPULSE: &str = "rapier_impulse";
/// CLI name of the multibody backend.
pub const MULTIBODY: &str = "rapier_multibody";

/// Which Rapier joint family carries the scene's springs and constraints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Every spring and constraint is an impulse joint.
    Impulse,
    /// Tree edges are multibody joints; loops and edges past the tree cap are impulse joints.
    Multibody,
}

impl Mode {
    /// The backend's method name.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Impulse => IMPULSE,
            Mode::Multibody => MULTIBODY,
        }
    }
    /// The mode of the backend called `name`, `None` for any other method.
    pub fn of(name: &str) -> Option<Mode> {
        [Mode::Impulse, Mode::Multibody]
            .into_iter()
            .find(|m| m.name() == name)
    }
}
