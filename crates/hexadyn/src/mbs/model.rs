//! The immutable multibody description.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use super::dependent::{DependentFunction, MAX_INPUTS};
use crate::spatial::{Axis, Htm};

/// Index of a body in its [`Model`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BodyId(pub usize);

/// A scalar variable of an elementary transform: `scale * source + offset`, the source being a
/// configuration parameter q_j or a dependent parameter p_k.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Var {
    pub source: Source,
    pub scale: f64,
    pub offset: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    Coordinate(usize),
    Dependent(usize),
}

impl Var {
    /// q_j.
    pub fn q(j: usize) -> Var {
        Var { source: Source::Coordinate(j), scale: 1.0, offset: 0.0 }
    }
    /// p_k (index returned by [`ModelBuilder::add_dependent`] plus the output number).
    pub fn p(k: usize) -> Var {
        Var { source: Source::Dependent(k), scale: 1.0, offset: 0.0 }
    }
    pub fn scaled(mut self, s: f64) -> Var {
        self.scale *= s;
        self.offset *= s;
        self
    }
    pub fn plus(mut self, c: f64) -> Var {
        self.offset += c;
        self
    }
}

/// One factor of a body's HTM relative to its reference body (Appendix A).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Elementary {
    /// A constant HTM.
    Fixed(Htm),
    /// T^R about a unit axis of the current frame by the angle `var` (Eq. A.2-A.4).
    Rotation { axis: Vector3<f64>, var: Var },
    /// T^d along a unit axis of the current frame by the length `var` (Eq. A.1).
    Translation { axis: Vector3<f64>, var: Var },
}

impl Elementary {
    /// Constant T^d(x, y, z).
    pub fn offset(x: f64, y: f64, z: f64) -> Self {
        Elementary::Fixed(Htm::displacement(x, y, z))
    }
    pub fn rx(var: Var) -> Self {
        Elementary::Rotation { axis: Vector3::x(), var }
    }
    pub fn ry(var: Var) -> Self {
        Elementary::Rotation { axis: Vector3::y(), var }
    }
    pub fn rz(var: Var) -> Self {
        Elementary::Rotation { axis: Vector3::z(), var }
    }
    pub fn tx(var: Var) -> Self {
        Elementary::Translation { axis: Vector3::x(), var }
    }
    pub fn ty(var: Var) -> Self {
        Elementary::Translation { axis: Vector3::y(), var }
    }
    pub fn tz(var: Var) -> Self {
        Elementary::Translation { axis: Vector3::z(), var }
    }
    /// A free body on the six coordinates from `first`: T^d(X, Y, Z) T^Rz(Φ) T^Ry(Θ) T^Rx(Ψ)
    /// (yaw, pitch, roll; Eq. 3.52).
    pub fn free_body(first: usize) -> Vec<Self> {
        vec![
            Elementary::tx(Var::q(first)),
            Elementary::ty(Var::q(first + 1)),
            Elementary::tz(Var::q(first + 2)),
            Elementary::rz(Var::q(first + 3)),
            Elementary::ry(Var::q(first + 4)),
            Elementary::rx(Var::q(first + 5)),
        ]
    }
}

/// What the user gives for one body.
#[derive(Clone, Debug, PartialEq)]
pub struct BodySpec {
    pub name: String,
    /// Reference body (relative motion); `None` for the ground.
    pub parent: Option<BodyId>,
    /// T_{parent, body} as a product of elementary HTMs, ending at the centre of gravity.
    pub joint: Vec<Elementary>,
    pub mass: f64,
    /// Central inertia tensor Φ_G in the body frame.
    pub inertia: Matrix3<f64>,
}

#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ModelError {
    #[error("body {body}: parent {parent} must be defined before the body")]
    ParentOrder { body: String, parent: usize },
    #[error("body {body}: {what}")]
    Invalid { body: String, what: String },
    #[error("coordinate index {index} out of range (the model has {count} coordinates)")]
    Coordinate { index: usize, count: usize },
    #[error("dependent parameter index {index} out of range ({count} defined)")]
    Dependent { index: usize, count: usize },
    #[error("a dependent-parameter group takes 1 to {max} inputs, not {inputs}")]
    DependentInputs { inputs: usize, max: usize },
}

