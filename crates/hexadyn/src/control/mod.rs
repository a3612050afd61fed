//! Control (thesis Section 2.3.2, 3.4.4, Chapters 4 and 7): the controller/plant interface shared
//! by the simulated and the real robot, the digital PI controllers of AMRU5 with their encoders,
//! joint-space reference tracking, the continuous PID element of the 96-DOF model, the leg
//! kinematics (Section 7.3) and the gait controller (Sections 7.4-7.6).

pub mod gait;
mod interface;
mod joint_control;
mod leg_kinematics;
mod pi;

pub use interface::{BodyPose, Command, Controller, Measurements, Plant, JOINTS};
pub use joint_control::{joint_pis, JointMotion, JointPiController, JointReferences, ReferenceFeed, ReferenceSource, Unpowered};
pub use leg_kinematics::{Clamping, IkOptions, IkOutcome, IkSolution, JointLimits, LegKinematics, LegKinematicsError, Limit, Workspace};
pub use pi::{ContinuousPid, DigitalPi, Encoder, PidIntegralResidual, PidVoltageResidual};
