//! The run of a scenario: the model is built and settled, the controller of the control mode
//! drives the [`SimulatedRobot`] over the duration, every control instant is recorded (the
//! columns of [`crate::robot::columns`]) and observed for the [`Summary`].

use std::cell::RefCell;
use std::ops::ControlFlow;
use std::rc::Rc;
use std::sync::Arc;
use std::time::Instant;

use super::summary::{summarize, GaitStats, RunStats};
use super::{ControlMode, GaitSummary, Result, Scenario, ScenarioError, Summary};
use crate::control::gait::schedule::GaitState;
use crate::control::{joint_pis, Controller, GroundDetector, GroundExperimentController, GroundExperimentState, JointPiController, JointReferences, Unpowered};
use crate::description::Robot as Description;
use crate::hexapod::{LegKinematics, SerialLegKinematics};
use crate::robot::columns::{record_row, ColumnGroups};
use crate::robot::model::{FrictionModel, Robot};
use crate::robot::recorder::{Recorder, TimeSeries};
use crate::robot::simulation::{run_until, SimulatedRobot};
use crate::sim::{static_equilibrium, SimError, StaticOptions};

/// The outcome of [`run_scenario`].
#[derive(Clone, Debug)]
pub struct ScenarioResults {
    /// One row per control instant; empty with [`Record::SummaryOnly`].
    pub series: TimeSeries,
    pub summary: Summary,
}

/// What a run keeps besides its summary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Record {
    /// The time series of every control instant (the columns of [`crate::robot::columns`]).
    TimeSeries,
    /// The summary alone (campaigns of many runs): no time series is built.
    SummaryOnly,
}

/// Runs a scenario and records its time series; `progress` is called with the simulated time
/// at every control instant.
pub fn run_scenario(s: &Scenario, mut progress: impl FnMut(f64)) -> Result<ScenarioResults> {
    run_scenario_until(s, Record::TimeSeries, |t| {
        progress(t);
        ControlFlow::Continue(())
    })
}

/// [`run_scenario`] keeping what `record` says, with a `progress` that may stop the run
/// ([`ScenarioError::Stopped`]).
pub fn run_scenario_until(s: &Scenario, record: Record, progress: impl FnMut(f64) -> ControlFlow<()>) -> Result<ScenarioResults> {
    let (rec, summary) = run(s, record == Record::TimeSeries, |_| ControlFlow::Continue(()), progress)?;
    Ok(ScenarioResults { series: rec.finish(), summary })
}

/// [`run_scenario_until`] handing the time series out in chunks as the run goes, so that it
/// never holds more than one chunk: `chunk` receives the first row alone (the columns are then
/// known), then every `rows_per_chunk` rows, then the rest. A `chunk` that breaks stops the
/// run ([`ScenarioError::Stopped`]). Returns the summary.
pub fn run_scenario_chunked(s: &Scenario, rows_per_chunk: usize, mut chunk: impl FnMut(TimeSeries) -> ControlFlow<()>, progress: impl FnMut(f64) -> ControlFlow<()>) -> Result<Summary> {
    let rows_per_chunk = rows_per_chunk.max(1);
    let (mut rec, summary) = run(
        s,
        true,
        |rec| {
            if rec.rows() == 1 || rec.buffered() >= rows_per_chunk {
                chunk(rec.take_chunk())
            } else {
                ControlFlow::Continue(())
            }
        },
        progress,
    )?;
    if rec.buffered() > 0 && chunk(rec.take_chunk()).is_break() {
        return Err(ScenarioError::Stopped { file: s.origin.clone(), t: s.duration });
    }
    Ok(summary)
}

/// The run: `recorded` rows go to a [`Recorder`], handed to `after_row` after each row.
fn run(s: &Scenario, recorded: bool, mut after_row: impl FnMut(&mut Recorder) -> ControlFlow<()>, mut progress: impl FnMut(f64) -> ControlFlow<()>) -> Result<(Recorder, Summary)> {
    let started = Instant::now();
    let sim_err = |stage: &'static str| move |source: SimError| ScenarioError::Simulation { file: s.origin.clone(), stage, source, hint: "" };
    let mut plant = settled_robot(s)?;
    let q = plant.state().q.as_slice().to_vec();
    let (mut controller, Published { gait: gait_state, ground }) = controller(s);

    // The joint references are recorded and tracked by the PI loops in these modes.
    let pi = s.control.tracks_references();
    let groups = ColumnGroups { references: pi, bristles: s.model.friction == FrictionModel::LuGre };
    let supply = s.model.supply_voltage;
    let weight = plant.robot.model.multibody.total_mass() * crate::mbs::STANDARD_GRAVITY;
    let mut rec = Recorder::default();
    let mut stats = RunStats::default();
    let mut gait_stats = s.gait.as_ref().map(|g| GaitStats::new(g.heading.source()));
    let mut last_t = 0.0;
    let flow = run_until(&mut plant, controller.as_mut(), s.duration, |p, meas, cmd| {
        let state = gait_state.as_ref().map(|g| g.borrow());
        stats.observe(p, cmd, supply, pi);
        if let (Some(state), Some(g), Some(gait_stats)) = (state.as_deref(), &s.gait, gait_stats.as_mut()) {
            let normal: [f64; 6] = std::array::from_fn(|f| p.robot.outputs.contact[f].normal_force);
            gait_stats.observe(p.state().t, p.state().q.as_slice(), state, &normal, weight, &g.workspaces);
        }
        last_t = meas.t;
        if recorded {
            let ground = ground.as_ref().map(|g| g.borrow());
            record_row(&mut rec, p, meas, cmd, groups, state.as_deref(), ground.as_deref());
            after_row(&mut rec)?;
        }
        progress(meas.t)
    })
    .map_err(sim_err("the simulation"))?;
    if flow.is_break() {
        return Err(ScenarioError::Stopped { file: s.origin.clone(), t: last_t });
    }

    let mut summary = summarize(s, &plant, &stats, &q, started.elapsed().as_secs_f64());
    if let (Some(g), Some(state), Some(gait_stats)) = (&s.gait, &gait_state, &gait_stats) {
        summary.gait = Some(GaitSummary::new(g, gait_stats, &state.borrow().diagnostics));
    }
    Ok((rec, summary))
}

