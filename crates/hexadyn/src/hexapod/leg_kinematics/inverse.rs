//! Inverse kinematics of a leg (thesis Eq. 7.7): the joints whose foot k(q) is a target.
//!
//! [`LegKinematics::inverse`] runs the Newton-Raphson iteration of Eq. 7.7 from the current
//! joints, each iterate projected into the joint ranges (Table 5.2). A target the foot cannot
//! reach (outside the ranges, or where the linkage would not close) ends in
//! [`IkOutcome::Clamped`]: the joints within the ranges whose foot is the closest to the
//! target (a box-constrained least-squares problem, solved on every face, edge and corner
//! of the joint box), with the remaining distance, the joints at their limits and, when the
//! linkage can reach the target with the ranges ignored, how far beyond the ranges that
//! would be. The joints returned are always finite and within the ranges.

use nalgebra::{Matrix3, Vector3};

use super::{JointLimits, LegKinematics, LegKinematicsError, RzMinus};
use crate::hexapod::workspace::Workspace;
use crate::spatial::Htm;

/// A leg as the gait controllers use it (Chapter 7), whatever its mechanism: its chain (k(q),
/// J(q), the inverse of Eq. 7.7) and its frame on the body (Eq. 7.10). The leg frame's origin
/// is at the height of the body frame's, z_l = z_b, so that a foot on flat ground under a level
/// body at height h is at z = −h in every leg frame.
pub trait Leg: LegChain {
    /// T_{b,l}.
    fn body_from_leg(&self) -> Htm;
    /// A point of the leg frame in the body frame.
    fn to_body(&self, p_leg: &Vector3<f64>) -> Vector3<f64> {
        self.body_from_leg().apply(p_leg)
    }
    /// A point of the body frame in the leg frame.
    fn to_leg(&self, p_body: &Vector3<f64>) -> Vector3<f64> {
        let t = self.body_from_leg();
        t.rotation.transpose() * (p_body - t.translation)
    }
    /// A direction (or velocity) of the body frame in the leg frame.
    fn direction_to_leg(&self, v_body: &Vector3<f64>) -> Vector3<f64> {
        self.body_from_leg().rotation.transpose() * v_body
    }
    /// {p_F/b}_b: the foot in the body frame (Eq. 7.10 without T_{0,b}).
    fn foot_in_body(&self, q: &Vector3<f64>) -> Vector3<f64> {
        self.to_body(&self.foot(q))
    }
    /// The joints Eq. 7.7 starts from when there are no current ones (a standing posture).
    fn neutral(&self) -> Vector3<f64>;
    /// The workspace cylinder for foot heights [z_min, z_max] in the leg frame (Section 7.1.1).
    fn workspace(&self, z_min: f64, z_max: f64) -> Result<Workspace, LegKinematicsError>;
    /// The lowest and highest foot heights in the leg frame over the joint ranges.
    fn height_range(&self) -> (f64, f64);
    /// Whether `other` reaches the same points of its leg frame (the same workspaces).
    fn same_leg_frame_reach(&self, other: &Self) -> bool;
    /// Whether the foot reaches the point `p` of the leg frame with the joints in their
    /// ranges: by default Eq. 7.7 from the neutral posture (with the mechanism's further
    /// starts) ends on it.
    fn reaches_point(&self, p: &Vector3<f64>) -> bool {
        Leg::inverse(self, p, &self.neutral()).is_ok_and(|ik| ik.is_reached())
    }
    /// [`inverse`] (Eq. 7.7) of a target in the leg frame from `start`.
    fn inverse(&self, target: &Vector3<f64>, start: &Vector3<f64>) -> Result<IkSolution, LegKinematicsError> {
        inverse(self, target, start)
    }
    /// Inverse kinematics of a target given in the body frame.
    fn inverse_in_body(&self, target_body: &Vector3<f64>, start: &Vector3<f64>) -> Result<IkSolution, LegKinematicsError> {
        Leg::inverse(self, &self.to_leg(target_body), start)
    }
}

