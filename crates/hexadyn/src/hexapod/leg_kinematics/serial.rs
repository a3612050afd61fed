//! Kinematics of a serial leg (Section 7.3 on the leg's own chain): k(q), its Jacobian and the
//! inverse of Eq. 7.7 by the same Newton-Raphson as the pantograph ([`super::inverse`]).
//!
//! # The leg frame `l`
//!
//! As for the pantograph (Eq. 7.10), the leg frame is fixed to the body with z_l = z_b: its
//! origin is the first joint's origin brought to the height of the body frame's (a foot on
//! flat ground under a level body at height h is at z = −h in every leg frame) and x_l points
//! along the first joint's x axis projected on the body's horizontal plane (the leg's mounting
//! direction), so that the gaits' foot heights and workspace cylinders stay vertical whatever
//! the mounting.
//!
//! # k(q) and J(q)
//!
//! k(q) = T_{l,0} T_q0 T_1 T_q1 T_2 T_q2 f, with T_k the joint origins (URDF `<origin>`), T_qk
//! the rotation about (or the translation along) joint k's axis and f the foot centre in the
//! last link. Column k of J is a_k × (k(q) − o_k) for a revolute joint, a_k for a prismatic
//! one, with a_k and o_k the joint's axis and origin in the leg frame (the geometric Jacobian).

use nalgebra::{Matrix3, Vector3};

use super::inverse::{inverse, IkOptions, Leg, LegChain};
use super::{JointLimits, LegKinematicsError};
use std::sync::Mutex;

use crate::hexapod::workspace::{argmax, remembered, Recent, Workspace};
use crate::hexapod::{JointKind, SerialLeg};
use crate::spatial::{rotation_about, Htm};

/// Kinematics of one serial leg.
#[derive(Clone, Debug, PartialEq)]
pub struct SerialLegKinematics {
    /// T_{b,l}: the leg frame in the body (base link) frame.
    body_from_leg: Htm,
    /// Joint 0's frame in the leg frame, then joints 1 and 2 in their parent link's frame.
    origins: [Htm; 3],
    axes: [Vector3<f64>; 3],
    kinds: [JointKind; 3],
    /// Foot centre in the last link's frame.
    foot: Vector3<f64>,
    limits: JointLimits,
    options: IkOptions,
}

impl SerialLegKinematics {
    pub fn new(leg: &SerialLeg) -> Result<Self, LegKinematicsError> {
        let limits = JointLimits::new(Vector3::from_fn(|k, _| leg.joints[k].lower), Vector3::from_fn(|k, _| leg.joints[k].upper));
        limits.validate()?;
        let first = leg.joints[0].origin;
        let x = first.rotation.column(0);
        let yaw = if x.xy().norm() > 1e-9 { x.y.atan2(x.x) } else { 0.0 };
        let body_from_leg = Htm { rotation: rotation_about(&Vector3::z(), yaw), translation: Vector3::new(first.translation.x, first.translation.y, 0.0) };
        let origins = [body_from_leg.inverse().compose(&first), leg.joints[1].origin, leg.joints[2].origin];
        Ok(SerialLegKinematics {
            body_from_leg,
            origins,
            axes: std::array::from_fn(|k| leg.joints[k].axis),
            kinds: std::array::from_fn(|k| leg.joints[k].kind),
            foot: leg.foot,
            limits,
            options: IkOptions::default(),
        })
    }

    /// The six legs of a serial hexapod.
    pub fn hexapod(legs: &[SerialLeg; 6]) -> Result<[Self; 6], LegKinematicsError> {
        let legs = legs.iter().map(Self::new).collect::<Result<Vec<_>, _>>()?;
        Ok(legs.try_into().expect("six legs"))
    }
}

/// Directions and heights at which the workspace's radius is measured.
const DIRECTIONS: usize = 16;
const HEIGHTS: usize = 3;
/// March step (m) and bisection steps of the boundary search: 5 mm / 2^14, 0.3 µm.
const STEP: f64 = 0.005;
const BISECTIONS: usize = 14;
/// Width (m) at which the search for the cylinder's axis stops: a micrometre of the
/// workspace's centre is far below what a foothold needs.
const AXIS_TOLERANCE: f64 = 1e-6;

