//! `[control] mode = "gait"`: walking scenarios (thesis Chapter 7; the validation case of
//! Section 6.3, Table 6.2). The `[gait]` table (format: `docs/scenario-format.md`) is mirrored
//! and validated into a [`GaitScenario`]: the patterns and the foot cycle, the leg kinematics
//! and the workspace cylinders at the body height, the initial joints (every foot at its
//! steady foothold for its initial phase) and the heading source, with every support stroke checked against the
//! workspace. At run time [`GaitScenario::controller`] gives the gait controller with its
//! schedule of gait changes ([`crate::control::gait::schedule`]).

use std::cell::RefCell;
use std::path::Path;
use std::rc::Rc;

use nalgebra::Vector3;
use serde::Deserialize;

use crate::control::gait::controller::{joints_at, steady_footholds, AepMode, GaitController, GaitOptions};
use crate::control::gait::free::{FreeGaitController, FreeGaitOptions, LandingDetector, MotorCurrent, NormalForce, THESIS_CURRENT_THRESHOLD, THESIS_FORCE_THRESHOLD};
use crate::control::gait::heading::{Constant, Heading, HeadingSource, Segments, Series, Spline};
use crate::control::gait::pattern::{FootCycle, GaitKind, GaitPattern};
use crate::control::gait::schedule::{GaitChange, GaitState, PublishedFreeGait, ScheduledGait};
use crate::control::{joint_pis, Controller, DigitalPi, FrictionFeedForward, GroundSensingLeg};
use crate::hexapod::{default_serial_height, Leg, LegKinematics, LegKinematicsError, SerialLegKinematics, Workspace, JOINTS};
use crate::fields::{Ctx, DescriptionError};
use crate::description::Robot;

type Result<T> = std::result::Result<T, DescriptionError>;

/// Default foot clearance, the lift at mid-swing (m). INTERPRETATION (docs/validation-walk.md):
/// the lift of the validation walk, fitted to the 0.8 mm largest vertical tracking error of
/// Section 6.4.2 and above the 8 cm step the same takeoff generation crosses (Section 7.7.5);
/// no table of the thesis gives it.
pub const DEFAULT_CLEARANCE: f64 = 0.105;
/// Default overlap Δφ of the enhanced cycle (Table 6.2).
pub const DEFAULT_OVERLAP: f64 = 0.05;
/// Default duty factor of the wave and equal-phase gaits.
pub const DEFAULT_DUTY_FACTOR: f64 = 0.75;
/// The posture whose body height is the default (q_v = 0.06 m as the standing scenarios; q_h
/// does not change the foot height to first order).
const DEFAULT_POSTURE: [f64; 3] = [0.0, 0.06, 0.035];

// =============================================================================================
// Raw mirror of the [gait] table
// =============================================================================================

#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
enum CycleKind {
    #[default]
    Enhanced,
    Plain,
}

/// `gait.pattern`: a periodic pattern, or the free gait of Section 7.7.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
enum RawPattern {
    Tripod,
    Wave,
    EqualPhase,
    Free,
}

