//! A multibody system as a [`crate::sim::System`].

use super::{mass_matrix, partial_velocities, relative_kinematics, residual, Data, Model};
use crate::sim::{finite_difference_jacobian, Jacobian, Layout, Order, System};

/// Applied forces of a multibody system, evaluated after the kinematics of each evaluation
/// (the AddAppliedEfforts routine of EasyDyn, Section 3.3.3). Gravity is added by the model.
pub trait AppliedForces: Send {
    fn apply(&mut self, model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64]);
}

/// No applied force besides gravity.
impl AppliedForces for () {
    fn apply(&mut self, _: &Model, _: &mut Data, _: f64, _: &[f64], _: &[f64]) {}
}

impl<F: FnMut(&Model, &mut Data, f64, &[f64], &[f64]) + Send> AppliedForces for F {
    fn apply(&mut self, model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64]) {
        self(model, data, t, q, qd)
    }
}

/// The residual of Eq. 3.38 for a pure multibody system with applied forces `A`.
pub struct MultibodySystem<A: AppliedForces = ()> {
    pub model: Model,
    pub data: Data,
    pub forces: A,
    layout: Layout,
}

impl<A: AppliedForces> MultibodySystem<A> {
    /// `scale`: the size of the coordinates for the error estimate (e.g. 1e-3 for mm-level
    /// accuracy on metres and milliradians).
    pub fn new(model: Model, forces: A, scale: f64) -> Self {
        let mut layout = Layout::default();
        for j in 0..model.coordinate_count() {
            layout.push(format!("q[{j}]"), Order::Second, scale, "multibody");
        }
        let data = Data::new(&model);
        MultibodySystem { model, data, forces, layout }
    }

    /// Kinematics (relative partial velocities only, see [`relative_kinematics`]) and applied
    /// forces at (t, q, q̇).
    pub fn evaluate(&mut self, t: f64, q: &[f64], qd: &[f64]) {
        relative_kinematics(&self.model, &mut self.data, q, qd);
        self.data.clear_forces();
        self.forces.apply(&self.model, &mut self.data, t, q, qd);
    }
}

impl<A: AppliedForces> System for MultibodySystem<A> {
    fn layout(&self) -> &Layout {
        &self.layout
    }
    fn residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
        self.evaluate(t, q, qd);
        residual(&self.model, &mut self.data, qdd, f);
    }
    /// M exact (Eq. 3.39); CT and KT by finite differences (the inertia and applied-force
    /// terms depend on q through the whole kinematics).
    fn jacobian(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], jac: &mut Jacobian) -> bool {
        let fd = finite_difference_jacobian(self, t, q, qd, qdd);
        jac.ct = fd.ct;
        jac.kt = fd.kt;
        self.evaluate(t, q, qd);
        partial_velocities(&self.model, &mut self.data);
        mass_matrix(&self.model, &self.data, &mut jac.m);
        true
    }
}
