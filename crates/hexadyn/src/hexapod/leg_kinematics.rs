//! Kinematic control of a leg (thesis Section 7.3, Eq. 7.6-7.9) and the leg workspace
//! (Section 7.1.1, Fig. 7.3) with the kinematic margin of Section 7.7.3 (Eq. 7.3).
//!
//! # The leg frame `l`
//!
//! Eq. 7.6 writes the foot in "the leg local frame" `{p_F/l}_l = k(q)` and Eq. 7.10-7.11 go
//! from it to the body through `T_{b,l}`. Fig. 7.10 and 7.11 are lost; the frame used here is
//! the one of the multibody model just before the joint q_r (Eq. 3.64):
//!
//! - origin O_l on the q_r axis, at the height of the body centre of mass (the interpretation
//!   of [`MechanicsParameters::from_description`]), at R_rot from the body centre;
//! - x_l radial, along the leg direction α (the direction of the leg chassis at q_r = 0);
//! - z_l = z_b up, y_l = z_l × x_l;
//!
//! so that `T_{b,l} = T^{Rz}(α) T^d(R_rot, 0, 0)` (the first two factors of Eq. 3.64) and
//! `{p_F/b}_b = R_z(α) (R_rot e_x + {p_F/l}_l)`. The leg frame is fixed to the body: it does
//! not turn with q_r.
//!
//! # The kinematic function k(q) (Eq. 7.6)
//!
//! With q = (q_r, q_v, q_h), `k(q) = R_z(−q_r) (O_l C* + (F_x, 0, F_z))` where O_l C* = O_l G_c +
//! G_c C* is the crossing point of the pantograph in the chassis frame and (F_x, F_z) the foot
//! of the planar linkage ([`PantographGeometry::points`]): `F = C + (l_3 / l_1)(D − B)`. The
//! minus sign on q_r is the one of Eq. 3.64: a positive q_r turns the leg clockwise seen
//! from above. The 3x3 Jacobian `J = ∂k/∂q` (Eq. 7.8-7.9) is in closed form: the dependent
//! angle p0 of link 0 is differentiated through the closure of the triangle A-B-D,
//! `|B − D|² = l_1²` (Eq. 3.57-3.63), so `∂p0/∂q_v = −r_z / (c r·n_0)` and
//! `∂p0/∂q_h = r_x / (c r·n_0)` with r = B − D and n_0 the normal of link 0.
//!
//! # Inverse kinematics (Eq. 7.7)
//!
//! [`LegKinematics::inverse`] runs the Newton-Raphson iteration of Eq. 7.7 from the current
//! joints, each iterate projected into the joint ranges (Table 5.2). A target the foot cannot
//! reach (outside the ranges, or where the linkage would not close) ends in
//! [`IkOutcome::Clamped`]: the joints within the ranges whose foot is the closest to the
//! target (a box-constrained least-squares problem, solved on every face, edge and corner
//! of the joint box), with the remaining distance, the joints at their limits and, when the
//! linkage can reach the target with the ranges ignored, how far beyond the ranges that
//! would be. The joints returned are always finite and within the ranges.
//!
//! # Workspace (Fig. 7.3)
//!
//! The thesis restricts the workspace of a leg to "a simple cylinder" (Section 7.1.1) whose
//! centre C is used for the AEP (Eq. 7.24, 7.30) and whose boundary defines the kinematic
//! margin (Section 7.7.3). Fig. 7.3 is lost; [`LegKinematics::workspace`] builds the largest
//! vertical cylinder that fits in the reachable set of the foot for all heights of a given
//! range [z_min, z_max] (leg frame; e.g. from the ground under a body at height h, z = −h,
//! up to the foot lift). At height z the reachable set is an annular sector: radii
//! [ρ_lo(z), ρ_hi(z)] from the q_r axis given by the pantograph (q_v, q_h) ranges, azimuths
//! −q_r over the q_r range. The cylinder's disc lies in the intersection over the height
//! range, the annular sector [max ρ_lo, min ρ_hi] × q_r range; its centre lies on the
//! bisector of the sector.

