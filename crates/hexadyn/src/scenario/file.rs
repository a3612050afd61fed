//! The scenario file: the raw serde mirror of its tables with their defaults, and its
//! validation into a [`Scenario`]: the robot it names, the model, integrator and
//! initial-configuration options, the control mode and the joint motions, each value checked
//! against what the robot description allows (joint ranges, control period). Unknown keys are
//! errors (`deny_unknown_fields`). The `[gait]` and `[model.joint_friction]` tables are mirrored
//! and validated in their own submodules ([`super::gait`], [`super::joint_friction`]). The
//! format is documented in `docs/scenario-format.md`.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::gait::{self, RawGait};
use super::joint_friction::RawJointFriction;
use super::terrain::{self, RawTerrain};
use super::{ControlMode, Initial, ModelFlags, Motion, Result, Scenario, ScenarioError, DEFAULT_ROBOT};
use crate::control::{GroundExperiment, JointMotion};
use crate::description::{Robot, RobotDescription, AMRU5_TOML, SHIPPED_ROBOTS};
use crate::fields::{Ctx, DescriptionError};
use crate::description::SerialRobot;
use crate::hexapod::{default_serial_height, Leg, LegChain, PantographJoint, SerialLegKinematics, JOINTS};
use crate::mbs::STANDARD_GRAVITY;
use nalgebra::Vector3;
use crate::physics::LOAD_GRAVITY;
use crate::robot::model::FrictionModel;
use crate::robot::simulation::PlantOptions;

// =============================================================================================
// Raw mirror of the file
// =============================================================================================

/// The whole file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawScenario {
    scenario: RawHeader,
    #[serde(default)]
    model: RawModel,
    #[serde(default)]
    integrator: RawIntegrator,
    #[serde(default)]
    initial: RawInitial,
    #[serde(default)]
    control: RawControl,
    gait: Option<RawGait>,
    terrain: Option<RawTerrain>,
    #[serde(default)]
    sensors: RawSensors,
    ground_detection: Option<GroundExperiment>,
}

/// `[sensors]`: the current sensors of the plant (Section 5.6.2).
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawSensors {
    current_noise_a: Option<f64>,
    #[serde(default)]
    seed: u64,
}

/// `[scenario]`.
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

/// `[model]`.
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
    foot_radius_m: Option<f64>,
    supply_voltage_v: Option<f64>,
    #[serde(default)]
    joint_friction: RawJointFriction,
    #[serde(default)]
    stand: bool,
    foot_load_kg: Option<Vec<f64>>,
}

impl RawScenario {
    /// The `[model]` flags as written (defaults filled in).
    pub(super) fn model_flags(&self) -> ModelFlags {
        ModelFlags { friction: self.model.friction, load_dependence: self.model.load_dependence, inductance: self.model.inductance }
    }
}

fn default_friction() -> FrictionModel {
    FrictionModel::LuGre
}

impl Default for RawModel {
    fn default() -> Self {
        RawModel { friction: default_friction(), load_dependence: false, inductance: false, k_gnd: None, d_gnd: None, mu: None, foot_radius_m: None, supply_voltage_v: None, joint_friction: Default::default(), stand: false, foot_load_kg: None }
    }
}

/// `[integrator]`.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawIntegrator {
    tolerance: Option<f64>,
    h_max_s: Option<f64>,
    surrogate_iterations: Option<usize>,
    unverified_steps: Option<usize>,
}

/// `[initial]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInitial {
    // The joint fields are options so that gait mode can reject them when written.
    /// Serial legs: the body height the feet stand at the centre of their workspaces (m).
    body_height_m: Option<f64>,
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

/// Defaults of `[initial]` (m): q_v of the supporting legs, q_h, q_v of the lifted legs.
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
        RawInitial { body_height_m: None, q_r_deg: None, q_v_m: None, q_h_m: None, lifted_legs: None, q_v_lifted_m: None, settle: true, body_height_offset_m: 0.0 }
    }
}

