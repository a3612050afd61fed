//! The joint torques one leg needs on a still body: the gravity, inertia, Coriolis and
//! centrifugal terms of Eq. 3.37 applied to the hexapod's multibody model, either leg mechanism
//! (τ_grav + τ_iner of Eq. 5.14). The friction identification removes τ_grav from the measured
//! motor torques (Section 5.2.1, Eq. 5.7) and the ground detection estimates both (Section
//! 5.6.2, Fig. 5.12).

use super::{joint_index, Mechanics, DOF, JOINTS, LEG_COUNT};
use nalgebra::Vector3;

use crate::mbs::{relative_kinematics, residual, BodyId, Data, Model};

/// The body at rest under the legs of [`LegDynamics::joint_torques`]: its pitch and roll (rad,
/// Eq. 3.52), which set the direction of gravity in the body frame; `StillBody::default()` is
/// level.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StillBody {
    pub pitch: f64,
    pub roll: f64,
}

/// A hexapod's multibody model on the coordinates of Eq. 3.51 with its feet, whatever the legs
/// (AMRU5's 49 bodies, [`Mechanics`]; serial legs, [`super::SerialMechanics`]), rotors included:
/// what the joint torques on a still body need.
#[derive(Clone, Debug)]
pub struct LegDynamics {
    pub model: Model,
    /// Each foot: its body and the foot point in that body's frame.
    pub feet: [(BodyId, Vector3<f64>); LEG_COUNT],
}

impl From<Mechanics> for LegDynamics {
    fn from(m: Mechanics) -> Self {
        LegDynamics { feet: std::array::from_fn(|leg| (m.legs[leg].links[3], m.foot_local)), model: m.model }
    }
}

impl LegDynamics {
    /// The generalized forces (Nm for a revolute joint, N for a prismatic one; joint
    /// k = 3 leg + j) the motors must apply for the legs to follow (q, q', q'') = (`q`, `qd`, `qdd`) with
    /// the body at rest at the attitude `body` and the forces `foot_forces` (global frame, N) on
    /// the feet: the joint rows of the multibody residual M q̈ + h − g (Eq. 3.37, 3.38) without
    /// applied joint forces, i.e. τ_grav + τ_iner of Eq. 5.14. The rotors are part of the legs
    /// (their inertia counts in q'').
    pub fn joint_torques(
        &self,
        data: &mut Data,
        body: StillBody,
        q: &[f64; JOINTS],
        qd: &[f64; JOINTS],
        qdd: &[f64; JOINTS],
        foot_forces: Option<&[Vector3<f64>; LEG_COUNT]>,
    ) -> [f64; JOINTS] {
        let (mut x, mut xd, mut xdd) = ([0.0; DOF], [0.0; DOF], [0.0; DOF]);
        (x[4], x[5]) = (body.pitch, body.roll);
        x[joint_index(0, 0)..].copy_from_slice(q);
        xd[joint_index(0, 0)..].copy_from_slice(qd);
        xdd[joint_index(0, 0)..].copy_from_slice(qdd);
        relative_kinematics(&self.model, data, &x, &xd);
        data.clear_forces();
        for (&(foot, local), force) in self.feet.iter().zip(foot_forces.into_iter().flatten()) {
            let p = data.point(foot, &local);
            data.add_force(foot, &p, force);
        }
        let mut f = [0.0; DOF];
        residual(&self.model, data, &xdd, &mut f);
        std::array::from_fn(|k| f[joint_index(0, 0) + k])
    }

    /// The centre of mass of the whole robot in the body frame with the joints at `q` (joint
    /// k = 3 leg + j): Σ m_i p_i / Σ m_i over the bodies of the model, whose frames end at their
    /// centres of gravity (Eq. 3.23), the body frame at the origin.
    pub fn centre_of_mass(&self, data: &mut Data, q: &[f64; JOINTS]) -> Vector3<f64> {
        let mut x = [0.0; DOF];
        x[joint_index(0, 0)..].copy_from_slice(q);
        relative_kinematics(&self.model, data, &x, &[0.0; DOF]);
        let (weighted, mass) = (0..self.model.bodies.len()).map(BodyId).fold((Vector3::zeros(), 0.0), |(w, m), b| {
            let mass = self.model.body_mass(b);
            (w + data.position(b) * mass, m + mass)
        });
        weighted / mass
    }

