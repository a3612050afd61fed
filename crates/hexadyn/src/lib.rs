//! hexadyn engine: multiphysics dynamics and gait control of six-legged walking robots.
//!
//! The layers follow the thesis (EasyDyn, Section 3.3):
//! - [`spatial`]: homogeneous transformation matrices and rotations (Appendix A);
//! - [`sim`]: systems in residual form f(q, q', q'', t) = 0 and their Newmark integration,
//!   static equilibrium and linearization (Section 3.3.2);
//! - [`mbs`]: minimal-coordinates multibody systems, equations of motion by the virtual power
//!   principle (Section 3.3.3-3.3.4);
//! - [`robot`]: the robot description as data (`robots/amru5.toml`, Tables 2.1-6.7, App. B),
//!   the pantograph leg and the hexapod mechanics (Section 3.4.1);
//! - [`physics`]: ground contact, joint friction and DC motors (Section 3.4.2-3.4.4, Chapter 5);
//! - [`control`]: joint controllers and encoders (Section 3.4.4, Chapter 4);
//! - [`analysis`]: controller design (Section 4.4).

pub mod analysis;
pub mod control;
pub mod mbs;
pub mod physics;
pub mod robot;
pub mod sim;
pub mod spatial;

#[cfg(test)]
mod test_util;