impl Leg for LegKinematics {
    fn body_from_leg(&self) -> Htm {
        LegKinematics::body_from_leg(self)
    }
    fn to_body(&self, p_leg: &Vector3<f64>) -> Vector3<f64> {
        LegKinematics::to_body(self, p_leg)
    }
    fn to_leg(&self, p_body: &Vector3<f64>) -> Vector3<f64> {
        LegKinematics::to_leg(self, p_body)
    }
    fn direction_to_leg(&self, v_body: &Vector3<f64>) -> Vector3<f64> {
        LegKinematics::direction_to_leg(self, v_body)
    }
    fn foot_in_body(&self, q: &Vector3<f64>) -> Vector3<f64> {
        LegKinematics::foot_in_body(self, q)
    }
    /// The neutral posture of Section 4.1 with q_h = 0.03 m.
    fn neutral(&self) -> Vector3<f64> {
        Vector3::new(0.0, 0.06, 0.03)
    }
    fn workspace(&self, z_min: f64, z_max: f64) -> Result<Workspace, LegKinematicsError> {
        LegKinematics::workspace(self, z_min, z_max)
    }
    fn height_range(&self) -> (f64, f64) {
        LegKinematics::height_range(self)
    }
    fn same_leg_frame_reach(&self, other: &Self) -> bool {
        LegKinematics::same_leg_frame_reach(self, other)
    }
    /// In closed form: the horizontal distance of `p` from the q_r axis within the radii the
    /// pantograph reaches at its height ([`LegKinematics::radii_at`]; q_r is taken to turn the
    /// foot to the point's azimuth).
    fn reaches_point(&self, p: &Vector3<f64>) -> bool {
        let rho = p.xy().norm();
        self.radii_at(p.z).is_some_and(|(lo, hi)| lo <= rho && rho <= hi)
    }
}

/// What the inverse kinematics of Eq. 7.7 needs of a leg mechanism, whatever it is (the
/// pantograph, a serial chain): k(q) and J(q) in the leg frame, the joint ranges and the
/// iteration settings.
pub trait LegChain {
    /// k(q) and J(q) = ∂k/∂q (Eq. 7.6, 7.8).
    fn foot_and_jacobian(&self, q: &Vector3<f64>) -> (Vector3<f64>, Matrix3<f64>);
    fn limits(&self) -> &JointLimits;
    fn ik_options(&self) -> &IkOptions;
    /// Whether the mechanism is assembled at q, ranges ignored (the pantograph's triangle
    /// A-B-D closes); a serial chain always is.
    fn assembles(&self, _q: &Vector3<f64>) -> bool {
        true
    }
    /// A start for the closest-point search: q0 with the joints that aim the foot at the
    /// target set (the pantograph turns q_r to the target's azimuth); none by default.
    fn aimed(&self, _target: &Vector3<f64>, _q0: &Vector3<f64>, _foot: &Vector3<f64>) -> Option<(usize, f64)> {
        None
    }
    fn foot(&self, q: &Vector3<f64>) -> Vector3<f64> {
        self.foot_and_jacobian(q).0
    }
    /// Further starts of Eq. 7.7 when the one given ends away from the target: a mechanism
    /// with several branches (a serial leg's knee up or down) can put a local minimum of
    /// |k(q) − p*| between the current joints and a reachable target. None by default.
    fn seeds(&self) -> Vec<Vector3<f64>> {
        Vec::new()
    }
}