impl RawPattern {
    fn periodic(self) -> Option<GaitKind> {
        match self {
            RawPattern::Tripod => Some(GaitKind::Tripod),
            RawPattern::Wave => Some(GaitKind::Wave),
            RawPattern::EqualPhase => Some(GaitKind::EqualPhase),
            RawPattern::Free => None,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawGait {
    period_s: Option<f64>,
    pattern: RawPattern,
    duty_factor: Option<f64>,
    cycle: Option<CycleKind>,
    overlap: Option<f64>,
    aep: Option<AepMode>,
    clearance_m: Option<f64>,
    #[serde(default)]
    navigation: bool,
    #[serde(default)]
    friction_feedforward: bool,
    body_height_m: Option<f64>,
    foothold_offset_m: Option<f64>,
    heading: RawHeading,
    #[serde(default)]
    change: Vec<RawChange>,
    free: Option<RawFree>,
}

/// How the free gait detects the landings (`gait.free.landing`). Without the field: the motor
/// currents, as on the real robot.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum LandingKind {
    /// The ground force estimated from the motor currents (Section 5.6.3), as on the real
    /// robot, on the leg's own Jacobian and dynamics.
    Current,
    /// The true normal force above a threshold: the simulation mode of Section 7.7.
    Force,
}

/// `[gait.free]`: the free gait's parameters.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawFree {
    takeoff_s: Option<f64>,
    swing_s: Option<f64>,
    posture_time_s: Option<f64>,
    landing: Option<LandingKind>,
    landing_threshold_n: Option<f64>,
    failed_leg: Option<i64>,
    stability_margin_m: Option<f64>,
    energy_margin_m: Option<f64>,
    elevator: Option<bool>,
}

/// Kind of heading source in `[gait.heading]`.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
enum HeadingKind {
    Constant,
    Csv,
    BackAndForth,
    Square,
    Spline,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHeading {
    kind: HeadingKind,
    vx_m_s: Option<f64>,
    vy_m_s: Option<f64>,
    omega_z_rad_s: Option<f64>,
    file: Option<String>,
    side_m: Option<f64>,
    speed_m_s: Option<f64>,
    t_s: Option<Vec<f64>>,
    x_m: Option<Vec<f64>>,
    y_m: Option<Vec<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawChange {
    at_s: f64,
    pattern: GaitKind,
    duty_factor: Option<f64>,
}

// =============================================================================================
// The validated gait
// =============================================================================================

/// Where the heading velocities of a gait scenario come from.
#[derive(Clone, Debug, PartialEq)]
pub enum HeadingSpec {
    Constant(Heading),
    /// A CSV time series (t, vx, vy, omega_z), read when the scenario is validated.
    Csv { file: String, series: Series },
    /// Section 7.5.3: V_x = 0.015 m/s, then −0.02 m/s from t = 140 s.
    BackAndForth,
    /// Straight lines with sharp 90° turns: a square of `side` metres at `speed` m/s, then a
    /// stop.
    Square { side: f64, speed: f64 },
    /// A spline through waypoints (turned about its first one to start along +x), or the
    /// built-in path of Section 7.5.3.
    Spline { spline: Spline, built_in: bool },
}

impl HeadingSpec {
    /// The kind as written in scenario files.
    pub fn kind(&self) -> &'static str {
        match self {
            HeadingSpec::Constant(_) => "constant",
            HeadingSpec::Csv { .. } => "csv",
            HeadingSpec::BackAndForth => "back_and_forth",
            HeadingSpec::Square { .. } => "square",
            HeadingSpec::Spline { .. } => "spline",
        }
    }

    /// A fresh heading source for a run.
    pub fn source(&self) -> Box<dyn HeadingSource> {
        match self {
            HeadingSpec::Constant(h) => Box::new(Constant(*h)),
            HeadingSpec::Csv { series, .. } => Box::new(series.clone()),
            HeadingSpec::BackAndForth => Box::new(Segments::back_and_forth()),
            HeadingSpec::Square { side, speed } => {
                let mut s = Segments::square(*side, *speed);
                s.0.push((4.0 * side / speed, Heading::default()));
                Box::new(s)
            }
            HeadingSpec::Spline { spline, .. } => Box::new(spline.clone()),
        }
    }
}

/// The landing detection of a free gait scenario.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LandingSpec {
    /// [`MotorCurrent`]: the ground detection of Section 5.6.3 with its threshold on the
    /// estimated vertical ground force (N).
    Current { threshold: f64 },
    /// [`NormalForce`] with its threshold (N).
    Force { threshold: f64 },
}

impl LandingSpec {
    /// A fresh detector for a run of `robot`, whose legs have the kinematics `legs`, at the
    /// control period `dt` (s).
    pub fn detector<L: GroundSensingLeg + Clone + Send + 'static>(&self, robot: &Robot, legs: &[L; 6], dt: f64) -> Box<dyn LandingDetector> {
        match *self {
            LandingSpec::Current { threshold } => Box::new(MotorCurrent::new(robot, legs.clone(), dt, threshold)),
            LandingSpec::Force { threshold } => Box::new(NormalForce { threshold }),
        }
    }

    /// The threshold (N), on the estimated or on the true normal force.
    pub fn threshold(&self) -> f64 {
        match *self {
            LandingSpec::Current { threshold } | LandingSpec::Force { threshold } => threshold,
        }
    }
}

/// The free gait of a scenario (`pattern = "free"`).
#[derive(Clone, Debug, PartialEq)]
pub struct FreeGaitSpec {
    pub options: FreeGaitOptions,
    pub landing: LandingSpec,
}

/// The validated `[gait]` table, SI units.
#[derive(Clone, Debug, PartialEq)]
pub struct GaitScenario {
    /// Period, initial pattern, foot cycle, AEP mode, clearance (`lift`) and control period. For
    /// the free gait only `lift` and `dt` apply: the pattern is named "free", the period and
    /// the duty factor are NaN (no fixed cycle).
    pub options: GaitOptions,
    /// The free gait's parameters, with `pattern = "free"`.
    pub free: Option<FreeGaitSpec>,
    pub heading: HeadingSpec,
    /// Whether the controller receives the true body pose.
    pub navigation: bool,
    /// The friction feed-forward the master adds to its servo goals
    /// ([`crate::control::FrictionFeedForward`]; servo robots only), built from the robot as its
    /// file describes it: the friction the master knows, not a `[model.joint_friction]`
    /// override (a Monte Carlo draw).
    pub friction_feedforward: Option<FrictionFeedForward>,
    /// Height of the body frame above the ground the workspaces are computed for (m).
    pub body_height: f64,
    pub legs: GaitLegs,
    pub workspaces: [Workspace; 6],
    pub changes: Vec<GaitChange>,
    /// The initial posture: the steady footholds of the initial phases on the ground, by
    /// inverse kinematics.
    pub joints: [f64; JOINTS],
}

/// The legs a gait walks on: AMRU5's pantographs or serial chains. (Built once per scenario:
/// the variants' sizes do not matter.)
#[derive(Clone, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)]
pub enum GaitLegs {
    Pantograph([LegKinematics; 6]),
    Serial([SerialLegKinematics; 6]),
}

impl GaitScenario {
    /// A fresh gait controller for a run (the periodic one with the scheduled gait changes, or
    /// the free gait) with the 18 PI loops of the robot, and the state it publishes after each
    /// update.
    pub fn controller(&self, robot: &Robot) -> (Box<dyn Controller>, Rc<RefCell<GaitState>>) {
        let pis = joint_pis(&robot.pi_gains(), self.options.dt);
        match (&self.free, &self.legs) {
            (Some(free), GaitLegs::Pantograph(legs)) => self.published(free, legs, pis, robot),
            (Some(free), GaitLegs::Serial(legs)) => self.published(free, legs, pis, robot),
            (None, GaitLegs::Pantograph(legs)) => self.scheduled(legs, pis),
            (None, GaitLegs::Serial(legs)) => self.scheduled(legs, pis),
        }
    }

