//! Scenarios: a ready-to-run simulation of the robot described by a TOML file, and its run into
//! a [`TimeSeries`] with units and a [`Summary`].
//!
//! # File format
//!
//! Units are SI; angles are in radians except where a key ends in `_deg`. Unknown keys are
//! errors. Every error names the file, the line, the dotted field, the value and what is
//! allowed, like the robot description ([`super::description`]).
//!
//! ```toml
//! [scenario]
//! name = "stand_six_legs"          # required, non-empty
//! description = "..."              # optional
//! duration_s = 10.0                # required, >= one control period; run in whole periods
//! robot = "amru5"                  # default: the embedded AMRU5 description; or a path
//!                                  # relative to the scenario file
//!
//! [model]                          # optional table
//! friction = "lugre"               # "none" | "dry_viscous" | "lugre" (default "lugre")
//! load_dependence = false          # Eq. 5.12 on the horizontal joints (needs friction)
//! inductance = false               # currents as states (Eq. 3.91) instead of Eq. 4.4
//! k_gnd = 1.0e6                    # optional overrides of the robot's ground (Table 3.3):
//! d_gnd = 5.0e4                    #   K_gnd N/m^p_K, D_gnd N s/m^(p_D+1), mu (1),
//! mu = 0.3
//! supply_voltage_v = 12.0          #   and of the H-bridge supply (V)
//! [model.joint_friction.q_h]       # optional: friction identical for every leg (Section 6.5),
//! tau_f_d_plus = 328.5             #   replacing Tables 5.3/5.5 key by key; see the private
//! a_2_plus = 5.5                   #   submodule joint_friction for the keys and signs
//!
//! [integrator]                     # optional table
//! tolerance = 1.0                  # error estimate of Eq. 3.15 in units of the layout scales
//! h_max_s = 0.01                   # largest step, (0, control period]
//!
//! [initial]                        # optional table; defaults shown
//!                                  # (gait mode: only settle and body_height_offset_m)
//! q_r_deg = 0.0                    # q_r of every leg (deg, within the joint range)
//! q_v_m = 0.06                     # q_v of the supporting legs (m)
//! q_h_m = 0.03                     # q_h of every leg (m)
//! lifted_legs = []                 # legs 0..5 held up at q_v_lifted_m
//! q_v_lifted_m = 0.045             # < q_v_m: a smaller q_v lifts the foot (z_foot ~ -6 q_v)
//! settle = true                    # static equilibrium with the joints locked (Section 6.2)
//! body_height_offset_m = 0.0       # >= 0, added to the body height after settling
//!
//! [control]                        # optional table
//! mode = "pi"                      # "pi": 18 digital PI loops (Table 4.1) holding the initial
//!                                  # joints plus the motions below; "unpowered": 0 V;
//!                                  # "gait": walking, with a [gait] table (see `gait` below)
//! [[control.motion]]               # any number; one per (leg, joint); needs mode = "pi"
//! leg = 1                          # 0..5
//! joint = "q_v"                    # "q_r" | "q_v" | "q_h"
//! kind = "ramp"                    # "ramp": rate, start_s (default 0), stop_s (default the end)
//! rate = 0.00857                   # "sine": amplitude, frequency_hz
//!                                  # "sawtooth": min, max, speed
//! ```
//!
//! Walking scenarios (`mode = "gait"`) add a `[gait]` table: period, pattern, duty factor,
//! foot cycle and overlap, AEP mode, clearance, navigation, body height, `[gait.heading]` (the
//! heading velocities: constant, CSV file, the paths of Section 7.5.3) and `[[gait.change]]`
//! (gait changes while walking); its format is in the docs of the private submodule `gait`
//! (`src/robot/scenario/gait.rs`), summarized in docs/architecture.md. Every support stroke
//! |v_C| (β + 4Δφ) T must fit the workspace diameter. The legs start at their workspace centres
//! at the body height.
//!
//! [`Scenario::from_file_with`] sets fields from outside the file by dotted name
//! ([`Override`], e.g. `gait.heading.vx_m_s = 0.01`): the friction comparison and the Monte
//! Carlo campaigns run one file under many overrides.
//!
//! Motion values are SI joint units: rad, rad/s for q_r; m, m/s for q_v and q_h. The reference
//! is the initial joint position (the base) plus the motion ([`JointMotion`]); it must stay
//! within the joint stroke of the robot description (`joint_ranges`) over the run.
//!
//! # Run and results
//!
//! [`run_scenario`] builds the model, settles it ([`static_equilibrium`] with
//! [`RobotModel::standing_locks`]), runs the controller on the [`SimulatedRobot`] with
//! [`run_until`] and records one row per control instant (the start and the end included).
//! Each row holds the state at that instant t; the electrical columns (`u_*`, `i_*`, `tau_m_*`)
//! are those of the voltage held during the control period that ends at t — what the current
//! sensors read at t —, the references (`q_*_ref`) those the controller computed at t.
//!
//! | columns | unit | |
//! | --- | --- | --- |
//! | `t` | s | control instant |
//! | `X`, `Y`, `Z`; `yaw`, `pitch`, `roll` | m; rad | body pose (Eq. 3.51-3.52) |
//! | `X_dot` ... `roll_dot` | m/s; rad/s | body velocities |
//! | `q_r[i]`, `q_v[i]`, `q_h[i]` | rad, m, m | joints of leg i |
//! | `q_r_dot[i]` ... | rad/s, m/s | joint velocities |
//! | `q_r_ref[i]` ... | rad, m | joint references (modes `pi` and `gait`) |
//! | `X_ref`, `Y_ref`, `Z_ref`; `yaw_ref`, `pitch_ref`, `roll_ref` | m; rad | desired body pose T*_{0,b} (gait) |
//! | `X_dot_ref`, `Y_dot_ref`; `omega_z_ref` | m/s; rad/s | commanded heading velocities (gait) |
//! | `duty_factor` | 1 | β of the current gait pattern (gait) |
//! | `phase[l]` | 1 | foot phase code of leg l: 0 support, 1 takeoff, 2 swing, 3 landing (gait) |
//! | `foot_ref_x[l]`, `foot_ref_y[l]`, `foot_ref_z[l]` | m | foot reference in the leg frame (gait) |
//! | `u_q_v[i]` ... | V | voltage across motor + H-bridge (after saturation and limit switches) |
//! | `i_q_v[i]` ... | A | motor current |
//! | `tau_m_q_v[i]` ... | Nm (q_r), N | motor torque at the joint, n k_t i |
//! | `tau_f_q_v[i]` ... | Nm (q_r), N | joint friction torque |
//! | `z_q_v[i]` ... | rad (q_r), m | LuGre bristle deflection (friction `lugre` only) |
//! | `Fx[f]`, `Fy[f]`, `Fz[f]`, `Fn[f]` | N | ground force on foot f (global frame), normal part |
//! | `penetration[f]` | m | δ: > 0 in the ground, < 0 the clearance |
//! | `foot_x[f]`, `foot_y[f]`, `foot_z[f]` | m | foot position (global frame) |
//! | `E_el_q_v[i]`, `E_joule_q_v[i]`, `E_fric_q_v[i]` ... | J | cumulative electrical energy ∫u i dt, Joule losses, friction work ∫τ_f q' dt |
//! | `E_kin`, `E_pot` | J | kinetic and gravitational potential energy |
//! | `E_contact`, `E_stored`, `E_balance` | J | cumulative work on the ground; energy in bristles, ground springs and inductances; energy balance error |
//!
//! In gait mode the [`Summary`] adds a [`GaitSummary`]: body XY tracking error (largest and
//! final), yaw error, distance walked and its reference, clamped IK references, gait switches,
//! fewest feet on the ground, largest excursion of a foot reference outside its workspace.
//!
//! Runs are deterministic: the same scenario gives bit-identical columns.

