//! A method ready to run: a fresh stepper with the registry's facts about it, so that the
//! runner reads how the method meets it (contacts, frame splitting) from the facts, written
//! once in the registry, and never from the stepper.

use super::info::MethodInfo;
use crate::integrate::Stepper;

/// A fresh stepper of a registered method and that method's facts.
pub struct Instance {
    /// The method's facts, as registered.
    pub info: MethodInfo,
    /// The stepper, owning its scratch and history.
    pub stepper: Box<dyn Stepper>,
}

impl std::fmt::Debug for Instance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Instance")
            .field("method", &self.info.name)
            .finish()
    }
}

/// An instance steps as its stepper does.
impl std::ops::Deref for Instance {
    type Target = dyn Stepper;
    fn deref(&self) -> &Self::Target {
        self.stepper.as_ref()
    }
}

/// An instance steps as its stepper does.
impl std::ops::DerefMut for Instance {
    fn deref_mut(&mut self) -> &mut Self::Target {
        self.stepper.as_mut()
    }
}

impl Instance {
    /// The method's canonical name.
    pub fn name(&self) -> &'static str {
        self.info.name
    }
}

/// The stepper alone, for code that steps it outside the runner (a reference's samples).
impl AsMut<dyn Stepper> for Instance {
    fn as_mut(&mut self) -> &mut (dyn Stepper + 'static) {
        self.stepper.as_mut()
    }
}
