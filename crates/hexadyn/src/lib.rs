//! hexadyn engine: multiphysics dynamics and gait control of six-legged walking robots.
//!
//! The layers follow the thesis (EasyDyn, Section 3.3):
//! - [`spatial`]: homogeneous transformation matrices and rotations (Appendix A);
//! - [`sim`]: systems in residual form f(q, q', q'', t) = 0 and their Newmark integration,
//!   static equilibrium and linearization (Section 3.3.2);
//! - [`mbs`]: minimal-coordinates multibody systems, equations of motion by the virtual power
//!   principle (Section 3.3.3-3.3.4);
//! - [`robot`]: the robot description as data (`robots/amru5.toml`, Tables 2.1-6.7, App. B).

pub mod analysis;
pub mod mbs;
pub mod robot;
pub mod sim;
pub mod spatial;