use std::collections::BTreeSet;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use serde::Deserialize;

use crate::description::{Ctx, DescriptionError, FieldError, RobotDescription, SpanIndex, AMRU5_TOML};
use crate::hexapod::{Joint, JOINTS};
use crate::robot::model::{FrictionModel, ModelOptions, Robot, RobotModel};
use crate::robot::recorder::{Recorder, TimeSeries};
use crate::robot::simulation::{run_until, PlantOptions, SimulatedRobot};

mod drivers;
mod gait;
mod joint_friction;
mod overrides;
pub use overrides::Override;
pub use drivers::{settled_robot, GaitColumns, ScenarioController};
pub use gait::{phase_code, GaitChange, GaitScenario, GaitSummary, HeadingSpec, DEFAULT_CLEARANCE, DEFAULT_DUTY_FACTOR, DEFAULT_OVERLAP};
use crate::control::{joint_pis, Command, Controller, JointMotion, JointPiController, JointReferences, Measurements, Unpowered};
use crate::physics::FlatGround;
use crate::sim::{static_equilibrium, SimError, StaticOptions};

/// Name of the embedded default robot in `scenario.robot`.
pub const DEFAULT_ROBOT: &str = "amru5";

/// Where "missing field" errors send the reader.
const REFERENCE: &str = "the module docs of hexadyn::scenario or the shipped scenarios";

/// Relative tolerance on stroke checks (a sawtooth written to the printed stroke ends passes).
const STROKE_TOLERANCE: f64 = 1e-6;

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
    /// The settled body tilts by more than 5°: the stance cannot carry it (it rests on lifted
    /// legs).
    #[error("{file}: settling tips the body over (pitch {pitch_deg:.1}°, roll {roll_deg:.1}°); check that the supporting feet surround the centre of mass (initial.lifted_legs)")]
    Tipped { file: String, pitch_deg: f64, roll_deg: f64 },
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

