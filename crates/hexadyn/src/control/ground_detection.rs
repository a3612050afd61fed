//! Ground detection from the motor currents, thesis Section 5.6.3: the ground torque of the
//! torque estimator ([`TorqueEstimator`], Fig. 5.12) turned into the vertical ground force on
//! the foot by the leg Jacobian (Eq. 5.20-5.22), compared with a threshold while the foot is
//! being lowered.
//!
//! Any leg mechanism ([`GroundSensingLeg`]): AMRU5's pantograph as the thesis writes it (α_21
//! alone, the vertical joint's velocity), a serial leg on its own Jacobian (the whole vertical
//! row of J^{−T}, the foot's vertical velocity).
//!
//! A gait controller calls [`GroundDetector::update`] once per control period with the
//! measurements and reads, per leg, the force estimate and the `detected` flag.

use nalgebra::{Matrix3, Vector3};

use super::interface::Measurements;
use super::low_pass::DIGITAL_CUTOFF_HZ;
use super::torque_estimation::{TorqueEstimate, TorqueEstimator};
use crate::description::Robot;
use crate::hexapod::{LegChain, LegKinematics, SerialLegKinematics, LEG_COUNT};

/// What the detector says about one leg at a control instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LegDetection {
    /// F̂_z,gnd (N): the estimated vertical ground force on the foot, Eq. 5.22 (> 0 pushing up).
    pub force: f64,
    /// How fast the foot is lowered, > 0 down ([`GroundSensingLeg::lowering`]: q̂_v' (m/s) on
    /// the pantograph, the foot's downward velocity (m/s) on other legs).
    pub lowering: f64,
    /// Every joint that carries F̂_z ([`CARRYING_SHARE`]) slides, beyond the linear zone ε of
    /// its dry/viscous law (Eq. 6.1).
    pub sliding: bool,
    /// Ground detected: `force` at or above the threshold while the foot is lowered
    /// (`lowering` > 0), the two conditions of Section 5.6.3.
    pub detected: bool,
}

/// What the ground detection of Section 5.6.3 asks of a leg mechanism beyond its kinematics:
/// how the vertical ground force follows from the ground torques of its joints, and how fast
/// its foot is lowered. The defaults hold for any leg; the pantograph keeps the thesis'
/// simplifications.
pub trait GroundSensingLeg: LegChain {
    /// ∂F_z/∂τ_gnd at `q`: F̂_z,gnd = r · τ_gnd with r the vertical row of −J^{−T}
    /// (Eq. 5.20-5.21, F = −J^{−T} τ_gnd); None where J is singular.
    fn vertical_force_row(&self, q: &Vector3<f64>) -> Option<Vector3<f64>> {
        Some(-jacobian_inverse_transpose(self, q)?.row(2).transpose())
    }

    /// How fast the foot is lowered at (q, q') (> 0 down): −(J q')_z (m/s).
    fn lowering(&self, q: &Vector3<f64>, qd: &Vector3<f64>) -> f64 {
        -(self.foot_and_jacobian(q).1 * qd).z
    }
}

/// AMRU5's pantograph as Section 5.6.3 writes it: Eq. 5.22 keeps α_21 τ_v,gnd, and the foot is
/// lowered when the vertical joint goes down (q̂_v' > 0).
impl GroundSensingLeg for LegKinematics {
    fn vertical_force_row(&self, q: &Vector3<f64>) -> Option<Vector3<f64>> {
        alpha(self, q).map(|(a21, _)| Vector3::new(0.0, a21, 0.0))
    }

    fn lowering(&self, _q: &Vector3<f64>, qd: &Vector3<f64>) -> f64 {
        qd[1]
    }
}

impl GroundSensingLeg for SerialLegKinematics {}

