//! Scenarios: a ready-to-run simulation of the robot described by a TOML file, and its run into
//! a [`TimeSeries`] with units and a [`Summary`].
//!
//! The file format (every table and key with its unit, default and allowed values) is documented
//! once, in `docs/scenario-format.md`; the shipped scenarios (`python/hexadyn/scenarios/`) are
//! examples of it. Every error names the file, the line, the dotted field, the value and what is
//! allowed, like the robot description ([`crate::description`]).
//!
//! The module is cut by job (private submodules):
//! - `file.rs`: the file's raw serde mirror with its defaults, and its validation into a
//!   [`Scenario`] (robot, model and integrator options, initial configuration, control mode,
//!   joint motions); `gait.rs`: the `[gait]` table, mirrored and validated into a
//!   [`GaitScenario`]; `joint_friction.rs`: `[model.joint_friction]`, likewise; `overrides.rs`:
//!   fields set from outside the file by dotted name ([`Scenario::from_file_with`],
//!   [`Override`], e.g. `gait.heading.vx_m_s = 0.01`: the friction comparison and the Monte
//!   Carlo campaigns run one file under many overrides);
//! - `run.rs`: the run ([`run_scenario`], [`run_scenario_until`], and [`run_scenario_chunked`]
//!   handing the time series out in chunks, for long runs streamed to disk);
//! - `summary.rs`: what the run is reduced to ([`Summary`], [`GaitSummary`]).
//!
//! # Run and results
//!
//! [`run_scenario`] builds the model, settles it ([`static_equilibrium`] with
//! [`RobotModel::standing_locks`]), runs the controller of the control mode on the
//! [`SimulatedRobot`] with [`run_until`] (in gait mode the gait controller with its schedule of
//! gait changes, [`crate::control::gait::schedule`]) and records one row per control instant,
//! the start and the end included: the columns of [`crate::robot::columns`]. The [`Summary`]
//! holds the totals (energies and their balance, integration statistics, body height change,
//! saturation, limit-switch cuts, tracking errors, the averaged power and in gait mode the
//! specific resistance ξ = E/(m g l) of Eq. 6.6) and in gait mode a [`GaitSummary`].
//!
//! Runs are deterministic: the same scenario gives bit-identical columns.
//!
//! [`static_equilibrium`]: crate::sim::static_equilibrium
//! [`RobotModel::standing_locks`]: crate::robot::model::RobotModel::standing_locks
//! [`SimulatedRobot`]: crate::robot::simulation::SimulatedRobot
//! [`run_until`]: crate::robot::simulation::run_until
//! [`TimeSeries`]: crate::robot::recorder::TimeSeries

use std::path::Path;
use std::sync::Arc;

use serde::Deserialize;

use crate::control::{GroundExperiment, JointMotion};
use crate::description::Robot;
use crate::fields::{struct_fields, Ctx, DescriptionError, FieldError, SpanIndex};
use crate::hexapod::JOINTS;
use crate::robot::model::{FrictionModel, ModelOptions, RobotModel};
use crate::robot::simulation::PlantOptions;
use crate::physics::Terrain;
use crate::sim::SimError;

mod drivers;
mod episodes;
mod file;
mod gait;
mod joint_friction;
mod overrides;
mod run;
mod summary;
mod terrain;

pub use crate::control::gait::schedule::GaitChange;
pub use gait::{FreeGaitSpec, GaitLegs, GaitScenario, HeadingSpec, LandingSpec, DEFAULT_CLEARANCE, DEFAULT_DUTY_FACTOR, DEFAULT_OVERLAP};
pub use overrides::Override;
pub use drivers::{GaitColumns, ScenarioController};
pub use joint_friction::{physical_bounds, serial_parameters};
pub use run::settled_robot;
pub use run::{run_scenario, run_scenario_chunked, run_scenario_until, Record, ScenarioResults};
pub use summary::{per_joint_entries, specific_resistance, GaitSummary, Summary, SummaryValue};

/// Name of the embedded default robot in `scenario.robot`.
pub const DEFAULT_ROBOT: &str = "amru5";

/// Where "missing field" errors send the reader.
const REFERENCE: &str = "docs/scenario-format.md or the shipped scenarios";

// =============================================================================================
// Errors
// =============================================================================================

