//! The link's joints in the controller's units: a joint's position count and its setpoint for
//! either kind of packets ([`Protocol`]), for the master ([`super::UdpPlant`]) and the emulated
//! boards ([`super::emulator`]).
//!
//! - A DC motor's board (protocol 1) counts its encoder from the joint zero of the robot
//!   description (Section 2.3.2: 500 counts per motor revolution on AMRU5): count
//!   c = ⌊n q / 2π · counts per revolution⌋, position c · 2π / (counts per revolution · n).
//! - A position servo's board (protocol 2) reads and writes the servo's position register:
//!   INTERPRETATION: the servo is mounted with the middle of its sensor at the joint zero (512
//!   of an AX-12A's 1024 counts over 300°) and counts up when q increases, so the register is
//!   that middle plus the count of q at the sensor's resolution (range / counts). Goals are
//!   the nearest register (a servo takes whole counts); present positions are read like an
//!   encoder, rounded down.

use super::protocol::{Duty, Goal, Protocol, Setpoint, GOAL_MAX};
use crate::control::{Command, Encoder};

/// The scale of one joint's position counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointScale {
    /// The position sensor: the motor encoder, or the servo's sensor.
    pub encoder: Encoder,
    /// The count at the joint zero.
    pub zero: i64,
}

impl JointScale {
    /// The counts of `encoder` in the packets of `protocol`: from 0 at the joint zero (motor
    /// encoders), or from the middle of the servo's sensor.
    pub fn new(protocol: Protocol, encoder: Encoder) -> Self {
        let zero = match protocol {
            Protocol::Motors => 0,
            Protocol::Servos => i64::from(encoder.counts_per_rev / 2),
        };
        JointScale { encoder, zero }
    }

    /// The count a board latches at the joint position `q` (rad or m).
    pub fn count(&self, q: f64) -> i64 {
        self.zero + self.encoder.counts(q)
    }

    /// The count nearest to the joint position `q`: a servo's goal.
    pub fn nearest(&self, q: f64) -> i64 {
        self.zero + (q / self.encoder.resolution()).round() as i64
    }

    /// The joint position of a count (rad or m).
    pub fn position(&self, count: i32) -> f64 {
        (i64::from(count) - self.zero) as f64 * self.encoder.resolution()
    }
}

/// A setpoint in the controller's units: what the master sends for a controller's command and
/// what a board applies.
pub trait Drive: Setpoint {
    /// The setpoint of joint k for `command`, from the supply `supply` its board measured.
    fn commanded(command: &Command, k: usize, scale: &JointScale, supply: f64) -> Self;
    /// Applies the setpoint to joint k of the command `applied` of the emulated robot, whose
    /// supply is `supply`.
    fn apply(self, k: usize, scale: &JointScale, supply: f64, applied: &mut Command);
    /// The voltage held with it (V); NaN where the master does not know it (a servo's own loop).
    fn held_voltage(self, supply: f64) -> f64;
    /// The goal position it holds (rad or m); NaN for none (a duty, a servo's torque off).
    fn goal(self, scale: &JointScale) -> f64;
}

impl Drive for Duty {
    /// round(u / U · 1023) of the controller's voltage u.
    fn commanded(command: &Command, k: usize, _: &JointScale, supply: f64) -> Self {
        Duty::from_voltage(command.voltages[k], supply)
    }

    fn apply(self, k: usize, _: &JointScale, supply: f64, applied: &mut Command) {
        applied.voltages[k] = self.voltage(supply);
    }

    fn held_voltage(self, supply: f64) -> f64 {
        self.voltage(supply)
    }

    fn goal(self, _: &JointScale) -> f64 {
        f64::NAN
    }
}

impl Drive for Goal {
    /// The register nearest to the command's goal (its reference without a friction
    /// feed-forward), within 0..=2047, with the torque on.
    fn commanded(command: &Command, k: usize, scale: &JointScale, _: f64) -> Self {
        let goal = command.goals.as_ref().map_or(command.references[k], |g| g[k]);
        let register = scale.nearest(goal).clamp(0, i64::from(GOAL_MAX)) as u16;
        Goal::position(register).unwrap_or(Goal::OFF)
    }

    /// The goal of the register. INTERPRETATION: the model's servos cannot be switched off: a
    /// servo told to turn its torque off holds its last goal.
    fn apply(self, k: usize, scale: &JointScale, _: f64, applied: &mut Command) {
        let Some(register) = self.register() else { return };
        let goal = scale.position(i32::from(register));
        applied.references[k] = goal;
        applied.goals.get_or_insert(applied.references)[k] = goal;
    }

    fn held_voltage(self, _: f64) -> f64 {
        f64::NAN
    }

    fn goal(self, scale: &JointScale) -> f64 {
        self.register().map_or(f64::NAN, |r| scale.position(i32::from(r)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ax12() -> JointScale {
        // 1024 counts over 300°: counts per turn of a shaft turning 360/300 times the joint.
        JointScale::new(Protocol::Servos, Encoder { counts_per_rev: 1024, n: 1.2 })
    }

    #[test]
    fn a_servo_register_has_its_middle_at_the_joint_zero() {
        let s = ax12();
        let count = 300f64.to_radians() / 1024.0;
        assert_eq!((s.zero, s.count(0.0), s.count(-0.5 * count), s.nearest(0.6 * count)), (512, 512, 511, 513));
        assert!((s.position(1023) - 511.0 * count).abs() < 1e-12);
        let command = Command { references: [0.1; 18], goals: None, ..Default::default() };
        let g = Goal::commanded(&command, 4, &s, 11.1);
        assert_eq!(g.register(), Some(s.nearest(0.1) as u16));
        assert!((g.goal(&s) - 0.1).abs() <= 0.5 * count);
        let mut applied = Command { references: [0.3; 18], goals: Some([0.3; 18]), ..Default::default() };
        g.apply(4, &s, 11.1, &mut applied);
        Goal::OFF.apply(5, &s, 11.1, &mut applied);
        assert_eq!((applied.goals.unwrap()[4], applied.references[4], applied.goals.unwrap()[5]), (g.goal(&s), g.goal(&s), 0.3));
        // Beyond the register's 11 bits: the last register.
        let far = Command { references: [100.0; 18], ..Default::default() };
        assert_eq!(Goal::commanded(&far, 0, &s, 11.1).register(), Some(GOAL_MAX));
    }

    #[test]
    fn a_motor_encoder_counts_from_the_joint_zero() {
        let s = JointScale::new(Protocol::Motors, Encoder { counts_per_rev: 500, n: 1682.0 });
        assert_eq!((s.zero, s.count(0.0)), (0, 0));
        assert_eq!(s.position(500), f64::from(500) * s.encoder.resolution());
        let mut applied = Command::default();
        Duty::commanded(&Command { voltages: [6.0; 18], ..Default::default() }, 2, &s, 12.0).apply(2, &s, 12.0, &mut applied);
        assert_eq!(applied.voltages[2], Duty::from_voltage(6.0, 12.0).voltage(12.0));
    }
}
