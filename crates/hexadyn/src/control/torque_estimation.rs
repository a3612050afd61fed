//! Model-based estimation of the joint torques, thesis Section 5.6.2 and Fig. 5.12: from the
//! encoder positions, numerical derivatives behind a 3 Hz low-pass filter, a dry/viscous friction
//! model (Eq. 6.1 with the unloaded parameters of Table 5.3) and the inertia and gravity of the
//! legs by the virtual power principle (Eq. 3.37); against it, the joint torque measured from the
//! motor current (Eq. 5.17 and 3.90: τ = n k_t i), filtered at 3 Hz as well. Their difference
//! is the torque of the ground contact, Eq. 5.16: τ − τ̂ ≈ τ_gnd.
//!
//! It reads sensor values only ([`Measurements`]: encoder positions, currents and, when a
//! navigation system is present, the body attitude for the direction of gravity).
//!
//! INTERPRETATION: Fig. 5.12 is lost; the text places the 3 Hz filter "at the input" of the
//! positions and also on the current. Both are filtered here with the same filter, so that the
//! measured and the estimated torques carry the same lag. Velocities and accelerations are
//! backward differences of the filtered positions (the z⁻¹ of Fig. 5.12). The leg model is that
//! of the robot description (Eq. 3.37 on the multibody model of the hexapod) with the body at
//! rest: level, or at the attitude the navigation system reports.

use super::interface::Measurements;
use super::low_pass::DigitalLowPass;
use crate::description::Robot;
use crate::hexapod::{LegDynamics, StillBody, JOINTS};
use crate::mbs::Data;
use crate::physics::{DryViscous, JointFriction};
use crate::robot::model::FrictionModel;

/// The joint torques of one control instant (Nm for a revolute joint, N for a prismatic one:
/// q_r, and q_v, q_h on AMRU5), per joint k = 3 leg + j.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TorqueEstimate {
    /// Filtered positions q̂ and their backward differences q̂', q̂''.
    pub q: [f64; JOINTS],
    pub qd: [f64; JOINTS],
    pub qdd: [f64; JOINTS],
    /// τ = n k_t i from the filtered current (Eq. 5.17).
    pub measured: [f64; JOINTS],
    /// τ̂ = τ̂_iner + τ̂_grav + τ̂_fric (Eq. 5.14).
    pub estimated: [f64; JOINTS],
    /// τ̂_fric, part of `estimated`.
    pub friction: [f64; JOINTS],
}

impl TorqueEstimate {
    /// τ − τ̂ ≈ τ_gnd of joint k (Eq. 5.16).
    pub fn ground(&self, k: usize) -> f64 {
        self.measured[k] - self.estimated[k]
    }
}

/// The torque estimator of Fig. 5.12 for the 18 joints.
#[derive(Clone, Debug)]
pub struct TorqueEstimator {
    dynamics: LegDynamics,
    data: Data,
    friction: [DryViscous; JOINTS],
    /// n k_t per joint (Eq. 5.17).
    torque_per_ampere: [f64; JOINTS],
    dt: f64,
    positions: [DigitalLowPass; JOINTS],
    currents: [DigitalLowPass; JOINTS],
    estimate: Option<TorqueEstimate>,
}

impl TorqueEstimator {
    /// The estimator of a robot (either leg mechanism) at the control period `dt` with the
    /// filter cut-off `cutoff_hz` (3 Hz on AMRU5, [`super::DIGITAL_CUTOFF_HZ`]).
    pub fn new(robot: &Robot, dt: f64, cutoff_hz: f64) -> Self {
        // Section 5.6.2: "a simple dry/viscous model", the unloaded parameters (Table 5.3 on
        // AMRU5; a serial robot's drive friction).
        let parts = robot.parts(&robot.model_options(FrictionModel::DryViscous));
        let friction = std::array::from_fn(|k| match parts.friction[k].law {
            JointFriction::DryViscous(law) => law,
            _ => unreachable!("the parts of FrictionModel::DryViscous"),
        });
        let torque_per_ampere = std::array::from_fn(|k| parts.motors[k].k_t * parts.motors[k].n);
        let dynamics = LegDynamics::from(parts);
        TorqueEstimator {
            data: Data::new(&dynamics.model),
            dynamics,
            friction,
            torque_per_ampere,
            dt,
            positions: [DigitalLowPass::new(cutoff_hz, dt); JOINTS],
            currents: [DigitalLowPass::new(cutoff_hz, dt); JOINTS],
            estimate: None,
        }
    }

    /// The dry/viscous law of each joint (Eq. 6.1), k = 3 leg + j.
    pub fn dry_viscous(&self) -> &[DryViscous; JOINTS] {
        &self.friction
    }

    /// The estimate of the last update.
    pub fn estimate(&self) -> Option<&TorqueEstimate> {
        self.estimate.as_ref()
    }

    /// One control period: filters the measurements, differentiates, and evaluates Eq. 5.14.
    pub fn update(&mut self, m: &Measurements) -> &TorqueEstimate {
        let previous = self.estimate.take();
        let mut e = TorqueEstimate::default();
        for k in 0..JOINTS {
            e.q[k] = self.positions[k].update(m.positions[k]);
            e.measured[k] = self.torque_per_ampere[k] * self.currents[k].update(m.currents[k]);
            if let Some(p) = &previous {
                e.qd[k] = (e.q[k] - p.q[k]) / self.dt;
                e.qdd[k] = (e.qd[k] - p.qd[k]) / self.dt;
            }
            e.friction[k] = self.friction[k].torque(e.qd[k]).0;
        }
        self.inertia_and_gravity(m, &mut e);
        self.estimate = Some(e);
        self.estimate.as_ref().expect("just set")
    }

    /// τ̂_iner + τ̂_grav added to τ̂_fric into `e.estimated`: Eq. 3.37 on the legs with the
    /// body at rest ([`LegDynamics::joint_torques`]), no foot force.
    fn inertia_and_gravity(&mut self, m: &Measurements, e: &mut TorqueEstimate) {
        let body = m.pose.map_or(StillBody::default(), |p| StillBody { pitch: p.pitch, roll: p.roll });
        let tau = self.dynamics.joint_torques(&mut self.data, body, &e.q, &e.qd, &e.qdd, None);
        for k in 0..JOINTS {
            e.estimated[k] = tau[k] + e.friction[k];
        }
    }
}