/// A scenario that could not be read, validated or run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ScenarioError {
    /// The scenario file could not be read.
    #[error("{file}: cannot read the scenario: {reason}")]
    Io { file: String, reason: String },
    /// The text is not valid TOML.
    #[error("{file}:{line}:{column}: TOML syntax error: {message}")]
    Syntax { file: String, line: usize, column: usize, message: String },
    /// A field is missing, unknown, of the wrong type or out of its allowed range.
    #[error("{0}")]
    Field(Box<FieldError>),
    /// The robot description the scenario names is invalid (the message names its file).
    #[error("{0}")]
    Robot(DescriptionError),
    /// The settling or the simulation failed; `hint` (empty or starting with "; ") suggests a
    /// cause.
    #[error("{file}: {stage} failed: {source}{hint}")]
    Simulation { file: String, stage: &'static str, source: SimError, hint: &'static str },
    /// The settled body tilts by more than 5° from the ground below it: the stance cannot carry it (it rests on lifted
    /// legs).
    #[error("{file}: settling tips the body over (pitch {pitch_deg:.1}°, roll {roll_deg:.1}°); check that the supporting feet surround the centre of mass (initial.lifted_legs)")]
    Tipped { file: String, pitch_deg: f64, roll_deg: f64 },
    /// A foot stands beyond the border of the terrain mesh at the start.
    #[error("{file}: foot {foot} stands at (x, y) = ({x:.3}, {y:.3}) m, beyond the border of the terrain mesh {terrain}: the mesh must cover the ground under the robot at the start (it stands centred on x = y = 0)")]
    OffTerrain { file: String, terrain: String, foot: usize, x: f64, y: f64 },
    /// The progress callback asked to stop.
    #[error("{file}: stopped at t = {t:.3} s")]
    Stopped { file: String, t: f64 },
}

impl ScenarioError {
    /// The dotted field path, for field errors.
    pub fn field(&self) -> Option<&str> {
        match self {
            ScenarioError::Field(e) => Some(&e.field),
            _ => None,
        }
    }

    /// A validation error of the scenario file itself (reported with the scenario's name).
    fn from_parse(e: DescriptionError) -> Self {
        match e {
            DescriptionError::Io { file, reason } => ScenarioError::Io { file, reason },
            DescriptionError::Syntax { file, line, column, message } => ScenarioError::Syntax { file, line, column, message },
            DescriptionError::Field(f) => ScenarioError::Field(f),
        }
    }
}

type Result<T> = std::result::Result<T, ScenarioError>;

/// Control mode of a scenario.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ControlMode {
    /// 18 digital PI loops (Eq. 4.18-4.20, Table 4.1) tracking the initial joints plus motions.
    #[default]
    Pi,
    /// All voltages zero (Section 6.2): the motor circuits are closed through the H-bridges.
    Unpowered,
    /// The gait controller of Chapter 7 (`[gait]` table): heading velocities, foot references,
    /// inverse kinematics and the same 18 PI loops.
    Gait,
    /// The ground detection experiment of Section 5.6.3 (`[ground_detection]` table): the
    /// tested legs lowered in a sawtooth onto the ground and stopped on the detection from the
    /// motor currents, the same 18 PI loops.
    GroundDetection,
}

impl ControlMode {
    pub fn name(self) -> &'static str {
        match self {
            ControlMode::Pi => "pi",
            ControlMode::Unpowered => "unpowered",
            ControlMode::Gait => "gait",
            ControlMode::GroundDetection => "ground_detection",
        }
    }

    /// Whether the controller tracks joint references (the PI loops of modes `pi`, `gait` and
    /// `ground_detection`), so that references and tracking errors are recorded.
    pub fn tracks_references(self) -> bool {
        matches!(self, ControlMode::Pi | ControlMode::Gait | ControlMode::GroundDetection)
    }
}

// =============================================================================================
// The validated scenario
// =============================================================================================

/// Initial configuration (before settling), SI.
#[derive(Clone, Debug, PartialEq)]
pub struct Initial {
    /// Joint positions per joint k = 3 leg + j (j in the order of the robot's joints; AMRU5:
    /// 0 q_r, 1 q_v, 2 q_h).
    pub joints: [f64; JOINTS],
    pub lifted_legs: Vec<usize>,
    /// Static equilibrium with the joints locked before the start (Section 6.2).
    pub settle: bool,
    /// Added to the body height Z after settling (m).
    pub body_height_offset: f64,
}