#[derive(Clone, Debug)]
pub(crate) struct DependentGroup {
    pub inputs: Vec<usize>,
    pub first_output: usize,
    pub function: Arc<dyn DependentFunction>,
}

/// A compiled scalar variable: where its value comes from and which body columns it moves.
#[derive(Clone, Debug)]
pub(crate) struct CompiledVar {
    pub var: Var,
    /// For each input of the source (1 for a coordinate): position in the body's own columns
    /// ([`Body::own`]).
    pub columns: Vec<usize>,
}

#[derive(Clone, Debug)]
pub(crate) enum CompiledElementary {
    /// A constant HTM with a rotation.
    Fixed(Htm),
    /// A constant displacement T^d (Eq. A.1).
    Offset(Vector3<f64>),
    /// `angle`: index of the variable in [`Model::angles`], whose sine and cosine are
    /// evaluated once per kinematics; `None` for a spin (see [`spins_freely`]): the rotation's
    /// ω, α and δ are carried, the turn of R about the axis is left to [`super::Data::pose`].
    Rotation { axis: Axis, var: CompiledVar, angle: Option<usize> },
    Translation { axis: Axis, var: CompiledVar },
}

#[derive(Clone, Debug)]
pub(crate) struct Body {
    pub name: String,
    pub parent: Option<usize>,
    pub joint: Vec<CompiledElementary>,
    pub mass: f64,
    pub inertia: Matrix3<f64>,
    /// The diagonal of `inertia` when the body axes are its principal axes (the usual case).
    pub principal: Option<Vector3<f64>>,
    /// Sorted configuration parameters this body's motion depends on (its non-zero columns of
    /// J_S and J_ω).
    pub columns: Vec<usize>,
    /// Position in `columns` of each of the parent's columns.
    pub parent_columns: Vec<usize>,
    /// Offset of this body's columns in the flat partial-velocity arrays of [`super::Data`].
    pub offset: usize,
    /// Sorted configuration parameters the body's own joint depends on (directly or through
    /// dependent parameters): the columns of its partial velocities relative to its reference
    /// body.
    pub own: Vec<usize>,
    /// Position in `columns` of each of `own`.
    pub own_columns: Vec<usize>,
    /// Offset of the own columns in the flat relative partial-velocity arrays of [`super::Data`].
    pub own_offset: usize,
}

impl Body {
    /// Central inertia tensor in the global frame {Φ_G}_0 = R Φ Rᵀ (Eq. 3.38) for the body axes
    /// R (the mass matrix; the residual takes the inertia torque in the body axes).
    pub(crate) fn world_inertia(&self, r: &Matrix3<f64>) -> Matrix3<f64> {
        r * self.inertia * r.transpose()
    }

    /// Φ x for x in the body axes.
    fn inertia_times(&self, x: &Vector3<f64>) -> Vector3<f64> {
        match &self.principal {
            Some(phi) => Vector3::new(phi.x * x.x, phi.y * x.y, phi.z * x.z),
            None => self.inertia * x,
        }
    }

    /// The inertia torque Φ_G ω̇ + ω × Φ_G ω of Eq. 3.38 for the body axes R, angular velocity ω
    /// and acceleration ω̇ (global frame), taken in the body axes, R (Φ Rᵀω̇ + Rᵀω × Φ Rᵀω):
    /// the tensor R Φ Rᵀ is not formed.
    pub(crate) fn inertia_torque(&self, r: &Matrix3<f64>, omega: &Vector3<f64>, alpha: &Vector3<f64>) -> Vector3<f64> {
        let (w, a) = (r.tr_mul(omega), r.tr_mul(alpha));
        r * (self.inertia_times(&a) + w.cross(&self.inertia_times(&w)))
    }

    /// Rotational kinetic energy ½ ω·Φ_G ω for the body axes R (Eq. 3.38), in the body axes.
    pub(crate) fn rotational_energy(&self, r: &Matrix3<f64>, omega: &Vector3<f64>) -> f64 {
        let w = r.tr_mul(omega);
        0.5 * w.dot(&self.inertia_times(&w))
    }
}