    /// The free gait on `legs`, publishing its state, with the master's friction feed-forward
    /// and the robot's masses (the centre of mass of its stability check).
    fn published<L: Leg + GroundSensingLeg + Clone + Send + 'static>(&self, free: &FreeGaitSpec, legs: &[L; 6], pis: [DigitalPi; JOINTS], robot: &Robot) -> (Box<dyn Controller>, Rc<RefCell<GaitState>>) {
        let controller = FreeGaitController::new(free.options.clone(), legs.clone(), self.workspaces, pis, self.heading.source(), free.landing.detector(robot, legs, self.options.dt));
        let (c, state) = PublishedFreeGait::new(controller.with_friction_feedforward(self.friction_feedforward.clone()).with_masses(robot.leg_dynamics()));
        (Box::new(c), state)
    }

    /// The periodic gait on `legs` with its scheduled changes, with the master's friction
    /// feed-forward.
    fn scheduled<L: Leg + Clone + 'static>(&self, legs: &[L; 6], pis: [DigitalPi; JOINTS]) -> (Box<dyn Controller>, Rc<RefCell<GaitState>>) {
        let controller = GaitController::new(self.options.clone(), legs.clone(), self.workspaces, pis, self.heading.source());
        let (c, state) = ScheduledGait::new(controller.with_friction_feedforward(self.friction_feedforward.clone()), self.changes.clone());
        (Box::new(c), state)
    }
}

/// The body height with q_v = 0.06 m (the default of `gait.body_height_m`).
pub fn default_body_height(legs: &[LegKinematics; 6]) -> f64 {
    -legs[0].foot(&Vector3::from(DEFAULT_POSTURE)).z
}

fn kind_name(k: GaitKind) -> &'static str {
    match k {
        GaitKind::Tripod => "tripod",
        GaitKind::Wave => "wave",
        GaitKind::EqualPhase => "equal_phase",
    }
}

/// The duty factor of a pattern: the tripod's is 1/2; wave and equal phase take [0.5, β_max).
fn duty_factor(c: &Ctx, field: &str, kind: GaitKind, value: Option<f64>, cycle: FootCycle) -> Result<f64> {
    match kind {
        GaitKind::Tripod => match value {
            None => Ok(0.5),
            Some(v) => c.check(v == 0.5, field, v, "0.5 or no duty_factor: the tripod gait has β = 1/2 (use pattern = \"wave\" or \"equal_phase\" for another β)").map(|_| 0.5),
        },
        GaitKind::Wave | GaitKind::EqualPhase => {
            let v = value.unwrap_or(DEFAULT_DUTY_FACTOR);
            // The horizontal swing lasts (1 − β − 4Δφ) T (enhanced) or (1 − β) T (plain).
            let max = cycle.swing_fraction(0.0);
            let why = match cycle {
                FootCycle::Plain => "β < 1 leaves a swing".to_string(),
                FootCycle::Enhanced { overlap } => format!("β + 4 overlap < 1 leaves a swing, overlap = {overlap}"),
            };
            c.check(v >= 0.5 && v < max, field, v, &format!("a duty factor in [0.5, {max}) for pattern = \"{}\" ({why}; at least three feet on the ground needs β >= 0.5)", kind_name(kind)))?;
            Ok(v)
        }
    }
}

/// Validates the `[gait]` table. `duration` is the scenario's (s).
///
/// `feedforward` is the master's friction feed-forward for the robot's servos (None without
/// servos), built from the robot as its file describes it, before the scenario's friction
/// overrides.
pub(super) fn validate(g: &RawGait, c: &Ctx, robot: &Robot, feedforward: Option<FrictionFeedForward>, dir: &Path, duration: f64) -> Result<GaitScenario> {
    let dt = robot.period();
    let periodic = match g.pattern.periodic() {
        Some(kind) => Some(periodic_pattern(g, c, kind, dt, duration)?),
        None => {
            reject_periodic_fields(g, c)?;
            None
        }
    };
    if let (Some(_), Some(_)) = (&periodic, &g.free) {
        return Err(c.err("gait.free", "[gait.free]", "a free gait table with a periodic pattern", "pattern = \"free\" with [gait.free] (or no [gait.free] table)"));
    }

    let clearance = g.clearance_m.unwrap_or(DEFAULT_CLEARANCE);
    c.positive("gait.clearance_m", clearance)?;
    let heading = || validate_heading(&g.heading, c, dir);
    let no_kinematics = |e: LegKinematicsError, what: &str| c.err("scenario.robot", robot.origin(), &format!("no leg kinematics: {e}"), what);

    let gait = match robot {
        Robot::Pantograph(d) => {
            let legs = LegKinematics::hexapod_from_description(d).map_err(|e| no_kinematics(e, "a robot description whose pantograph closes over the joint ranges"))?;
            let stance = stance(g, c, &legs, default_body_height(&legs), " (the default, q_v = 0.06 m)", clearance)?;
            let heading = heading()?;
            match periodic {
                None => free_gait(g, c, heading, &legs, &stance, clearance, dt, LandingDefaults::PANTOGRAPH),
                Some(p) => periodic_gait(g, c, p, heading, &legs, &stance, clearance, dt, duration),
            }
            .map(|w| w.on(GaitLegs::Pantograph(legs), stance))
        }
        Robot::Serial(s) => {
            let legs = SerialLegKinematics::hexapod(&s.hexapod.legs).map_err(|e| no_kinematics(e, "serial legs with valid joint ranges"))?;
            let stance = stance(g, c, &legs, default_serial_height(&legs), " (the default: the feet with every joint at mid-range)", clearance)?;
            let heading = heading()?;
            match periodic {
                None => free_gait(g, c, heading, &legs, &stance, clearance, dt, LandingDefaults::weighted(robot)),
                Some(p) => periodic_gait(g, c, p, heading, &legs, &stance, clearance, dt, duration),
            }
            .map(|w| w.on(GaitLegs::Serial(legs), stance))
        }
    }?;
    let friction_feedforward = match (g.friction_feedforward, feedforward) {
        (false, _) => None,
        (true, Some(f)) => Some(f),
        (true, None) => return Err(c.err("gait.friction_feedforward", "true", "a feed-forward for position servos", "false with a robot whose joints are driven by PI loops (their integral action takes the friction)")),
    };
    Ok(GaitScenario { friction_feedforward, ..gait })
}