// `!(a < b)` is used on purpose: it is also true when a comparison involves a NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use nalgebra::{Matrix3, Vector2, Vector3};

use super::mechanics::MechanicsParameters;
use super::pantograph::PantographGeometry;
use super::Joint;
use crate::spatial::{rotation_about, Htm};

/// Errors of the leg kinematics: an unusable geometry or non-finite inputs.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LegKinematicsError {
    #[error("leg {0} does not exist (legs 0..5)")]
    NoSuchLeg(usize),
    #[error("the range of {joint} is not a finite, non-empty interval: [{lower}, {upper}]")]
    InvalidRange { joint: Joint, lower: f64, upper: f64 },
    #[error("the pantograph does not close everywhere in the joint ranges (AD from {k_min:.4} to {k_max:.4} m, needs |l_1 - c| < AD < l_1 + c)")]
    LinkageOpen { k_min: f64, k_max: f64 },
    #[error("non-finite {0}")]
    NonFinite(&'static str),
    #[error("height range [{z_min}, {z_max}] m of the workspace is not within the heights the foot reaches [{lowest}, {highest}] m")]
    HeightOutOfReach { z_min: f64, z_max: f64, lowest: f64, highest: f64 },
    #[error("no workspace cylinder fits in the reachable set for heights [{z_min}, {z_max}] m")]
    EmptyWorkspace { z_min: f64, z_max: f64 },
}

/// Ranges of the joints (q_r in rad, q_v and q_h in m), Table 5.2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLimits {
    pub lower: Vector3<f64>,
    pub upper: Vector3<f64>,
}

impl JointLimits {
    pub fn new(lower: Vector3<f64>, upper: Vector3<f64>) -> Self {
        JointLimits { lower, upper }
    }

    /// q projected into the ranges.
    pub fn clamp(&self, q: &Vector3<f64>) -> Vector3<f64> {
        Vector3::from_fn(|i, _| q[i].clamp(self.lower[i], self.upper[i]))
    }

    pub fn contains(&self, q: &Vector3<f64>) -> bool {
        (0..3).all(|i| q[i] >= self.lower[i] && q[i] <= self.upper[i])
    }

    /// Middle of the ranges.
    pub fn middle(&self) -> Vector3<f64> {
        (self.lower + self.upper) / 2.0
    }

