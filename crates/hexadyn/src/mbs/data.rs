//! The mutable multibody workspace (Model/Data split).

use nalgebra::{Matrix3, Vector3};

use super::dependent::{DependentValue, Jet};
use super::model::{BodyId, CompiledElementary, Model};
use crate::spatial::{Axis, Htm};

/// Kinematic quantities of every body, their partial velocities and the applied wrenches of
/// one evaluation. Create with [`Data::new`]; fill with [`super::kinematics`].
#[derive(Clone, Debug)]
pub struct Data {
    /// T_{0,i} (Eq. 3.23), but for the turn of a spin about its axis (see `spin`).
    pub(crate) pose: Vec<Htm>,
    /// For the bodies whose joint ends with a spin (see [`super::model::CompiledElementary`]):
    /// its axis and angle at this evaluation, which [`Data::pose`] applies to `pose`.
    pub(crate) spin: Vec<Option<(Axis, f64)>>,
    /// ω_i and v_i in the global frame (Eq. 3.26, 3.33).
    pub(crate) omega: Vec<Vector3<f64>>,
    pub(crate) velocity: Vec<Vector3<f64>>,
    /// Convective accelerations J̇_ω q̇ and J̇_S q̇ (Eq. 3.27, 3.34).
    pub(crate) alpha_bias: Vec<Vector3<f64>>,
    pub(crate) accel_bias: Vec<Vector3<f64>>,
    /// Partial velocities d_ij and δ_ij (Eq. 3.24, 3.31), flat over the bodies' columns; filled
    /// from the relative ones by [`super::partial_velocities`] (`complete` tells when).
    pub(crate) d: Vec<Vector3<f64>>,
    pub(crate) delta: Vec<Vector3<f64>>,
    pub(crate) complete: bool,
    /// Partial velocities of each body relative to its reference body, over the body's own
    /// columns: d_ij = d_pj + δ_pj × (p_i − p_p) + d^rel_ij and δ_ij = δ_pj + δ^rel_ij.
    pub(crate) d_rel: Vec<Vector3<f64>>,
    pub(crate) delta_rel: Vec<Vector3<f64>>,
    /// Work of the residual, per body: the accelerations (linear, angular) proportional to q̈
    /// and the resultant (force, moment at G_i) of the inertia and applied forces of the body
    /// and its descendants.
    pub(crate) qdd_acceleration: Vec<(Vector3<f64>, Vector3<f64>)>,
    pub(crate) subtree: Vec<(Vector3<f64>, Vector3<f64>)>,
    pub(crate) dependents: Vec<DependentValue>,
    /// Resultant applied force R_i and moment M_i at G_i, global frame (Eq. 3.35-3.36),
    /// gravity excluded (added by the equations of motion).
    pub(crate) force: Vec<Vector3<f64>>,
    pub(crate) moment: Vec<Vector3<f64>>,
    /// Generalized forces applied directly on the configuration parameters.
    pub(crate) generalized: Vec<f64>,
    pub(crate) dual_work: Vec<Jet>,
    /// (sin, cos) of each of [`Model::angles`] at this evaluation.
    pub(crate) angles: Vec<(f64, f64)>,
    pub(crate) input_work: (Vec<f64>, Vec<f64>),
}

impl Data {
    pub fn new(model: &Model) -> Self {
        let nb = model.bodies.len();
        let z = Vector3::zeros();
        let mut dependents = vec![DependentValue::default(); model.dependent_count];
        for g in &model.dependents {
            for k in 0..g.function.output_count() {
                dependents[g.first_output + k].gradient = vec![0.0; g.inputs.len()];
            }
        }
        Data {
            pose: vec![Htm::identity(); nb],
            spin: model
                .bodies
                .iter()
                .map(|b| match b.joint.last() {
                    Some(CompiledElementary::Rotation { axis, angle: None, .. }) => Some((*axis, 0.0)),
                    _ => None,
                })
                .collect(),
            omega: vec![z; nb],
            velocity: vec![z; nb],
            alpha_bias: vec![z; nb],
            accel_bias: vec![z; nb],
            d: vec![z; model.column_total],
            delta: vec![z; model.column_total],
            complete: false,
            d_rel: vec![z; model.own_total],
            delta_rel: vec![z; model.own_total],
            qdd_acceleration: vec![(z, z); nb],
            subtree: vec![(z, z); nb],
            dependents,
            force: vec![z; nb],
            moment: vec![z; nb],
            generalized: vec![0.0; model.coordinates],
            dual_work: Vec::new(),
            angles: vec![(0.0, 1.0); model.angles.len()],
            input_work: (Vec::new(), Vec::new()),
        }
    }

