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
use crate::control::gait::heading::{Constant, Heading, HeadingSource, Segments, Series, Spline};
use crate::control::gait::pattern::{FootCycle, GaitKind, GaitPattern};
use crate::control::gait::schedule::{GaitChange, GaitState, ScheduledGait};
use crate::control::joint_pis;
use crate::hexapod::{LegKinematics, Workspace, JOINTS};
use crate::fields::{Ctx, DescriptionError};
use crate::description::RobotDescription;

type Result<T> = std::result::Result<T, DescriptionError>;

/// Default foot clearance (m).
pub const DEFAULT_CLEARANCE: f64 = 0.045;
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

fn default_aep() -> AepMode {
    AepMode::Periodic
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawGait {
    period_s: f64,
    pattern: GaitKind,
    duty_factor: Option<f64>,
    #[serde(default)]
    cycle: CycleKind,
    overlap: Option<f64>,
    #[serde(default = "default_aep")]
    aep: AepMode,
    clearance_m: Option<f64>,
    #[serde(default)]
    navigation: bool,
    body_height_m: Option<f64>,
    heading: RawHeading,
    #[serde(default)]
    change: Vec<RawChange>,
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

/// The validated `[gait]` table, SI units.
#[derive(Clone, Debug, PartialEq)]
pub struct GaitScenario {
    /// Period, initial pattern, foot cycle, AEP mode, clearance (`lift`) and control period.
    pub options: GaitOptions,
    pub heading: HeadingSpec,
    /// Whether the controller receives the true body pose.
    pub navigation: bool,
    /// Height of the body frame above the ground the workspaces are computed for (m).
    pub body_height: f64,
    pub legs: [LegKinematics; 6],
    pub workspaces: [Workspace; 6],
    pub changes: Vec<GaitChange>,
    /// The initial posture: the steady footholds of the initial phases on the ground, by
    /// inverse kinematics.
    pub joints: [f64; JOINTS],
}

impl GaitScenario {
    /// A fresh gait controller for a run, with the scheduled gait changes and the 18 PI loops of
    /// the robot, and the state it publishes after each update.
    pub fn controller(&self, robot: &RobotDescription) -> (ScheduledGait, Rc<RefCell<GaitState>>) {
        let pis = joint_pis(robot, self.options.dt);
        let controller = GaitController::new(self.options.clone(), self.legs.clone(), self.workspaces, pis, self.heading.source());
        ScheduledGait::new(controller, self.changes.clone())
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
pub(super) fn validate(g: &RawGait, c: &Ctx, robot: &RobotDescription, dir: &Path, duration: f64) -> Result<GaitScenario> {
    let dt = robot.controller.period_s;

    // Foot cycle.
    let cycle = match g.cycle {
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
    let beta = duty_factor(c, "gait.duty_factor", g.pattern, g.duty_factor, cycle)?;
    let pattern = GaitPattern::of(g.pattern, beta);
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
    c.check(g.period_s >= min_period * (1.0 - 1e-9), "gait.period_s", g.period_s, &format!("a leg cycle time >= {min_period:.4} s, so that the swing{} each last at least one control period ({dt} s)", if cycle.transition_fraction() > 0.0 { ", the takeoff and the landing" } else { "" }))?;

    let clearance = g.clearance_m.unwrap_or(DEFAULT_CLEARANCE);
    c.positive("gait.clearance_m", clearance)?;

    // Leg kinematics and workspaces at the body height.
    let legs = LegKinematics::hexapod_from_description(robot)
        .map_err(|e| c.err("scenario.robot", &robot.origin, &format!("no leg kinematics: {e}"), "a robot description whose pantograph closes over the joint ranges"))?;
    let height = match g.body_height_m {
        Some(h) => h,
        None => default_body_height(&legs),
    };
    let given = if g.body_height_m.is_some() { "" } else { " (the default, q_v = 0.06 m)" };
    let (lowest, highest) = legs[0].height_range();
    // The feet on the ground are at z = −height in the leg frame.
    let reach = format!("a body height in ({:.4}, {:.4}) m, where the feet reach the ground (foot heights [{:.4}, {:.4}] m in the leg frame)", -highest, -lowest, lowest, highest);
    if !(height.is_finite() && height > 0.0) {
        return Err(c.err("gait.body_height_m", height, "not a positive finite number", reach));
    }
    for leg in &legs {
        if leg.workspace(-height, -height).is_err() {
            return Err(c.err("gait.body_height_m", format!("{height}{given}"), "the feet cannot stand at this height", reach));
        }
    }
    let mut workspaces: Vec<Workspace> = Vec::with_capacity(6);
    for (l, leg) in legs.iter().enumerate() {
        // The workspace search is costly (a large share of a short walk's run time): legs that
        // reach the same points of their leg frames share it.
        if let Some(m) = (0..l).find(|&m| legs[m].same_leg_frame_reach(leg)) {
            workspaces.push(workspaces[m]);
            continue;
        }
        match leg.workspace_for_body_height(height, clearance) {
            Ok(w) => workspaces.push(w),
            Err(e) => {
                // The largest clearance that still has a workspace, by bisection.
                let (mut ok, mut bad) = (0.0, clearance);
                for _ in 0..30 {
                    let m = 0.5 * (ok + bad);
                    if leg.workspace_for_body_height(height, m).is_ok() {
                        ok = m;
                    } else {
                        bad = m;
                    }
                }
                return Err(c.err("gait.clearance_m", clearance, &format!("no workspace: {e}"), format!("a clearance in (0, {ok:.4}) m at the body height {height:.4} m{given}")));
            }
        }
    }
    let workspaces: [Workspace; 6] = workspaces.try_into().expect("six legs");
    let heading = validate_heading(&g.heading, c, dir)?;

    // Strokes: every support stroke, |v_C| x support time, fits the workspace diameter.
    let support = patterns.iter().map(|p| cycle.support_fraction(p.beta)).fold(0.0, f64::max) * g.period_s;
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
                g.period_s,
                g.period_s / worst_ratio
            ),
        ));
    }

    let options = GaitOptions { period: g.period_s, pattern, cycle, aep: g.aep, lift: clearance, dt };
    let footholds = steady_footholds(&legs, &workspaces, height, &options, &heading.source().heading(0.0));
    let joints = joints_at(&legs, &footholds)
        .map_err(|l| c.err("gait.body_height_m", format!("{height}{given}"), &format!("leg {l} cannot reach its start foothold"), reach.clone()))?;
    Ok(GaitScenario { options, heading, navigation: g.navigation, body_height: height, legs, workspaces, changes, joints })
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
