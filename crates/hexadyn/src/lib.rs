//! hexadyn engine: multiphysics dynamics and gait control of six-legged walking robots.
//!
//! The layers follow the thesis (EasyDyn, Section 3.3):
//! - [`spatial`]: homogeneous transformation matrices and rotations (Appendix A);
//! - [`sim`]: systems in residual form f(q, q', q'', t) = 0 and their Newmark integration,
//!   static equilibrium and linearization (Section 3.3.2);
//! - [`mbs`]: minimal-coordinates multibody systems, equations of motion by the virtual power
//!   principle (Section 3.3.3-3.3.4).

pub mod analysis;
pub mod mbs;
pub mod sim;
pub mod robot;
pub mod spatial;