    /// T_{0,i}: pose of the body's centre-of-gravity frame.
    pub fn pose(&self, b: BodyId) -> Htm {
        let mut pose = self.pose[b.0];
        if let Some((axis, angle)) = self.spin[b.0] {
            axis.rotate(&mut pose.rotation, angle.sin_cos());
        }
        pose
    }
    pub fn position(&self, b: BodyId) -> Vector3<f64> {
        self.pose[b.0].translation
    }
    pub fn rotation(&self, b: BodyId) -> Matrix3<f64> {
        self.pose(b).rotation
    }
    pub fn velocity(&self, b: BodyId) -> Vector3<f64> {
        self.velocity[b.0]
    }
    pub fn angular_velocity(&self, b: BodyId) -> Vector3<f64> {
        self.omega[b.0]
    }
    /// Value, rate and derivatives of dependent parameter k.
    pub fn dependent(&self, k: usize) -> &DependentValue {
        &self.dependents[k]
    }
    /// Global position of a point given in the body frame.
    pub fn point(&self, b: BodyId, local: &Vector3<f64>) -> Vector3<f64> {
        self.pose(b).apply(local)
    }
    /// Velocity of a material point of body b at global position `p`.
    pub fn point_velocity(&self, b: BodyId, p: &Vector3<f64>) -> Vector3<f64> {
        self.velocity[b.0] + self.omega[b.0].cross(&(p - self.pose[b.0].translation))
    }
    /// Linear acceleration of G_b for the accelerations q̈ (Eq. 3.27).
    pub fn acceleration(&self, model: &Model, b: BodyId, qdd: &[f64]) -> Vector3<f64> {
        self.assert_complete();
        let body = &model.bodies[b.0];
        let mut a = self.accel_bias[b.0];
        for (k, &c) in body.columns.iter().enumerate() {
            a += self.d[body.offset + k] * qdd[c];
        }
        a
    }
    /// Angular acceleration of body b for q̈ (Eq. 3.34).
    pub fn angular_acceleration(&self, model: &Model, b: BodyId, qdd: &[f64]) -> Vector3<f64> {
        self.assert_complete();
        let body = &model.bodies[b.0];
        let mut a = self.alpha_bias[b.0];
        for (k, &c) in body.columns.iter().enumerate() {
            a += self.delta[body.offset + k] * qdd[c];
        }
        a
    }
    /// The non-zero columns of J_S and J_ω of body b: (coordinate j, d_bj, δ_bj).
    pub fn partial_velocities<'a>(&'a self, model: &'a Model, b: BodyId) -> impl Iterator<Item = (usize, Vector3<f64>, Vector3<f64>)> + 'a {
        self.assert_complete();
        let body = &model.bodies[b.0];
        body.columns.iter().enumerate().map(move |(k, &c)| (c, self.d[body.offset + k], self.delta[body.offset + k]))
    }
    /// Partial velocity of a point of body b at global position p: column j of its J_S.
    pub fn point_partial_velocities<'a>(&'a self, model: &'a Model, b: BodyId, p: &Vector3<f64>) -> impl Iterator<Item = (usize, Vector3<f64>)> + 'a {
        let r = p - self.pose[b.0].translation;
        self.partial_velocities(model, b).map(move |(c, d, delta)| (c, d + delta.cross(&r)))
    }

    /// The partial velocity of a point of body b at global position p (column j of its J_S) as
    /// the terms of the joints on its path, Eq. 3.24 summed over b and its ancestors a:
    /// d_pj = Σ_a d^rel_aj + δ^rel_aj × (p − p_a), (coordinate j, term) pairs, a coordinate
    /// possibly in several (the dependent parameters of a pantograph move several of its links).
    /// Needs only [`super::relative_kinematics`].
    pub fn point_partial_velocity_terms<'a>(&'a self, model: &'a Model, b: BodyId, p: Vector3<f64>) -> impl Iterator<Item = (usize, Vector3<f64>)> + 'a {
        std::iter::successors(Some(b.0), move |&a| model.bodies[a].parent).flat_map(move |a| {
            let body = &model.bodies[a];
            let r = p - self.pose[a].translation;
            body.own.iter().enumerate().map(move |(k, &c)| (c, self.d_rel[body.own_offset + k] + self.delta_rel[body.own_offset + k].cross(&r)))
        })
    }

    /// The partial velocities of every body are only available after [`super::kinematics`] or
    /// [`super::partial_velocities`] ([`super::relative_kinematics`] leaves them out).
    pub(crate) fn assert_complete(&self) {
        assert!(self.complete, "partial velocities not computed: call mbs::partial_velocities after mbs::relative_kinematics");
    }

    /// Removes all applied forces (start of an evaluation).
    pub fn clear_forces(&mut self) {
        self.force.iter_mut().for_each(|f| *f = Vector3::zeros());
        self.moment.iter_mut().for_each(|m| *m = Vector3::zeros());
        self.generalized.iter_mut().for_each(|g| *g = 0.0);
    }
    /// Applies force F (global frame) at the global point p of body b (Eq. 3.35-3.36).
    pub fn add_force(&mut self, b: BodyId, p: &Vector3<f64>, f: &Vector3<f64>) {
        self.force[b.0] += f;
        self.moment[b.0] += (p - self.pose[b.0].translation).cross(f);
    }
    /// Applies a pure moment (global frame) on body b.
    pub fn add_moment(&mut self, b: BodyId, m: &Vector3<f64>) {
        self.moment[b.0] += m;
    }
    /// Adds a generalized force on configuration parameter j (a joint torque or force).
    pub fn add_generalized_force(&mut self, j: usize, value: f64) {
        self.generalized[j] += value;
    }
}