impl SerialLegKinematics {
    /// Joints reaching `target` by Eq. 7.7 from `start` alone (no closest-point search).
    fn reached_from(&self, target: &Vector3<f64>, start: &Vector3<f64>) -> Option<Vector3<f64>> {
        let tol = 1e-9;
        let mut q = *start;
        for _ in 0..self.options.max_iterations {
            let (p, j) = self.foot_and_jacobian(&q);
            if (p - target).norm() <= tol {
                return Some(q);
            }
            let dq = j.lu().solve(&(p - target))?;
            let q_new = self.limits.clamp(&(q - dq));
            if !((self.foot(&q_new) - target).norm() < (p - target).norm()) {
                return None;
            }
            q = q_new;
        }
        ((self.foot(&q) - target).norm() <= tol).then_some(q)
    }

    /// How far from `centre` (reached with joints `q`) along the unit `direction` the foot
    /// reaches continuously, up to `limit`.
    fn reach_along(&self, centre: &Vector3<f64>, mut q: Vector3<f64>, direction: &Vector3<f64>, limit: f64) -> f64 {
        let mut r = 0.0;
        while r < limit {
            let next = (r + STEP).min(limit);
            match self.reached_from(&(centre + direction * next), &q) {
                Some(q_next) => (r, q) = (next, q_next),
                None => {
                    let (mut inside, mut outside) = (r, next);
                    for _ in 0..BISECTIONS {
                        let mid = (inside + outside) / 2.0;
                        match self.reached_from(&(centre + direction * mid), &q) {
                            Some(q_mid) => (inside, q) = (mid, q_mid),
                            None => outside = mid,
                        }
                    }
                    return inside;
                }
            }
        }
        limit
    }

    /// The largest radius of a cylinder of axis `axis` (leg frame) over the heights.
    fn radius_about(&self, axis: &nalgebra::Vector2<f64>, heights: &[f64], limit: f64) -> f64 {
        let mut radius = limit;
        for &z in heights {
            let centre = Vector3::new(axis.x, axis.y, z);
            let Ok(s) = inverse(self, &centre, &self.limits.middle()) else { return 0.0 };
            if !s.is_reached() {
                return 0.0;
            }
            for k in 0..DIRECTIONS {
                let a = std::f64::consts::TAU * k as f64 / DIRECTIONS as f64;
                radius = radius.min(self.reach_along(&centre, s.joints, &Vector3::new(a.cos(), a.sin(), 0.0), radius));
            }
        }
        radius
    }

    /// The workspace cylinder for foot heights [z_min, z_max] (leg frame), see the module docs.
    /// The last searches are kept, as the pantograph's (a scenario validates its stance and its
    /// walk on the same legs; a campaign the same walk many times).
    pub fn workspace(&self, z_min: f64, z_max: f64) -> Result<Workspace, LegKinematicsError> {
        // The leg frame's reach: the chain without its mounting (see `same_leg_frame_reach`).
        type Key = ([Htm; 3], [Vector3<f64>; 3], [JointKind; 3], Vector3<f64>, JointLimits, u64, u64);
        static RECENT: Recent<Key> = Mutex::new(Vec::new());
        remembered(&RECENT, (self.origins, self.axes, self.kinds, self.foot, self.limits, z_min.to_bits(), z_max.to_bits()), || self.search_workspace(z_min, z_max))
    }

    fn search_workspace(&self, z_min: f64, z_max: f64) -> Result<Workspace, LegKinematicsError> {
        if !(z_min.is_finite() && z_max.is_finite()) {
            return Err(LegKinematicsError::NonFinite("workspace height range"));
        }
        if z_min > z_max {
            return Err(LegKinematicsError::EmptyWorkspace { z_min, z_max });
        }
        // One height for a flat cylinder (a stance at one height).
        let n = if z_max > z_min { HEIGHTS } else { 1 };
        let heights: Vec<f64> = (0..n).map(|k| z_min + (z_max - z_min) * k as f64 / (n - 1).max(1) as f64).collect();
        let middle = self.foot(&self.limits.middle());
        let bisector = nalgebra::Vector2::new(middle.x, middle.y);
        let reach = self.origins.iter().skip(1).map(|o| o.translation.norm()).sum::<f64>() + self.foot.norm();
        if !(bisector.norm() > 1e-9) {
            return Err(LegKinematicsError::EmptyWorkspace { z_min, z_max });
        }
        let u = bisector.normalize();
        let (d, radius) = argmax(&|d| self.radius_about(&(u * d), &heights, reach), 0.0, reach, 24, AXIS_TOLERANCE);
        if !(radius > 0.0) {
            return Err(LegKinematicsError::EmptyWorkspace { z_min, z_max });
        }
        Ok(Workspace { centre: u * d, radius, z_min, z_max })
    }
}

