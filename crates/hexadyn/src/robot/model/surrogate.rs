//! The robot's surrogate residual (`System::surrogate_residual`): the kinematics held at the last
//! evaluation of f, the force laws (ground contact, joint friction, motors) exact at the feet
//! moved to first order, for the Newton iterations between two evaluations of f
//! (`Newmark::iterate_on_surrogate`, `NewmarkOptions::surrogate_iterations`: 8 on the robot by
//! default) and the reset of q'' after each control instant's input jump
//! (`Newmark::reset_accelerations_after_input_jump`).

use nalgebra::{SMatrix, SVector, Vector3};

use super::{Foot, Robot};
use crate::hexapod::{joint_index, DOF, JOINTS};
use crate::physics::Proximity;

/// The coordinates a foot moves with: the body's six and its leg's three.
const FOOT_COORDINATES: usize = 9;

/// J_foot of one foot point (3 × 24, Eq. 3.24 for a point) on the [`FOOT_COORDINATES`] columns
/// it can have non-zero, those of the body's six coordinates and of its leg's three joints
/// (Eq. 3.51): the other legs' joints do not move it. The products with J_foot and J_footᵀ of a
/// surrogate evaluation are then 3 × 9 instead of 3 × 24.
#[derive(Clone, Copy, Debug)]
struct FootJacobian {
    leg: usize,
    j: SMatrix<f64, 3, FOOT_COORDINATES>,
}

impl FootJacobian {
    /// Column of coordinate `c` (0 to 23).
    fn column(&self, c: usize) -> usize {
        if c < 6 {
            c
        } else {
            debug_assert!((joint_index(self.leg, 0)..joint_index(self.leg, 3)).contains(&c), "foot {} moved by coordinate {c}", self.leg);
            6 + c - joint_index(self.leg, 0)
        }
    }

    /// The coordinates of the columns.
    fn coordinates(&self) -> [usize; FOOT_COORDINATES] {
        std::array::from_fn(|k| if k < 6 { k } else { joint_index(self.leg, k - 6) })
    }

    /// J_foot Δx.
    fn times(&self, dx: &SVector<f64, DOF>) -> Vector3<f64> {
        let c = self.coordinates();
        self.j * SVector::<f64, FOOT_COORDINATES>::from_fn(|k, _| dx[c[k]])
    }

    /// rows ← rows − J_footᵀ ΔF.
    fn subtract_transpose_times(&self, force: &Vector3<f64>, rows: &mut SVector<f64, DOF>) {
        let product = self.j.tr_mul(force);
        for (k, c) in self.coordinates().into_iter().enumerate() {
            rows[c] -= product[k];
        }
    }
}

/// What [`crate::sim::System::surrogate_residual`] expands about: an evaluation of the residual (q0, q'0,
/// q''0, the multibody rows f0) with its foot states, contact forces and joint forces. Between
/// two Newton iterates of a step q moves by βh² Δq'' and q' by γh Δq'' (Eq. 3.7-3.8), tiny
/// beside the scales the kinematics change over, but the force laws are stiff and non-smooth
/// in the same small moves (Hertz contact and its friction's linear zone, Eq. 3.72-3.73; the
/// LuGre bristles, Eq. 3.85; the dry friction's regularisation, Eq. 6.1).
#[derive(Clone, Debug)]
pub(super) struct Surrogate {
    q: [f64; DOF],
    qd: [f64; DOF],
    qdd: [f64; DOF],
    f: [f64; DOF],
    /// Position, velocity and ground proximity of each foot.
    feet: [Foot; 6],
    /// Contact force on each foot and joint force of each joint (τ_m − τ_f, or a series spring's).
    contact: [Vector3<f64>; 6],
    joint: [f64; JOINTS],
    /// The feet's J_foot, taken at the first surrogate evaluation (an evaluation whose Newton
    /// correction passes has none).
    j_foot: Option<[FootJacobian; 6]>,
}

impl Robot {
    /// [`crate::sim::System::keep_surrogate_base`]: the evaluation at (q, q') as the base, when a Jacobian
    /// has left a mass matrix to expand with.
    pub(super) fn keep_base(&mut self, q: &[f64], qd: &[f64], qdd: &[f64], f: &[f64]) -> bool {
        let evaluated = self.kinematics_at.as_ref().is_some_and(|(q0, qd0)| q0[..] == q[..DOF] && qd0[..] == qd[..DOF]);
        let (Some(feet), Some(_), true) = (self.feet, &self.inertial, evaluated) else { return false };
        let o = &self.outputs;
        let array = |x: &[f64]| -> [f64; DOF] { x[..DOF].try_into().expect("DOF coordinates") };
        self.surrogate = Some(Box::new(Surrogate {
            q: array(q),
            qd: array(qd),
            qdd: array(qdd),
            f: array(f),
            feet,
            contact: o.contact.map(|c| c.force),
            joint: o.joint_force,
            j_foot: None,
        }));
        true
    }

    /// The surrogate of the residual about `base` (see [`crate::sim::System::surrogate_residual`]): the force
    /// laws exact at the feet moved by J_foot Δq and J_foot Δq' (the ground's proximity to first
    /// order in the move, the mesh not searched again), the multibody rows
    /// f0 + M Δq'' − Σ J_footᵀ ΔF − Δτ (Eq. 3.37 with M the kept mass matrix of the Jacobian and
    /// the kinematics held at the base), the rows of the states exact.
    pub(super) fn write_surrogate(&mut self, base: &mut Surrogate, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
        if base.j_foot.is_none() {
            self.kinematics(&base.q, &base.qd);
            let m = &self.model;
            base.j_foot = Some(std::array::from_fn(|leg| {
                let mut foot = FootJacobian { leg, j: SMatrix::zeros() };
                for (c, d) in self.data.point_partial_velocity_terms(&m.multibody, m.feet[leg].0, base.feet[leg].position) {
                    let mut column = foot.j.column_mut(foot.column(c));
                    column += d;
                }
                foot
            }));
        }
        let j_foot = base.j_foot.as_ref().expect("taken above");
        let change = |x: &[f64], x0: &[f64; DOF]| SVector::<f64, DOF>::from_fn(|i, _| x[i] - x0[i]);
        let (dq, dqd, dqdd) = (change(q, &base.q), change(qd, &base.qd), change(qdd, &base.qdd));
        let feet: [Foot; 6] = std::array::from_fn(|leg| {
            let Foot { position, velocity, proximity: p } = base.feet[leg];
            let dp = j_foot[leg].times(&dq);
            let proximity = Proximity {
                penetration: p.penetration + p.penetration_gradient.dot(&dp),
                normal: p.normal + p.normal_jacobian * dp,
                penetration_gradient: p.penetration_gradient + p.penetration_hessian * dp,
                ..p
            };
            Foot { position: position + dp, velocity: velocity + j_foot[leg].times(&dqd), proximity }
        });
        self.force_laws(q, qd, qdd, &feet);
        let mut rows = SVector::<f64, DOF>::from_column_slice(&base.f);
        if let Some(inertial) = &self.inertial {
            rows.gemv(1.0, &inertial.mass, &dqdd, 1.0);
        }
        for (leg, j) in j_foot.iter().enumerate() {
            j.subtract_transpose_times(&(self.outputs.contact[leg].force - base.contact[leg]), &mut rows);
        }
        for k in 0..JOINTS {
            rows[6 + k] -= self.outputs.joint_force[k] - base.joint[k];
        }
        f[..DOF].copy_from_slice(rows.as_slice());
        self.write_state_rows(q, qd, qdd, f);
    }
}