/// The simulated robot at the start: feet on the ground, static equilibrium with the joints
/// locked (Section 6.2) unless `initial.settle` is off, then the body raised by
/// `initial.body_height_offset`.
pub fn settled_robot(s: &Scenario) -> Result<SimulatedRobot> {
    let model = Arc::new(s.model());
    let mut q = model.touching_ground(&s.initial.joints);
    let feet = model.foot_positions(&q);
    if let Some(foot) = (0..6).find(|&f| !s.terrain.covers(feet[f].x, feet[f].y)) {
        let terrain = s.terrain_file.clone().unwrap_or_else(|| "of [terrain]".into());
        return Err(ScenarioError::OffTerrain { file: s.origin.clone(), terrain, foot, x: feet[foot].x, y: feet[foot].y });
    }
    // The attitude of the body parallel to the ground, which the settling should keep.
    let (pitch0, roll0) = (q[4], q[5]);
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
        let (pitch, roll) = ((q[4] - pitch0).to_degrees(), (q[5] - roll0).to_degrees());
        if pitch.abs() > 5.0 || roll.abs() > 5.0 {
            return Err(ScenarioError::Tipped { file: s.origin.clone(), pitch_deg: pitch, roll_deg: roll });
        }
    }
    q[2] += s.initial.body_height_offset;
    SimulatedRobot::new(model, &q, &qd, &s.plant).map_err(|source| ScenarioError::Simulation { file: s.origin.clone(), stage: "the start", source, hint: "" })
}

/// What a scenario's controller publishes after each update, for the record.
#[derive(Default)]
pub(super) struct Published {
    /// Walking: the gait controller's state.
    pub gait: Option<Rc<RefCell<GaitState>>>,
    /// The ground detection experiment's state.
    pub ground: Option<Rc<RefCell<GroundExperimentState>>>,
}

/// The controller of the scenario's control mode and what it publishes.
pub(super) fn controller(s: &Scenario) -> (Box<dyn Controller>, Published) {
    match s.control {
        ControlMode::Gait => {
            let g = s.gait.as_ref().expect("gait mode has a validated [gait]");
            let (controller, state) = g.controller(&s.robot);
            (controller, Published { gait: Some(state), ground: None })
        }
        ControlMode::Pi => {
            let pis = joint_pis(&s.robot.pi_gains(), s.plant.period);
            let motions = s.motions.iter().map(|m| (m.joint_index(), m.motion)).collect();
            (Box::new(JointPiController { pis, references: JointReferences { base: s.initial.joints, motions } }), Published::default())
        }
        ControlMode::Unpowered => (Box::new(Unpowered), Published::default()),
        ControlMode::GroundDetection => {
            let e = s.ground_detection.clone().expect("ground_detection mode has a validated [ground_detection]");
            let pis = joint_pis(&s.robot.pi_gains(), s.plant.period);
            let (controller, state): (Box<dyn Controller>, _) = match &s.robot {
                Description::Pantograph(d) => {
                    let legs = LegKinematics::hexapod_from_description(d).expect("a validated description has valid leg kinematics");
                    let (c, state) = GroundExperimentController::new(e.clone(), pis, s.initial.joints, GroundDetector::new(&s.robot, legs, s.plant.period, e.thresholds[0]));
                    (Box::new(c), state)
                }
                Description::Serial(r) => {
                    let legs = SerialLegKinematics::hexapod(&r.hexapod.legs).expect("a validated description has valid leg kinematics");
                    let (c, state) = GroundExperimentController::new(e.clone(), pis, s.initial.joints, GroundDetector::new(&s.robot, legs, s.plant.period, e.thresholds[0]));
                    (Box::new(c), state)
                }
            };
            (controller, Published { gait: None, ground: Some(state) })
        }
    }
}