/// A distinct variable of the rotations, with the sine and cosine of its offset (the kinematics
/// turns those of a dependent parameter into the angle's, `kinematics::angle_sin_cos`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Angle {
    pub(crate) var: Var,
    pub(crate) offset_sin_cos: (f64, f64),
}

/// Immutable multibody description (Model/Data split). Cheap to clone: dependent functions
/// are shared.
#[derive(Clone, Debug)]
pub struct Model {
    pub(crate) coordinates: usize,
    pub(crate) bodies: Vec<Body>,
    pub(crate) dependents: Vec<DependentGroup>,
    pub(crate) dependent_count: usize,
    pub(crate) column_total: usize,
    pub(crate) own_total: usize,
    /// The distinct variables of the rotations (see [`CompiledElementary::Rotation`]).
    pub(crate) angles: Vec<Angle>,
    /// Gravity acceleration in the global frame (m/s²).
    pub gravity: Vector3<f64>,
}

impl Model {
    pub fn coordinate_count(&self) -> usize {
        self.coordinates
    }
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }
    pub fn body_name(&self, id: BodyId) -> &str {
        &self.bodies[id.0].name
    }
    pub fn body_mass(&self, id: BodyId) -> f64 {
        self.bodies[id.0].mass
    }
    pub fn body_by_name(&self, name: &str) -> Option<BodyId> {
        self.bodies.iter().position(|b| b.name == name).map(BodyId)
    }
    /// Total mass of the system.
    pub fn total_mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.mass).sum()
    }
    pub fn dependent_count(&self) -> usize {
        self.dependent_count
    }
}

/// Standard gravity g (m/s²): the default gravity of a [`Model`], along −z.
pub const STANDARD_GRAVITY: f64 = 9.81;

/// Whether the last elementary of the body's joint is a spin: a rotation about a frame axis of
/// a body that is no reference body and whose central inertia is symmetric about that axis
/// (the two other principal moments equal, e.g. a rotor turning at n q, Eq. 3.69-3.71). Its
/// angle then enters no dynamic quantity: R R_e(θ) Φ R_e(θ)ᵀ Rᵀ = R Φ Rᵀ, the centre of
/// gravity stays on the axis, ω, α and the partial velocities do not depend on θ, and no other
/// body is placed from it. Any other body turns in full (the fallback).
fn spins_freely(spec: &BodySpec, is_parent: bool) -> bool {
    let Some(Elementary::Rotation { axis, .. }) = spec.joint.last() else { return false };
    let Axis::Frame(k) = Axis::of(axis) else { return false };
    let phi = &spec.inertia;
    let principal = *phi == Matrix3::from_diagonal(&phi.diagonal());
    !is_parent && principal && phi[((k + 1) % 3, (k + 1) % 3)] == phi[((k + 2) % 3, (k + 2) % 3)]
}

/// Builds a [`Model`] body after body.
#[derive(Debug)]
pub struct ModelBuilder {
    coordinates: usize,
    specs: Vec<BodySpec>,
    dependents: Vec<DependentGroup>,
    dependent_count: usize,
    gravity: Vector3<f64>,
}