impl Leg for SerialLegKinematics {
    fn body_from_leg(&self) -> Htm {
        self.body_from_leg
    }
    /// The middle of the ranges.
    fn neutral(&self) -> Vector3<f64> {
        self.limits.middle()
    }
    fn workspace(&self, z_min: f64, z_max: f64) -> Result<Workspace, LegKinematicsError> {
        SerialLegKinematics::workspace(self, z_min, z_max)
    }
    /// The same chain in the leg frame (a mirrored leg is another chain).
    fn same_leg_frame_reach(&self, other: &Self) -> bool {
        (self.origins, self.axes, self.kinds, self.foot, self.limits) == (other.origins, other.axes, other.kinds, other.foot, other.limits)
    }
    /// Over a grid of 11 values of each joint's range (the extremes of a chain's foot height
    /// need not lie on the box's edges).
    fn height_range(&self) -> (f64, f64) {
        let (lo, hi) = (self.limits.lower, self.limits.upper);
        let at = |k: usize, i: usize| lo[k] + (hi[k] - lo[k]) * i as f64 / 10.0;
        (0..11 * 11 * 11).map(|c| self.foot(&Vector3::new(at(0, c % 11), at(1, c / 11 % 11), at(2, c / 121))).z).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| (a.min(z), b.max(z)))
    }
}

/// The default body height of serial legs: the mean height of the feet below the body with
/// every joint at mid-range (m).
pub fn default_serial_height(legs: &[SerialLegKinematics; 6]) -> f64 {
    -legs.iter().map(|l| l.to_body(&l.foot(&l.limits().middle())).z).sum::<f64>() / 6.0
}

