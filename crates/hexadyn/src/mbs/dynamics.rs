//! Equations of motion by the virtual power principle (thesis Eq. 3.37-3.41):
//! M(q) q̈ + h(q, q̇) = g(q, q̇, t).

use nalgebra::{DMatrix, Vector3};

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
        let phi = data.world_inertia[i];
        let w = data.omega[i];
        let lin = (data.accel_bias[i] + a - model.gravity) * body.mass - data.force[i];
        let ang = phi * (data.alpha_bias[i] + alpha) + w.cross(&(phi * w)) - data.moment[i];
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

/// Mass matrix M(q) (Eq. 3.39) into the top-left n × n block of `m` (overwritten). Needs the
/// partial velocities ([`super::kinematics`], or [`super::partial_velocities`] after
/// [`super::relative_kinematics`]).
pub fn mass_matrix(model: &Model, data: &Data, m: &mut DMatrix<f64>) {
    data.assert_complete();
    let n = model.coordinates;
    m.view_mut((0, 0), (n, n)).fill(0.0);
    for (i, body) in model.bodies.iter().enumerate() {
        let cols = &body.columns;
        let d = &data.d[body.offset..body.offset + cols.len()];
        let delta = &data.delta[body.offset..body.offset + cols.len()];
        let phi = data.world_inertia[i];
        for (k, &ck) in cols.iter().enumerate() {
            let md = d[k] * body.mass;
            let pd = phi * delta[k];
            for (l, &cl) in cols.iter().enumerate().skip(k) {
                m[(ck, cl)] += md.dot(&d[l]) + pd.dot(&delta[l]);
            }
        }
    }
    for r in 0..n {
        for c in 0..r {
            m[(r, c)] = m[(c, r)];
        }
    }
    // Columns were visited in sorted order, so (ck <= cl) and the upper triangle is complete.
}

/// Centrifugal and Coriolis contribution h(q, q̇) (Eq. 3.40).
pub fn nonlinear_effects(model: &Model, data: &Data) -> Vec<f64> {
    data.assert_complete();
    let mut h = vec![0.0; model.coordinates];
    for (i, body) in model.bodies.iter().enumerate() {
        let phi = data.world_inertia[i];
        let w = data.omega[i];
        let lin = data.accel_bias[i] * body.mass;
        let ang = phi * data.alpha_bias[i] + w.cross(&(phi * w));
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
            0.5 * (b.mass * data.velocity[i].norm_squared() + w.dot(&(data.world_inertia[i] * w)))
        })
        .sum()
}

/// Gravitational potential energy −Σ m_i g·p_i.
pub fn potential_energy(model: &Model, data: &Data) -> f64 {
    model.bodies.iter().enumerate().map(|(i, b)| -b.mass * model.gravity.dot(&data.pose[i].translation)).sum()
}