/// The share of the detection threshold below which a joint held by its dry friction does not
/// matter to F̂_z,gnd: a joint whose dry friction τ_f,d could move the estimate by more,
/// |∂F_z/∂τ_j| τ_f,d, carries the vertical force, and the estimate is only known while it
/// slides (Section 5.6.2: the dry/viscous model is the sliding friction).
///
/// INTERPRETATION: a tenth. On AMRU5's pantograph q_v alone carries F_z (Eq. 5.22), its dry
/// friction worth 16 N at the foot against 4 N; on the PhantomX the femur and the tibia (6 N
/// each against 0.2 N), not the coxa, whose vertical axis puts no vertical force on the foot.
pub const CARRYING_SHARE: f64 = 0.1;

/// The coefficients (α_21, α_22) of Eq. 5.21 at the joint positions `q` of `leg`: the vertical
/// ground force on the foot is F_z = α_21 τ_v,gnd + α_22 τ_h,gnd (α_20 = 0).
///
/// The generalized forces of a ground force F on the foot are J^T F (virtual power, Eq. 3.41,
/// with J = ∂k/∂q of Eq. 7.8 in the leg frame); the motor balances them, so τ_gnd = −J^T F and
/// F = −J^{−T} τ_gnd (Eq. 5.20 written for the force on the foot rather than by it). Eq. 5.22
/// keeps α_21 alone: the pantograph decouples q_v (vertical) and q_h (horizontal), so α_22 is
/// small.
pub fn alpha(leg: &LegKinematics, q: &Vector3<f64>) -> Option<(f64, f64)> {
    let j_inv_t = jacobian_inverse_transpose(leg, q)?;
    Some((-j_inv_t[(2, 1)], -j_inv_t[(2, 2)]))
}

/// J^{−T} of the leg at q (Eq. 5.20: F = −J^{−T} τ); None where J is singular.
fn jacobian_inverse_transpose<L: LegChain + ?Sized>(leg: &L, q: &Vector3<f64>) -> Option<Matrix3<f64>> {
    leg.foot_and_jacobian(q).1.transpose().try_inverse()
}

/// The estimator's (filtered) joint positions of `leg`.
fn leg_joints(e: &TorqueEstimate, leg: usize) -> Vector3<f64> {
    Vector3::new(e.q[3 * leg], e.q[3 * leg + 1], e.q[3 * leg + 2])
}

/// The estimated ground torques τ − τ̂ of the joints of `leg` (Eq. 5.16).
fn ground_torques(e: &TorqueEstimate, leg: usize) -> Vector3<f64> {
    let k = 3 * leg;
    Vector3::new(e.ground(k), e.ground(k + 1), e.ground(k + 2))
}

/// The ground detector of the six legs.
#[derive(Clone, Debug)]
pub struct GroundDetector<L> {
    estimator: TorqueEstimator,
    legs: [L; LEG_COUNT],
    /// Detection threshold on F̂_z,gnd (N): 40, 50 or 60 N in Table 5.7.
    pub threshold: f64,
}

impl<L: GroundSensingLeg> GroundDetector<L> {
    /// The detector of `robot` with the kinematics `legs` of its legs at the control period
    /// `dt`, with the 3 Hz filters of Section 5.6.2 and the force `threshold` (N).
    pub fn new(robot: &Robot, legs: [L; LEG_COUNT], dt: f64, threshold: f64) -> Self {
        GroundDetector { estimator: TorqueEstimator::new(robot, dt, DIGITAL_CUTOFF_HZ), legs, threshold }
    }

    /// One control period: Eq. 5.14-5.16 and 5.22 for every leg from the measurements.
    pub fn update(&mut self, m: &Measurements) -> [LegDetection; LEG_COUNT] {
        self.estimator.update(m);
        let (e, friction) = (self.estimator.estimate().expect("just updated"), self.estimator.dry_viscous());
        std::array::from_fn(|leg| {
            let k = 3 * leg;
            let q = leg_joints(e, leg);
            let qd = Vector3::new(e.qd[k], e.qd[k + 1], e.qd[k + 2]);
            let lowering = self.legs[leg].lowering(&q, &qd);
            let Some(row) = self.legs[leg].vertical_force_row(&q) else {
                return LegDetection { force: 0.0, lowering, sliding: false, detected: false };
            };
            let force = row.dot(&ground_torques(e, leg));
            let carrying = |j: usize| row[j].abs() * friction[k + j].tau_f_d_plus.abs().max(friction[k + j].tau_f_d_minus.abs()) > CARRYING_SHARE * self.threshold;
            let sliding = (0..3).all(|j| !carrying(j) || qd[j].abs() > friction[k + j].epsilon);
            LegDetection { force, lowering, sliding, detected: force >= self.threshold && lowering > 0.0 }
        })
    }

