//! The slowly varying part of the robot's Jacobian (`System::jacobian`): the multibody rows'
//! derivatives with the contact and joint forces held at their values (inertia, gravity and the
//! geometry of the points the forces act at), the foot velocities' derivatives and the mass
//! matrix, taken by differences at a configuration and kept while it moves little.

use nalgebra::{DMatrix, Vector3};

use super::Robot;
use crate::hexapod::{JointKind, LegJoints, DOF, JOINTS};
use crate::mbs;
use crate::sim::zero_matrix;

/// ∂/∂q and ∂/∂q' of the multibody rows with the contact forces and joint forces held at their
/// values (inertia, gravity and the geometry of the points the forces act at), and the
/// derivatives of the foot velocities with respect to q, by central differences.
#[derive(Clone, Debug)]
pub(super) struct InertialJacobian {
    q: Vec<f64>,
    pub(super) kt: DMatrix<f64>,
    pub(super) ct: DMatrix<f64>,
    /// ∂v_foot/∂q per foot (3 × 24).
    pub(super) dv_dq: Vec<nalgebra::Matrix3xX<f64>>,
    /// The mass matrix of the multibody rows (Eq. 3.39): it changes with the configuration as
    /// slowly as the terms above (2 % fewer instructions on the 75 s LuGre walk than taking it
    /// at every Jacobian, the Newton iterations the same to 0.1 %).
    pub(super) mass: DMatrix<f64>,
}

impl InertialJacobian {
    /// Whether the configuration moved little enough since it was taken: 0.2 rad on the body
    /// attitude and on the revolute joints (AMRU5's q_r), 2 cm on the prismatic ones (AMRU5's
    /// nuts, about a third of their strokes). The body
    /// position does not matter: inertia and gravity do not change with a translation. These
    /// terms are small beside the contact and motor terms, which are exact at every call:
    /// benches/walk counts the same Newton iterations with this part re-taken every 10 mrad and
    /// 1 mm, at twice the cost.
    pub(super) fn holds_at(&self, q: &[f64], joints: &LegJoints) -> bool {
        (3..DOF).all(|i| {
            let tolerance = if i < 6 || joints.kind((i - 6) % 3) == JointKind::Revolute { 0.2 } else { 0.02 };
            (q[i] - self.q[i]).abs() <= tolerance
        })
    }
}

impl Robot {
    /// Multibody rows with the contact and joint forces frozen at `contact` and `joint`
    /// (generalized joint forces), and the foot velocities.
    #[allow(clippy::too_many_arguments)] // the state (q, q', q''), the two frozen forces, two outputs
    fn frozen_residual(&mut self, q: &[f64], qd: &[f64], qdd: &[f64], contact: &[Vector3<f64>; 6], joint: &[f64; JOINTS], f: &mut [f64], feet: &mut [Vector3<f64>; 6]) {
        self.kinematics(q, qd);
        self.data.clear_forces();
        for (leg, (body, point)) in self.model.feet.iter().enumerate() {
            let p = self.data.point(*body, point);
            feet[leg] = self.data.point_velocity(*body, &p);
            self.data.add_force(*body, &p, &contact[leg]);
        }
        for (k, tau) in joint.iter().enumerate() {
            self.data.add_generalized_force(6 + k, *tau);
        }
        mbs::residual(&self.model.multibody, &mut self.data, &qdd[..DOF], &mut f[..DOF]);
    }

    /// Forward differences of [`Self::frozen_residual`] over q and q' (Eq. 3.12): an iteration
    /// matrix only needs the first digits, and one evaluation per column halves the cost of
    /// central differences.
    pub(super) fn inertial_jacobian(&mut self, q: &[f64], qd: &[f64], qdd: &[f64]) -> InertialJacobian {
        self.evaluate(q, qd, qdd);
        let contact = self.outputs.contact.map(|c| c.force);
        let joint: [f64; JOINTS] = self.outputs.joint_force;
        let scales = self.model.layout.scales.clone();
        let mut mass = zero_matrix(DOF, DOF);
        mbs::mass_matrix(&self.model.multibody, &self.data, &mut mass);
        let mut jac = InertialJacobian { q: q.to_vec(), kt: zero_matrix(DOF, DOF), ct: zero_matrix(DOF, DOF), dv_dq: vec![nalgebra::Matrix3xX::zeros(DOF); 6], mass };
        let (mut f0, mut fp) = (vec![0.0; DOF], vec![0.0; DOF]);
        let (mut v0, mut vp) = ([Vector3::zeros(); 6], [Vector3::zeros(); 6]);
        self.frozen_residual(q, qd, qdd, &contact, &joint, &mut f0, &mut v0);
        let (mut x, mut xd) = (q.to_vec(), qd.to_vec());
        for j in 0..DOF {
            let step = 1e-6 * x[j].abs().max(1e3 * scales[j]);
            x[j] = q[j] + step;
            self.frozen_residual(&x, qd, qdd, &contact, &joint, &mut fp, &mut vp);
            x[j] = q[j];
            for i in 0..DOF {
                jac.kt[(i, j)] = (fp[i] - f0[i]) / step;
            }
            for leg in 0..6 {
                jac.dv_dq[leg].set_column(j, &((vp[leg] - v0[leg]) / step));
            }
            let step = 1e-6 * xd[j].abs().max(1e2 * scales[j]);
            xd[j] = qd[j] + step;
            self.frozen_residual(q, &xd, qdd, &contact, &joint, &mut fp, &mut vp);
            xd[j] = qd[j];
            for i in 0..DOF {
                jac.ct[(i, j)] = (fp[i] - f0[i]) / step;
            }
        }
        jac
    }

}