/// `[control]`.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawControl {
    #[serde(default)]
    mode: ControlMode,
    #[serde(default)]
    motion: Vec<RawMotion>,
}

#[derive(Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
enum MotionKind {
    Ramp,
    Sine,
    Sawtooth,
    VoltageRamp,
}

/// One `[[control.motion]]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMotion {
    leg: i64,
    /// One of the robot's joint names (`[joints] names`).
    joint: String,
    kind: MotionKind,
    rate: Option<f64>,
    start_s: Option<f64>,
    stop_s: Option<f64>,
    amplitude: Option<f64>,
    frequency_hz: Option<f64>,
    min: Option<f64>,
    max: Option<f64>,
    speed: Option<f64>,
    speed_step: Option<f64>,
    speed_max: Option<f64>,
    rate_v_per_s: Option<f64>,
}

// =============================================================================================
// Validation
// =============================================================================================

// Documented ranges of the numerical settings (docs/scenario-format.md): outside them a run
// is either meaningless or does not end in reasonable time.
// INTERPRETATION: the thesis gives one value of each (Table 3.3, Section 4.4.3, the integrator
// of Chapter 3); the ranges are chosen wide around them, bounded where the models stop being
// valid (supply beyond twice the motors' rating, friction coefficients beyond any real
// foot-ground pair) or the run stops being feasible (steps below 1e-5 s; tolerances below 1e-4,
// where the validation walk already closes its energy balance to 0.007 % with 5 times the
// steps of the robot's tolerance), and where the results lose their meaning (tolerance 1e3:
// 12.8 % energy balance error).
/// `model.k_gnd`: factors of the robot's ground stiffness.
const RANGE_FACTOR_GROUND: [f64; 2] = [1e-3, 1e3];
/// `model.mu`.
const MU_RANGE: [f64; 2] = [0.0, 5.0];
/// `model.supply_voltage_v`: the lower bound (V); the upper is twice the motor rating.
const SUPPLY_MIN_V: f64 = 0.1;
/// `integrator.tolerance`.
const TOLERANCE_RANGE: [f64; 2] = [1e-4, 10.0];
/// `integrator.h_max_s`: the smallest largest step (s).
const H_MAX_MIN_S: f64 = 1e-5;
/// `integrator.surrogate_iterations`: at most this many per evaluation of f (the Newton
/// iterations on f itself are at most 8).
const SURROGATE_ITERATIONS_MAX: usize = 50;
/// `integrator.unverified_steps`: at most this many steps in a row accepted on the surrogate.
const UNVERIFIED_STEPS_MAX: usize = 1000;

/// Checks that `v` is a finite number in `[lo, hi]` (`unit` and `why` go into the message).
fn in_range(c: &Ctx, field: &str, v: f64, [lo, hi]: [f64; 2], unit: &str, why: &str) -> Result<()> {
    let unit = if unit.is_empty() { String::new() } else { format!(" {unit}") };
    c.check(v >= lo && v <= hi, field, v, &format!("a number in [{}, {}]{unit}: {why}", readable(lo), readable(hi))).map_err(ScenarioError::from_parse)
}

