//! The controller interface (thesis Section 2.3.2 and architecture principle 3): every control
//! period the controller receives what the real robot measures — encoder positions, motor
//! currents, the supply voltage — plus the body pose when a navigation system is present (and, in
//! simulation only, the true foot normal forces), and returns the 18 motor voltages. A [`Plant`] is what is driven: the simulated robot, or the real
//! robot's slave boards through the master/slave link.

use nalgebra::Vector3;

use crate::hexapod::JOINTS;

/// Body pose from a navigation system (Section 7.4), yaw-pitch-roll as in Eq. 3.52.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyPose {
    pub position: Vector3<f64>,
    pub yaw: f64,
    pub pitch: f64,
    pub roll: f64,
}

/// What the controller receives at a control instant.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Measurements {
    pub t: f64,
    /// Joint positions as the encoders report them (q_r in rad, q_v and q_h in m), per joint
    /// k = 3 leg + (0: q_r, 1: q_v, 2: q_h).
    pub positions: [f64; JOINTS],
    /// Motor currents (A).
    pub currents: [f64; JOINTS],
    /// Supply voltage of the H-bridges (V).
    pub supply_voltage: f64,
    /// True body pose, when the scenario has a navigation system.
    pub pose: Option<BodyPose>,
    /// True normal ground force on each foot (N), filled by the simulated plant only: the real
    /// robot has no foot force sensors (it detects the ground from its motor currents, Section
    /// 5.6). The free gait's landing detection "force" reads it, the simulation mode of
    /// Section 7.7 (ground detected above 10 N).
    pub foot_normal_forces: Option<[f64; 6]>,
}

/// What the controller returns: the motor voltages and, for the record, the joint references
/// it tracks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Command {
    pub voltages: [f64; JOINTS],
    pub references: [f64; JOINTS],
    /// The goals sent to position servos when they are not the references (a friction
    /// feed-forward, [`super::FrictionFeedForward`]).
    pub goals: Option<[f64; JOINTS]>,
}

/// A controller run at the control period with zero-order-hold outputs.
pub trait Controller {
    fn update(&mut self, m: &Measurements) -> Command;
}

/// What a controller drives, one control period at a time.
pub trait Plant {
    type Error: std::error::Error;
    /// Control period Δt (s).
    fn period(&self) -> f64;
    fn measure(&mut self) -> Measurements;
    /// Applies the command for the next period (zero-order hold): the voltages, or the
    /// references when the plant's joint controllers are its own.
    fn actuate(&mut self, command: &Command);
    /// Lets one control period pass.
    fn wait_period(&mut self) -> Result<(), Self::Error>;
}