/// The body height of a gait and the workspace cylinders of the legs at it.
struct Stance {
    height: f64,
    workspaces: [Workspace; 6],
    /// " (the default ...)" when the height was not written.
    given: &'static str,
}

/// The body height (`gait.body_height_m` or `default`) and the workspace of each leg for the
/// foot heights from the ground to the clearance (Section 7.1.1), moved radially by
/// `gait.foothold_offset_m` (beyond the thesis, whose footholds centre on the largest
/// cylinder's axis C, Eq. 7.24: the spread of the feet as a design parameter, the cylinder
/// shrunk to stay within the reach).
fn stance<L: Leg>(g: &RawGait, c: &Ctx, legs: &[L; 6], default: f64, default_text: &'static str, clearance: f64) -> Result<Stance> {
    let height = g.body_height_m.unwrap_or(default);
    let given = if g.body_height_m.is_some() { "" } else { default_text };
    if !(height.is_finite() && height > 0.0) {
        return Err(c.err("gait.body_height_m", height, "not a positive finite number", reach(legs)));
    }
    let mut workspaces: Vec<Workspace> = Vec::with_capacity(6);
    for (l, leg) in legs.iter().enumerate() {
        // The workspace search is costly (a large share of a short walk's run time): legs that
        // reach the same points of their leg frames share it.
        if let Some(m) = (0..l).find(|&m| legs[m].same_leg_frame_reach(leg)) {
            workspaces.push(workspaces[m]);
            continue;
        }
        match leg.workspace(-height, -height + clearance) {
            Ok(w) => workspaces.push(w),
            // No workspace even without a clearance: the height is the problem.
            Err(_) if leg.workspace(-height, -height).is_err() => return Err(c.err("gait.body_height_m", format!("{height}{given}"), "the feet cannot stand at this height", reach(legs))),
            Err(e) => {
                // The largest clearance that still has a workspace, by bisection.
                let (mut ok, mut bad) = (0.0, clearance);
                for _ in 0..30 {
                    let m = 0.5 * (ok + bad);
                    if leg.workspace(-height, -height + m).is_ok() {
                        ok = m;
                    } else {
                        bad = m;
                    }
                }
                return Err(c.err("gait.clearance_m", clearance, &format!("no workspace: {e}"), format!("a clearance in (0, {ok:.4}) m at the body height {height:.4} m{given}")));
            }
        }
    }
    if let Some(offset) = g.foothold_offset_m {
        let smallest = workspaces.iter().map(|w| w.radius).fold(f64::INFINITY, f64::min);
        let allowed = format!("a finite offset (m) of magnitude below {smallest:.4}, the smallest workspace radius at the body height {height:.4} m{given} and clearance {clearance} m");
        c.check(offset.is_finite() && offset.abs() < smallest, "gait.foothold_offset_m", offset, &allowed)?;
        for w in &mut workspaces {
            *w = w.moved_radially(offset).ok_or_else(|| c.err("gait.foothold_offset_m", offset, "a leg whose workspace centre is on its mount's vertical", "no foothold offset with this robot"))?;
        }
    }
    Ok(Stance { height, workspaces: workspaces.try_into().expect("six legs"), given })
}

/// What `gait.body_height_m` allows, for the errors: the heights where every foot reaches the
/// ground (the feet on the ground are at z = −height in the leg frame). Only an error asks for
/// it: a serial leg's height range is a search over its joint box.
fn reach<L: Leg>(legs: &[L; 6]) -> String {
    let (lowest, highest) = legs.iter().map(|l| l.height_range()).fold((f64::NEG_INFINITY, f64::INFINITY), |(lo, hi), (l, h)| (lo.max(l), hi.min(h)));
    format!("a body height in ({:.4}, {:.4}) m, where the feet reach the ground (foot heights [{:.4}, {:.4}] m in the leg frame)", -highest, -lowest, lowest, highest)
}