impl ModelBuilder {
    /// A model with `coordinates` configuration parameters and gravity -9.81 z.
    pub fn new(coordinates: usize) -> Self {
        ModelBuilder { coordinates, specs: Vec::new(), dependents: Vec::new(), dependent_count: 0, gravity: Vector3::new(0.0, 0.0, -STANDARD_GRAVITY) }
    }
    pub fn gravity(mut self, g: Vector3<f64>) -> Self {
        self.gravity = g;
        self
    }
    /// Declares a group of dependent parameters computed from the coordinates `inputs`;
    /// returns the index of its first output (use `Var::p(first + k)`).
    pub fn add_dependent(&mut self, inputs: &[usize], function: Arc<dyn DependentFunction>) -> Result<usize, ModelError> {
        if inputs.is_empty() || inputs.len() > MAX_INPUTS {
            return Err(ModelError::DependentInputs { inputs: inputs.len(), max: MAX_INPUTS });
        }
        for &i in inputs {
            if i >= self.coordinates {
                return Err(ModelError::Coordinate { index: i, count: self.coordinates });
            }
        }
        assert_eq!(inputs.len(), function.input_count(), "dependent function inputs");
        let first = self.dependent_count;
        self.dependent_count += function.output_count();
        self.dependents.push(DependentGroup { inputs: inputs.to_vec(), first_output: first, function });
        Ok(first)
    }
    pub fn add_body(&mut self, spec: BodySpec) -> Result<BodyId, ModelError> {
        let id = self.specs.len();
        if let Some(BodyId(p)) = spec.parent {
            if p >= id {
                return Err(ModelError::ParentOrder { body: spec.name.clone(), parent: p });
            }
        }
        let bad = |what: String| ModelError::Invalid { body: spec.name.clone(), what };
        if !(spec.mass >= 0.0 && spec.mass.is_finite()) {
            return Err(bad(format!("mass {} must be finite and >= 0", spec.mass)));
        }
        let sym = (spec.inertia - spec.inertia.transpose()).norm();
        if !spec.inertia.iter().all(|x| x.is_finite()) || sym > 1e-12 * spec.inertia.norm().max(1e-300) {
            return Err(bad("inertia tensor must be finite and symmetric".into()));
        }
        if spec.inertia.symmetric_eigenvalues().iter().any(|&e| e < -1e-12) {
            return Err(bad("inertia tensor must be positive semi-definite".into()));
        }
        for e in &spec.joint {
            if let Elementary::Rotation { axis, var } | Elementary::Translation { axis, var } = e {
                if (axis.norm() - 1.0).abs() > 1e-12 {
                    return Err(bad(format!("joint axis {axis:?} must be a unit vector")));
                }
                match var.source {
                    Source::Coordinate(j) if j >= self.coordinates => return Err(ModelError::Coordinate { index: j, count: self.coordinates }),
                    Source::Dependent(k) if k >= self.dependent_count => return Err(ModelError::Dependent { index: k, count: self.dependent_count }),
                    _ => {}
                }
            }
        }
        self.specs.push(spec);
        Ok(BodyId(id))
    }

    fn source_inputs(&self, source: Source) -> Vec<usize> {
        match source {
            Source::Coordinate(j) => vec![j],
            Source::Dependent(k) => {
                let g = self.dependents.iter().find(|g| k >= g.first_output && k < g.first_output + g.function.output_count()).expect("validated");
                g.inputs.clone()
            }
        }
    }

