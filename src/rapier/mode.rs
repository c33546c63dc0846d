//! The two Rapier methods: which joint family carries the scene's springs, and each one's
//! method name (the registry registers them under these names).

/// CLI name of the impulse-joint method.
pub const IMPULSE: &str = "rapier_impulse";
/// CLI name of the multibody method.
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
    /// The method's name.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Impulse => IMPULSE,
            Mode::Multibody => MULTIBODY,
        }
    }
    /// The mode of the method called `name`, `None` for any other method.
    pub fn of(name: &str) -> Option<Mode> {
        [Mode::Impulse, Mode::Multibody]
            .into_iter()
            .find(|m| m.name() == name)
    }
}