    /// The kinematics of the legs.
    pub fn legs(&self) -> &[L; LEG_COUNT] {
        &self.legs
    }

    /// The torques of the last update.
    pub fn estimate(&self) -> Option<&TorqueEstimate> {
        self.estimator.estimate()
    }

    /// The ground force on each foot (leg frame, N) from the last update's ground torques of
    /// its three joints: Eq. 5.20 with the whole J^{−T} (Eq. 5.22 keeps its vertical row), as the
    /// elevator reflex of the free gait reads the horizontal resistance to the swing. None
    /// before the first update or where J is singular.
    pub fn foot_forces(&self) -> Option<[Option<Vector3<f64>>; LEG_COUNT]> {
        let e = self.estimator.estimate()?;
        Some(std::array::from_fn(|leg| Some(-(jacobian_inverse_transpose(&self.legs[leg], &leg_joints(e, leg))? * ground_torques(e, leg)))))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::RobotDescription;
    use crate::physics::JointFriction;
    use crate::test_util::rng;
    use rand::Rng;

    fn legs() -> [LegKinematics; 6] {
        LegKinematics::hexapod_from_description(&RobotDescription::amru5()).unwrap()
    }

    /// J by central differences of the foot position k(q).
    fn jacobian_fd(leg: &LegKinematics, q: &Vector3<f64>) -> Matrix3<f64> {
        let h = 1e-7;
        Matrix3::from_fn(|i, j| {
            let mut a = *q;
            let mut b = *q;
            a[j] += h;
            b[j] -= h;
            (leg.foot(&a)[i] - leg.foot(&b)[i]) / (2.0 * h)
        })
    }

    #[test]
    fn alpha_by_virtual_work_on_the_finite_difference_jacobian() {
        let mut r = rng(51);
        for leg in legs() {
            let (lo, hi) = (leg.limits().lower, leg.limits().upper);
            for _ in 0..200 {
                let q = Vector3::from_fn(|i, _| r.random_range(lo[i]..hi[i]));
                let (a21, a22) = alpha(&leg, &q).unwrap();
                // A vertical force F on the foot: the motors balance τ_gnd = −J^T F, whose work
                // over a virtual displacement δq equals −F·δp (δp = J δq, by finite differences).
                let f = Vector3::new(0.0, 0.0, 50.0);
                let tau_gnd = -jacobian_fd(&leg, &q).transpose() * f;
                let fz = a21 * tau_gnd[1] + a22 * tau_gnd[2];
                assert!((fz - 50.0).abs() < 1e-5, "leg at {q}: {fz}");
                let dq = Vector3::new(1e-6, -2e-7, 3e-7);
                let dp = leg.foot(&(q + dq)) - leg.foot(&(q - dq));
                assert!((tau_gnd.dot(&(2.0 * dq)) + f.dot(&dp)).abs() < 1e-9);
                // Eq. 5.22: the pantograph decoupling leaves α_22 τ_h small against α_21 τ_v.
                assert!((a21 * tau_gnd[1] - 50.0).abs() < 0.05 * 50.0, "leg at {q}: α21 τ_v = {}", a21 * tau_gnd[1]);
                // Eq. B.2, z_foot ≈ −6 q_v: α_21 ≈ 1/6.
                assert!((a21 * 6.0 - 1.0).abs() < 0.1, "α21 = {a21}");
            }
        }
    }

    /// A PhantomX leg (serial, AX-12A servos) lowering its foot straight down at 1 cm/s from
    /// the middle of its joint ranges for 2 s (six time constants of the 3 Hz filters), the
    /// currents of its three motors balancing a vertical ground force `f` and their friction:
    /// the estimated foot force (vertical row and whole vector of −J^{−T} τ_gnd), against the
    /// same leg in the air, is the oracle's force to 1 %. The oracle's Jacobian is the finite
    /// difference of the leg's foot position; it leaves out the weight of the links.
    #[test]
    fn a_serial_leg_estimates_its_foot_force_on_its_own_jacobian() {
        use crate::description::SHIPPED_ROBOTS;
        use crate::hexapod::Leg;
        use crate::robot::model::FrictionModel;
        let (_, text, origin) = SHIPPED_ROBOTS[1];
        let robot = Robot::from_str(text, origin).unwrap();
        let Robot::Serial(serial) = &robot else { panic!("a serial robot") };
        let legs = SerialLegKinematics::hexapod(&serial.hexapod.legs).unwrap();
        let parts = robot.parts(&robot.model_options(FrictionModel::DryViscous));
        let dt = robot.period();
        let run = |f: f64| {
            let mut detector = GroundDetector::new(&robot, legs.clone(), dt, 1.0);
            let mut m = Measurements { supply_voltage: 12.0, ..Default::default() };
            let mut q: [Vector3<f64>; 6] = std::array::from_fn(|l| legs[l].limits().middle());
            let start: [Vector3<f64>; 6] = std::array::from_fn(|l| legs[l].foot(&q[l]));
            let mut out = [LegDetection::default(); 6];
            for n in 0..=(2.0 / dt).round() as usize {
                for (l, leg) in legs.iter().enumerate() {
                    let target = start[l] - Vector3::new(0.0, 0.0, 0.01 * n as f64 * dt);
                    let next = Leg::inverse(leg, &target, &q[l]).unwrap();
                    assert!(next.is_reached(), "leg {l} reaches {target}");
                    let qd = (next.joints - q[l]) / dt;
                    q[l] = next.joints;
                    let h = 1e-7;
                    let jacobian = Matrix3::from_fn(|i, j| {
                        let (mut a, mut b) = (q[l], q[l]);
                        a[j] += h;
                        b[j] -= h;
                        (leg.foot(&a)[i] - leg.foot(&b)[i]) / (2.0 * h)
                    });
                    let tau_gnd = -jacobian.transpose() * Vector3::new(0.0, 0.0, f);
                    for j in 0..3 {
                        let k = 3 * l + j;
                        let JointFriction::DryViscous(law) = parts.friction[k].law else { unreachable!() };
                        m.positions[k] = q[l][j];
                        m.currents[k] = (tau_gnd[j] + law.torque(qd[j]).0) / (parts.motors[k].k_t * parts.motors[k].n);
                    }
                }
                m.t = n as f64 * dt;
                out = detector.update(&m);
            }
            (out, detector.foot_forces().unwrap().map(Option::unwrap))
        };
        let (air, air_forces) = run(0.0);
        for f in [2.0, 8.0] {
            let (loaded, forces) = run(f);
            for l in 0..6 {
                assert!((loaded[l].force - air[l].force - f).abs() < 0.01 * f, "leg {l}, F = {f} N: {} N, {} N in the air", loaded[l].force, air[l].force);
                let force = forces[l] - air_forces[l];
                assert!((force - Vector3::new(0.0, 0.0, f)).norm() < 0.01 * f, "leg {l}, F = {f} N: {force}");
                // Lowered at 1 cm/s, every joint sliding.
                assert!((loaded[l].lowering - 0.01).abs() < 1e-3, "leg {l}: {:?}", loaded[l]);
                // The femur and the tibia carry F_z and slide, not the coxa (vertical axis).
                assert!(loaded[l].sliding, "leg {l}: {:?}", loaded[l]);
                assert!(loaded[l].detected);
            }
        }
    }
}