// =============================================================================================
// Raw mirror of the file
// =============================================================================================

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScenario {
    scenario: RawHeader,
    #[serde(default)]
    model: RawModel,
    #[serde(default)]
    integrator: RawIntegrator,
    #[serde(default)]
    initial: RawInitial,
    #[serde(default)]
    control: RawControl,
    gait: Option<gait::RawGait>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHeader {
    name: String,
    #[serde(default)]
    description: String,
    duration_s: f64,
    #[serde(default = "default_robot")]
    robot: String,
}

fn default_robot() -> String {
    DEFAULT_ROBOT.to_string()
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawModel {
    #[serde(default = "default_friction")]
    friction: FrictionModel,
    #[serde(default)]
    load_dependence: bool,
    #[serde(default)]
    inductance: bool,
    k_gnd: Option<f64>,
    d_gnd: Option<f64>,
    mu: Option<f64>,
    supply_voltage_v: Option<f64>,
    #[serde(default)]
    joint_friction: joint_friction::RawJointFriction,
}

fn default_friction() -> FrictionModel {
    FrictionModel::LuGre
}

impl Default for RawModel {
    fn default() -> Self {
        RawModel { friction: default_friction(), load_dependence: false, inductance: false, k_gnd: None, d_gnd: None, mu: None, supply_voltage_v: None, joint_friction: Default::default() }
    }
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawIntegrator {
    tolerance: Option<f64>,
    h_max_s: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInitial {
    // The joint fields are options so that gait mode can reject them when written.
    q_r_deg: Option<f64>,
    q_v_m: Option<f64>,
    q_h_m: Option<f64>,
    lifted_legs: Option<Vec<i64>>,
    q_v_lifted_m: Option<f64>,
    #[serde(default = "default_true")]
    settle: bool,
    #[serde(default)]
    body_height_offset_m: f64,
}

fn default_q_v() -> f64 {
    0.06
}
fn default_q_h() -> f64 {
    0.03
}
fn default_q_v_lifted() -> f64 {
    0.045
}
fn default_true() -> bool {
    true
}

impl Default for RawInitial {
    fn default() -> Self {
        RawInitial { q_r_deg: None, q_v_m: None, q_h_m: None, lifted_legs: None, q_v_lifted_m: None, settle: true, body_height_offset_m: 0.0 }
    }
}

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
}

impl ControlMode {
    pub fn name(self) -> &'static str {
        match self {
            ControlMode::Pi => "pi",
            ControlMode::Unpowered => "unpowered",
            ControlMode::Gait => "gait",
        }
    }
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawControl {
    #[serde(default)]
    mode: ControlMode,
    #[serde(default)]
    motion: Vec<RawMotion>,
}

#[derive(Clone, Copy, Deserialize)]
enum RawJoint {
    #[serde(rename = "q_r")]
    Rotation,
    #[serde(rename = "q_v")]
    Vertical,
    #[serde(rename = "q_h")]
    Horizontal,
}

#[derive(Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
enum MotionKind {
    Ramp,
    Sine,
    Sawtooth,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMotion {
    leg: i64,
    joint: RawJoint,
    kind: MotionKind,
    rate: Option<f64>,
    start_s: Option<f64>,
    stop_s: Option<f64>,
    amplitude: Option<f64>,
    frequency_hz: Option<f64>,
    min: Option<f64>,
    max: Option<f64>,
    speed: Option<f64>,
}

// =============================================================================================
// The validated scenario
// =============================================================================================

/// Initial configuration (before settling), SI.
#[derive(Clone, Debug, PartialEq)]
pub struct Initial {
    /// Joint positions per joint k = 3 leg + (0: q_r, 1: q_v, 2: q_h).
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
    pub joint: Joint,
    pub motion: JointMotion,
}

impl Motion {
    /// Joint index k = 3 leg + joint.
    pub fn joint_index(&self) -> usize {
        3 * self.leg + joint_number(self.joint)
    }
}

fn joint_number(j: Joint) -> usize {
    match j {
        Joint::Rotation => 0,
        Joint::Vertical => 1,
        Joint::Horizontal => 2,
    }
}

/// A validated scenario, SI units.
#[derive(Clone, Debug)]
pub struct Scenario {
    pub name: String,
    pub description: String,
    /// Simulated time (s); the run covers round(duration / period) control periods.
    pub duration: f64,
    pub robot: RobotDescription,
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
        let text = std::fs::read_to_string(path).map_err(|e| ScenarioError::Io { file: file.clone(), reason: e.to_string() })?;
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
        let text = std::fs::read_to_string(path).map_err(|e| ScenarioError::Io { file: file.clone(), reason: e.to_string() })?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let effective = overrides::apply(&text, &file, overrides)?;
        Self::from_str(&effective, &format!("{file} (with overrides)"), &dir).map_err(|e| overrides::locate(e, overrides))
    }

    /// Parses and validates a scenario; `origin` names it in errors, `dir` is the folder a
    /// relative `robot` path is taken from.
    #[allow(clippy::should_implement_trait)]
    pub fn from_str(text: &str, origin: &str, dir: &Path) -> Result<Scenario> {
        let index = SpanIndex::build_for(text, origin, REFERENCE).map_err(ScenarioError::from_parse)?;
        let raw: RawScenario = toml::from_str(text).map_err(|e| ScenarioError::from_parse(index.serde_error(&e)))?;
        let c = Ctx { file: origin, index: Some(&index) };
        validate(&raw, &c, text, origin, dir)
    }

    /// The control period (s).
    pub fn period(&self) -> f64 {
        self.plant.period
    }
}

fn validate(raw: &RawScenario, c: &Ctx, text: &str, origin: &str, dir: &Path) -> Result<Scenario> {
    let e = ScenarioError::from_parse;
    let h = &raw.scenario;
    if h.name.trim().is_empty() {
        return Err(e(c.err("scenario.name", "\"\"", "empty", "a non-empty scenario name")));
    }

    // The robot first: the strokes and the control period bound the other fields.
    let (mut robot, robot_source, robot_text) = if h.robot == DEFAULT_ROBOT {
        (RobotDescription::amru5(), DEFAULT_ROBOT.to_string(), AMRU5_TOML.to_string())
    } else {
        let path: PathBuf = if Path::new(&h.robot).is_absolute() { PathBuf::from(&h.robot) } else { dir.join(&h.robot) };
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(&path).map_err(|err| {
            e(c.err(
                "scenario.robot",
                format!("{:?}", h.robot),
                &format!("cannot read {shown}: {err}"),
                format!("\"{DEFAULT_ROBOT}\" (the embedded AMRU5 description) or the path of a robot description file, relative to the scenario file"),
            ))
        })?;
        let robot = RobotDescription::from_str(&text, &shown).map_err(ScenarioError::Robot)?;
        (robot, shown, text)
    };
    let period = robot.controller.period_s;
    c.check(h.duration_s >= period, "scenario.duration_s", h.duration_s, &format!("a duration >= {period} s (one control period)")).map_err(e)?;

    // Model.
    let m = &raw.model;
    m.joint_friction.apply(c, &mut robot).map_err(e)?;
    let mut model = ModelOptions::from_description(&robot, m.friction);
    if m.load_dependence && m.friction == FrictionModel::None {
        return Err(e(c.err("model.load_dependence", "true", "needs joint friction", "false with friction = \"none\" (or friction = \"dry_viscous\" or \"lugre\")")));
    }
    model.load_dependence = m.load_dependence;
    model.inductance = m.inductance;
    if let Some(v) = m.k_gnd {
        c.positive("model.k_gnd", v).map_err(e)?;
        model.ground.k_gnd = v;
    }
    if let Some(v) = m.d_gnd {
        c.non_negative("model.d_gnd", v).map_err(e)?;
        model.ground.d_gnd = v;
    }
    if let Some(v) = m.mu {
        c.non_negative("model.mu", v).map_err(e)?;
        model.ground.mu = v;
    }
    if let Some(v) = m.supply_voltage_v {
        c.positive("model.supply_voltage_v", v).map_err(e)?;
        model.supply_voltage = v;
    }

    // Integrator.
    let mut plant = PlantOptions::from_description(&robot, &model);
    if let Some(v) = raw.integrator.tolerance {
        c.positive("integrator.tolerance", v).map_err(e)?;
        plant.integrator.tolerance = v;
    }
    if let Some(v) = raw.integrator.h_max_s {
        c.check(v > 0.0 && v <= period, "integrator.h_max_s", v, &format!("a step in (0, {period}] s (at most one control period)")).map_err(e)?;
        plant.integrator.h_max = v;
        plant.integrator.h_initial = plant.integrator.h_initial.min(v);
    }

    // Control mode and the walking set-up: in gait mode the initial joints come from the gait.
    let mode = raw.control.mode;
    let gait = match (mode, &raw.gait) {
        (ControlMode::Gait, Some(g)) => Some(gait::validate(g, c, &robot, dir, h.duration_s).map_err(e)?),
        (ControlMode::Gait, None) => {
            return Err(e(c.err("gait", "<missing>", "missing table", "a [gait] table with control.mode = \"gait\" (period_s, pattern, [gait.heading]; see the shipped walking scenarios)")));
        }
        (_, Some(_)) => {
            return Err(e(c.err("gait", "[gait]", &format!("a [gait] table with control.mode = \"{}\"", mode.name()), "control.mode = \"gait\" with a [gait] table (or no [gait] table)")));
        }
        (_, None) => None,
    };
    if let Some(g) = &gait {
        plant.navigation = g.navigation;
    }

    // Initial configuration.
    let i = &raw.initial;
    if gait.is_some() {
        let written = [("q_r_deg", i.q_r_deg.map(|v| v.to_string())), ("q_v_m", i.q_v_m.map(|v| v.to_string())), ("q_h_m", i.q_h_m.map(|v| v.to_string())), ("lifted_legs", i.lifted_legs.as_ref().map(|v| format!("{v:?}"))), ("q_v_lifted_m", i.q_v_lifted_m.map(|v| v.to_string()))];
        if let Some((name, Some(value))) = written.into_iter().find(|(_, v)| v.is_some()) {
            return Err(e(c.err(
                &format!("initial.{name}"),
                value,
                "not used in gait mode",
                "only settle and body_height_offset_m in [initial] with control.mode = \"gait\": the feet start at their workspace centres at gait.body_height_m",
            )));
        }
    }
    let (q_r_deg, q_v_m, q_h_m, q_v_lifted_m) = (i.q_r_deg.unwrap_or(0.0), i.q_v_m.unwrap_or_else(default_q_v), i.q_h_m.unwrap_or_else(default_q_h), i.q_v_lifted_m.unwrap_or_else(default_q_v_lifted));
    let range = |j: Joint| robot.joint_range(j);
    let stroke = |field: &str, v: f64, (lo, hi): (f64, f64), unit: &str, what: &str| {
        c.check(v >= lo && v <= hi, field, v, &format!("a finite number in [{lo}, {hi}] {unit} ({what} of the robot description, joint_ranges)"))
    };
    let r = &robot.joint_ranges.q_r_deg;
    stroke("initial.q_r_deg", q_r_deg, (r.min, r.max), "deg", "the q_r range").map_err(e)?;
    stroke("initial.q_v_m", q_v_m, range(Joint::Vertical), "m", "the q_v stroke").map_err(e)?;
    stroke("initial.q_h_m", q_h_m, range(Joint::Horizontal), "m", "the q_h stroke").map_err(e)?;
    let mut lifted = Vec::new();
    for (n, &leg) in i.lifted_legs.iter().flatten().enumerate() {
        let field = format!("initial.lifted_legs[{n}]");
        if !(0..6).contains(&leg) {
            return Err(e(c.err(&field, leg, "no such leg", "a leg number 0..5")));
        }
        let leg = leg as usize;
        if lifted.contains(&leg) {
            return Err(e(c.err(&field, leg, "listed twice", "each leg at most once")));
        }
        lifted.push(leg);
    }
    lifted.sort_unstable();
    if !lifted.is_empty() {
        stroke("initial.q_v_lifted_m", q_v_lifted_m, range(Joint::Vertical), "m", "the q_v stroke").map_err(e)?;
        if q_v_lifted_m >= q_v_m {
            return Err(e(c.err(
                "initial.q_v_lifted_m",
                q_v_lifted_m,
                "does not lift the foot",
                format!("a value < initial.q_v_m = {q_v_m} (a smaller q_v lifts the foot, z_foot ~ -6 q_v)"),
            )));
        }
    }
    if i.settle && lifted.len() > 3 {
        return Err(e(c.err(
            "initial.lifted_legs",
            format!("{lifted:?}"),
            "too few supporting legs to settle",
            "at most 3 lifted legs with settle = true (a static equilibrium needs at least 3 feet on the ground)",
        )));
    }
    c.check(i.body_height_offset_m >= 0.0, "initial.body_height_offset_m", i.body_height_offset_m, "a finite number >= 0 (m, added to the body height after settling)").map_err(e)?;
    let joints: [f64; JOINTS] = match &gait {
        Some(g) => g.joints,
        None => std::array::from_fn(|k| match k % 3 {
            0 => q_r_deg.to_radians(),
            1 => {
                if lifted.contains(&(k / 3)) {
                    q_v_lifted_m
                } else {
                    q_v_m
                }
            }
            _ => q_h_m,
        }),
    };
    let initial = Initial { joints, lifted_legs: lifted, settle: i.settle, body_height_offset: i.body_height_offset_m };

    // Joint motions.
    if mode != ControlMode::Pi && !raw.control.motion.is_empty() {
        return Err(e(c.err(
            "control.motion",
            format!("{} motion(s)", raw.control.motion.len()),
            &format!("motions need mode = \"pi\" (not \"{}\")", mode.name()),
            format!("no [[control.motion]] with mode = \"{}\" (or mode = \"pi\")", mode.name()),
        )));
    }
    let mut motions = Vec::new();
    let mut seen = BTreeSet::new();
    for (n, rm) in raw.control.motion.iter().enumerate() {
        let motion = validate_motion(rm, &format!("control.motion[{n}]"), c, &robot, &joints, h.duration_s).map_err(e)?;
        if !seen.insert(motion.joint_index()) {
            return Err(e(c.err(&format!("control.motion[{n}].joint"), motion.joint.symbol(), &format!("a second motion of leg {}'s {}", motion.leg, motion.joint), "one motion per (leg, joint)")));
        }
        motions.push(motion);
    }

    Ok(Scenario {
        name: h.name.clone(),
        description: h.description.clone(),
        duration: h.duration_s,
        robot,
        robot_source,
        robot_text,
        model,
        plant,
        initial,
        control: mode,
        motions,
        gait,
        origin: origin.to_string(),
        text: text.to_string(),
    })
}

fn validate_motion(m: &RawMotion, path: &str, c: &Ctx, robot: &RobotDescription, joints: &[f64; JOINTS], duration: f64) -> std::result::Result<Motion, DescriptionError> {
    let field = |name: &str| format!("{path}.{name}");
    if !(0..6).contains(&m.leg) {
        return Err(c.err(&field("leg"), m.leg, "no such leg", "a leg number 0..5"));
    }
    let leg = m.leg as usize;
    let joint = match m.joint {
        RawJoint::Rotation => Joint::Rotation,
        RawJoint::Vertical => Joint::Vertical,
        RawJoint::Horizontal => Joint::Horizontal,
    };
    let base = joints[3 * leg + joint_number(joint)];
    let (lo, hi) = robot.joint_range(joint);
    let tol = STROKE_TOLERANCE * (hi - lo);
    let unit = if joint.is_rotational() { "rad" } else { "m" };
    let (kind, used): (&str, &[&str]) = match m.kind {
        MotionKind::Ramp => ("ramp", &["rate", "start_s", "stop_s"]),
        MotionKind::Sine => ("sine", &["amplitude", "frequency_hz"]),
        MotionKind::Sawtooth => ("sawtooth", &["min", "max", "speed"]),
    };
    let fields = [("rate", m.rate), ("start_s", m.start_s), ("stop_s", m.stop_s), ("amplitude", m.amplitude), ("frequency_hz", m.frequency_hz), ("min", m.min), ("max", m.max), ("speed", m.speed)];
    for (name, value) in fields {
        if let Some(v) = value {
            if !used.contains(&name) {
                return Err(c.err(&field(name), v, &format!("not a field of kind = \"{kind}\""), format!("for kind = \"{kind}\": {}", used.join(", "))));
            }
        }
    }
    let required = |name: &str, v: Option<f64>| {
        v.ok_or_else(|| c.err(&field(name), "<missing>", "missing field", format!("kind = \"{kind}\" needs {}", used.join(", "))))
    };
    let (lo_s, hi_s, base_s) = (short(lo), short(hi), short(base));
    let stroke_text = format!("the {} stroke [{lo_s}, {hi_s}] {unit} (joint_ranges of the robot description; base {base_s} {unit})", joint.symbol());
    let motion = match m.kind {
        MotionKind::Ramp => {
            let rate = required("rate", m.rate)?;
            c.finite(&field("rate"), rate)?;
            let start_s = m.start_s.unwrap_or(0.0);
            c.non_negative(&field("start_s"), start_s)?;
            let stop_s = m.stop_s.unwrap_or(duration.max(start_s));
            c.check(stop_s >= start_s, &field("stop_s"), stop_s, &format!("a time >= start_s = {start_s} s"))?;
            let span = stop_s.min(duration) - start_s;
            if span > 0.0 {
                let end = base + rate * span;
                let ok = end >= lo - tol && end <= hi + tol;
                let allowed = format!("a rate in [{:.6}, {:.6}] {unit}/s so that the reference stays in {stroke_text} over {span} s", (lo - base) / span, (hi - base) / span);
                c.check(ok, &field("rate"), rate, &allowed)?;
            }
            JointMotion::Ramp { rate, start_s, stop_s }
        }
        MotionKind::Sine => {
            let amplitude = required("amplitude", m.amplitude)?;
            let frequency_hz = required("frequency_hz", m.frequency_hz)?;
            let max = (hi - base).min(base - lo);
            c.check(amplitude.abs() <= max + tol, &field("amplitude"), amplitude, &format!("|amplitude| <= {max:.6} {unit} so that the reference stays in {stroke_text}"))?;
            c.positive(&field("frequency_hz"), frequency_hz)?;
            JointMotion::Sine { amplitude, frequency_hz }
        }
        MotionKind::Sawtooth => {
            let min = required("min", m.min)?;
            let max = required("max", m.max)?;
            let speed = required("speed", m.speed)?;
            c.check(min >= lo - tol && min <= base, &field("min"), min, &format!("a value in [{lo_s}, {base_s}] {unit}: within {stroke_text}, at most the base"))?;
            c.check(max <= hi + tol && max >= base && max > min, &field("max"), max, &format!("a value in [{base_s}, {hi_s}] {unit} and > min: within {stroke_text}, at least the base"))?;
            c.positive(&field("speed"), speed)?;
            JointMotion::Sawtooth { min, max, speed }
        }
    };
    Ok(Motion { leg, joint, motion })
}

/// A number with at most 6 decimals, trailing zeros removed (0.4363323129985824 -> 0.436332).
fn short(x: f64) -> String {
    let s = format!("{x:.6}");
    let s = if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.') } else { &s };
    if s == "-0" { "0".to_string() } else { s.to_string() }
}

// =============================================================================================
// Running
// =============================================================================================

/// One summary value.
#[derive(Clone, Debug, PartialEq)]
pub enum SummaryValue {
    Text(String),
    Count(u64),
    Number(f64),
}

/// Totals and diagnostics of a run. Energies in J, lengths in m, times in s.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    pub scenario: String,
    pub friction: &'static str,
    pub control: &'static str,
    /// Simulated time (s).
    pub duration_s: f64,
    pub wall_time_s: f64,
    pub control_periods: u64,
    pub rows: u64,
    pub integration_steps: u64,
    pub rejected_steps: u64,
    pub newton_iterations: u64,
    /// Evaluations of the residual f by the integrator: Newton iterations and consistent
    /// accelerations (those inside a Jacobian evaluation are not counted).
    pub residual_evaluations: u64,
    pub jacobian_evaluations: u64,
    pub factorizations: u64,
    /// Body height Z at the start (after settling and offset).
    pub initial_body_height_m: f64,
    /// Z at the end minus Z at the start.
    pub body_height_change_m: f64,
    /// Horizontal displacement of the body centre over the run.
    pub body_horizontal_drift_m: f64,
    /// Mass of the robot m of Eq. 6.6 (kg).
    pub robot_mass_kg: f64,
    /// Electrical energy E = sum of u i dt over the actuators (Eq. 6.7).
    pub energy_electrical_j: f64,
    /// The same per joint type (q_r, q_v, q_h), summed over the legs.
    pub energy_electrical_by_joint_j: [f64; 3],
    /// E over the simulated time: the averaged power of the robot (W).
    pub average_power_w: f64,
    pub energy_joule_j: f64,
    pub energy_friction_j: f64,
    pub energy_motor_work_j: f64,
    pub energy_contact_j: f64,
    pub kinetic_change_j: f64,
    pub potential_change_j: f64,
    /// Electrical energy minus everything it became (Δ kinetic, Δ potential, Joule, friction,
    /// contact, Δ magnetic): zero up to integration error.
    pub energy_balance_error_j: f64,
    /// The balance error over the sum of the magnitudes of its terms.
    pub energy_balance_error_relative: f64,
    /// Largest |voltage| across a motor (V).
    pub max_abs_voltage_v: f64,
    /// Fraction of the controller commands (all joints and instants) at the supply voltage.
    pub saturated_fraction: f64,
    /// Commands cut by a limit switch (joint at a stroke end, pushed further out).
    pub limit_switch_cuts: u64,
    /// Largest |reference − q| per joint type (q_r rad, q_v m, q_h m), PI mode only.
    pub max_tracking_error: Option<[f64; 3]>,
    /// Largest foot penetration into the ground.
    pub max_penetration_m: f64,
    /// Walking figures, in gait mode.
    pub gait: Option<GaitSummary>,
}

impl Summary {
    /// The values in a fixed order, names with units as suffixes.
    pub fn entries(&self) -> Vec<(&'static str, SummaryValue)> {
        use SummaryValue::{Count, Number, Text};
        let mut v = vec![
            ("scenario", Text(self.scenario.clone())),
            ("friction", Text(self.friction.to_string())),
            ("control", Text(self.control.to_string())),
            ("duration_s", Number(self.duration_s)),
            ("wall_time_s", Number(self.wall_time_s)),
            ("control_periods", Count(self.control_periods)),
            ("rows", Count(self.rows)),
            ("integration_steps", Count(self.integration_steps)),
            ("rejected_steps", Count(self.rejected_steps)),
            ("newton_iterations", Count(self.newton_iterations)),
            ("residual_evaluations", Count(self.residual_evaluations)),
            ("jacobian_evaluations", Count(self.jacobian_evaluations)),
            ("factorizations", Count(self.factorizations)),
            ("initial_body_height_m", Number(self.initial_body_height_m)),
            ("body_height_change_m", Number(self.body_height_change_m)),
            ("body_horizontal_drift_m", Number(self.body_horizontal_drift_m)),
            ("robot_mass_kg", Number(self.robot_mass_kg)),
            ("energy_electrical_j", Number(self.energy_electrical_j)),
            ("energy_electrical_q_r_j", Number(self.energy_electrical_by_joint_j[0])),
            ("energy_electrical_q_v_j", Number(self.energy_electrical_by_joint_j[1])),
            ("energy_electrical_q_h_j", Number(self.energy_electrical_by_joint_j[2])),
            ("average_power_w", Number(self.average_power_w)),
            ("energy_joule_j", Number(self.energy_joule_j)),
            ("energy_friction_j", Number(self.energy_friction_j)),
            ("energy_motor_work_j", Number(self.energy_motor_work_j)),
            ("energy_contact_j", Number(self.energy_contact_j)),
            ("kinetic_change_j", Number(self.kinetic_change_j)),
            ("potential_change_j", Number(self.potential_change_j)),
            ("energy_balance_error_j", Number(self.energy_balance_error_j)),
            ("energy_balance_error_relative", Number(self.energy_balance_error_relative)),
            ("max_abs_voltage_v", Number(self.max_abs_voltage_v)),
            ("saturated_fraction", Number(self.saturated_fraction)),
            ("limit_switch_cuts", Count(self.limit_switch_cuts)),
        ];
        if let Some([r, vv, hh]) = self.max_tracking_error {
            v.push(("max_tracking_error_q_r_rad", Number(r)));
            v.push(("max_tracking_error_q_v_m", Number(vv)));
            v.push(("max_tracking_error_q_h_m", Number(hh)));
        }
        v.push(("max_penetration_m", Number(self.max_penetration_m)));
        if let Some(g) = &self.gait {
            v.push(("gait_pattern", Text(g.pattern.clone())));
            v.push(("gait_cycle", Text(g.cycle.to_string())));
            v.push(("gait_heading", Text(g.heading.to_string())));
            v.push(("navigation", Text(g.navigation.to_string())));
            v.push(("tracking_error_xy_max_m", Number(g.tracking_error_xy_max_m)));
            v.push(("tracking_error_xy_final_m", Number(g.tracking_error_xy_final_m)));
            v.push(("tracking_error_yaw_max_rad", Number(g.tracking_error_yaw_max_rad)));
            v.push(("distance_walked_m", Number(g.distance_walked_m)));
            v.push(("reference_distance_m", Number(g.reference_distance_m)));
            v.push(("specific_resistance", Number(specific_resistance(self.energy_electrical_j, self.robot_mass_kg, g.distance_walked_m))));
            v.push(("clamped_ik_references", Count(g.clamped_ik_references)));
            v.push(("gait_switches", Count(g.gait_switches)));
            v.push(("min_feet_on_ground", Count(g.min_feet_on_ground)));
            v.push(("max_foot_reference_outside_workspace_m", Number(g.max_foot_reference_outside_workspace_m)));
        }
        v
    }
}

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
    /// The time series of every control instant (the columns of the module documentation).
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
pub fn run_scenario_until(s: &Scenario, record: Record, mut progress: impl FnMut(f64) -> ControlFlow<()>) -> Result<ScenarioResults> {
    let started = Instant::now();
    let sim_err = |stage: &'static str| move |source: SimError| ScenarioError::Simulation { file: s.origin.clone(), stage, source, hint: "" };
    let model = Arc::new(RobotModel::new(&s.robot, s.model.clone(), Arc::new(FlatGround { height: 0.0 })));

    // Initial state: feet on the ground, static equilibrium with the joints locked (Section 6.2).
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

    let mut plant = SimulatedRobot::new(model.clone(), &q, &qd, &s.plant).map_err(sim_err("the start"))?;
    let mut gait_state = None;
    let mut controller: Box<dyn Controller> = match s.control {
        ControlMode::Gait => {
            let g = s.gait.as_ref().expect("gait mode has a validated [gait]");
            let (controller, state) = gait::ScheduledGait::new(g, &s.robot);
            gait_state = Some(state);
            Box::new(controller)
        }
        ControlMode::Pi => {
            let pis = joint_pis(&s.robot, s.plant.period);
            let motions = s.motions.iter().map(|m| (m.joint_index(), m.motion)).collect();
            Box::new(JointPiController { pis, references: JointReferences { base: s.initial.joints, motions } })
        }
        ControlMode::Unpowered => Box::new(Unpowered),
    };

    let lugre = s.model.friction == FrictionModel::LuGre;
    // The joint references are recorded and tracked by the PI loops in these modes.
    let pi = matches!(s.control, ControlMode::Pi | ControlMode::Gait);
    let supply = s.model.supply_voltage;
    let mut rec = Recorder::default();
    let mut stats = RunStats::default();
    let mut gait_stats = gait::GaitStats::default();
    let mut last_t = 0.0;
    let flow = run_until(&mut plant, controller.as_mut(), s.duration, |p, meas, cmd| {
        let state = gait_state.as_ref().map(|g| g.borrow());
        if record == Record::TimeSeries {
            record_row(&mut rec, p, meas, cmd, lugre, pi, state.as_deref());
        }
        stats.observe(p, cmd, supply, pi);
        if let (Some(state), Some(g)) = (state.as_deref(), &s.gait) {
            let feet_down = p.robot.outputs.contact.iter().filter(|c| c.normal_force > 0.0).count();
            gait_stats.observe(p.state().q.as_slice(), state, feet_down, &g.workspaces);
        }
        last_t = meas.t;
        progress(meas.t)
    })
    .map_err(sim_err("the simulation"))?;
    if flow.is_break() {
        return Err(ScenarioError::Stopped { file: s.origin.clone(), t: last_t });
    }

    let series = rec.finish();
    let mut summary = summarize(s, &plant, &stats, &q, started.elapsed().as_secs_f64());
    if let (Some(g), Some(state)) = (&s.gait, &gait_state) {
        summary.gait = Some(GaitSummary::new(g, &gait_stats, &state.borrow().diagnostics));
    }
    Ok(ScenarioResults { series, summary })
}

/// Specific resistance xi = E / (m g l) (Eq. 6.6), g the standard gravity of the multibody
/// model; NaN when nothing was walked.
pub fn specific_resistance(energy_j: f64, mass_kg: f64, distance_m: f64) -> f64 {
    if distance_m > 0.0 {
        energy_j / (mass_kg * crate::mbs::STANDARD_GRAVITY * distance_m)
    } else {
        f64::NAN
    }
}

struct RunStats {
    /// Control instants seen.
    rows: u64,
    max_penetration: f64,
    commands: u64,
    saturated: u64,
    cuts: u64,
    max_abs_voltage: f64,
    tracking: [f64; 3],
}

impl Default for RunStats {
    fn default() -> Self {
        RunStats { rows: 0, max_penetration: f64::NEG_INFINITY, commands: 0, saturated: 0, cuts: 0, max_abs_voltage: 0.0, tracking: [0.0; 3] }
    }
}

impl RunStats {
    fn observe(&mut self, p: &SimulatedRobot, cmd: &Command, supply: f64, pi: bool) {
        let q = p.state().q.as_slice();
        let out = &p.robot.outputs;
        let model = &p.robot.model;
        self.rows += 1;
        self.max_penetration = out.contact.iter().map(|c| c.penetration).fold(self.max_penetration, f64::max);
        for k in 0..JOINTS {
            self.commands += 1;
            if cmd.voltages[k].abs() >= supply {
                self.saturated += 1;
            }
            let held = crate::physics::limit_switch(cmd.voltages[k], q[6 + k], &model.strokes[k % 3]);
            if held == 0.0 && cmd.voltages[k] != 0.0 {
                self.cuts += 1;
            }
            self.max_abs_voltage = self.max_abs_voltage.max(out.voltage[k].abs());
            if pi {
                self.tracking[k % 3] = self.tracking[k % 3].max((cmd.references[k] - q[6 + k]).abs());
            }
        }
    }
}

fn summarize(s: &Scenario, plant: &SimulatedRobot, stats: &RunStats, q0: &[f64], wall: f64) -> Summary {
    let e = &plant.energy;
    let e0 = &plant.initial_energy;
    let sum = |a: &[f64]| a.iter().sum::<f64>();
    let q = plant.state().q.as_slice();
    let n = plant.integrator.stats();
    let balance = e.balance_error(e0);
    let terms = sum(&e.electrical).abs()
        + (e.kinetic - e0.kinetic).abs()
        + (e.potential - e0.potential).abs()
        + sum(&e.joule)
        + sum(&e.friction_work).abs()
        + sum(&e.contact_work).abs()
        + (e.magnetic_energy - e0.magnetic_energy).abs();
    let rows = stats.rows;
    Summary {
        scenario: s.name.clone(),
        friction: s.model.friction.name(),
        control: s.control.name(),
        duration_s: plant.state().t,
        wall_time_s: wall,
        control_periods: rows.saturating_sub(1),
        rows,
        integration_steps: n.steps as u64,
        rejected_steps: n.rejected_steps as u64,
        newton_iterations: n.newton_iterations as u64,
        residual_evaluations: n.residual_evaluations as u64,
        jacobian_evaluations: n.jacobian_evaluations as u64,
        factorizations: n.factorizations as u64,
        initial_body_height_m: q0[2],
        body_height_change_m: q[2] - q0[2],
        body_horizontal_drift_m: (q[0] - q0[0]).hypot(q[1] - q0[1]),
        robot_mass_kg: plant.robot.model.mechanics.model.total_mass(),
        energy_electrical_j: sum(&e.electrical),
        energy_electrical_by_joint_j: std::array::from_fn(|j| e.electrical.iter().skip(j).step_by(3).sum()),
        average_power_w: if plant.state().t > 0.0 { sum(&e.electrical) / plant.state().t } else { 0.0 },
        energy_joule_j: sum(&e.joule),
        energy_friction_j: sum(&e.friction_work),
        energy_motor_work_j: sum(&e.motor_work),
        energy_contact_j: sum(&e.contact_work),
        kinetic_change_j: e.kinetic - e0.kinetic,
        potential_change_j: e.potential - e0.potential,
        energy_balance_error_j: balance,
        energy_balance_error_relative: if terms > 0.0 { balance / terms } else { 0.0 },
        max_abs_voltage_v: stats.max_abs_voltage,
        saturated_fraction: if stats.commands > 0 { stats.saturated as f64 / stats.commands as f64 } else { 0.0 },
        limit_switch_cuts: stats.cuts,
        max_tracking_error: matches!(s.control, ControlMode::Pi | ControlMode::Gait).then_some(stats.tracking),
        max_penetration_m: stats.max_penetration,
        gait: None,
    }
}

/// The gait controller's columns: desired body pose and velocities, duty factor, foot phases
/// and foot references.
fn record_gait(rec: &mut Recorder, g: &gait::GaitState) {
    let s = |x: &str| x.to_string();
    let pose = [g.pose.position.x, g.pose.position.y, g.pose.position.z, g.pose.angles.x, g.pose.angles.y, g.pose.angles.z];
    const POSE: [(&str, &str); 6] = [("X_ref", "m"), ("Y_ref", "m"), ("Z_ref", "m"), ("yaw_ref", "rad"), ("pitch_ref", "rad"), ("roll_ref", "rad")];
    for ((n, u), v) in POSE.iter().zip(pose) {
        rec.put(v, || (s(n), u, format!("desired body pose {} (T*_0,b, Eq. 7.12-7.23)", &n[..n.len() - 4])));
    }
    rec.put(g.velocity.x, || (s("X_dot_ref"), "m/s", s("commanded heading velocity V_x (global)")));
    rec.put(g.velocity.y, || (s("Y_dot_ref"), "m/s", s("commanded heading velocity V_y (global)")));
    rec.put(g.omega.z, || (s("omega_z_ref"), "rad/s", s("commanded yaw rate Omega_z")));
    rec.put(g.beta, || (s("duty_factor"), "1", s("duty factor beta of the current gait pattern")));
    for (l, phase) in g.phases.iter().enumerate() {
        rec.put(*phase, || (format!("phase[{l}]"), "1", s("foot phase code: 0 support, 1 takeoff, 2 swing, 3 landing")));
    }
    for (l, f) in g.feet.iter().enumerate() {
        rec.put(f.x, || (format!("foot_ref_x[{l}]"), "m", s("foot reference x, leg frame")));
        rec.put(f.y, || (format!("foot_ref_y[{l}]"), "m", s("foot reference y, leg frame")));
        rec.put(f.z, || (format!("foot_ref_z[{l}]"), "m", s("foot reference z, leg frame")));
    }
}

/// Unit of a joint quantity: (rotational, translational).
fn joint_unit(k: usize, units: (&'static str, &'static str)) -> &'static str {
    if Joint::ALL[k % 3].is_rotational() {
        units.0
    } else {
        units.1
    }
}

/// `q_v[2]` style name of joint k with a prefix and suffix: `{prefix}q_v{suffix}[2]`.
fn joint_name(prefix: &str, k: usize, suffix: &str) -> String {
    format!("{prefix}{}{suffix}[{}]", Joint::ALL[k % 3].symbol(), k / 3)
}

fn record_row(rec: &mut Recorder, p: &SimulatedRobot, meas: &Measurements, cmd: &Command, lugre: bool, pi: bool, gait: Option<&gait::GaitState>) {
    let st = p.state();
    let (q, qd) = (st.q.as_slice(), st.qd.as_slice());
    let out = &p.robot.outputs;
    let e = &p.energy;
    let s = |x: &str| x.to_string();
    rec.begin_row();
    rec.put(meas.t, || (s("t"), "s", s("control instant")));
    const BODY: [(&str, &str, &str); 6] = [("X", "m", "body centre x"), ("Y", "m", "body centre y"), ("Z", "m", "body centre height"), ("yaw", "rad", "body yaw"), ("pitch", "rad", "body pitch"), ("roll", "rad", "body roll")];
    for (i, (n, u, d)) in BODY.iter().enumerate() {
        rec.put(q[i], || (s(n), u, s(d)));
    }
    const BODY_DOT: [(&str, &str); 6] = [("X_dot", "m/s"), ("Y_dot", "m/s"), ("Z_dot", "m/s"), ("yaw_dot", "rad/s"), ("pitch_dot", "rad/s"), ("roll_dot", "rad/s")];
    for (i, (n, u)) in BODY_DOT.iter().enumerate() {
        rec.put(qd[i], || (s(n), u, format!("time derivative of {}", &n[..n.len() - 4])));
    }
    for k in 0..JOINTS {
        rec.put(q[6 + k], || (joint_name("", k, ""), joint_unit(k, ("rad", "m")), format!("joint position, leg {}", k / 3)));
    }
    for k in 0..JOINTS {
        rec.put(qd[6 + k], || (joint_name("", k, "_dot"), joint_unit(k, ("rad/s", "m/s")), format!("joint velocity, leg {}", k / 3)));
    }
    if pi {
        for k in 0..JOINTS {
            rec.put(cmd.references[k], || (joint_name("", k, "_ref"), joint_unit(k, ("rad", "m")), format!("PI reference computed at t, leg {}", k / 3)));
        }
    }
    if let Some(g) = gait {
        record_gait(rec, g);
    }
    for k in 0..JOINTS {
        rec.put(out.voltage[k], || (joint_name("u_", k, ""), "V", s("voltage across motor and H-bridge held over the period ending at t (after saturation and limit switches)")));
    }
    for k in 0..JOINTS {
        rec.put(out.current[k], || (joint_name("i_", k, ""), "A", s("motor current")));
    }
    for k in 0..JOINTS {
        rec.put(out.motor_torque[k], || (joint_name("tau_m_", k, ""), joint_unit(k, ("Nm", "N")), s("motor torque at the joint, n k_t i")));
    }
    for k in 0..JOINTS {
        rec.put(out.friction_torque[k], || (joint_name("tau_f_", k, ""), joint_unit(k, ("Nm", "N")), s("joint friction torque (opposing the motion)")));
    }
    if lugre {
        for k in 0..JOINTS {
            rec.put(out.bristle[k], || (joint_name("z_", k, ""), joint_unit(k, ("rad", "m")), s("LuGre bristle deflection")));
        }
    }
    for (f, c) in out.contact.iter().enumerate() {
        rec.put(c.force.x, || (format!("Fx[{f}]"), "N", s("ground force on the foot, x (global)")));
        rec.put(c.force.y, || (format!("Fy[{f}]"), "N", s("ground force on the foot, y (global)")));
        rec.put(c.force.z, || (format!("Fz[{f}]"), "N", s("ground force on the foot, z (global)")));
        rec.put(c.normal_force, || (format!("Fn[{f}]"), "N", s("normal ground force on the foot")));
        rec.put(c.penetration, || (format!("penetration[{f}]"), "m", s("foot penetration into the ground (< 0: clearance)")));
    }
    for (f, x) in out.foot.iter().enumerate() {
        rec.put(x.x, || (format!("foot_x[{f}]"), "m", s("foot position x (global)")));
        rec.put(x.y, || (format!("foot_y[{f}]"), "m", s("foot position y (global)")));
        rec.put(x.z, || (format!("foot_z[{f}]"), "m", s("foot position z (global)")));
    }
    for k in 0..JOINTS {
        rec.put(e.electrical[k], || (joint_name("E_el_", k, ""), "J", s("cumulative electrical energy drawn, integral of u i")));
    }
    for k in 0..JOINTS {
        rec.put(e.joule[k], || (joint_name("E_joule_", k, ""), "J", s("cumulative Joule losses in motor and H-bridge")));
    }
    for k in 0..JOINTS {
        rec.put(e.friction_work[k], || (joint_name("E_fric_", k, ""), "J", s("cumulative work against joint friction, integral of tau_f q'")));
    }
    rec.put(e.kinetic, || (s("E_kin"), "J", s("kinetic energy")));
    rec.put(e.potential, || (s("E_pot"), "J", s("gravitational potential energy")));
    rec.put(e.contact_work.iter().sum(), || (s("E_contact"), "J", s("cumulative work of the feet on the ground")));
    rec.put(e.bristle_energy + e.contact_energy + e.magnetic_energy, || (s("E_stored"), "J", s("energy stored in bristles, ground springs and inductances")));
    rec.put(e.balance_error(&p.initial_energy), || (s("E_balance"), "J", s("energy balance error so far (electrical in minus what it became)")));
    rec.end_row();
}