impl LegChain for LegKinematics {
    fn foot_and_jacobian(&self, q: &Vector3<f64>) -> (Vector3<f64>, Matrix3<f64>) {
        LegKinematics::foot_and_jacobian(self, q)
    }
    fn limits(&self) -> &JointLimits {
        &self.limits
    }
    fn ik_options(&self) -> &IkOptions {
        &self.options
    }
    fn assembles(&self, q: &Vector3<f64>) -> bool {
        self.pantograph.closes(q[1], q[2])
    }
    fn foot(&self, q: &Vector3<f64>) -> Vector3<f64> {
        LegKinematics::foot(self, q)
    }
    /// q_r aimed at the target's azimuth: the foot's azimuth is −q_r + atan2(s_y, s_x).
    fn aimed(&self, target: &Vector3<f64>, q0: &Vector3<f64>, foot: &Vector3<f64>) -> Option<(usize, f64)> {
        let s = RzMinus::new(-q0[0]).apply(foot);
        (target.xy().norm() > 1e-9).then(|| (0, (s.y.atan2(s.x) - target.y.atan2(target.x)).clamp(self.limits.lower[0], self.limits.upper[0])))
    }
}

/// Settings of the Newton-Raphson iteration of Eq. 7.7.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IkOptions {
    /// Converged when |k(q) − p*| ≤ tolerance (m).
    pub tolerance: f64,
    /// Newton iterations before the target is treated as out of reach.
    pub max_iterations: usize,
}

impl Default for IkOptions {
    fn default() -> Self {
        IkOptions { tolerance: 1e-12, max_iterations: 12 }
    }
}

/// Where a joint ended with respect to its range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Limit {
    Free,
    Lower,
    Upper,
}

/// How an unreachable target was handled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clamping {
    /// Distance from the foot reached to the target, |k(q) − p*| (m): how far the target lies
    /// outside the reachable set.
    pub distance: f64,
    /// k(q) − p*, leg frame (m).
    pub error: Vector3<f64>,
    /// Joints resting on a limit (q_r, q_v, q_h).
    pub limits: [Limit; 3],
    /// Joints that would reach the target with the ranges ignored, minus the joints returned
    /// (rad, m, m): by how much the ranges clamp them. It is the solution Newton-Raphson finds
    /// from the returned joints without the ranges (the linkage continued beyond its strokes,
    /// e.g. a negative q_h for a target behind the leg). `None` when the linkage cannot reach
    /// the target at all (the triangle A-B-D would not close on the way).
    pub excess: Option<Vector3<f64>>,
}

/// Outcome of the inverse kinematics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IkOutcome {
    /// |k(q) − p*| ≤ tolerance with q within the ranges.
    Reached,
    /// The target is out of reach: q are the closest joints within the ranges.
    Clamped(Clamping),
}

/// Result of [`LegKinematics::inverse`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IkSolution {
    /// (q_r, q_v, q_h), always finite and within the ranges.
    pub joints: Vector3<f64>,
    /// k(joints), leg frame.
    pub foot: Vector3<f64>,
    /// Newton-Raphson (Eq. 7.7) updates done, plus the Gauss-Newton updates of the
    /// closest-point search when the target was out of reach.
    pub iterations: usize,
    pub outcome: IkOutcome,
}

impl IkSolution {
    pub fn is_reached(&self) -> bool {
        matches!(self.outcome, IkOutcome::Reached)
    }
    pub fn clamping(&self) -> Option<&Clamping> {
        match &self.outcome {
            IkOutcome::Reached => None,
            IkOutcome::Clamped(c) => Some(c),
        }
    }
}

impl LegKinematics {
    /// Inverse kinematics of a target given in the body frame.
    pub fn inverse_in_body(&self, target_body: &Vector3<f64>, start: &Vector3<f64>) -> Result<IkSolution, LegKinematicsError> {
        self.inverse(&self.to_leg(target_body), start)
    }

    /// [`inverse`] of this leg.
    pub fn inverse(&self, target: &Vector3<f64>, start: &Vector3<f64>) -> Result<IkSolution, LegKinematicsError> {
        inverse(self, target, start)
    }
}