/// A gait's set-up before its legs are wrapped.
struct Walking {
    options: GaitOptions,
    /// The free gait's parameters, with `pattern = "free"`.
    free: Option<FreeGaitSpec>,
    heading: HeadingSpec,
    navigation: bool,
    changes: Vec<GaitChange>,
    joints: [f64; JOINTS],
}

impl Walking {
    fn on(self, legs: GaitLegs, stance: Stance) -> GaitScenario {
        GaitScenario { options: self.options, free: self.free, heading: self.heading, navigation: self.navigation, friction_feedforward: None, body_height: stance.height, legs, workspaces: stance.workspaces, changes: self.changes, joints: self.joints }
    }
}

/// The periodic gait: every support stroke fits its workspace and the feet start at their
/// steady footholds.
#[allow(clippy::too_many_arguments)]
fn periodic_gait<L: Leg>(g: &RawGait, c: &Ctx, p: Periodic, heading: HeadingSpec, legs: &[L; 6], stance: &Stance, clearance: f64, dt: f64, duration: f64) -> Result<Walking> {
    let Stance { height, workspaces, given } = stance;
    let (height, workspaces) = (*height, *workspaces);
    let (cycle, period_s) = (p.cycle, p.period);
    let patterns: Vec<&GaitPattern> = std::iter::once(&p.pattern).chain(p.changes.iter().map(|ch| &ch.pattern)).collect();

    // Strokes: every support stroke, |v_C| x support time, fits the workspace diameter.
    let support = patterns.iter().map(|p| cycle.support_fraction(p.beta)).fold(0.0, f64::max) * period_s;
    // Only the instants where the heading can be largest are checked (a bounded number, not
    // one per control period of a possibly very long run).
    let mut source = heading.source();
    let arms: Vec<f64> = (0..6).map(|l| legs[l].to_body(&workspaces[l].centre_at(-height)).xy().norm()).collect();
    let (mut worst, mut worst_t, mut worst_leg, mut worst_ratio) = (0.0f64, 0.0, 0, 0.0f64);
    for t in source.extreme_times(duration, dt) {
        let h = source.heading(t);
        for l in 0..6 {
            // The largest |v + ω × r_C| over the yaw the body may have.
            let v = h.velocity.xy().norm() + h.yaw_rate.abs() * arms[l];
            let ratio = v * support / (2.0 * workspaces[l].radius);
            if ratio > worst_ratio {
                (worst, worst_t, worst_leg, worst_ratio) = (v, t, l, ratio);
            }
        }
    }
    if worst_ratio > 1.0 + 1e-9 {
        let r = workspaces[worst_leg].radius;
        let which = match cycle {
            FootCycle::Plain => "β T".to_string(),
            FootCycle::Enhanced { .. } => "(β + 4 overlap) T".to_string(),
        };
        return Err(c.err(
            "gait.heading",
            format!("{} heading with |v_C| up to {worst:.4} m/s (t = {worst_t:.2} s, leg {worst_leg})", heading.kind()),
            &format!("the support stroke |v_C| x {which} = {worst:.4} m/s x {support:.2} s = {:.4} m does not fit the workspace (diameter 2 x {r:.4} m)", worst * support),
            format!(
                "|v_C| <= {:.4} m/s with gait.period_s = {} s (v_C = v + Ω_z x r_C at the workspace centre; Section 7.5), or a gait.period_s <= {:.3} s",
                2.0 * r / support,
                period_s,
                period_s / worst_ratio
            ),
        ));
    }

    let options = GaitOptions { period: period_s, pattern: p.pattern, cycle, aep: p.aep, lift: clearance, dt };
    let footholds = steady_footholds(legs, &workspaces, height, &options, &heading.source().heading(0.0));
    let joints = joints_at(legs, &footholds)
        .map_err(|l| c.err("gait.body_height_m", format!("{height}{given}"), &format!("leg {l} cannot reach its start foothold"), reach(legs)))?;
    Ok(Walking { options, free: None, heading, navigation: g.navigation, changes: p.changes, joints })
}


/// Default takeoff duration of the free gait (s).
///
/// INTERPRETATION: Section 7.7.3 fixes the takeoff time without giving it; the enhanced cycle
/// of the validation walks (Table 6.2, T = 12 s, Δφ = 5 %) takes off in 1.5 Δφ T = 0.9 s. 1 s.
pub const DEFAULT_TAKEOFF_S: f64 = 1.0;
/// Section 7.7.3: the swing's constant time, "fixed in our case at 3 s".
pub const DEFAULT_SWING_S: f64 = 3.0;
/// Section 7.7.1: t_post "has been set to 2 s".
pub const DEFAULT_POSTURE_TIME_S: f64 = 2.0;
/// Smallest static stability margin when a leg lifts on five legs (m).
///
/// INTERPRETATION (beyond the thesis): 2 cm, about the 1.5 cm the feet and the body centre of
/// mass move apart when the body pitches by 2° at the 0.41 m body height, plus the foot radius.
pub const DEFAULT_STABILITY_MARGIN_M: f64 = 0.02;
/// Smallest normalized energy stability margin when a leg lifts (m, any number of legs).
///
/// INTERPRETATION (beyond the thesis): 0, static stability itself: a lift that would leave the
/// feet in support unable to hold the body still (its centre beyond an edge of their polygon,
/// tilted ground included) waits; any positive margin lets the thesis' rules choose as they
/// do. A reserve against the body's sway and the estimate of its centre is the user's to add.
pub const DEFAULT_ENERGY_MARGIN_M: f64 = 0.0;

