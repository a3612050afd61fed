//! Equations of motion by the virtual power principle (thesis Eq. 3.37-3.41):
//! M(q) q̈ + h(q, q̇) = g(q, q̇, t).

use nalgebra::{DMatrix, Matrix3, Vector3};

use super::data::Data;
use super::model::Model;

/// Residual f = M q̈ + h − g of the multibody rows (Eq. 3.37, 3.38) written into `f[..n]`,
/// without forming M: f_j = Σ_i d_ij·(m_i a_i − R_i) + δ_ij·(Φ_i ω̇_i + ω_i × Φ_i ω_i − M_i) − Q_j.
/// As d_ij, δ_ij sum the relative partial velocities of the joints on the path to body i,
/// each carried rigidly to G_i (d^rel_aj + δ^rel_aj × (p_i − p_a)), the sum is taken joint by
/// joint: f_j = Σ_a d^rel_aj·F_a + δ^rel_aj·M_a − Q_j, with (F_a, M_a) the resultant at G_a of
/// the inertia and applied forces of body a and its descendants. Needs
/// [`super::relative_kinematics`] and the applied forces of this evaluation.
pub fn residual(model: &Model, data: &mut Data, qdd: &[f64], f: &mut [f64]) {
    let n = model.coordinates;
    for j in 0..n {
        f[j] = -data.generalized[j];
    }
    // Accelerations proportional to q̈ (Eq. 3.27, 3.34), from the reference body's.
    for (i, body) in model.bodies.iter().enumerate() {
        let (mut a, mut alpha) = match body.parent {
            Some(p) => {
                let (a, alpha) = data.qdd_acceleration[p];
                (a + alpha.cross(&(data.pose[i].translation - data.pose[p].translation)), alpha)
            }
            None => (Vector3::zeros(), Vector3::zeros()),
        };
        for (k, &c) in body.own.iter().enumerate() {
            a += data.d_rel[body.own_offset + k] * qdd[c];
            alpha += data.delta_rel[body.own_offset + k] * qdd[c];
        }
        data.qdd_acceleration[i] = (a, alpha);
        data.subtree[i] = (Vector3::zeros(), Vector3::zeros());
    }
    // Resultants over the subtrees, descendants first (a body comes after its reference body).
    for (i, body) in model.bodies.iter().enumerate().rev() {
        let (a, alpha) = data.qdd_acceleration[i];
        let lin = (data.accel_bias[i] + a - model.gravity) * body.mass - data.force[i];
        let ang = body.inertia_torque(&data.pose[i].rotation, &data.omega[i], &(data.alpha_bias[i] + alpha)) - data.moment[i];
        let (force, moment) = data.subtree[i];
        let (force, moment) = (force + lin, moment + ang);
        for (k, &c) in body.own.iter().enumerate() {
            f[c] += data.d_rel[body.own_offset + k].dot(&force) + data.delta_rel[body.own_offset + k].dot(&moment);
        }
        if let Some(p) = body.parent {
            let r = data.pose[i].translation - data.pose[p].translation;
            let (pf, pm) = &mut data.subtree[p];
            *pf += force;
            *pm += moment + r.cross(&force);
        }
    }
}

/// Mass and inertia of a body and its descendants about the body's centre of gravity G_b,
/// global frame: mass m, first moment h = Σ m_i (p_i − p_b) and inertia tensor
/// I = Σ Φ_i + m_i (|s_i|² E − s_i s_iᵀ), s_i = p_i − p_b (a composite rigid body).
#[derive(Clone, Copy, Debug)]
struct Composite {
    mass: f64,
    first_moment: Vector3<f64>,
    inertia: Matrix3<f64>,
}

impl Composite {
    /// Adds `c`, given about a point at `r` from G_b (parallel axes: s = r + s_c).
    fn add(&mut self, c: &Composite, r: &Vector3<f64>) {
        let h = c.first_moment;
        let shift = Matrix3::from_diagonal_element(c.mass * r.norm_squared() + 2.0 * r.dot(&h)) - (r * r.transpose()) * c.mass - r * h.transpose() - h * r.transpose();
        self.inertia += c.inertia + shift;
        self.first_moment += h + r * c.mass;
        self.mass += c.mass;
    }

    /// Momentum (linear L, angular H about G_b) of the composite moving rigidly with velocity
    /// v at G_b and angular velocity ω: L = m v + ω × h, H = h × v + I ω.
    fn momentum(&self, v: &Vector3<f64>, omega: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        (v * self.mass + omega.cross(&self.first_moment), self.first_moment.cross(v) + self.inertia * omega)
    }
}