/// A bound as a reader writes it: 0.1, 30, 1000, but 1e-4 and 1e9.
fn readable(x: f64) -> String {
    if x != 0.0 && (x.abs() >= 1e4 || x.abs() < 1e-3) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// Relative tolerance on stroke checks (a sawtooth written to the printed stroke ends passes).
const STROKE_TOLERANCE: f64 = 1e-6;

pub(super) fn validate(raw: &RawScenario, c: &Ctx, text: &str, origin: &str, dir: &Path) -> Result<Scenario> {
    let e = ScenarioError::from_parse;
    let h = &raw.scenario;
    if h.name.trim().is_empty() {
        return Err(e(c.err("scenario.name", "\"\"", "empty", "a non-empty scenario name")));
    }

    // The robot first: the strokes and the control period bound the other fields.
    let shipped = SHIPPED_ROBOTS.iter().find(|(name, _, _)| *name == h.robot);
    let (mut robot, robot_source, robot_text) = if h.robot == DEFAULT_ROBOT {
        (Robot::Pantograph(RobotDescription::amru5()), DEFAULT_ROBOT.to_string(), AMRU5_TOML.to_string())
    } else if let Some((name, text, origin)) = shipped {
        (Robot::from_str(text, origin).map_err(ScenarioError::Robot)?, name.to_string(), text.to_string())
    } else {
        let path: PathBuf = if Path::new(&h.robot).is_absolute() { PathBuf::from(&h.robot) } else { dir.join(&h.robot) };
        let shown = path.display().to_string();
        let text = crate::fields::read_input(&path).map_err(|err| {
            e(c.err(
                "scenario.robot",
                format!("{:?}", h.robot),
                &format!("cannot read {shown}: {err}"),
                format!("a shipped robot ({}) or the path of a robot description file, relative to the scenario file", SHIPPED_ROBOTS.map(|(name, _, _)| format!("\"{name}\"")).join(", ")),
            ))
        })?;
        let robot = Robot::from_str(&text, &shown).map_err(ScenarioError::Robot)?;
        (robot, shown, text)
    };
    let period = robot.period();
    c.check(h.duration_s.is_finite() && h.duration_s >= period, "scenario.duration_s", h.duration_s, &format!("a finite duration >= {period} s (one control period)")).map_err(e)?;

    // Model.
    let m = &raw.model;
    // The master's friction feed-forward knows the robot as its file describes it, not the
    // overrides below.
    let feedforward = robot.friction_feedforward(period);
    m.joint_friction.apply(c, &mut robot).map_err(e)?;
    if matches!(robot, Robot::Serial(_)) && m.load_dependence {
        return Err(e(c.err("model.load_dependence", "true", "no load dependence on serial legs", "false with a serial robot (Eq. 5.12 is identified on AMRU5's horizontal joints)")));
    }
    let mut model = robot.model_options(m.friction);
    if m.load_dependence && m.friction == FrictionModel::None {
        return Err(e(c.err("model.load_dependence", "true", "needs joint friction", "false with friction = \"none\" (or friction = \"dry_viscous\" or \"lugre\")")));
    }
    if m.load_dependence && m.friction == FrictionModel::Efficiency {
        return Err(e(c.err("model.load_dependence", "true", "the efficiency law's loss already follows the transmitted load", "false with friction = \"efficiency\" (Eq. 5.12 goes with friction = \"dry_viscous\" or \"lugre\")")));
    }
    model.load_dependence = m.load_dependence;
    model.inductance = m.inductance;
    let ground = model.ground;
    if let Some(v) = m.k_gnd {
        in_range(c, "model.k_gnd", v, RANGE_FACTOR_GROUND.map(|f| f * ground.k_gnd), "N/m^p_K", "ground stiffness within a factor 1000 of the robot's (Table 3.3): stiffer ground needs steps below the integrator's")?;
        model.ground.k_gnd = v;
    }
    if let Some(v) = m.d_gnd {
        in_range(c, "model.d_gnd", v, [0.0, RANGE_FACTOR_GROUND[1] * ground.d_gnd], "N s/m^(p_D+1)", "ground damping up to 1000 times the robot's (Table 3.3)")?;
        model.ground.d_gnd = v;
    }
    if let Some(v) = m.mu {
        in_range(c, "model.mu", v, MU_RANGE, "", "a foot-ground friction coefficient (rubber on rough ground is below 1.5)")?;
        model.ground.mu = v;
    }
    if let Some(v) = m.foot_radius_m {
        c.check((0.0..=0.05).contains(&v), "model.foot_radius_m", v, "a radius in [0, 0.05] m (0: the point foot of Section 3.4.2)").map_err(e)?;
        model.ground.foot_radius = v;
    }
    let terrain = terrain::validate(raw.terrain.as_ref(), c, dir).map_err(e)?;
    if let Some(v) = m.supply_voltage_v {
        let rated = robot.nominal_voltage();
        in_range(c, "model.supply_voltage_v", v, [SUPPLY_MIN_V, 2.0 * rated], "V", &format!("up to twice the motors' nominal voltage ({rated} V): the motor model has no limit beyond it"))?;
        model.supply_voltage = v;
    }
    model.stand = m.stand;
    if let Some(loads) = &m.foot_load_kg {
        let shown = format!("{loads:?}");
        if loads.len() != 6 {
            return Err(e(c.err("model.foot_load_kg", &shown, &format!("{} values", loads.len()), "six masses >= 0 (kg), one per leg 0..5")));
        }
        for (leg, &kg) in loads.iter().enumerate() {
            c.non_negative(&format!("model.foot_load_kg[{leg}]"), kg).map_err(e)?;
            model.foot_load[leg] = kg * LOAD_GRAVITY;
        }
    }

    // Integrator.
    let mut plant = PlantOptions::new(period, &model);
    if let Some(v) = raw.integrator.tolerance {
        in_range(c, "integrator.tolerance", v, TOLERANCE_RANGE, "", "the error estimate of Eq. 3.15 in units of the layout scales (the robot's is 1; 1e3 already leaves a 13 % energy balance error; 1e-4 takes 5 times the robot's steps for a balance error below 0.01 %, tighter only costs time)")?;
        plant.integrator.tolerance = v;
    }
    if let Some(v) = raw.integrator.h_max_s {
        c.check(v >= H_MAX_MIN_S && v <= period, "integrator.h_max_s", v, &format!("a step in [{H_MAX_MIN_S}, {period}] s (at most one control period; at least 1e-5 s, so that a control period takes at most 1000 steps)")).map_err(e)?;
        plant.integrator.h_max = v;
        plant.integrator.h_initial = plant.integrator.h_initial.min(v);
    }
    if let Some(v) = raw.integrator.surrogate_iterations {
        c.check(v <= SURROGATE_ITERATIONS_MAX, "integrator.surrogate_iterations", v as f64, &format!("0 (the thesis' Newton iteration on f alone) to {SURROGATE_ITERATIONS_MAX} Newton iterations on the surrogate residual after each evaluation of f"))
            .map_err(e)?;
        plant.integrator.surrogate_iterations = v;
    }
    if let Some(v) = raw.integrator.unverified_steps {
        c.check(v <= UNVERIFIED_STEPS_MAX, "integrator.unverified_steps", v as f64, &format!("0 (every step verified by an evaluation of the residual, the thesis' acceptance) to {UNVERIFIED_STEPS_MAX} steps in a row accepted on the surrogate's Newton test"))
            .map_err(e)?;
        plant.integrator.unverified_steps = v;
    }

    // Control mode and the walking set-up: in gait mode the initial joints come from the gait.
    let mode = raw.control.mode;
    let gait = match (mode, &raw.gait) {
        (ControlMode::Gait, Some(g)) => Some(gait::validate(g, c, &robot, feedforward.clone(), dir, h.duration_s).map_err(e)?),
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
    if let Some(v) = raw.sensors.current_noise_a {
        c.non_negative("sensors.current_noise_a", v).map_err(e)?;
        plant.current_sensing.noise_a = v;
    }
    plant.current_sensing.seed = raw.sensors.seed;

    // Initial configuration.
    let i = &raw.initial;
    if gait.is_some() {
        let written = [("body_height_m", i.body_height_m.map(|v| v.to_string())), ("q_r_deg", i.q_r_deg.map(|v| v.to_string())), ("q_v_m", i.q_v_m.map(|v| v.to_string())), ("q_h_m", i.q_h_m.map(|v| v.to_string())), ("lifted_legs", i.lifted_legs.as_ref().map(|v| format!("{v:?}"))), ("q_v_lifted_m", i.q_v_lifted_m.map(|v| v.to_string()))];
        if let Some((name, Some(value))) = written.into_iter().find(|(_, v)| v.is_some()) {
            return Err(e(c.err(
                &format!("initial.{name}"),
                value,
                "not used in gait mode",
                "only settle and body_height_offset_m in [initial] with control.mode = \"gait\": the feet start at their steady footholds at gait.body_height_m",
            )));
        }
    }
    let (posture, lifted) = match &robot {
        Robot::Pantograph(d) => pantograph_initial(i, c, d).map_err(e)?,
        Robot::Serial(s) => (serial_initial(i, c, s).map_err(e)?, Vec::new()),
    };
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
        None => posture,
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
            let name = robot.joints().name(motion.joint);
            return Err(e(c.err(&format!("control.motion[{n}].joint"), name, &format!("a second motion of leg {}'s {name}", motion.leg), "one motion per (leg, joint)")));
        }
        motions.push(motion);
    }

    let ground_detection = match (mode, &raw.ground_detection) {
        (ControlMode::GroundDetection, Some(g)) => {
            let mut g = validate_ground_detection(g, c, &robot, &initial).map_err(e)?;
            g.feedforward = match (g.friction_feedforward, &feedforward) {
                (false, _) => None,
                (true, Some(f)) => Some(f.clone()),
                (true, None) => return Err(e(c.err("ground_detection.friction_feedforward", "true", "a feed-forward for position servos", "false with a robot whose joints are driven by PI loops (their integral action takes the friction)"))),
            };
            Some(g)
        }
        (ControlMode::GroundDetection, None) => {
            return Err(e(c.err("ground_detection", "<missing>", "missing table", "a [ground_detection] table with control.mode = \"ground_detection\" (see python/hexadyn/scenarios/ground_detection.toml)")));
        }
        (_, Some(_)) => {
            return Err(e(c.err("ground_detection", "[ground_detection]", &format!("a [ground_detection] table with control.mode = \"{}\"", mode.name()), "control.mode = \"ground_detection\" with the table (or no table)")));
        }
        (_, None) => None,
    };

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
        terrain_file: terrain::mesh_file(raw.terrain.as_ref(), dir),
        terrain,
        ground_detection,
        origin: origin.to_string(),
        text: text.to_string(),
    })
}