/// Joints q* with k(q*) = p* (leg frame) by Newton-Raphson (Eq. 7.7) from `start`
/// (normally the current joints; projected into the ranges first).
///
/// Every iterate is projected into the joint ranges. When the iteration cannot reach the
/// tolerance (the target is out of the reachable set), the closest foot position within
/// the ranges is searched and the solution is [`IkOutcome::Clamped`]. Only non-finite
/// inputs are errors.
pub fn inverse<L: LegChain + ?Sized>(leg: &L, target: &Vector3<f64>, start: &Vector3<f64>) -> Result<IkSolution, LegKinematicsError> {
    if !target.iter().all(|v| v.is_finite()) {
        return Err(LegKinematicsError::NonFinite("inverse-kinematics target"));
    }
    if !start.iter().all(|v| v.is_finite()) {
        return Err(LegKinematicsError::NonFinite("inverse-kinematics start"));
    }
    let limits = leg.limits();
    let tol = leg.ik_options().tolerance;
    let (q, p, e, mut iterations) = newton(leg, target, start);
    if e <= tol {
        return Ok(IkSolution { joints: q, foot: p, iterations, outcome: IkOutcome::Reached });
    }
    // Out of reach (or slow): the closest point within the joint box.
    let (q, p, extra) = closest(leg, target, &q);
    iterations += extra;
    let error = p - target;
    let distance = error.norm();
    if distance <= tol {
        return Ok(IkSolution { joints: q, foot: p, iterations, outcome: IkOutcome::Reached });
    }
    for seed in leg.seeds() {
        let (q, p, n) = gauss_newton(leg, target, seed, [true; 3]);
        iterations += n;
        if (p - target).norm() <= tol {
            return Ok(IkSolution { joints: q, foot: p, iterations, outcome: IkOutcome::Reached });
        }
    }
    let at_limits = std::array::from_fn(|i| {
        if q[i] <= limits.lower[i] {
            Limit::Lower
        } else if q[i] >= limits.upper[i] {
            Limit::Upper
        } else {
            Limit::Free
        }
    });
    let excess = unconstrained(leg, target, &q).map(|qu| qu - q);
    Ok(IkSolution { joints: q, foot: p, iterations, outcome: IkOutcome::Clamped(Clamping { distance, error, limits: at_limits, excess }) })
}

/// Eq. 7.7 from `start`: q^k = q^{k−1} − J^{-1} (k(q^{k−1}) − p*), each iterate projected into
/// the ranges, until the tolerance, no progress (the projection stalls on a limit: the target
/// is out of reach) or the iteration budget. Returns (q, k(q), |k(q) − p*|, iterations).
fn newton<L: LegChain + ?Sized>(leg: &L, target: &Vector3<f64>, start: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>, f64, usize) {
    let (limits, options) = (leg.limits(), leg.ik_options());
    let mut q = limits.clamp(start);
    let (mut p, mut j) = leg.foot_and_jacobian(&q);
    let mut e = (p - target).norm();
    let mut iterations = 0;
    while e > options.tolerance && iterations < options.max_iterations {
        let Some(dq) = j.lu().solve(&(p - target)) else { break };
        let q_new = limits.clamp(&(q - dq));
        iterations += 1;
        let (p_new, j_new) = leg.foot_and_jacobian(&q_new);
        let e_new = (p_new - target).norm();
        if !(e_new < e) {
            break;
        }
        (q, p, j, e) = (q_new, p_new, j_new, e_new);
    }
    (q, p, e, iterations)
}

