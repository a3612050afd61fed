//! Control (thesis Section 2.3.2, 3.4.4, Chapters 4 and 7): the controller/plant interface shared
//! by the simulated and the real robot, the digital PI controllers of AMRU5 with their encoders,
//! joint-space reference tracking, the continuous PID element of the 96-DOF model and the gait
//! controller (Sections 7.4-7.6). It sees the robot through the hexapod's vocabulary and
//! kinematics ([`crate::hexapod`]) and its description, never through the simulated robot.

pub mod gait;
mod interface;
mod joint_control;
mod pi;

pub use interface::{BodyPose, Command, Controller, Measurements, Plant};
pub use joint_control::{joint_pis, JointMotion, JointPiController, JointReferences, ReferenceFeed, ReferenceSource, Unpowered};
pub use pi::{ContinuousPid, DigitalPi, Encoder, PidIntegralResidual, PidVoltageResidual};