/// The initial joints of a pantograph robot (`q_r_deg`, `q_v_m`, `q_h_m`, the lifted legs at
/// `q_v_lifted_m`), each within its stroke, and the lifted legs.
fn pantograph_initial(i: &RawInitial, c: &Ctx, robot: &RobotDescription) -> std::result::Result<([f64; JOINTS], Vec<usize>), DescriptionError> {
    if let Some(v) = i.body_height_m {
        return Err(c.err("initial.body_height_m", v, "a serial robot's key", "q_r_deg, q_v_m, q_h_m (and lifted_legs, q_v_lifted_m) for the pantograph legs of this robot"));
    }
    let (q_r_deg, q_v_m, q_h_m, q_v_lifted_m) = (i.q_r_deg.unwrap_or(0.0), i.q_v_m.unwrap_or_else(default_q_v), i.q_h_m.unwrap_or_else(default_q_h), i.q_v_lifted_m.unwrap_or_else(default_q_v_lifted));
    let range = |j: PantographJoint| robot.joint_range(j);
    let stroke = |field: &str, v: f64, (lo, hi): (f64, f64), unit: &str, what: &str| {
        c.check(v >= lo && v <= hi, field, v, &format!("a finite number in [{lo}, {hi}] {unit} ({what} of the robot description, joint_ranges)"))
    };
    let r = &robot.joint_ranges.q_r_deg;
    stroke("initial.q_r_deg", q_r_deg, (r.min, r.max), "deg", "the q_r range")?;
    stroke("initial.q_v_m", q_v_m, range(PantographJoint::Vertical), "m", "the q_v stroke")?;
    stroke("initial.q_h_m", q_h_m, range(PantographJoint::Horizontal), "m", "the q_h stroke")?;
    let mut lifted = Vec::new();
    for (n, &leg) in i.lifted_legs.iter().flatten().enumerate() {
        let field = format!("initial.lifted_legs[{n}]");
        if !(0..6).contains(&leg) {
            return Err(c.err(&field, leg, "no such leg", "a leg number 0..5"));
        }
        let leg = leg as usize;
        if lifted.contains(&leg) {
            return Err(c.err(&field, leg, "listed twice", "each leg at most once"));
        }
        lifted.push(leg);
    }
    lifted.sort_unstable();
    if !lifted.is_empty() {
        stroke("initial.q_v_lifted_m", q_v_lifted_m, range(PantographJoint::Vertical), "m", "the q_v stroke")?;
        if q_v_lifted_m >= q_v_m {
            return Err(c.err("initial.q_v_lifted_m", q_v_lifted_m, "does not lift the foot", format!("a value < initial.q_v_m = {q_v_m} (a smaller q_v lifts the foot, z_foot ~ -6 q_v)")));
        }
    }
    let joints = std::array::from_fn(|k| match k % 3 {
        0 => q_r_deg.to_radians(),
        1 => {
            if lifted.contains(&(k / 3)) {
                q_v_lifted_m
            } else {
                q_v_m
            }
        }
        _ => q_h_m,
    });
    Ok((joints, lifted))
}