/// The default thresholds of each landing detection of a free gait.
#[derive(Clone, Copy, Debug)]
struct LandingDefaults {
    /// N, on the true normal force (Section 7.7's 10 N on AMRU5).
    force: f64,
    /// N, on the force estimated from the currents (Section 5.6.3's 40 N on AMRU5).
    current: f64,
}

impl LandingDefaults {
    /// AMRU5's pantograph: the thesis' thresholds.
    const PANTOGRAPH: LandingDefaults = LandingDefaults { force: THESIS_FORCE_THRESHOLD, current: THESIS_CURRENT_THRESHOLD };

    /// A robot other than AMRU5: the thresholds at the same share of the robot's weight as of
    /// AMRU5's.
    ///
    /// INTERPRETATION: 10 N is 3 % of AMRU5's weight; on the 1.8 kg PhantomX it would be 55 %,
    /// reached only once the leg carries half the body, and its free gait clamps its references
    /// and halts after 0.10 m. The currents' 40 N scale the same way (2.1 N on the PhantomX, a
    /// third of a tripod leg's 6 N load; AMRU5's 40 N is 40 % of its 100 N, Section 5.6.3).
    fn weighted(robot: &Robot) -> LandingDefaults {
        let (mass, amru5_mass) = (robot.total_mass_kg(), crate::description::RobotDescription::amru5().total_mass_kg());
        let weighted = |threshold: f64| threshold * mass / amru5_mass;
        LandingDefaults { force: weighted(THESIS_FORCE_THRESHOLD), current: weighted(THESIS_CURRENT_THRESHOLD) }
    }
}

/// The free gait (`pattern = "free"`, `[gait.free]`): every working foot starts on the ground at
/// its workspace centre, a failed leg held up at the top of its workspace. Without a `landing`
/// field the landings are detected from the motor currents, as on the real robot (Section 7.7);
/// `defaults`: the thresholds without a `landing_threshold_n`.
#[allow(clippy::too_many_arguments)]
fn free_gait<L: Leg>(g: &RawGait, c: &Ctx, heading: HeadingSpec, legs: &[L; 6], stance: &Stance, lift: f64, dt: f64, defaults: LandingDefaults) -> Result<Walking> {
    let Stance { height, workspaces, given } = *stance;
    let default = RawFree::default();
    let raw = g.free.as_ref().unwrap_or(&default);
    let positive = |field: &str, v: Option<f64>, default: f64| -> Result<f64> {
        let v = v.unwrap_or(default);
        c.check(v.is_finite() && v >= dt, &format!("gait.free.{field}"), v, &format!("a duration >= the control period {dt} s"))?;
        Ok(v)
    };
    let takeoff_time = positive("takeoff_s", raw.takeoff_s, DEFAULT_TAKEOFF_S)?;
    let swing_time = positive("swing_s", raw.swing_s, DEFAULT_SWING_S)?;
    let posture_time = positive("posture_time_s", raw.posture_time_s, DEFAULT_POSTURE_TIME_S)?;
    let landing = raw.landing.unwrap_or(LandingKind::Current);
    let (default_threshold, allowed) = match landing {
        LandingKind::Current => (defaults.current, "an estimated vertical ground force > 0 N with landing = \"current\" (default: Section 5.6.3's lowest threshold, 40 N on AMRU5, at the share of the robot's weight it is of AMRU5's)"),
        LandingKind::Force => (defaults.force, "a normal force > 0 N with landing = \"force\" (default: Section 7.7's 10 N at the share of the robot's weight it is of AMRU5's)"),
    };
    let threshold = raw.landing_threshold_n.unwrap_or(default_threshold);
    c.check(threshold.is_finite() && threshold > 0.0, "gait.free.landing_threshold_n", threshold, allowed)?;
    let failed_leg = match raw.failed_leg {
        None => None,
        Some(l) => {
            c.check((0..6).contains(&l), "gait.free.failed_leg", l as f64, "a leg number 0..5 (0, 2, 4 on the left from front to rear, 1, 3, 5 on the right), or no failed_leg")?;
            Some(l as usize)
        }
    };
    let stability_margin = raw.stability_margin_m.unwrap_or(DEFAULT_STABILITY_MARGIN_M);
    c.check(stability_margin.is_finite() && stability_margin >= 0.0, "gait.free.stability_margin_m", stability_margin, "a distance >= 0 m")?;
    let energy_margin = raw.energy_margin_m.unwrap_or(DEFAULT_ENERGY_MARGIN_M);
    c.check(energy_margin.is_finite() && energy_margin >= 0.0, "gait.free.energy_margin_m", energy_margin, "a height >= 0 m")?;
    // The elevator reflex reads the same estimator as the landing, at the same threshold.
    let elevator = raw.elevator.unwrap_or(true).then_some(threshold);
    let options = FreeGaitOptions { body_height: height, lift, takeoff_time, swing_time, posture_time, failed_leg, stability_margin, energy_margin, dt, elevator };
    let footholds: [Vector3<f64>; 6] = std::array::from_fn(|l| {
        let w = &workspaces[l];
        if failed_leg == Some(l) {
            w.centre_at(w.z_max)
        } else {
            w.centre_at(-height)
        }
    });
    let joints = joints_at(legs, &footholds)
        .map_err(|l| c.err("gait.body_height_m", format!("{height}{given}"), &format!("leg {l} cannot reach its start foothold"), reach(legs)))?;
    let free_pattern = GaitPattern { name: "free".into(), beta: f64::NAN, offsets: [0.0; 6] };
    let periodic = GaitOptions { period: f64::NAN, pattern: free_pattern, cycle: FootCycle::Plain, aep: AepMode::Omnidirectional, lift, dt };
    let free = FreeGaitSpec { options, landing: match landing {
        LandingKind::Current => LandingSpec::Current { threshold },
        LandingKind::Force => LandingSpec::Force { threshold },
    } };
    Ok(Walking { options: periodic, free: Some(free), heading, navigation: g.navigation, changes: Vec::new(), joints })
}

