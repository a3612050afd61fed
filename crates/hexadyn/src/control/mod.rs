//! Control (thesis Section 2.3.2, 3.4.4 and Chapter 4): the controller/plant interface shared by
//! the simulated and the real robot, the digital PI controllers of AMRU5 with their encoders,
//! joint-space reference tracking, and the continuous PID element of the 96-DOF model.

mod interface;
mod joint_control;
mod pi;

pub use interface::{BodyPose, Command, Controller, Measurements, Plant, JOINTS};
pub use joint_control::{JointMotion, JointPiController, JointReferences, ReferenceSource, Unpowered};
pub use pi::{ContinuousPid, DigitalPi, Encoder, PidIntegralResidual, PidVoltageResidual};
mod leg_kinematics;
pub use leg_kinematics::{Clamping, IkOptions, IkOutcome, IkSolution, JointLimits, LegKinematics, LegKinematicsError, Limit, Workspace};