    fn validate(&self) -> Result<(), LegKinematicsError> {
        for (i, joint) in Joint::ALL.into_iter().enumerate() {
            let (lower, upper) = (self.lower[i], self.upper[i]);
            if !(lower.is_finite() && upper.is_finite() && lower < upper) {
                return Err(LegKinematicsError::InvalidRange { joint, lower, upper });
            }
        }
        Ok(())
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

/// Kinematics of one leg: k(q) of Eq. 7.6, its Jacobian (Eq. 7.8), the inverse of Eq. 7.7,
/// the frame change T_{b,l} of Eq. 7.10 and the workspace cylinder.
#[derive(Clone, Debug, PartialEq)]
pub struct LegKinematics {
    pub(super) pantograph: PantographGeometry,
    /// O_l C* in the chassis frame (= leg frame at q_r = 0): O_l G_c + G_c C*.
    pub(super) crossing: Vector3<f64>,
    pub(super) limits: JointLimits,
    /// α, angle of the leg from x_b about z_b.
    alpha: f64,
    /// R_rot.
    r_rot: f64,
    options: IkOptions,
}

/// Foot of the planar linkage and its derivatives, in the leg plane (x radial, z up, from C*).
struct PlanarFoot {
    f: Vector2<f64>,
    d_qv: Vector2<f64>,
    d_qh: Vector2<f64>,
}

impl LegKinematics {
    /// Leg `leg` of the mechanics `p` with the joint ranges `limits`.
    pub fn new(p: &MechanicsParameters, limits: JointLimits, leg: usize) -> Result<Self, LegKinematicsError> {
        let alpha = *p.leg_angles.get(leg).ok_or(LegKinematicsError::NoSuchLeg(leg))?;
        limits.validate()?;
        let pg = p.pantograph;
        // AD = sqrt(q_v² + q_h²) over the (q_v, q_h) box: nearest and farthest points from A's
        // origin (the triangle A-B-D of Eq. 3.57-3.63 must close everywhere).
        let near = Vector2::new(0.0f64.clamp(limits.lower[1], limits.upper[1]), 0.0f64.clamp(limits.lower[2], limits.upper[2]));
        let far = Vector2::new(
            if limits.lower[1].abs() > limits.upper[1].abs() { limits.lower[1] } else { limits.upper[1] },
            if limits.lower[2].abs() > limits.upper[2].abs() { limits.lower[2] } else { limits.upper[2] },
        );
        let (k_min, k_max) = (near.norm(), far.norm());
        if !(k_min > (pg.c - pg.l1).abs() && k_max < pg.c + pg.l1) {
            return Err(LegKinematicsError::LinkageOpen { k_min, k_max });
        }
        Ok(LegKinematics {
            pantograph: pg,
            crossing: p.chassis_cog + p.crossing_point,
            limits,
            alpha,
            r_rot: p.r_rot,
            options: IkOptions::default(),
        })
    }

    /// The six legs, each with its angle α.
    pub fn hexapod(p: &MechanicsParameters, limits: JointLimits) -> Result<[Self; 6], LegKinematicsError> {
        let legs = (0..6).map(|leg| Self::new(p, limits, leg)).collect::<Result<Vec<_>, _>>()?;
        Ok(legs.try_into().expect("six legs"))
    }

    pub fn with_options(mut self, options: IkOptions) -> Self {
        self.options = options;
        self
    }

    pub fn options(&self) -> &IkOptions {
        &self.options
    }
    pub fn limits(&self) -> &JointLimits {
        &self.limits
    }
    /// α (rad).
    pub fn alpha(&self) -> f64 {
        self.alpha
    }
    /// O_l C*: the crossing point in the leg frame at q_r = 0.
    pub fn crossing_point(&self) -> Vector3<f64> {
        self.crossing
    }

    // ------------------------------------------------------------------------------------
    // Forward kinematics, Eq. 7.6-7.9
    // ------------------------------------------------------------------------------------

    /// Planar foot F(q_v, q_h) and its closed-form derivatives.
    fn planar(&self, q_v: f64, q_h: f64) -> PlanarFoot {
        let g = &self.pantograph;
        let (s, c) = g.p0_sin_cos(q_v, q_h);
        let u0 = Vector2::new(c, s);
        let n0 = Vector2::new(-s, c);
        let a = Vector2::new(0.0, q_v);
        let d = Vector2::new(q_h, 0.0);
        let b = a + u0 * g.c;
        // As in PantographGeometry::points: F = C + l_3 (D − B) / l_1.
        let f = (a + u0 * g.l0) + (d - b) / g.l1 * g.l3;
        // F = A (1 − l_3/l_1) + D l_3/l_1 + u0 (l_0 − c l_3/l_1); p0 through |B − D|² = l_1².
        let ratio = g.l3 / g.l1;
        let lever = g.l0 - g.c * ratio;
        let r = b - d;
        let den = g.c * r.dot(&n0);
        let (dp0_dqv, dp0_dqh) = (-r.y / den, r.x / den);
        PlanarFoot {
            f,
            d_qv: Vector2::new(0.0, 1.0 - ratio) + n0 * (lever * dp0_dqv),
            d_qh: Vector2::new(ratio, 0.0) + n0 * (lever * dp0_dqh),
        }
    }

    /// k(q) of Eq. 7.6: the foot F in the leg frame for q = (q_r, q_v, q_h).
    pub fn foot(&self, q: &Vector3<f64>) -> Vector3<f64> {
        let f = self.pantograph.foot(q[1], q[2]);
        RzMinus::new(q[0]).apply(&(self.crossing + Vector3::new(f.x, 0.0, f.y)))
    }

    /// J = ∂k/∂q of Eq. 7.8-7.9, columns (q_r, q_v, q_h).
    pub fn jacobian(&self, q: &Vector3<f64>) -> Matrix3<f64> {
        self.foot_and_jacobian(q).1
    }

    /// k(q) and J(q) together.
    pub fn foot_and_jacobian(&self, q: &Vector3<f64>) -> (Vector3<f64>, Matrix3<f64>) {
        let pf = self.planar(q[1], q[2]);
        let rz = RzMinus::new(q[0]);
        let p = rz.apply(&(self.crossing + Vector3::new(pf.f.x, 0.0, pf.f.y)));
        // ∂/∂q_r R_z(−q_r) s = −e_z × p.
        let jr = Vector3::new(p.y, -p.x, 0.0);
        let jv = rz.apply(&Vector3::new(pf.d_qv.x, 0.0, pf.d_qv.y));
        let jh = rz.apply(&Vector3::new(pf.d_qh.x, 0.0, pf.d_qh.y));
        (p, Matrix3::from_columns(&[jr, jv, jh]))
    }

    // ------------------------------------------------------------------------------------
    // Leg frame <-> body frame, Eq. 7.10
    // ------------------------------------------------------------------------------------

    /// T_{b,l} = T^{Rz}(α) T^d(R_rot, 0, 0).
    pub fn body_from_leg(&self) -> Htm {
        Htm::rotation(&Vector3::z(), self.alpha).compose(&Htm::displacement(self.r_rot, 0.0, 0.0))
    }

    /// A point of the leg frame in the body frame.
    pub fn to_body(&self, p_leg: &Vector3<f64>) -> Vector3<f64> {
        rotation_about(&Vector3::z(), self.alpha) * (p_leg + Vector3::new(self.r_rot, 0.0, 0.0))
    }

    /// A point of the body frame in the leg frame.
    pub fn to_leg(&self, p_body: &Vector3<f64>) -> Vector3<f64> {
        rotation_about(&Vector3::z(), -self.alpha) * p_body - Vector3::new(self.r_rot, 0.0, 0.0)
    }

    /// A direction (or velocity) of the body frame in the leg frame.
    pub fn direction_to_leg(&self, v_body: &Vector3<f64>) -> Vector3<f64> {
        rotation_about(&Vector3::z(), -self.alpha) * v_body
    }

    /// {p_F/b}_b: the foot in the body frame (Eq. 7.10 without T_{0,b}).
    pub fn foot_in_body(&self, q: &Vector3<f64>) -> Vector3<f64> {
        self.to_body(&self.foot(q))
    }

    /// Inverse kinematics of a target given in the body frame.
    pub fn inverse_in_body(&self, target_body: &Vector3<f64>, start: &Vector3<f64>) -> Result<IkSolution, LegKinematicsError> {
        self.inverse(&self.to_leg(target_body), start)
    }

    // ------------------------------------------------------------------------------------
    // Inverse kinematics, Eq. 7.7
    // ------------------------------------------------------------------------------------

    /// Joints q* with k(q*) = p* (leg frame) by Newton-Raphson (Eq. 7.7) from `start`
    /// (normally the current joints; projected into the ranges first).
    ///
    /// Every iterate is projected into the joint ranges. When the iteration cannot reach the
    /// tolerance (the target is out of the reachable set), the closest foot position within
    /// the ranges is searched and the solution is [`IkOutcome::Clamped`]. Only non-finite
    /// inputs are errors.
    pub fn inverse(&self, target: &Vector3<f64>, start: &Vector3<f64>) -> Result<IkSolution, LegKinematicsError> {
        if !target.iter().all(|v| v.is_finite()) {
            return Err(LegKinematicsError::NonFinite("inverse-kinematics target"));
        }
        if !start.iter().all(|v| v.is_finite()) {
            return Err(LegKinematicsError::NonFinite("inverse-kinematics start"));
        }
        let tol = self.options.tolerance;
        let mut q = self.limits.clamp(start);
        let (mut p, mut j) = self.foot_and_jacobian(&q);
        let mut e = (p - target).norm();
        let mut iterations = 0;
        // Eq. 7.7: q^k = q^{k−1} − J^{-1} (k(q^{k−1}) − p*), projected into the ranges.
        while e > tol && iterations < self.options.max_iterations {
            let Some(dq) = j.lu().solve(&(p - target)) else { break };
            let q_new = self.limits.clamp(&(q - dq));
            iterations += 1;
            let (p_new, j_new) = self.foot_and_jacobian(&q_new);
            let e_new = (p_new - target).norm();
            if !(e_new < e) {
                break; // no progress: the projection stalls on a limit (target out of reach)
            }
            (q, p, j, e) = (q_new, p_new, j_new, e_new);
        }
        if e <= tol {
            return Ok(IkSolution { joints: q, foot: p, iterations, outcome: IkOutcome::Reached });
        }
        // Out of reach (or slow): the closest point within the joint box.
        let (q, p, extra) = self.closest(target, &q);
        iterations += extra;
        let error = p - target;
        let distance = error.norm();
        if distance <= tol {
            return Ok(IkSolution { joints: q, foot: p, iterations, outcome: IkOutcome::Reached });
        }
        let limits = std::array::from_fn(|i| {
            if q[i] <= self.limits.lower[i] {
                Limit::Lower
            } else if q[i] >= self.limits.upper[i] {
                Limit::Upper
            } else {
                Limit::Free
            }
        });
        let excess = self.unconstrained(target, &q).map(|qu| qu - q);
        Ok(IkSolution { joints: q, foot: p, iterations, outcome: IkOutcome::Clamped(Clamping { distance, error, limits, excess }) })
    }

    /// min |k(q) − p*| over the joint box: projected Gauss-Newton on the interior and on every
    /// face, edge and corner of the box (26 + 1 sub-problems of at most 3 unknowns); the
    /// minimizer is the best of them. Returns (q, k(q), Gauss-Newton updates).
    fn closest(&self, target: &Vector3<f64>, q0: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>, usize) {
        let mut best = (*q0, self.foot(q0));
        let mut best_e = (best.1 - target).norm();
        let mut updates = 0;
        // Azimuth of the target for q_r: azimuth of the foot is −q_r + atan2(s_y, s_x).
        let s = RzMinus::new(-q0[0]).apply(&best.1);
        let q_r_aim = (s.y.atan2(s.x) - target.y.atan2(target.x)).clamp(self.limits.lower[0], self.limits.upper[0]);
        let aim = target.xy().norm() > 1e-9;
        for code in 0..27usize {
            // Each joint: 0 free, 1 at lower, 2 at upper; code 0 is the interior problem.
            let mask = [code % 3, (code / 3) % 3, code / 9];
            let mut q = *q0;
            for i in 0..3 {
                match mask[i] {
                    1 => q[i] = self.limits.lower[i],
                    2 => q[i] = self.limits.upper[i],
                    _ => {}
                }
            }
            if mask[0] == 0 && aim {
                q[0] = q_r_aim;
            }
            let (q, p, n) = self.gauss_newton(target, q, mask.map(|m| m == 0));
            updates += n;
            let e = (p - target).norm();
            if e < best_e {
                (best, best_e) = ((q, p), e);
            }
        }
        (best.0, best.1, updates)
    }

    /// Projected Gauss-Newton with backtracking on the `free` joints.
    fn gauss_newton(&self, target: &Vector3<f64>, mut q: Vector3<f64>, free: [bool; 3]) -> (Vector3<f64>, Vector3<f64>, usize) {
        let (mut p, mut j) = self.foot_and_jacobian(&q);
        let mut e = (p - target).norm();
        let mut updates = 0;
        if !free.iter().any(|&f| f) {
            return (q, p, 0);
        }
        for _ in 0..50 {
            if e <= self.options.tolerance {
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
                let q_new = self.limits.clamp(&(q - step * t));
                let (p_new, j_new) = self.foot_and_jacobian(&q_new);
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
    /// triangle A-B-D closes; `None` when it does not converge there.
    fn unconstrained(&self, target: &Vector3<f64>, q0: &Vector3<f64>) -> Option<Vector3<f64>> {
        let mut q = *q0;
        let (mut p, mut j) = self.foot_and_jacobian(&q);
        let mut e = (p - target).norm();
        for _ in 0..50 {
            if e <= self.options.tolerance {
                return Some(q);
            }
            let dq = j.lu().solve(&(p - target))?;
            let mut t = 1.0;
            let mut accepted = None;
            for _ in 0..40 {
                let q_new = q - dq * t;
                if q_new.iter().all(|v| v.is_finite()) && self.pantograph.closes(q_new[1], q_new[2]) {
                    let (p_new, j_new) = self.foot_and_jacobian(&q_new);
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
        (e <= self.options.tolerance).then_some(q)
    }
}

/// R_z(−q_r), from the sine and cosine of q_r taken once for the vectors it turns.
#[derive(Clone, Copy)]
struct RzMinus {
    sin: f64,
    cos: f64,
}

impl RzMinus {
    fn new(q_r: f64) -> Self {
        let (sin, cos) = q_r.sin_cos();
        RzMinus { sin, cos }
    }

    /// R_z(−q_r) v.
    fn apply(&self, v: &Vector3<f64>) -> Vector3<f64> {
        let (s, c) = (self.sin, self.cos);
        Vector3::new(c * v.x + s * v.y, -s * v.x + c * v.y, v.z)
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::description::RobotDescription;
    use crate::hexapod::Workspace;
    use crate::mbs::{kinematics, Data};
    use crate::hexapod::{joint_index, Mechanics, DOF};
    use crate::spatial::yaw_pitch_roll;
    use crate::test_util::{central, rng};
    use approx::assert_relative_eq;
    use rand::Rng;

    /// The neutral posture of the leg linearization, Section 4.1: q_r = 0, q_v = 0.06, q_h = 0.04.
    pub(crate) fn neutral() -> Vector3<f64> {
        Vector3::new(0.0, 0.06, 0.04)
    }

    pub(crate) fn amru5() -> [LegKinematics; 6] {
        LegKinematics::hexapod_from_description(&RobotDescription::amru5()).unwrap()
    }

    pub(crate) fn random_joints(r: &mut impl Rng, l: &JointLimits) -> Vector3<f64> {
        Vector3::from_fn(|i, _| r.random_range(l.lower[i]..=l.upper[i]))
    }

    /// Workspace for a level body at the height of the neutral posture, foot lift 5 cm.
    pub(crate) fn neutral_workspace(leg: &LegKinematics) -> Workspace {
        let height = -leg.foot(&neutral()).z;
        leg.workspace_for_body_height(height, 0.05).unwrap()
    }

    /// k(q) in the body frame is the foot of the multibody model (Eq. 3.64-3.68) for any body
    /// pose, and J(q) its partial velocities (Eq. 7.9).
    #[test]
    fn leg_kinematics_match_the_multibody_model() {
        let d = RobotDescription::amru5();
        let mech = Mechanics::new(&MechanicsParameters::from_description(&d)).unwrap();
        let legs = amru5();
        let mut data = Data::new(&mech.model);
        let l = *legs[0].limits();
        let sets = [
            neutral(),
            l.lower,
            l.upper,
            Vector3::new(l.lower[0], l.upper[1], l.lower[2]),
            Vector3::new(0.3, 0.045, 0.05),
            Vector3::new(-0.2, 0.07, 0.01),
        ];
        let poses = [[0.0; 6], [0.1, -0.2, 0.45, 0.3, 0.05, -0.04]];
        for pose in poses {
            for s in 0..sets.len() {
                let mut q = vec![0.0; DOF];
                q[..6].copy_from_slice(&pose);
                for leg in 0..6 {
                    // A different joint set on each leg.
                    let qs = sets[(s + leg) % sets.len()];
                    for k in 0..3 {
                        q[joint_index(leg, k)] = qs[k];
                    }
                }
                kinematics(&mech.model, &mut data, &q, &[0.0; DOF]);
                let body = Htm { rotation: yaw_pitch_roll(pose[3], pose[4], pose[5]), translation: Vector3::new(pose[0], pose[1], pose[2]) };
                for (leg, bodies) in mech.legs.iter().enumerate() {
                    let kin = &legs[leg];
                    let qs = Vector3::new(q[joint_index(leg, 0)], q[joint_index(leg, 1)], q[joint_index(leg, 2)]);
                    let foot = data.point(bodies.links[3], &mech.foot_local);
                    assert_relative_eq!(body.apply(&kin.foot_in_body(&qs)), foot, epsilon = 1e-12);
                    assert_relative_eq!(body.compose(&kin.body_from_leg()).apply(&kin.foot(&qs)), foot, epsilon = 1e-12);
                    let to_global = body.rotation * rotation_about(&Vector3::z(), kin.alpha());
                    let j = kin.jacobian(&qs);
                    for (c, v) in data.point_partial_velocities(&mech.model, bodies.links[3], &foot) {
                        if (joint_index(leg, 0)..joint_index(leg, 3)).contains(&c) {
                            let k = c - joint_index(leg, 0);
                            assert_relative_eq!(to_global * j.column(k), v, epsilon = 1e-12);
                        }
                    }
                }
            }
        }
    }

    /// Leg frame of the module docs: O_l at R_rot along α at body-centre height; at q_r = 0 the
    /// foot lies in the vertical plane x_l z_l, C* at (0.112, 0, −0.052) (NOTES.md), and
    /// x_foot ≈ 7 q_h, z_foot ≈ −6 q_v from C* (Eq. B.1-B.2).
    #[test]
    fn leg_kinematics_frame_conventions() {
        let legs = amru5();
        let kin = &legs[2];
        assert_relative_eq!(kin.crossing_point(), Vector3::new(0.112, 0.0, -0.052), epsilon = 1e-12);
        assert_relative_eq!(kin.to_body(&Vector3::zeros()), Vector3::new(0.0, 0.175, 0.0), epsilon = 1e-12);
        let p = kin.foot(&neutral());
        assert!(p.y.abs() < 1e-15);
        assert!((p.x - 0.112 - 7.0 * 0.04).abs() < 2.1e-3 && (p.z + 0.052 + 6.0 * 0.06).abs() < 2.1e-3, "{p}");
        // A positive q_r turns the foot clockwise seen from above (minus sign of Eq. 3.64).
        assert!(kin.foot(&Vector3::new(0.2, 0.06, 0.04)).y < 0.0);
        assert_relative_eq!(kin.to_leg(&kin.to_body(&p)), p, epsilon = 1e-15);
    }

    /// The closed-form Jacobian against central finite differences of k(q).
    #[test]
    fn leg_kinematics_jacobian_matches_finite_differences() {
        let legs = amru5();
        let mut r = rng(7);
        for n in 0..500 {
            let kin = &legs[n % 6];
            let q = random_joints(&mut r, kin.limits());
            let (p, j) = kin.foot_and_jacobian(&q);
            assert_relative_eq!(p, kin.foot(&q), epsilon = 1e-15);
            for k in 0..3 {
                let h = if k == 0 { 1e-6 } else { 1e-7 };
                for i in 0..3 {
                    let g = |x: f64| {
                        let mut qq = q;
                        qq[k] = x;
                        kin.foot(&qq)[i]
                    };
                    let fd = central(g, q[k], h);
                    assert!((j[(i, k)] - fd).abs() <= 1e-7 * j.column(k).norm() + 1e-10, "J[{i},{k}] = {} vs {fd} at {q}", j[(i, k)]);
                }
            }
        }
    }

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

    /// Ranges where the pantograph cannot close are refused when the leg is built.
    #[test]
    fn leg_kinematics_refuses_open_linkages() {
        let p = MechanicsParameters::from_description(&RobotDescription::amru5());
        let l = JointLimits::from_description(&RobotDescription::amru5());
        let open = JointLimits { upper: Vector3::new(l.upper[0], 0.1, 0.055), ..l };
        assert!(matches!(LegKinematics::new(&p, open, 0), Err(LegKinematicsError::LinkageOpen { .. })));
        let empty = JointLimits { upper: Vector3::new(l.lower[0], l.upper[1], l.upper[2]), ..l };
        assert!(matches!(LegKinematics::new(&p, empty, 0), Err(LegKinematicsError::InvalidRange { .. })));
        assert!(matches!(LegKinematics::new(&p, l, 6), Err(LegKinematicsError::NoSuchLeg(6))));
    }
}