/// The initial joints of a serial robot: every foot at the centre of its workspace cylinder
/// (Section 7.1.1) at `initial.body_height_m` below the body (default: the mean height of the
/// feet with every joint at mid-range).
fn serial_initial(i: &RawInitial, c: &Ctx, robot: &SerialRobot) -> std::result::Result<[f64; JOINTS], DescriptionError> {
    let written = [("q_r_deg", i.q_r_deg), ("q_v_m", i.q_v_m), ("q_h_m", i.q_h_m), ("q_v_lifted_m", i.q_v_lifted_m)];
    if let Some((name, Some(v))) = written.into_iter().find(|(_, v)| v.is_some()) {
        return Err(c.err(&format!("initial.{name}"), v, "a pantograph key on serial legs", "initial.body_height_m (m) for a serial robot: the feet stand at the centre of their workspaces"));
    }
    if let Some(legs) = &i.lifted_legs {
        return Err(c.err("initial.lifted_legs", format!("{legs:?}"), "not available on serial legs yet", "no lifted_legs with a serial robot (every foot starts on the ground)"));
    }
    let legs = SerialLegKinematics::hexapod(&robot.hexapod.legs).map_err(|err| c.err("scenario.robot", robot.origin.clone(), &format!("no leg kinematics: {err}"), "serial legs with valid joint ranges"))?;
    let height = match i.body_height_m {
        Some(h) => h,
        None => default_serial_height(&legs),
    };
    let mut joints = [0.0; JOINTS];
    for (l, leg) in legs.iter().enumerate() {
        let z = -height;
        let reached = leg.workspace(z, z).ok().and_then(|w| leg.inverse(&w.centre_at(z), &leg.neutral()).ok()).filter(|s| s.is_reached());
        let Some(s) = reached else {
            let (lowest, highest) = leg.height_range();
            return Err(c.err("initial.body_height_m", height, &format!("leg {l}'s foot cannot stand at this height"), format!("a body height in ({:.4}, {:.4}) m, where the feet reach the ground", -highest, -lowest)));
        };
        joints[3 * l..3 * l + 3].copy_from_slice(s.joints.as_slice());
    }
    Ok(joints)
}