    pub fn build(self) -> Model {
        let mut bodies: Vec<Body> = Vec::with_capacity(self.specs.len());
        let (mut offset, mut own_offset) = (0, 0);
        let mut angles: Vec<Var> = Vec::new();
        let is_parent: Vec<bool> = (0..self.specs.len()).map(|id| self.specs.iter().any(|s| s.parent == Some(BodyId(id)))).collect();
        for (id, spec) in self.specs.iter().enumerate() {
            let spin = spins_freely(spec, is_parent[id]);
            let mut own: Vec<usize> = Vec::new();
            for e in &spec.joint {
                if let Elementary::Rotation { var, .. } | Elementary::Translation { var, .. } = e {
                    own.extend(self.source_inputs(var.source));
                }
            }
            own.sort_unstable();
            own.dedup();
            let mut columns: Vec<usize> = spec.parent.map(|p| bodies[p.0].columns.clone()).unwrap_or_default();
            columns.extend(&own);
            columns.sort_unstable();
            columns.dedup();
            let pos = |c: usize| columns.binary_search(&c).expect("column present");
            let parent_columns = spec.parent.map(|p| bodies[p.0].columns.iter().map(|&c| pos(c)).collect()).unwrap_or_default();
            let own_columns = own.iter().map(|&c| pos(c)).collect();
            let own_pos = |c: usize| own.binary_search(&c).expect("own column present");
            let compile = |var: &Var| CompiledVar { var: *var, columns: self.source_inputs(var.source).into_iter().map(own_pos).collect() };
            // Consecutive constant HTMs are multiplied once here rather than at every evaluation.
            let mut joint: Vec<CompiledElementary> = Vec::with_capacity(spec.joint.len());
            for (k, e) in spec.joint.iter().enumerate() {
                match (e, joint.last_mut()) {
                    (Elementary::Fixed(h), Some(CompiledElementary::Fixed(previous))) => *previous = previous.compose(h),
                    (Elementary::Fixed(h), _) => joint.push(CompiledElementary::Fixed(*h)),
                    (Elementary::Rotation { axis, var }, _) => {
                        let angle = (!(spin && k + 1 == spec.joint.len())).then(|| {
                            angles.iter().position(|a| a == var).unwrap_or_else(|| {
                                angles.push(*var);
                                angles.len() - 1
                            })
                        });
                        joint.push(CompiledElementary::Rotation { axis: Axis::of(axis), var: compile(var), angle })
                    }
                    (Elementary::Translation { axis, var }, _) => joint.push(CompiledElementary::Translation { axis: Axis::of(axis), var: compile(var) }),
                }
            }
            for e in &mut joint {
                if let CompiledElementary::Fixed(h) = e {
                    if h.rotation == Matrix3::identity() {
                        *e = CompiledElementary::Offset(h.translation);
                    }
                }
            }
            let (n, n_own) = (columns.len(), own.len());
            bodies.push(Body {
                name: spec.name.clone(),
                parent: spec.parent.map(|p| p.0),
                joint,
                mass: spec.mass,
                inertia: spec.inertia,
                principal: (spec.inertia == Matrix3::from_diagonal(&spec.inertia.diagonal())).then(|| spec.inertia.diagonal()),
                columns,
                parent_columns,
                offset,
                own,
                own_columns,
                own_offset,
            });
            offset += n;
            own_offset += n_own;
        }
        Model {
            coordinates: self.coordinates,
            bodies,
            dependents: self.dependents,
            dependent_count: self.dependent_count,
            column_total: offset,
            own_total: own_offset,
            angles: angles.into_iter().map(|var| Angle { var, offset_sin_cos: var.offset.sin_cos() }).collect(),
            gravity: self.gravity,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mbs::{BodySpec, Elementary};
    use crate::spatial::yaw_pitch_roll;

    /// The inertia torque taken in the body axes is Φ_G ω̇ + ω × Φ_G ω with Φ_G = R Φ Rᵀ (and the
    /// energy ½ ω·Φ_G ω), for a body on its principal axes and for one with products of inertia.
    #[test]
    fn inertia_in_the_body_axes_is_the_world_tensor() {
        let principal = Matrix3::from_diagonal(&Vector3::new(0.3, 1.2, 2.5));
        let full = Matrix3::new(0.3, 0.05, -0.02, 0.05, 1.2, 0.1, -0.02, 0.1, 2.5);
        let mut b = ModelBuilder::new(6);
        for (name, inertia) in [("principal", principal), ("full", full)] {
            b.add_body(BodySpec { name: name.into(), parent: None, joint: Elementary::free_body(0), mass: 1.0, inertia }).unwrap();
        }
        let model = b.build();
        assert!(model.bodies[0].principal.is_some() && model.bodies[1].principal.is_none());
        let r = yaw_pitch_roll(0.7, -0.4, 1.9);
        let (omega, alpha) = (Vector3::new(0.4, -1.3, 2.2), Vector3::new(-3.0, 0.5, 1.7));
        for (body, inertia) in model.bodies.iter().zip([principal, full]) {
            let product = r * inertia * r.transpose();
            assert!((body.world_inertia(&r) - product).amax() < 1e-15 * product.amax());
            let torque = product * alpha + omega.cross(&(product * omega));
            assert!((body.inertia_torque(&r, &omega, &alpha) - torque).amax() < 1e-14 * torque.amax(), "{}", body.name);
            let energy = 0.5 * omega.dot(&(product * omega));
            assert!((body.rotational_energy(&r, &omega) - energy).abs() < 1e-14 * energy, "{}", body.name);
        }
    }
}