impl LegChain for SerialLegKinematics {
    /// k(q) and the geometric Jacobian J = ∂k/∂q.
    fn foot_and_jacobian(&self, q: &Vector3<f64>) -> (Vector3<f64>, Matrix3<f64>) {
        let mut t = Htm::identity();
        let mut axes = [(Vector3::zeros(), Vector3::zeros()); 3];
        for k in 0..3 {
            t = t.compose(&self.origins[k]);
            let a = t.rotation * self.axes[k];
            axes[k] = (a, t.translation);
            let motion = match self.kinds[k] {
                JointKind::Revolute => Htm { rotation: rotation_about(&self.axes[k], q[k]), translation: Vector3::zeros() },
                JointKind::Prismatic => Htm { rotation: Matrix3::identity(), translation: self.axes[k] * q[k] },
            };
            t = t.compose(&motion);
        }
        let p = t.apply(&self.foot);
        let column = |k: usize| {
            let (a, o) = axes[k];
            match self.kinds[k] {
                JointKind::Revolute => a.cross(&(p - o)),
                JointKind::Prismatic => a,
            }
        };
        (p, Matrix3::from_columns(&[column(0), column(1), column(2)]))
    }
    fn limits(&self) -> &JointLimits {
        &self.limits
    }
    fn ik_options(&self) -> &IkOptions {
        &self.options
    }
    /// A 3 × 3 × 3 grid over the joint box (5 %, 50 % and 95 % of each range): starts in
    /// each branch of a coxa-femur-tibia leg whose ranges span several.
    fn seeds(&self) -> Vec<Vector3<f64>> {
        let (lo, hi) = (self.limits.lower, self.limits.upper);
        let at = |k: usize, level: usize| lo[k] + [0.05, 0.5, 0.95][level] * (hi[k] - lo[k]);
        (0..27).map(|c| Vector3::new(at(0, c % 3), at(1, c / 3 % 3), at(2, c / 9))).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::urdf::serial_hexapod_from_urdf;
    use crate::hexapod::{joint_index, SerialHexapod, DOF};
    use crate::mbs::{kinematics, Data};
    use crate::test_util::{central, rng};
    use approx::assert_relative_eq;
    use rand::Rng;

    fn robot() -> SerialHexapod {
        serial_hexapod_from_urdf(include_str!("../../../tests/data/random_hexapod.urdf"), "random_hexapod.urdf").unwrap()
    }

    fn random_joints(r: &mut impl Rng, limits: &JointLimits) -> Vector3<f64> {
        Vector3::from_fn(|k, _| r.random_range(limits.lower[k]..limits.upper[k]))
    }

    /// k(q), taken to the body frame, is the foot of the multibody model (body at the origin,
    /// level), and z_l = z_b.
    #[test]
    fn the_foot_is_the_multibody_models() {
        let robot = robot();
        let m = robot.mechanics().unwrap();
        let legs = SerialLegKinematics::hexapod(&robot.legs).unwrap();
        let mut data = Data::new(&m.model);
        let mut r = rng(3);
        for _ in 0..50 {
            let mut q = vec![0.0; DOF];
            for (leg, kin) in legs.iter().enumerate() {
                let qs = random_joints(&mut r, kin.limits());
                q[joint_index(leg, 0)..joint_index(leg, 0) + 3].copy_from_slice(qs.as_slice());
            }
            kinematics(&m.model, &mut data, &q, &[0.0; DOF]);
            for (leg, kin) in legs.iter().enumerate() {
                let qs = Vector3::from_fn(|k, _| q[joint_index(leg, k)]);
                let (body, foot) = m.feet[leg];
                assert_relative_eq!(kin.to_body(&kin.foot(&qs)), data.point(body, &foot), epsilon = 1e-14);
                assert_relative_eq!(kin.body_from_leg().rotation.column(2).into_owned(), Vector3::z(), epsilon = 1e-15);
            }
        }
    }

    /// J is ∂k/∂q (central differences).
    #[test]
    fn the_jacobian_is_the_derivative_of_the_foot() {
        let robot = robot();
        let mut r = rng(4);
        for leg in &robot.legs {
            let kin = SerialLegKinematics::new(leg).unwrap();
            let q = random_joints(&mut r, kin.limits());
            let (_, j) = kin.foot_and_jacobian(&q);
            for k in 0..3 {
                for i in 0..3 {
                    let d = central(
                        |x| {
                            let mut qh = q;
                            qh[k] = x;
                            kin.foot(&qh)[i]
                        },
                        q[k],
                        1e-6,
                    );
                    assert_relative_eq!(j[(i, k)], d, epsilon = 1e-9);
                }
            }
        }
    }

    /// Eq. 7.7 on the serial chain: k(inverse(k(q))) = k(q) from a start anywhere in the
    /// ranges (from the start alone, 36 % of these targets end in a local minimum of another
    /// branch; the seeds take them all); a target beyond the reach is clamped to the closest foot
    /// within the ranges.
    #[test]
    fn the_inverse_reaches_reachable_targets_and_clamps_the_others() {
        let robot = robot();
        let mut r = rng(5);
        for leg in &robot.legs {
            let kin = SerialLegKinematics::new(leg).unwrap();
            for _ in 0..100 {
                let target = kin.foot(&random_joints(&mut r, kin.limits()));
                let start = random_joints(&mut r, kin.limits());
                let s = kin.inverse(&target, &start).unwrap();
                assert!(s.is_reached(), "{:?} from {start:?}", s.outcome);
                assert!((kin.foot(&s.joints) - target).norm() < 1e-11 && kin.limits().contains(&s.joints));
            }
            let far = kin.foot(&kin.limits().middle()) * 10.0;
            let s = kin.inverse(&far, &kin.limits().middle()).unwrap();
            let c = s.clamping().expect("out of reach");
            assert!(c.distance > 0.1 && kin.limits().contains(&s.joints), "{c:?}");
        }
    }

    /// The workspace at the height of the foot at mid-range: every point of the cylinder is
    /// reached (Eq. 7.7 from the middle of the ranges, as `Leg::reaches_point` finds), and a
    /// cylinder 3 mm wider about the same axis is not.
    #[test]
    fn the_workspace_is_reachable_and_maximal() {
        let robot = robot();
        let mut r = rng(6);
        for leg in &robot.legs {
            let kin = SerialLegKinematics::new(leg).unwrap();
            let z = kin.foot(&kin.limits().middle()).z;
            let w = kin.workspace(z - 0.01, z + 0.01).unwrap();
            assert!(w.radius > 0.005, "{w:?}");
            for _ in 0..200 {
                let (a, rho, h): (f64, f64, f64) = (r.random_range(0.0..std::f64::consts::TAU), w.radius * r.random::<f64>().sqrt(), r.random_range(w.z_min..=w.z_max));
                let p = Vector3::new(w.centre.x + rho * a.cos(), w.centre.y + rho * a.sin(), h);
                assert!(kin.inverse(&p, &kin.limits().middle()).unwrap().is_reached() && kin.reaches_point(&p), "{p:?} in {w:?}");
            }
            let wider = (0..64).map(|k| std::f64::consts::TAU * k as f64 / 64.0).any(|a| {
                [w.z_min, w.z_max, (w.z_min + w.z_max) / 2.0].iter().any(|&h| {
                    let p = Vector3::new(w.centre.x + (w.radius + 0.003) * a.cos(), w.centre.y + (w.radius + 0.003) * a.sin(), h);
                    let reached = kin.inverse(&p, &kin.limits().middle()).unwrap().is_reached();
                    assert_eq!(reached, kin.reaches_point(&p), "{p:?}");
                    !reached
                })
            });
            assert!(wider, "a cylinder 3 mm wider than {w:?} is reached everywhere");
        }
    }
}
