//! Did a walk succeed? The judgement of a free-gait run over uneven ground (issue 11's terrain
//! classes): success is no fall and no permanent deadlock (Section 7.7.4), read from the
//! recorded columns ([`crate::robot::columns`]) and the ground the robot walked on.
//!
//! A fall is any of (INTERPRETATION, the thesis defines none; each is a physical state the
//! real robot could not walk out of):
//! - the body touches the ground: a point of the main body's bottom plate (a disc of radius
//!   R_rot, H/2 + e_b below the body centre, Table B.1) lies below the ground under it;
//! - the body tips over: its z_b axis leans more than [`Bounds::max_tilt`] (30°) from the
//!   normal of the ground at large (on the 25° slope the body stands parallel to the slope;
//!   a step or a 3 cm RMS roughness tilts it by a few degrees);
//! - the support is lost: fewer than three feet carry a normal force for longer than
//!   [`Bounds::support_loss_s`] (1 s): the robot rests on two feet at most, not a support
//!   polygon.
//!
//! A deadlock (the `deadlock` column) is permanent when it is still on at the end and has
//! lasted [`Bounds::deadlock_permanent_s`] (20 s, four times the 5 s a leg needs for takeoff,
//! swing and landing: a deadlock that the legs finishing their vertical motion clear ends well
//! before). A robot that advanced less than [`Bounds::min_progress`] of the commanded distance
//! is stalled: a deadlock that never shows as one (legs waiting on a landing that never comes).

use std::ops::ControlFlow;

use nalgebra::Vector3;

use crate::description::RobotDescription;
use crate::physics::Terrain;
use crate::robot::recorder::TimeSeries;
use crate::spatial::yaw_pitch_roll;

/// The main body as a disc under the body centre (Table B.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyBottom {
    /// Radius of the bottom plate: R_rot (m).
    pub radius: f64,
    /// Depth of the bottom plate's underside below the body centre along z_b: H/2 + e_b (m).
    /// INTERPRETATION: the body centre (the pose's origin) is taken midway between the rings.
    pub depth: f64,
}

impl BodyBottom {
    pub fn of(d: &RobotDescription) -> Self {
        let b = &d.geometry.body;
        BodyBottom { radius: b.r_rot_m, depth: b.ring_gap_h_m / 2.0 + b.e_b_m }
    }
}

/// The bounds of the judgement (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Largest angle of z_b from the ground's normal at large (rad).
    pub max_tilt: f64,
    /// Longest time with fewer than three loaded feet (s).
    pub support_loss_s: f64,
    /// Age of a deadlock still on at the end that makes it permanent (s).
    pub deadlock_permanent_s: f64,
    /// Smallest fraction of the commanded distance the body must advance.
    pub min_progress: f64,
}

impl Default for Bounds {
    fn default() -> Self {
        Bounds { max_tilt: 30f64.to_radians(), support_loss_s: 1.0, deadlock_permanent_s: 20.0, min_progress: 0.5 }
    }
}

/// Why a walk failed, with the instant it happened (s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Failure {
    /// The body's bottom plate `depth` (m) below the ground.
    BodyOnGround { t: f64, depth: f64 },
    /// z_b `tilt` (rad) from the ground's normal.
    Tipped { t: f64, tilt: f64 },
    /// Fewer than three loaded feet since `t`.
    SupportLost { t: f64 },
    /// A deadlock on since `t` at the end.
    Deadlock { t: f64 },
    /// The body advanced `walked` (m) of `commanded` (m).
    Stalled { walked: f64, commanded: f64 },
}

impl Failure {
    /// A short name of the cause, for tables.
    pub fn cause(&self) -> &'static str {
        match self {
            Failure::BodyOnGround { .. } => "body on ground",
            Failure::Tipped { .. } => "tipped",
            Failure::SupportLost { .. } => "support lost",
            Failure::Deadlock { .. } => "deadlock",
            Failure::Stalled { .. } => "stalled",
        }
    }
}

/// The judgement of one run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Verdict {
    /// The first failure, None for a success.
    pub failure: Option<Failure>,
    /// Horizontal distance of the body centre from its start at the end (m).
    pub walked_m: f64,
    /// Total time in deadlock (s).
    pub deadlock_s: f64,
}

/// A column the judgement needs is not in the series.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("column `{0}` is missing: the judgement needs a free-gait run's body pose, foot forces and deadlock flag")]
pub struct MissingColumn(pub String);

/// The judgement, fed the rows of a run chunk by chunk ([`Judge::observe`]) so that a run may
/// stop at its first fall.
pub struct Judge<'a> {
    terrain: &'a dyn Terrain,
    nominal_normal: Vector3<f64>,
    body: BodyBottom,
    bounds: Bounds,
    start: Option<[f64; 2]>,
    /// The last row's instant and the body centre's horizontal displacement from its start.
    last: Option<(f64, [f64; 2])>,
    few_feet_since: Option<f64>,
    deadlock_since: Option<f64>,
    deadlock_s: f64,
    failure: Option<Failure>,
}