fn validate_motion(m: &RawMotion, path: &str, c: &Ctx, robot: &Robot, joints: &[f64; JOINTS], duration: f64) -> std::result::Result<Motion, DescriptionError> {
    let field = |name: &str| format!("{path}.{name}");
    if !(0..6).contains(&m.leg) {
        return Err(c.err(&field("leg"), m.leg, "no such leg", "a leg number 0..5"));
    }
    let leg = m.leg as usize;
    let names = robot.joints();
    let joint = names.position(&m.joint).ok_or_else(|| c.err(&field("joint"), format!("{:?}", m.joint), "no such joint", format!("one of the robot's joints: {}", names.names().collect::<Vec<_>>().join(", "))))?;
    let base = joints[3 * leg + joint];
    let (lo, hi) = robot.joint_range(3 * leg + joint);
    let tol = STROKE_TOLERANCE * (hi - lo);
    let unit = names.kind(joint).unit(("rad", "m"));
    let (kind, used): (&str, &[&str]) = match m.kind {
        MotionKind::Ramp => ("ramp", &["rate", "start_s", "stop_s"]),
        MotionKind::Sine => ("sine", &["amplitude", "frequency_hz"]),
        MotionKind::Sawtooth => ("sawtooth", &["min", "max", "speed", "speed_step", "speed_max"]),
        MotionKind::VoltageRamp => ("voltage_ramp", &["rate_v_per_s"]),
    };
    if let (MotionKind::VoltageRamp, Robot::Serial(s)) = (m.kind, robot) {
        if s.has_servos() {
            return Err(c.err(&field("kind"), "\"voltage_ramp\"", "a voltage motion on position servos", "ramp, sine or sawtooth: the servos take goal positions, not voltages"));
        }
    }
    let fields = [
        ("rate", m.rate),
        ("start_s", m.start_s),
        ("stop_s", m.stop_s),
        ("amplitude", m.amplitude),
        ("frequency_hz", m.frequency_hz),
        ("min", m.min),
        ("max", m.max),
        ("speed", m.speed),
        ("speed_step", m.speed_step),
        ("speed_max", m.speed_max),
        ("rate_v_per_s", m.rate_v_per_s),
    ];
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
    let stroke_text = format!("the {} stroke [{lo_s}, {hi_s}] {unit} (joint_ranges of the robot description; base {base_s} {unit})", names.name(joint));
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
            let nyquist = 0.5 / robot.period();
            c.check(frequency_hz > 0.0 && frequency_hz < nyquist, &field("frequency_hz"), frequency_hz, &format!("a frequency in (0, {nyquist}) Hz, below the Nyquist frequency of the control period ({} s)", robot.period()))?;
            JointMotion::Sine { amplitude, frequency_hz }
        }
        MotionKind::Sawtooth => {
            let min = required("min", m.min)?;
            let max = required("max", m.max)?;
            let speed = required("speed", m.speed)?;
            c.check(min >= lo - tol && min <= base, &field("min"), min, &format!("a value in [{lo_s}, {base_s}] {unit}: within {stroke_text}, at most the base"))?;
            c.check(max <= hi + tol && max >= base && max > min, &field("max"), max, &format!("a value in [{base_s}, {hi_s}] {unit} and > min: within {stroke_text}, at least the base"))?;
            c.positive(&field("speed"), speed)?;
            // Optional staircase of Table 5.2: both keys or neither.
            match (m.speed_step, m.speed_max) {
                (None, None) => JointMotion::Sawtooth { min, max, speed },
                (Some(speed_step), Some(speed_max)) => {
                    c.positive(&field("speed_step"), speed_step)?;
                    c.check(speed_max >= speed, &field("speed_max"), speed_max, &format!("a speed >= speed = {speed} {unit}/s"))?;
                    JointMotion::SawtoothSteps { min, max, speed, speed_step, speed_max }
                }
                (Some(v), None) | (None, Some(v)) => {
                    let name = if m.speed_step.is_some() { "speed_max" } else { "speed_step" };
                    return Err(c.err(&field(name), "<missing>", "missing field", format!("speed_step and speed_max together (the speed staircase of Table 5.2; the other is {v})")));
                }
            }
        }
        MotionKind::VoltageRamp => {
            let rate = required("rate_v_per_s", m.rate_v_per_s)?;
            c.check(rate.is_finite() && rate != 0.0, &field("rate_v_per_s"), rate, "a finite, non-zero voltage rate (V/s; Section 5.3 uses 0.05, or -0.05 for the minus sense)")?;
            JointMotion::VoltageRamp { rate_v_per_s: rate }
        }
    };
    Ok(Motion { leg, joint, motion })
}