/// min |k(q) − p*| over the joint box: projected Gauss-Newton on the interior and on every
/// face, edge and corner of the box (26 + 1 sub-problems of at most 3 unknowns); the
/// minimizer is the best of them. Returns (q, k(q), Gauss-Newton updates).
fn closest<L: LegChain + ?Sized>(leg: &L, target: &Vector3<f64>, q0: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>, usize) {
    let limits = leg.limits();
    let mut best = (*q0, leg.foot(q0));
    let mut best_e = (best.1 - target).norm();
    let mut updates = 0;
    let aimed = leg.aimed(target, q0, &best.1);
    for code in 0..27usize {
        // Each joint: 0 free, 1 at lower, 2 at upper; code 0 is the interior problem.
        let mask = [code % 3, (code / 3) % 3, code / 9];
        let mut q = *q0;
        for i in 0..3 {
            match mask[i] {
                1 => q[i] = limits.lower[i],
                2 => q[i] = limits.upper[i],
                _ => {}
            }
        }
        if let Some((i, value)) = aimed.filter(|(i, _)| mask[*i] == 0) {
            q[i] = value;
        }
        let (q, p, n) = gauss_newton(leg, target, q, mask.map(|m| m == 0));
        updates += n;
        let e = (p - target).norm();
        if e < best_e {
            (best, best_e) = ((q, p), e);
        }
    }
    (best.0, best.1, updates)
}

/// Projected Gauss-Newton with backtracking on the `free` joints.
fn gauss_newton<L: LegChain + ?Sized>(leg: &L, target: &Vector3<f64>, mut q: Vector3<f64>, free: [bool; 3]) -> (Vector3<f64>, Vector3<f64>, usize) {
    let (mut p, mut j) = leg.foot_and_jacobian(&q);
    let mut e = (p - target).norm();
    let mut updates = 0;
    if !free.iter().any(|&f| f) {
        return (q, p, 0);
    }
    for _ in 0..50 {
        if e <= leg.ik_options().tolerance {
            break;
        }
        let r = p - target;
        let mut jtj = j.transpose() * j;
        let mut g = j.transpose() * r;
        for i in 0..3 {
            if !free[i] {
                jtj.row_mut(i).fill(0.0);
                jtj.column_mut(i).fill(0.0);
                jtj[(i, i)] = 1.0;
                g[i] = 0.0;
            }
        }
        let Some(step) = jtj.lu().solve(&g) else { break };
        let mut t = 1.0;
        let mut accepted = None;
        for _ in 0..40 {
            let q_new = leg.limits().clamp(&(q - step * t));
            let (p_new, j_new) = leg.foot_and_jacobian(&q_new);
            let e_new = (p_new - target).norm();
            if e_new < e {
                accepted = Some((q_new, p_new, j_new, e_new));
                break;
            }
            t *= 0.5;
        }
        let Some((q_new, p_new, j_new, e_new)) = accepted else { break };
        updates += 1;
        let progress = e - e_new;
        (q, p, j, e) = (q_new, p_new, j_new, e_new);
        if progress <= 1e-15 * (1.0 + e) {
            break;
        }
    }
    (q, p, updates)
}

/// Newton-Raphson without the joint ranges, from the clamped solution, as long as the
/// mechanism assembles ([`LegChain::assembles`]); `None` when it does not converge there.
fn unconstrained<L: LegChain + ?Sized>(leg: &L, target: &Vector3<f64>, q0: &Vector3<f64>) -> Option<Vector3<f64>> {
    let tol = leg.ik_options().tolerance;
    let mut q = *q0;
    let (mut p, mut j) = leg.foot_and_jacobian(&q);
    let mut e = (p - target).norm();
    for _ in 0..50 {
        if e <= tol {
            return Some(q);
        }
        let dq = j.lu().solve(&(p - target))?;
        let mut t = 1.0;
        let mut accepted = None;
        for _ in 0..40 {
            let q_new = q - dq * t;
            if q_new.iter().all(|v| v.is_finite()) && leg.assembles(&q_new) {
                let (p_new, j_new) = leg.foot_and_jacobian(&q_new);
                let e_new = (p_new - target).norm();
                if e_new < e {
                    accepted = Some((q_new, p_new, j_new, e_new));
                    break;
                }
            }
            t *= 0.5;
        }
        (q, p, j, e) = accepted?;
    }
    (e <= tol).then_some(q)
}

#[cfg(test)]
mod tests {
    use super::super::tests::{amru5, neutral, neutral_workspace, random_joints};
    use super::*;
    use crate::test_util::rng;
    use approx::assert_relative_eq;
    use rand::Rng;

