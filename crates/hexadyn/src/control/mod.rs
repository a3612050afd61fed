//! Control (thesis Section 2.3.2, 3.4.4, Chapters 4 and 7): the controller/plant interface shared
//! by the simulated and the real robot, the digital PI controllers of AMRU5 with their encoders,
//! joint-space reference tracking, the continuous PID element of the 96-DOF model, the gait
//! controller (Sections 7.4-7.6), and the joint torque estimation and ground detection from the
//! motor currents with its experiment (Section 5.6). It sees the robot through the hexapod's vocabulary and
//! kinematics ([`crate::hexapod`]) and its description, never through the simulated robot.

pub mod gait;
mod ground_detection;
mod ground_experiment;
mod interface;
mod joint_control;
mod low_pass;
mod pi;
mod servo;
mod torque_estimation;

pub use interface::{BodyPose, Command, Controller, Measurements, Plant};
pub use joint_control::{joint_command, joint_pis, pi_command, JointMotion, JointPiController, JointReferences, ReferenceFeed, ReferenceSource, Unpowered};
pub use ground_detection::{alpha, GroundDetector, GroundSensingLeg, LegDetection};
pub use ground_experiment::{GroundExperiment, GroundExperimentController, GroundExperimentState, Stop, StopOn, REST_S};
pub use low_pass::{settling_time, DigitalLowPass, DIGITAL_CUTOFF_HZ, SETTLING_TIME_CONSTANTS};
pub use torque_estimation::{TorqueEstimate, TorqueEstimator};
pub use pi::{ContinuousPid, DigitalPi, Encoder, PidIntegralResidual, PidVoltageResidual};
pub use servo::{FrictionFeedForward, PositionServo, ServoVoltage};
