//! hexadyn engine: multiphysics dynamics and gait control of six-legged walking robots.
//!
//! The modules form layers; each imports only from the layers above it in this list (the
//! thesis' EasyDyn structure, Section 3.3, extended by the robot and its controller):
//! 1. [`spatial`]: homogeneous transformation matrices and rotations (Appendix A);
//! 2. [`fields`]: the fields of the TOML input files: their positions, their errors
//!    (`file:line: field = value; allowed ...`) and the bounds a single field declares;
//! 3. [`sim`]: systems in residual form f(q, q', q'', t) = 0 and their Newmark integration,
//!    static equilibrium and linearization (Section 3.3.2);
//! 4. [`mbs`]: minimal-coordinates multibody systems, equations of motion by the virtual power
//!    principle (Section 3.3.3-3.3.4);
//! 5. [`physics`]: ground contact, joint friction and DC motors (Section 3.4.2-3.4.4, Chapter 5);
//! 6. [`hexapod`]: the hexapod's vocabulary (legs, joints, coordinates), the pantograph leg,
//!    the multibody assembly, leg kinematics and workspaces (Sections 3.4.1, 7.1, 7.3);
//! 7. [`description`]: the robot description file (`robots/amru5.toml`, Tables 2.1-6.7,
//!    App. B), its validation and SI views;
//! 8. [`control`]: the controller/plant interface, joint controllers, encoders and the gait
//!    controller (Section 2.3.2, 3.4.4, Chapters 4 and 7), the same on the simulated and the
//!    real robot;
//! 9. [`robot`]: the complete model as one residual system and the simulated robot (Chapter 3);
//! 10. [`scenario`]: ready-to-run simulations from TOML files, their run and summary;
//! 11. [`analysis`]: controller design from the model (Section 4.4);
//! 12. [`link`]: the master/slave UDP link to the real robot, its slave emulator on the
//!     simulated robot, and scenarios run through it (Section 2.3.2).
//!
//! `control` never imports `robot`: a controller sees only what the real robot measures.

pub mod analysis;
pub mod control;
pub mod description;
pub mod fields;
pub mod hexapod;
pub mod link;
pub mod mbs;
pub mod physics;
pub mod robot;
pub mod scenario;
pub mod sim;
pub mod spatial;

#[cfg(test)]
mod test_util;