/// The period, the patterns, the foot cycle and the gait changes of a periodic gait.
struct Periodic {
    period: f64,
    pattern: GaitPattern,
    cycle: FootCycle,
    aep: AepMode,
    changes: Vec<GaitChange>,
}

/// The fields of the periodic gaits are not those of the free gait.
fn reject_periodic_fields(g: &RawGait, c: &Ctx) -> Result<()> {
    let written = [
        ("period_s", g.period_s.map(|v| v.to_string())),
        ("duty_factor", g.duty_factor.map(|v| v.to_string())),
        ("cycle", g.cycle.map(|v| format!("{v:?}").to_lowercase())),
        ("overlap", g.overlap.map(|v| v.to_string())),
        ("aep", g.aep.map(|v| format!("{v:?}").to_lowercase())),
        ("change", (!g.change.is_empty()).then(|| format!("{} changes", g.change.len()))),
    ];
    for (name, value) in written {
        if let Some(v) = value {
            return Err(c.err(&format!("gait.{name}"), v, "not a field of pattern = \"free\"", "with the free gait: clearance_m, navigation, body_height_m, foothold_offset_m, [gait.heading] and [gait.free] (takeoff_s, swing_s, posture_time_s, landing, landing_threshold_n, failed_leg, stability_margin_m, energy_margin_m, elevator)"));
        }
    }
    Ok(())
}

fn periodic_pattern(g: &RawGait, c: &Ctx, kind: GaitKind, dt: f64, duration: f64) -> Result<Periodic> {
    let period_s = g.period_s.ok_or_else(|| c.err("gait.period_s", "<missing>", "missing field", format!("a leg cycle time T (s) with pattern = \"{}\"", kind_name(kind))))?;
    // Foot cycle.
    let cycle = match g.cycle.unwrap_or_default() {
        CycleKind::Plain => {
            if let Some(v) = g.overlap {
                return Err(c.err("gait.overlap", v, "not a field of cycle = \"plain\"", "no overlap with the plain cycle (or cycle = \"enhanced\")"));
            }
            FootCycle::Plain
        }
        CycleKind::Enhanced => {
            let overlap = g.overlap.unwrap_or(DEFAULT_OVERLAP);
            c.check(overlap > 0.0 && overlap < 0.125, "gait.overlap", overlap, "an overlap Δφ in (0, 0.125) (cycle fraction; the takeoff, swing and landing fill 1 − β − Δφ of the cycle, so β + 4Δφ < 1 with β >= 0.5; Table 6.2: 0.05), or cycle = \"plain\"")?;
            FootCycle::Enhanced { overlap }
        }
    };

    // Patterns: the initial one and the changes.
    let beta = duty_factor(c, "gait.duty_factor", kind, g.duty_factor, cycle)?;
    let pattern = GaitPattern::of(kind, beta);
    let mut changes = Vec::new();
    let mut previous = 0.0;
    for (n, ch) in g.change.iter().enumerate() {
        let field = |name: &str| format!("gait.change[{n}].{name}");
        c.check(ch.at_s > previous && ch.at_s < duration, &field("at_s"), ch.at_s, &format!("a time in ({previous}, {duration}) s: after the start{} and before the end of the scenario", if n > 0 { " and the previous change" } else { "" }))?;
        previous = ch.at_s;
        let b = duty_factor(c, &field("duty_factor"), ch.pattern, ch.duty_factor, cycle)?;
        changes.push(GaitChange { at: ch.at_s, pattern: GaitPattern::of(ch.pattern, b) });
    }
    let patterns: Vec<&GaitPattern> = std::iter::once(&pattern).chain(changes.iter().map(|ch| &ch.pattern)).collect();

    // Period: every swing, takeoff and landing lasts at least one control period.
    let shortest = patterns
        .iter()
        .map(|p| cycle.swing_fraction(p.beta))
        .chain((cycle.transition_fraction() > 0.0).then(|| cycle.transition_fraction()))
        .fold(f64::INFINITY, f64::min);
    let min_period = dt / shortest;
    c.check(period_s >= min_period * (1.0 - 1e-9), "gait.period_s", period_s, &format!("a leg cycle time >= {min_period:.4} s, so that the swing{} each last at least one control period ({dt} s)", if cycle.transition_fraction() > 0.0 { ", the takeoff and the landing" } else { "" }))?;
    Ok(Periodic { period: period_s, pattern, cycle, aep: g.aep.unwrap_or(AepMode::Periodic), changes })
}