    /// forward(inverse(p)) = p for random reachable targets, from random starts and from the
    /// neutral posture (iteration counts of Eq. 7.7).
    #[test]
    fn leg_kinematics_inverse_round_trip() {
        let legs = amru5();
        let mut r = rng(11);
        let mut histogram = [0usize; 16];
        for n in 0..6000 {
            let kin = &legs[n % 6];
            let q = random_joints(&mut r, kin.limits());
            let p = kin.foot(&q);
            let start = if n % 2 == 0 { neutral() } else { random_joints(&mut r, kin.limits()) };
            let s = kin.inverse(&p, &start).unwrap();
            assert!(s.is_reached(), "{p} from {start}: {s:?}");
            assert!((kin.foot(&s.joints) - p).norm() <= 1e-9);
            assert_relative_eq!(s.foot, kin.foot(&s.joints), epsilon = 1e-15);
            assert_relative_eq!(s.joints, q, epsilon = 1e-9);
            if n % 2 == 0 {
                assert!(s.iterations <= 8, "{} iterations from the neutral posture to {p}", s.iterations);
                histogram[s.iterations] += 1;
            }
            // Body-frame target.
            let sb = kin.inverse_in_body(&kin.foot_in_body(&q), &start).unwrap();
            assert!(sb.is_reached() && (kin.foot_in_body(&sb.joints) - kin.foot_in_body(&q)).norm() <= 1e-9);
        }
        println!("iterations from the neutral posture (count per number of iterations): {histogram:?}");
    }

    /// Random targets filling the workspace cylinder are all reached, and round-trip.
    #[test]
    fn leg_kinematics_inverse_over_the_workspace() {
        let legs = amru5();
        let w = neutral_workspace(&legs[0]);
        let mut r = rng(5);
        let mut max_iterations = 0;
        for n in 0..6000 {
            let kin = &legs[n % 6];
            let (rho, phi) = (w.radius * r.random_range(0.0f64..=1.0).sqrt(), r.random_range(0.0..std::f64::consts::TAU));
            let p = Vector3::new(w.centre.x + rho * phi.cos(), w.centre.y + rho * phi.sin(), r.random_range(w.z_min..=w.z_max));
            let s = kin.inverse(&p, &neutral()).unwrap();
            assert!(s.is_reached(), "{p}: {s:?}");
            assert!((kin.foot(&s.joints) - p).norm() <= 1e-9);
            max_iterations = max_iterations.max(s.iterations);
        }
        assert!(max_iterations <= 8);
    }

    /// From the previous control step's joints (foot moved by up to 1 mm), Eq. 7.7 converges
    /// in at most 4 iterations (the thesis: 3-4).
    #[test]
    fn leg_kinematics_inverse_from_a_nearby_start() {
        let legs = amru5();
        let mut r = rng(3);
        let mut histogram = [0usize; 8];
        for n in 0..6000 {
            let kin = &legs[n % 6];
            let q = random_joints(&mut r, kin.limits());
            let dir = Vector3::from_fn(|_, _| r.random_range(-1.0..1.0)).normalize();
            let step = r.random_range(0.0..1e-3);
            let dq = kin.jacobian(&q).lu().solve(&(dir * step)).unwrap();
            let q2 = kin.limits().clamp(&(q + dq));
            let p = kin.foot(&q2);
            let s = kin.inverse(&p, &q).unwrap();
            assert!(s.is_reached() && (kin.foot(&s.joints) - p).norm() <= 1e-9, "{s:?}");
            assert!(s.iterations <= 4, "{} iterations for a step of {step} m", s.iterations);
            histogram[s.iterations] += 1;
        }
        println!("iterations from the previous joints (foot step <= 1 mm): {histogram:?}");
    }

