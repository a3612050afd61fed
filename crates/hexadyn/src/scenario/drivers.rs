//! The parts of a scenario run that other drivers reuse: the scenario's controller with its
//! recorded gait columns, and its simulated robot at the settled start. The robot link runs
//! the same controller on the real robot ([`crate::link::run`]) and the emulator its slaves on
//! the same simulated robot ([`crate::link::emulator`], through [`super::settled_robot`]);
//! [`super::run_scenario`] is built from the same two functions, so a linked run starts and is controlled as a simulated one.

use std::cell::RefCell;
use std::rc::Rc;

use super::run::controller;
use super::Scenario;
use crate::control::gait::schedule::GaitState;
use crate::control::{Command, Controller, Measurements};
use crate::robot::columns::record_gait;
use crate::robot::recorder::Recorder;

/// The controller a scenario runs (gait, PI loops, ground detection experiment or unpowered), as
/// in [`super::run_scenario`]. Only the gait columns are recorded by the other drivers.
pub struct ScenarioController {
    controller: Box<dyn Controller>,
    gait: Option<Rc<RefCell<GaitState>>>,
}

impl ScenarioController {
    pub fn new(s: &Scenario) -> Self {
        let (controller, published) = controller(s);
        ScenarioController { controller, gait: published.gait }
    }

    /// The recorder of the gait columns, which stays readable while the controller is driven.
    pub fn gait_columns(&self) -> GaitColumns {
        GaitColumns(self.gait.clone())
    }
}

/// The gait columns of a [`ScenarioController`]'s last update.
pub struct GaitColumns(Option<Rc<RefCell<GaitState>>>);

impl GaitColumns {
    /// Puts the gait columns of the last update (desired body pose and velocities, duty factor,
    /// foot phases and references; see [`crate::robot::columns`]) into the row, in gait mode.
    pub fn record(&self, rec: &mut Recorder) {
        if let Some(g) = &self.0 {
            record_gait(rec, &g.borrow());
        }
    }
}

impl Controller for ScenarioController {
    fn update(&mut self, m: &Measurements) -> Command {
        self.controller.update(m)
    }
}