fn validate_heading(h: &RawHeading, c: &Ctx, dir: &Path) -> Result<HeadingSpec> {
    let field = |name: &str| format!("gait.heading.{name}");
    let (kind, used): (&str, &[&str]) = match h.kind {
        HeadingKind::Constant => ("constant", &["vx_m_s", "vy_m_s", "omega_z_rad_s"]),
        HeadingKind::Csv => ("csv", &["file"]),
        HeadingKind::BackAndForth => ("back_and_forth", &[]),
        HeadingKind::Square => ("square", &["side_m", "speed_m_s"]),
        HeadingKind::Spline => ("spline", &["t_s", "x_m", "y_m"]),
    };
    let present = [
        ("vx_m_s", h.vx_m_s.map(|v| v.to_string())),
        ("vy_m_s", h.vy_m_s.map(|v| v.to_string())),
        ("omega_z_rad_s", h.omega_z_rad_s.map(|v| v.to_string())),
        ("file", h.file.as_ref().map(|f| format!("{f:?}"))),
        ("side_m", h.side_m.map(|v| v.to_string())),
        ("speed_m_s", h.speed_m_s.map(|v| v.to_string())),
        ("t_s", h.t_s.as_ref().map(|v| format!("{v:?}"))),
        ("x_m", h.x_m.as_ref().map(|v| format!("{v:?}"))),
        ("y_m", h.y_m.as_ref().map(|v| format!("{v:?}"))),
    ];
    for (name, value) in &present {
        if let Some(v) = value {
            if !used.contains(name) {
                let allowed = if used.is_empty() { format!("no other field with kind = \"{kind}\"") } else { format!("for kind = \"{kind}\": {}", used.join(", ")) };
                return Err(c.err(&field(name), v, &format!("not a field of kind = \"{kind}\""), allowed));
            }
        }
    }
    let required = |name: &str, v: Option<f64>| v.ok_or_else(|| c.err(&field(name), "<missing>", "missing field", format!("kind = \"{kind}\" needs {}", used.join(", "))));
    Ok(match h.kind {
        HeadingKind::Constant => {
            let vx = h.vx_m_s.unwrap_or(0.0);
            let vy = h.vy_m_s.unwrap_or(0.0);
            let wz = h.omega_z_rad_s.unwrap_or(0.0);
            c.finite(&field("vx_m_s"), vx)?;
            c.finite(&field("vy_m_s"), vy)?;
            c.finite(&field("omega_z_rad_s"), wz)?;
            HeadingSpec::Constant(Heading::new(vx, vy, wz))
        }
        HeadingKind::Csv => {
            let file = h.file.as_ref().ok_or_else(|| c.err(&field("file"), "<missing>", "missing field", "kind = \"csv\" needs file, a CSV file relative to the scenario"))?;
            let path = if Path::new(file).is_absolute() { Path::new(file).to_path_buf() } else { dir.join(file) };
            let series = Series::from_csv(&path).map_err(|e| {
                c.err(&field("file"), format!("{file:?}"), &e.to_string(), "a CSV file relative to the scenario file, header t,vx,vy,omega_z (s, m/s, m/s, rad/s), times strictly increasing")
            })?;
            HeadingSpec::Csv { file: path.display().to_string(), series }
        }
        HeadingKind::BackAndForth => HeadingSpec::BackAndForth,
        HeadingKind::Square => {
            let side = required("side_m", h.side_m)?;
            let speed = required("speed_m_s", h.speed_m_s)?;
            c.positive(&field("side_m"), side)?;
            c.positive(&field("speed_m_s"), speed)?;
            HeadingSpec::Square { side, speed }
        }
        HeadingKind::Spline => match (&h.t_s, &h.x_m, &h.y_m) {
            (None, None, None) => HeadingSpec::Spline { spline: Spline::section_7_5_3(), built_in: true },
            (Some(t), Some(x), Some(y)) => {
                if t.len() < 2 {
                    return Err(c.err(&field("t_s"), format!("{t:?}"), "too few waypoints", "at least 2 waypoint times"));
                }
                for (name, v) in [("x_m", x), ("y_m", y)] {
                    if v.len() != t.len() {
                        return Err(c.err(&field(name), format!("{} values", v.len()), "not one value per waypoint", format!("{} values, as many as t_s", t.len())));
                    }
                }
                for (i, &ti) in t.iter().enumerate() {
                    let lower = if i == 0 { 0.0 } else { t[i - 1] };
                    let ok = if i == 0 { ti >= 0.0 } else { ti > lower };
                    c.check(ok, &format!("{}[{i}]", field("t_s")), ti, &if i == 0 { "a time >= 0 s".to_string() } else { format!("a time > t_s[{}] = {lower} s (strictly increasing)", i - 1) })?;
                }
                for (name, v) in [("x_m", x), ("y_m", y)] {
                    for (i, &vi) in v.iter().enumerate() {
                        c.finite(&format!("{}[{i}]", field(name)), vi)?;
                    }
                }
                HeadingSpec::Spline { spline: Spline::starting_along_x(t, x, y), built_in: false }
            }
            _ => {
                let missing = [("t_s", h.t_s.is_none()), ("x_m", h.x_m.is_none()), ("y_m", h.y_m.is_none())].iter().find(|(_, m)| *m).map(|(n, _)| *n).unwrap_or("t_s");
                return Err(c.err(&field(missing), "<missing>", "missing field", "all of t_s, x_m, y_m (waypoints), or none of them for the built-in path of Section 7.5.3"));
            }
        },
    })
}