    /// Unreachable targets: clamped to the closest joints within the ranges, reported, finite.
    #[test]
    fn leg_kinematics_out_of_reach_targets_are_clamped() {
        let legs = amru5();
        let kin = &legs[0];
        let l = *kin.limits();
        let (az, rho, z) = (40f64.to_radians(), 0.112 + 7.0 * 0.03, -0.052 - 6.0 * 0.055);
        let beyond_azimuth = Vector3::new(rho * az.cos(), rho * az.sin(), z);
        let targets = [
            beyond_azimuth,
            Vector3::new(1.0, 0.0, -0.4),
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(0.3, 0.0, 0.0),
            Vector3::new(0.3, 0.1, -0.8),
            Vector3::new(-0.5, 0.0, -0.4),
            Vector3::new(1e6, -1e6, 1e6),
            Vector3::new(0.2, -0.3, -0.35),
        ];
        for (n, t) in targets.iter().enumerate() {
            for start in [neutral(), l.lower, Vector3::new(10.0, -1.0, 2.0)] {
                let s = kin.inverse(t, &start).unwrap();
                let c = s.clamping().unwrap_or_else(|| panic!("target {n} {t} reached?"));
                println!("out-of-reach target {n}: {} iterations, distance {:.4e} m, limits {:?}, excess {:?}", s.iterations, c.distance, c.limits, c.excess.map(|e| e.as_slice().to_vec()));
                assert!(s.joints.iter().all(|v| v.is_finite()) && l.contains(&s.joints), "{s:?}");
                assert_relative_eq!(c.error, kin.foot(&s.joints) - t, epsilon = 1e-12 * (1.0 + t.norm()));
                assert!(c.distance > 1e-6 && c.limits.iter().any(|&m| m != Limit::Free), "{c:?}");
                // Closest: no joint set of a 31³ grid over the ranges does better.
                if t.norm() < 10.0 {
                    let grid = 30;
                    let mut best = f64::INFINITY;
                    for i in 0..=grid {
                        for j in 0..=grid {
                            for k in 0..=grid {
                                let f = Vector3::new(i as f64, j as f64, k as f64) / grid as f64;
                                let q = l.lower + (l.upper - l.lower).component_mul(&f);
                                best = best.min((kin.foot(&q) - t).norm());
                            }
                        }
                    }
                    assert!(c.distance <= best + 1e-12, "target {n}: {} vs grid {best}", c.distance);
                }
                if let Some(e) = c.excess {
                    assert!((kin.foot(&(s.joints + e)) - t).norm() <= 1e-9);
                }
            }
        }
        // Beyond the q_r range only: q_r stops at −25° instead of −40°, the rest is reachable.
        let s = kin.inverse(&beyond_azimuth, &neutral()).unwrap();
        let c = s.clamping().unwrap();
        assert_eq!(c.limits, [Limit::Lower, Limit::Free, Limit::Free]);
        let e = c.excess.expect("reachable without the q_r range");
        assert_relative_eq!(e[0], -15f64.to_radians(), epsilon = 1e-9);
        // The closest point is the projection on the half-plane of azimuth 25°: radius
        // ρ cos 15°, same height, at ρ sin 15° from the target.
        let a = 25f64.to_radians();
        assert_relative_eq!(s.foot, Vector3::new(a.cos(), a.sin(), 0.0) * rho * 15f64.to_radians().cos() + Vector3::z() * z, epsilon = 1e-9);
        assert_relative_eq!(c.distance, rho * 15f64.to_radians().sin(), epsilon = 1e-9);
        // The linkage cannot stretch to 1 m.
        assert_eq!(kin.inverse(&Vector3::new(1.0, 0.0, -0.4), &neutral()).unwrap().clamping().unwrap().excess, None);
        // Non-finite inputs are errors, not NaN joints.
        assert!(kin.inverse(&Vector3::new(f64::NAN, 0.0, 0.0), &neutral()).is_err());
        assert!(kin.inverse(&Vector3::new(0.3, 0.0, -0.4), &Vector3::new(0.0, f64::INFINITY, 0.0)).is_err());
    }
}