/// A joint motion of the PI references.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    pub leg: usize,
    /// Which joint of the leg (0..3, in the order of the robot's [`crate::hexapod::LegJoints`]).
    pub joint: usize,
    pub motion: JointMotion,
}

impl Motion {
    /// Joint index k = 3 leg + joint.
    pub fn joint_index(&self) -> usize {
        3 * self.leg + self.joint
    }
}

/// The `[model]` flags of a scenario (the rest of [`ModelOptions`] comes from the robot).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ModelFlags {
    pub friction: FrictionModel,
    pub load_dependence: bool,
    pub inductance: bool,
}

/// A validated scenario, SI units.
#[derive(Clone, Debug)]
pub struct Scenario {
    pub name: String,
    pub description: String,
    /// Simulated time (s); the run covers round(duration / period) control periods.
    pub duration: f64,
    pub robot: Robot,
    /// `"amru5"` or the path of the robot description file as opened.
    pub robot_source: String,
    /// The text of the robot description (the embedded file for `"amru5"`).
    pub robot_text: String,
    pub model: ModelOptions,
    pub plant: PlantOptions,
    pub initial: Initial,
    pub control: ControlMode,
    pub motions: Vec<Motion>,
    /// The walking set-up, in gait mode.
    pub gait: Option<GaitScenario>,
    /// The ground (`[terrain]`; flat at z = 0 without it).
    pub terrain: Arc<dyn Terrain>,
    /// The PLY file of a mesh terrain, for the messages.
    pub terrain_file: Option<String>,
    /// The ground detection experiment, in mode `ground_detection`.
    pub ground_detection: Option<GroundExperiment>,
    /// The scenario file (or origin name).
    pub origin: String,
    /// The scenario text.
    pub text: String,
}

impl Scenario {
    /// Reads and validates a scenario file; a relative `robot` path is taken from its folder.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Scenario> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let text = crate::fields::read_input(path).map_err(|reason| ScenarioError::Io { file: file.clone(), reason })?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_str(&text, &file, &dir)
    }

    /// [`Scenario::from_file`] with some fields set from outside the file ([`Override`]); the
    /// scenario's `text` is then the effective one.
    pub fn from_file_with(path: impl AsRef<Path>, overrides: &[Override]) -> Result<Scenario> {
        if overrides.is_empty() {
            return Self::from_file(path);
        }
        let path = path.as_ref();
        let file = path.display().to_string();
        let text = crate::fields::read_input(path).map_err(|reason| ScenarioError::Io { file: file.clone(), reason })?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let effective = overrides::apply(&text, &file, overrides)?;
        Self::from_str(&effective, &format!("{file} (with overrides)"), &dir).map_err(|e| overrides::locate(e, overrides))
    }

    /// Parses and validates a scenario; `origin` names it in errors, `dir` is the folder a
    /// relative `robot` path is taken from.
    #[allow(clippy::should_implement_trait)]
    pub fn from_str(text: &str, origin: &str, dir: &Path) -> Result<Scenario> {
        let index = SpanIndex::build_for(text, origin, REFERENCE).map_err(ScenarioError::from_parse)?;
        index.check_top_level(struct_fields::<file::RawScenario>()).map_err(ScenarioError::from_parse)?;
        let raw: file::RawScenario = toml::from_str(text).map_err(|e| ScenarioError::from_parse(index.serde_error(&e)))?;
        let c = Ctx { file: origin, index: Some(&index) };
        file::validate(&raw, &c, text, origin, dir)
    }

    /// The `[model]` flags of a scenario text, parsed as [`Scenario::from_str`] parses them,
    /// without validating the rest (the robot file a stored scenario names may be gone):
    /// what results saved before their metadata held the flags are read with.
    pub fn model_flags(text: &str, origin: &str) -> Result<ModelFlags> {
        let index = SpanIndex::build_for(text, origin, REFERENCE).map_err(ScenarioError::from_parse)?;
        let raw: file::RawScenario = toml::from_str(text).map_err(|e| ScenarioError::from_parse(index.serde_error(&e)))?;
        Ok(raw.model_flags())
    }

    /// The control period (s).
    pub fn period(&self) -> f64 {
        self.plant.period
    }

    /// The robot model of the scenario: its robot's parts under the scenario's model options,
    /// on its terrain.
    pub fn model(&self) -> RobotModel {
        RobotModel::assemble(self.robot.parts(&self.model), self.model.clone(), self.terrain.clone())
    }
}
