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
//! The inverse of k (Eq. 7.7) is in [`inverse`].
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

use nalgebra::{Matrix3, Vector2, Vector3};

use super::mechanics::MechanicsParameters;
use super::pantograph::PantographGeometry;
use super::PantographJoint;
use crate::spatial::{rotation_about, Htm};

mod inverse;
mod serial;
pub use inverse::{inverse, Clamping, IkOptions, IkOutcome, IkSolution, Leg, LegChain, Limit};
pub use serial::{default_serial_height, SerialLegKinematics};

/// Errors of the leg kinematics: an unusable geometry or non-finite inputs.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LegKinematicsError {
    #[error("leg {0} does not exist (legs 0..5)")]
    NoSuchLeg(usize),
    #[error("the range of {joint} is not a finite, non-empty interval: [{lower}, {upper}]")]
    InvalidRange { joint: PantographJoint, lower: f64, upper: f64 },
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

    pub(super) fn validate(&self) -> Result<(), LegKinematicsError> {
        for (i, joint) in PantographJoint::ALL.into_iter().enumerate() {
            let (lower, upper) = (self.lower[i], self.upper[i]);
            if !(lower.is_finite() && upper.is_finite() && lower < upper) {
                return Err(LegKinematicsError::InvalidRange { joint, lower, upper });
            }
        }
        Ok(())
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

    /// The pantograph's closed-form `Leg::reaches_point` (its reachable radii at the point's
    /// height) agrees with the trait's default, Eq. 7.7 from the neutral posture, on the
    /// vertical through the workspace centre where the free gait holds a failed leg: the highest
    /// point each finds by bisection within 1 mm (a tenth of the security margin the held-up
    /// foot keeps below it; measured 0.11 mm: near the edge of the reach Eq. 7.7's Newton
    /// iterations stop short of its 1e-12 m tolerance), and the same answer at heights farther
    /// than that from it.
    #[test]
    fn reaches_point_in_closed_form_is_the_inverse_kinematics() {
        use super::inverse::Leg as _;
        for leg in amru5().iter() {
            let w = neutral_workspace(leg);
            let by_ik = |p: &Vector3<f64>| inverse(leg, p, &leg.neutral()).is_ok_and(|ik| ik.is_reached());
            let top = leg.height_range().1;
            let highest = |reaches: &dyn Fn(&Vector3<f64>) -> bool| {
                let (mut low, mut high) = (w.z_max, top);
                assert!(reaches(&w.centre_at(low)));
                while high - low > 1e-7 {
                    let mid = 0.5 * (low + high);
                    if reaches(&w.centre_at(mid)) { low = mid } else { high = mid }
                }
                low
            };
            let (closed, ik) = (highest(&|p| leg.reaches_point(p)), highest(&by_ik));
            assert!((closed - ik).abs() < 1e-3, "highest reach {closed} m in closed form, {ik} m by Eq. 7.7");
            for k in 0..=40 {
                let z = w.z_min + (top + 0.02 - w.z_min) * k as f64 / 40.0;
                if (z - closed).abs() > 1e-3 {
                    assert_eq!(leg.reaches_point(&w.centre_at(z)), by_ik(&w.centre_at(z)), "z = {z}");
                }
            }
        }
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
