//! Minimal-coordinates multibody systems (thesis Section 3.3.3-3.3.4).
//!
//! A [`Model`] is the immutable description: bodies with mass and central inertia, each placed
//! relative to a reference body (relative motion, Section 3.3.4 point 2) by a chain of
//! elementary HTMs (Appendix A) whose variables are configuration parameters, scaled
//! configuration parameters (rotors turning at n q) or dependent parameters (Section 3.3.4
//! point 3, Eq. 3.42-3.48). [`Data`] is the mutable workspace: poses, velocities, partial
//! velocities d_ij and δ_ij computed directly (Section 3.3.4 point 1), and applied wrenches.
//! The equations of motion follow the virtual power principle (Eq. 3.37-3.41).

mod data;
mod dependent;
mod dynamics;
mod kinematics;
mod model;
mod system;

pub use data::Data;
pub use dependent::{evaluate_jets, DependentFunction, DependentValue, Jet, MAX_INPUTS};
pub use num_dual::DualNum;
pub use dynamics::{generalized_forces, kinetic_energy, mass_matrix, nonlinear_effects, potential_energy, residual};
pub use kinematics::{kinematics, partial_velocities, partial_velocities_numerical, relative_kinematics};
pub use model::{BodyId, BodySpec, Elementary, Model, ModelBuilder, ModelError, Var, STANDARD_GRAVITY};
pub use system::{AppliedForces, MultibodySystem};