/// `[ground_detection]`: legs 0..5 each at most once, thresholds between 0 and the robot's
/// weight, at least one trial, a sawtooth the tested legs follow around their initial joints
/// (inside the q_v stroke on AMRU5, the foot's height reached up and down on other legs), and a
/// period of at least four control periods.
fn validate_ground_detection(g: &GroundExperiment, c: &Ctx, robot: &Robot, initial: &Initial) -> std::result::Result<GroundExperiment, DescriptionError> {
    if g.legs.is_empty() {
        return Err(c.err("ground_detection.legs", "[]", "no leg to test", "a list of legs 0..5"));
    }
    for (n, &leg) in g.legs.iter().enumerate() {
        let field = format!("ground_detection.legs[{n}]");
        if leg >= 6 {
            return Err(c.err(&field, leg, "no such leg", "a leg number 0..5"));
        }
        if g.legs[..n].contains(&leg) {
            return Err(c.err(&field, leg, "listed twice", "each leg at most once"));
        }
        if initial.lifted_legs.contains(&leg) {
            return Err(c.err(&field, leg, "a lifted leg", "a leg standing on the ground at the start (not in initial.lifted_legs)"));
        }
    }
    if g.thresholds.is_empty() {
        return Err(c.err("ground_detection.thresholds_n", "[]", "no threshold", "a list of forces > 0 (N), e.g. [40, 50, 60]"));
    }
    // One foot never carries more than the whole robot: a higher threshold is never reached.
    let weight = robot.total_mass_kg() * STANDARD_GRAVITY;
    for (n, &f) in g.thresholds.iter().enumerate() {
        c.check(f > 0.0 && f < weight, &format!("ground_detection.thresholds_n[{n}]"), f, &format!("a force in (0, {}) N, below the robot's weight (the default [40, 50, 60] is AMRU5's Table 5.7: 12-18 % of its weight)", short(weight)))?;
    }
    c.check(g.trials >= 1, "ground_detection.trials", g.trials as f64, "an integer >= 1")?;
    let period = robot.period();
    c.check(g.period.is_finite() && g.period >= 4.0 * period, "ground_detection.period_s", g.period, &format!("a finite period >= {} s (four control periods)", 4.0 * period))?;
    match robot {
        Robot::Pantograph(d) => {
            let (lo, hi) = d.joint_range(PantographJoint::Vertical);
            let tol = STROKE_TOLERANCE * (hi - lo);
            let room = g.legs.iter().map(|&l| initial.joints[3 * l + 1]).map(|q| (q - lo).min(hi - q)).fold(f64::INFINITY, f64::min);
            c.check(g.amplitude > 0.0 && g.amplitude <= room + tol, "ground_detection.amplitude_m", g.amplitude, &format!("a value in (0, {}] m, so that q_v ± amplitude stays in the q_v stroke [{}, {}] m around initial.q_v_m", short(room), short(lo), short(hi)))?;
        }
        Robot::Serial(s) => {
            c.check(g.amplitude > 0.0 && g.amplitude.is_finite(), "ground_detection.amplitude_m", g.amplitude, "a foot height > 0 m")?;
            let legs = SerialLegKinematics::hexapod(&s.hexapod.legs).map_err(|err| c.err("scenario.robot", s.name.clone(), &format!("no leg kinematics: {err}"), "serial legs with valid joint ranges"))?;
            for &l in &g.legs {
                let foot = legs[l].foot(&Vector3::new(initial.joints[3 * l], initial.joints[3 * l + 1], initial.joints[3 * l + 2]));
                let reached = [1.0, -1.0].iter().all(|side| legs[l].reaches_point(&(foot + Vector3::z() * (side * g.amplitude))));
                c.check(reached, "ground_detection.amplitude_m", g.amplitude, &format!("a foot height that leg {l} reaches above and below its initial foothold (the sawtooth of a serial leg moves its foot straight up and down)"))?;
            }
        }
    }
    Ok(g.clone())
}

/// A number with at most 6 decimals, trailing zeros removed (0.4363323129985824 -> 0.436332).
fn short(x: f64) -> String {
    let s = format!("{x:.6}");
    let s = if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.') } else { &s };
    if s == "-0" { "0".to_string() } else { s.to_string() }
}
