//! Ground detection from the motor currents, thesis Section 5.6.3: the ground torque of the
//! torque estimator ([`TorqueEstimator`], Fig. 5.12) turned into the vertical ground force on
//! the foot by the leg Jacobian (Eq. 5.20-5.22), compared with a threshold while the foot is
//! being lowered.
//!
//! A gait controller calls [`GroundDetector::update`] once per control period with the
//! measurements and reads, per leg, the force estimate and the `detected` flag.

use nalgebra::{Matrix3, Vector3};

use super::interface::Measurements;
use super::low_pass::DIGITAL_CUTOFF_HZ;
use super::torque_estimation::{TorqueEstimate, TorqueEstimator};
use crate::description::RobotDescription;
use crate::hexapod::{LegKinematics, LegKinematicsError, LEG_COUNT};

/// What the detector says about one leg at a control instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LegDetection {
    /// F̂_z,gnd (N): the estimated vertical ground force on the foot, Eq. 5.22 (> 0 pushing up).
    pub force: f64,
    /// τ̂_v,gnd = τ_v − τ̂_v (N), Eq. 5.16.
    pub tau_v_gnd: f64,
    /// Estimated vertical joint velocity q̂_v' (m/s); > 0 lowers the foot.
    pub qd_v: f64,
    /// Ground detected: `force` at or above the threshold while the foot is lowered (q̂_v' > 0),
    /// the two conditions of Section 5.6.3.
    pub detected: bool,
}

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
fn jacobian_inverse_transpose(leg: &LegKinematics, q: &Vector3<f64>) -> Option<Matrix3<f64>> {
    leg.jacobian(q).transpose().try_inverse()
}

/// The estimator's (filtered) joint positions of `leg`.
fn leg_joints(e: &TorqueEstimate, leg: usize) -> Vector3<f64> {
    Vector3::new(e.q[3 * leg], e.q[3 * leg + 1], e.q[3 * leg + 2])
}

/// The ground detector of the six legs.
#[derive(Clone, Debug)]
pub struct GroundDetector {
    estimator: TorqueEstimator,
    legs: [LegKinematics; LEG_COUNT],
    /// Detection threshold on F̂_z,gnd (N): 40, 50 or 60 N in Table 5.7.
    pub threshold: f64,
}

impl GroundDetector {
    /// The detector of a robot description at the control period `dt`, with the 3 Hz filters
    /// of Section 5.6.2 and the force `threshold` (N).
    pub fn new(d: &RobotDescription, dt: f64, threshold: f64) -> Result<Self, LegKinematicsError> {
        Ok(GroundDetector { estimator: TorqueEstimator::new(d, dt, DIGITAL_CUTOFF_HZ), legs: LegKinematics::hexapod_from_description(d)?, threshold })
    }

    /// One control period: Eq. 5.14-5.16 and 5.22 for every leg from the measurements.
    pub fn update(&mut self, m: &Measurements) -> [LegDetection; LEG_COUNT] {
        let e = self.estimator.update(m);
        std::array::from_fn(|leg| detect(&self.legs[leg], e, leg, self.threshold))
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
        Some(std::array::from_fn(|leg| foot_force(&self.legs[leg], e, leg)))
    }
}

/// F = −J^{−T} τ_gnd (Eq. 5.20, the force on the foot) from the estimated ground torques of `leg`.
fn foot_force(kinematics: &LegKinematics, e: &TorqueEstimate, leg: usize) -> Option<Vector3<f64>> {
    let k = 3 * leg;
    let tau_gnd = Vector3::new(e.ground(k), e.ground(k + 1), e.ground(k + 2));
    Some(-(jacobian_inverse_transpose(kinematics, &leg_joints(e, leg))? * tau_gnd))
}

fn detect(kinematics: &LegKinematics, e: &TorqueEstimate, leg: usize, threshold: f64) -> LegDetection {
    let k = 3 * leg;
    let q = leg_joints(e, leg);
    let tau_v_gnd = e.ground(k + 1);
    let force = alpha(kinematics, &q).map_or(0.0, |(a21, _)| a21 * tau_v_gnd);
    let qd_v = e.qd[k + 1];
    LegDetection { force, tau_v_gnd, qd_v, detected: force >= threshold && qd_v > 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::RobotDescription;
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
}