/// Mass matrix M(q) (Eq. 3.39) into the top-left n × n block of `m` (overwritten). Needs
/// [`super::relative_kinematics`]. As d_ij, δ_ij sum the relative partial velocities of the
/// joints a on the path to body i carried rigidly to G_i (see [`residual`]),
/// M_jk = Σ_i m_i d_ij·d_ik + δ_ij·Φ_i δ_ik = Σ_(a, b) d^rel_aj·L_bk + δ^rel_aj·(H_bk + (p_b − p_a) × L_bk)
/// over the bodies b and their ancestors a (b included), (L_bk, H_bk) the momentum at G_b of
/// body b and its descendants moved rigidly by the relative partial velocity of column k of
/// b's joint (composite rigid bodies, the CRBA of Featherstone's Rigid Body Dynamics
/// Algorithms, Section 6.2, on the relative partial velocities).
pub fn mass_matrix(model: &Model, data: &Data, m: &mut DMatrix<f64>) {
    let n = model.coordinates;
    let rows = m.nrows();
    for column in m.as_mut_slice().chunks_mut(rows).take(n) {
        column[..n].fill(0.0);
    }
    let mut composite: Vec<Composite> = model.bodies.iter().enumerate().map(|(i, b)| Composite { mass: b.mass, first_moment: Vector3::zeros(), inertia: b.world_inertia(&data.pose[i].rotation) }).collect();
    // Descendants first (a body comes after its reference body).
    for (i, body) in model.bodies.iter().enumerate().rev() {
        if let Some(p) = body.parent {
            let c = composite[i];
            composite[p].add(&c, &(data.pose[i].translation - data.pose[p].translation));
        }
    }
    for (b, body) in model.bodies.iter().enumerate() {
        let own = |a: &super::model::Body, j: usize| (data.d_rel[a.own_offset + j], data.delta_rel[a.own_offset + j]);
        for (k, &ck) in body.own.iter().enumerate() {
            let (d, delta) = own(body, k);
            let (linear, mut angular) = composite[b].momentum(&d, &delta);
            // a = b: M is symmetric, the pairs j ≥ k give both triangles.
            for (j, &cj) in body.own.iter().enumerate().skip(k) {
                let (dj, deltaj) = own(body, j);
                let x = dj.dot(&linear) + deltaj.dot(&angular);
                m[(cj, ck)] += x;
                if j != k {
                    m[(ck, cj)] += x;
                }
            }
            // The strict ancestors a of b, each pair once in both triangles (twice on the
            // diagonal when a and b share the column: the cross term of (x + y)ᵀ I (x + y)).
            let (mut a, mut at) = (body.parent, data.pose[b].translation);
            while let Some(ai) = a {
                let ancestor = &model.bodies[ai];
                let pa = data.pose[ai].translation;
                angular += (at - pa).cross(&linear);
                at = pa;
                for (j, &cj) in ancestor.own.iter().enumerate() {
                    let (dj, deltaj) = own(ancestor, j);
                    let x = dj.dot(&linear) + deltaj.dot(&angular);
                    m[(cj, ck)] += x;
                    m[(ck, cj)] += x;
                }
                a = ancestor.parent;
            }
        }
    }
}

/// Centrifugal and Coriolis contribution h(q, q̇) (Eq. 3.40).
pub fn nonlinear_effects(model: &Model, data: &Data) -> Vec<f64> {
    data.assert_complete();
    let mut h = vec![0.0; model.coordinates];
    for (i, body) in model.bodies.iter().enumerate() {
        let lin = data.accel_bias[i] * body.mass;
        let ang = body.inertia_torque(&data.pose[i].rotation, &data.omega[i], &data.alpha_bias[i]);
        for (k, &c) in body.columns.iter().enumerate() {
            h[c] += data.d[body.offset + k].dot(&lin) + data.delta[body.offset + k].dot(&ang);
        }
    }
    h
}

/// Applied-force contribution g(q, q̇, t) (Eq. 3.41): gravity, applied wrenches and generalized
/// forces.
pub fn generalized_forces(model: &Model, data: &Data) -> Vec<f64> {
    data.assert_complete();
    let mut g = data.generalized.clone();
    for (i, body) in model.bodies.iter().enumerate() {
        let r = model.gravity * body.mass + data.force[i];
        for (k, &c) in body.columns.iter().enumerate() {
            g[c] += data.d[body.offset + k].dot(&r) + data.delta[body.offset + k].dot(&data.moment[i]);
        }
    }
    g
}

/// Kinetic energy ½ Σ (m_i v_i² + ω_i·Φ_i ω_i).
pub fn kinetic_energy(model: &Model, data: &Data) -> f64 {
    model
        .bodies
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let w = data.omega[i];
            0.5 * b.mass * data.velocity[i].norm_squared() + b.rotational_energy(&data.pose[i].rotation, &w)
        })
        .sum()
}

/// Gravitational potential energy −Σ m_i g·p_i.
pub fn potential_energy(model: &Model, data: &Data) -> f64 {
    model.bodies.iter().enumerate().map(|(i, b)| -b.mass * model.gravity.dot(&data.pose[i].translation)).sum()
}

