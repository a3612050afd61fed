//! The parts of a scenario run that other drivers reuse: the scenario's controller with its
//! recorded gait columns, and its simulated robot at the settled start. The robot link runs
//! the same controller on the real robot ([`crate::link::run`]) and the emulator its slaves on
//! the same simulated robot ([`crate::link::emulator`]), so a linked run starts where
//! [`super::run_scenario`] starts and is controlled as it is.
//!
//! `run_scenario_until` builds the same two things inline; they are kept equal by the link's
//! walk test (master + emulator against `run_scenario`).

use std::cell::RefCell;
use std::rc::Rc;
use std::sync::Arc;

use super::gait::{GaitState, ScheduledGait};
use super::{record_gait, ControlMode, Scenario, ScenarioError};
use crate::control::{joint_pis, Command, Controller, JointPiController, JointReferences, Measurements, Unpowered};
use crate::physics::FlatGround;
use crate::robot::model::{Robot, RobotModel};
use crate::robot::recorder::Recorder;
use crate::robot::simulation::SimulatedRobot;
use crate::sim::{static_equilibrium, StaticOptions};

/// The controller a scenario runs (gait, PI loops or unpowered), as in [`super::run_scenario`].
pub struct ScenarioController {
    controller: Box<dyn Controller>,
    gait: Option<Rc<RefCell<GaitState>>>,
}

impl ScenarioController {
    pub fn new(s: &Scenario) -> Self {
        match s.control {
            ControlMode::Gait => {
                let g = s.gait.as_ref().expect("gait mode has a validated [gait]");
                let (controller, state) = ScheduledGait::new(g, &s.robot);
                ScenarioController { controller: Box::new(controller), gait: Some(state) }
            }
            ControlMode::Pi => {
                let pis = joint_pis(&s.robot, s.plant.period);
                let motions = s.motions.iter().map(|m| (m.joint_index(), m.motion)).collect();
                ScenarioController { controller: Box::new(JointPiController { pis, references: JointReferences { base: s.initial.joints, motions } }), gait: None }
            }
            ControlMode::Unpowered => ScenarioController { controller: Box::new(Unpowered), gait: None },
        }
    }

    /// Whether the controller tracks joint references (PI and gait modes).
    pub fn tracks_references(&self, s: &Scenario) -> bool {
        matches!(s.control, ControlMode::Pi | ControlMode::Gait)
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
    /// foot phases and references; see the module docs of [`super`]) into the row, in gait mode.
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

/// The scenario's simulated robot at its start: feet on the ground, settled in static
/// equilibrium with the joints locked when the scenario says so, body height offset added.
pub fn settled_robot(s: &Scenario) -> Result<SimulatedRobot, ScenarioError> {
    let model = Arc::new(RobotModel::new(&s.robot, s.model.clone(), Arc::new(FlatGround { height: 0.0 })));
    let mut q = model.touching_ground(&s.initial.joints);
    let mut qd = vec![0.0; q.len()];
    if s.initial.settle {
        let mut robot = Robot::new(model.clone());
        let options = StaticOptions { residual_tolerance: 1e-6, max_iterations: 200 };
        static_equilibrium(&mut robot, 0.0, &mut q, &mut qd, &model.standing_locks(), &options).map_err(|source| ScenarioError::Simulation {
            file: s.origin.clone(),
            stage: "settling (static equilibrium with the joints locked)",
            source,
            hint: "; check that the supporting feet surround the centre of mass (initial.lifted_legs)",
        })?;
        let (pitch, roll) = (q[4].to_degrees(), q[5].to_degrees());
        if pitch.abs() > 5.0 || roll.abs() > 5.0 {
            return Err(ScenarioError::Tipped { file: s.origin.clone(), pitch_deg: pitch, roll_deg: roll });
        }
    }
    q[2] += s.initial.body_height_offset;
    SimulatedRobot::new(model, &q, &qd, &s.plant).map_err(|source| ScenarioError::Simulation { file: s.origin.clone(), stage: "the start", source, hint: "" })
}