    /// [`Self::joint_torques`] of one `leg` on a still, level body, the force `foot_force`
    /// (global frame, N) on its foot. Every leg is put in the same configuration (a closed
    /// pantograph needs a valid one), which does not change the rows of `leg`: with the body
    /// still, a leg's rows see only its own bodies.
    pub fn leg_joint_torques(&self, data: &mut Data, leg: usize, q: [f64; 3], qd: [f64; 3], qdd: [f64; 3], foot_force: Vector3<f64>) -> [f64; 3] {
        assert!(leg < LEG_COUNT, "leg {leg} of a hexapod");
        let every_leg_at_q: [f64; JOINTS] = std::array::from_fn(|k| q[k % 3]);
        let only_leg = |v: [f64; 3]| -> [f64; JOINTS] { std::array::from_fn(|k| if k / 3 == leg { v[k % 3] } else { 0.0 }) };
        let mut forces = [Vector3::zeros(); LEG_COUNT];
        forces[leg] = foot_force;
        let tau = self.joint_torques(data, StillBody::default(), &every_leg_at_q, &only_leg(qd), &only_leg(qdd), Some(&forces));
        std::array::from_fn(|j| tau[3 * leg + j])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::RobotDescription;
    use crate::hexapod::MechanicsParameters;
    use crate::mbs::STANDARD_GRAVITY;

    fn amru5() -> (Mechanics, LegDynamics, Data) {
        let mech = Mechanics::new(&MechanicsParameters::from_description(
            &RobotDescription::amru5(),
        ))
        .unwrap();
        let data = Data::new(&mech.model);
        (mech.clone(), mech.into(), data)
    }

    /// Virtual work: at rest, the gravity torque of q_v is the weight of the leg's moving
    /// parts times the vertical speed of their centres of mass per unit q'_v, which a finite
    /// difference of the potential energy gives independently of the residual.
    #[test]
    fn gravity_torque_is_the_gradient_of_the_potential_energy() {
        let (mech, dynamics, mut data) = amru5();
        let q = [0.1, 0.055, 0.03];
        let tau = dynamics.leg_joint_torques(&mut data, 2, q, [0.0; 3], [0.0; 3], Vector3::zeros());
        let potential = |q: [f64; 3], data: &mut Data| {
            let mut x = [0.0; DOF];
            for l in 0..LEG_COUNT {
                for j in 0..3 {
                    x[joint_index(l, j)] = q[j];
                }
            }
            relative_kinematics(&mech.model, data, &x, &[0.0; DOF]);
            let leg = &mech.legs[2];
            leg.links
                .iter()
                .chain(leg.rotors.iter())
                .chain(std::iter::once(&leg.chassis))
                .map(|&b| mech.model.bodies[b.0].mass * STANDARD_GRAVITY * data.position(b).z)
                .sum::<f64>()
        };
        for j in 0..3 {
            let h = 1e-6;
            let (mut qp, mut qm) = (q, q);
            qp[j] += h;
            qm[j] -= h;
            let dv = (potential(qp, &mut data) - potential(qm, &mut data)) / (2.0 * h);
            assert!(
                (tau[j] - dv).abs() <= 1e-6 * dv.abs().max(1.0),
                "joint {j}: {} vs dV/dq {dv}",
                tau[j]
            );
        }
        // Section 5.2.1: no gravity torque on q_r of a level body.
        assert!(tau[0].abs() < 1e-9);
    }

    /// The centre of mass against two independent facts: the legs are equally distributed
    /// around the body (Section 2.3, Fig. 2.14), so with every leg at the same joints it lies
    /// on the body's z axis; and at rest the gravity torque of every joint is M g ∂z_G/∂q
    /// (virtual work), which the residual gives without the centre of mass. One leg swung
    /// outwards moves it towards that leg by that leg's share of the mass.
    #[test]
    fn centre_of_mass_is_on_the_axis_of_a_symmetric_stance_and_its_height_gives_the_gravity_torques() {
        let (mech, dynamics, mut data) = amru5();
        let q: [f64; JOINTS] = std::array::from_fn(|k| [0.1, 0.055, 0.03][k % 3]);
        let g = dynamics.centre_of_mass(&mut data, &q);
        assert!(g.xy().norm() < 1e-12, "symmetric stance: {g}");
        let mass = mech.model.total_mass();
        let asym: [f64; JOINTS] = std::array::from_fn(|k| [0.1, 0.055, 0.03][k % 3] + 0.0005 * k as f64);
        let tau = dynamics.joint_torques(&mut data, StillBody::default(), &asym, &[0.0; JOINTS], &[0.0; JOINTS], None);
        for k in 0..JOINTS {
            let h = 1e-6;
            let (mut qp, mut qm) = (asym, asym);
            qp[k] += h;
            qm[k] -= h;
            let dz = (dynamics.centre_of_mass(&mut data, &qp).z - dynamics.centre_of_mass(&mut data, &qm).z) / (2.0 * h);
            let expected = mass * STANDARD_GRAVITY * dz;
            assert!((tau[k] - expected).abs() <= 1e-6 * expected.abs().max(1.0), "joint {k}: {} vs M g dz_G/dq {expected}", tau[k]);
        }
        // q_h of leg 0 (front left, Fig. 2.14) out by 5 cm: the centre of mass moves forwards
        // and to the left, by less than the leg's share of the mass times the foot's motion
        // (about 6 q_h, the pantograph's amplification).
        let mut out = q;
        out[joint_index(0, 2) - joint_index(0, 0)] += 0.05;
        let moved = dynamics.centre_of_mass(&mut data, &out) - g;
        let leg = &mech.legs[0];
        let leg_mass: f64 = leg.links.iter().chain(leg.rotors.iter()).map(|&b| mech.model.body_mass(b)).sum();
        assert!(moved.x > 1e-3 && moved.y > 1e-4 && moved.norm() < 6.0 * 0.05 * leg_mass / mass, "{moved}");
    }

    /// A vertical force F on the foot needs the torques −(∂z_foot/∂q) F: about 6 F on q_v
    /// (z_foot ≈ −6 q_v, Eq. B.2; the thesis' "pantograph amplification", Section 5.3).
    #[test]
    fn foot_force_is_balanced_through_the_pantograph() {
        let (_, dynamics, mut data) = amru5();
        let q = [0.0, 0.05, 0.03];
        let free = dynamics.leg_joint_torques(&mut data, 1, q, [0.0; 3], [0.0; 3], Vector3::zeros());
        let loaded = dynamics.leg_joint_torques(&mut data,
            1,
            q,
            [0.0; 3],
            [0.0; 3],
            Vector3::new(0.0, 0.0, 98.1),
        );
        let ratio = (loaded[1] - free[1]) / 98.1;
        assert!((ratio - 6.0).abs() < 0.1, "q_v amplification {ratio}");
    }

    /// Inertia: the torques are linear in q'' at rest, and the same for every leg.
    #[test]
    fn torques_are_linear_in_the_acceleration_and_alike_for_all_legs() {
        let (_, dynamics, mut data) = amru5();
        let q = [-0.2, 0.05, 0.02];
        let g = dynamics.leg_joint_torques(&mut data, 0, q, [0.0; 3], [0.0; 3], Vector3::zeros());
        let a = dynamics.leg_joint_torques(&mut data,
            0,
            q,
            [0.0; 3],
            [0.3, 0.01, 0.02],
            Vector3::zeros(),
        );
        let b = dynamics.leg_joint_torques(&mut data,
            0,
            q,
            [0.0; 3],
            [0.6, 0.02, 0.04],
            Vector3::zeros(),
        );
        for j in 0..3 {
            assert!(
                ((b[j] - g[j]) - 2.0 * (a[j] - g[j])).abs() < 1e-9 * (b[j] - g[j]).abs().max(1e-9)
            );
            assert!((a[j] - g[j]).abs() > 0.0);
        }
        for leg in 1..LEG_COUNT {
            let other = dynamics.leg_joint_torques(&mut data,
                leg,
                q,
                [0.0; 3],
                [0.3, 0.01, 0.02],
                Vector3::zeros(),
            );
            for j in 0..3 {
                assert!((other[j] - a[j]).abs() < 1e-9 * a[j].abs().max(1.0));
            }
        }
    }

    /// A serial leg (the PhantomX's): a force F on the foot needs the torques −J^T F, J the
    /// Jacobian of the leg's own kinematics (Eq. 7.8, [`crate::hexapod::SerialLegKinematics`],
    /// an implementation apart from the multibody model) by finite differences, and the
    /// gravity torques are the gradient of the potential energy of the leg's links.
    #[test]
    fn a_serial_leg_balances_its_foot_force_through_its_own_jacobian() {
        use crate::description::{Robot, SHIPPED_ROBOTS};
        use crate::hexapod::{Leg, LegChain, SerialLegKinematics};
        let (_, text, origin) = SHIPPED_ROBOTS[1];
        let Robot::Serial(robot) = Robot::from_str(text, origin).unwrap() else { panic!("a serial robot") };
        let dynamics = Robot::Serial(robot.clone()).leg_dynamics();
        let mut data = Data::new(&dynamics.model);
        let legs = SerialLegKinematics::hexapod(&robot.hexapod.legs).unwrap();
        let q = [0.1, 0.4, -1.1];
        let f = Vector3::new(1.5, -0.7, 4.0);
        for (leg, kinematics) in legs.iter().enumerate() {
            let free = dynamics.leg_joint_torques(&mut data, leg, q, [0.0; 3], [0.0; 3], Vector3::zeros());
            let loaded = dynamics.leg_joint_torques(&mut data, leg, q, [0.0; 3], [0.0; 3], f);
            let h = 1e-7;
            for j in 0..3 {
                let (mut a, mut b) = (Vector3::from(q), Vector3::from(q));
                a[j] += h;
                b[j] -= h;
                // dp/dq_j of the foot in the body frame (level, at rest: the global axes).
                let dp = (kinematics.to_body(&kinematics.foot(&a)) - kinematics.to_body(&kinematics.foot(&b))) / (2.0 * h);
                let expected = -dp.dot(&f);
                assert!((loaded[j] - free[j] - expected).abs() < 1e-6 * f.norm(), "leg {leg} joint {j}: {} vs {expected}", loaded[j] - free[j]);
            }
            let potential = |q: [f64; 3], data: &mut Data| {
                let x: [f64; DOF] = std::array::from_fn(|i| if i >= 6 { q[(i - 6) % 3] } else { 0.0 });
                relative_kinematics(&dynamics.model, data, &x, &[0.0; DOF]);
                (0..dynamics.model.bodies.len()).filter(|&b| dynamics.model.bodies[b].name.starts_with(&format!("leg{leg}."))).map(|b| dynamics.model.bodies[b].mass * STANDARD_GRAVITY * data.position(crate::mbs::BodyId(b)).z).sum::<f64>()
            };
            for j in 0..3 {
                let (mut qp, mut qm) = (q, q);
                qp[j] += 1e-6;
                qm[j] -= 1e-6;
                let dv = (potential(qp, &mut data) - potential(qm, &mut data)) / 2e-6;
                assert!((free[j] - dv).abs() <= 1e-6 * dv.abs().max(1e-3), "leg {leg} joint {j}: {} vs dV/dq {dv}", free[j]);
            }
        }
    }
}