/// Points of the bottom plate checked against the ground: its centre and 24 points of its rim.
const RIM_POINTS: usize = 24;

impl<'a> Judge<'a> {
    pub fn new(terrain: &'a dyn Terrain, nominal_normal: Vector3<f64>, body: BodyBottom, bounds: Bounds) -> Self {
        Judge { terrain, nominal_normal: nominal_normal.normalize(), body, bounds, start: None, last: None, few_feet_since: None, deadlock_since: None, deadlock_s: 0.0, failure: None }
    }

    /// Judges the rows of `series`; breaks at the first fall.
    pub fn observe(&mut self, series: &TimeSeries) -> Result<ControlFlow<()>, MissingColumn> {
        let column = |name: &str| series.values(name).ok_or_else(|| MissingColumn(name.to_string()));
        let [t, x, y, z, yaw, pitch, roll, deadlock] = ["t", "X", "Y", "Z", "yaw", "pitch", "roll", "deadlock"].map(column);
        let (t, x, y, z, yaw, pitch, roll, deadlock) = (t?, x?, y?, z?, yaw?, pitch?, roll?, deadlock?);
        let forces = (0..6).map(|f| column(&format!("Fn[{f}]"))).collect::<Result<Vec<_>, _>>()?;
        for k in 0..t.len() {
            if self.failure.is_some() {
                return Ok(ControlFlow::Break(()));
            }
            let start = *self.start.get_or_insert([x[k], y[k]]);
            if let (Some(_), Some((previous, _))) = (self.deadlock_since, self.last) {
                self.deadlock_s += t[k] - previous;
            }
            self.last = Some((t[k], [x[k] - start[0], y[k] - start[1]]));
            let rotation = yaw_pitch_roll(yaw[k], pitch[k], roll[k]);
            let centre = Vector3::new(x[k], y[k], z[k]);
            // The bottom plate against the ground.
            let lowest = (0..=RIM_POINTS)
                .map(|i| {
                    let a = i as f64 * std::f64::consts::TAU / RIM_POINTS as f64;
                    let r = if i == RIM_POINTS { 0.0 } else { self.body.radius };
                    let p = centre + rotation * Vector3::new(r * a.cos(), r * a.sin(), -self.body.depth);
                    p.z - self.terrain.height_normal(p.x, p.y).0
                })
                .fold(f64::INFINITY, f64::min);
            let tilt = (rotation * Vector3::z()).dot(&self.nominal_normal).clamp(-1.0, 1.0).acos();
            let loaded = forces.iter().filter(|f| f[k] > 0.0).count();
            if loaded < 3 {
                self.few_feet_since.get_or_insert(t[k]);
            } else {
                self.few_feet_since = None;
            }
            self.deadlock_since = if deadlock[k] > 0.5 { Some(self.deadlock_since.unwrap_or(t[k])) } else { None };
            self.failure = if lowest < 0.0 {
                Some(Failure::BodyOnGround { t: t[k], depth: -lowest })
            } else if tilt > self.bounds.max_tilt {
                Some(Failure::Tipped { t: t[k], tilt })
            } else {
                self.few_feet_since.filter(|&since| t[k] - since > self.bounds.support_loss_s).map(|since| Failure::SupportLost { t: since })
            };
        }
        Ok(if self.failure.is_some() { ControlFlow::Break(()) } else { ControlFlow::Continue(()) })
    }

    /// The verdict after the last row; `commanded_m` is the distance the heading asked for.
    pub fn finish(self, commanded_m: f64) -> Verdict {
        let (t_end, [dx, dy]) = self.last.unwrap_or((0.0, [0.0; 2]));
        let walked_m = dx.hypot(dy);
        let failure = self.failure.or_else(|| {
            let permanent = self.deadlock_since.filter(|&since| t_end - since >= self.bounds.deadlock_permanent_s);
            match permanent {
                Some(since) => Some(Failure::Deadlock { t: since }),
                None if walked_m < self.bounds.min_progress * commanded_m => Some(Failure::Stalled { walked: walked_m, commanded: commanded_m }),
                None => None,
            }
        });
        Verdict { failure, walked_m, deadlock_s: self.deadlock_s }
    }
}

/// Judges a whole recorded run ([`Judge`]).
pub fn judge(series: &TimeSeries, terrain: &dyn Terrain, nominal_normal: Vector3<f64>, body: BodyBottom, bounds: Bounds, commanded_m: f64) -> Result<Verdict, MissingColumn> {
    let mut j = Judge::new(terrain, nominal_normal, body, bounds);
    let _stopped_at_a_fall = j.observe(series)?;
    Ok(j.finish(commanded_m))
}

#[cfg(test)]
mod tests;
