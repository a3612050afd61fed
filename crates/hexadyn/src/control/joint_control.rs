//! Joint-space control: 18 digital PI loops (Eq. 4.18-4.20) tracking joint references.

use std::f64::consts::TAU;

use super::interface::{Command, Controller, Measurements};
use super::{DigitalPi, FrictionFeedForward};
use crate::description::PiGains;
use crate::hexapod::JOINTS;

/// The 18 digital PI of a robot with the gains K, T_i of each joint k = 3 leg + j (Table 4.1 for
/// AMRU5, [`crate::description::Robot::pi_gains`]) at the control period `dt`.
pub fn joint_pis(gains: &[PiGains; JOINTS], dt: f64) -> [DigitalPi; JOINTS] {
    std::array::from_fn(|k| DigitalPi::new(gains[k].k, gains[k].t_i, dt))
}

/// The command of the 18 digital PI position loops (Eq. 4.18-4.20, antiwindup at the supply
/// voltage, Section 4.4.5) tracking `references`: the last stage of every closed-loop controller.
pub fn pi_command(pis: &mut [DigitalPi; JOINTS], references: [f64; JOINTS], m: &Measurements) -> Command {
    let voltages = std::array::from_fn(|k| pis[k].update(references[k] - m.positions[k], m.supply_voltage));
    Command { voltages, references, goals: None }
}

/// [`pi_command`] with the servo goals of the master's friction feed-forward when it adds one
/// (the last stage of the gait controllers, which drive PI loops or position servos).
pub fn joint_command(pis: &mut [DigitalPi; JOINTS], feedforward: Option<&mut FrictionFeedForward>, references: [f64; JOINTS], m: &Measurements) -> Command {
    let goals = feedforward.map(|f| f.goals(&references, m.supply_voltage));
    Command { goals, ..pi_command(pis, references, m) }
}

/// Joint references q_d(t).
pub trait ReferenceSource {
    fn reference(&mut self, t: f64) -> [f64; JOINTS];
    /// The voltage of joint k at t if it is driven open loop instead of by its PI.
    fn open_loop_voltage(&self, _k: usize, _t: f64) -> Option<f64> {
        None
    }
}

/// The motion of one joint reference about its base position.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum JointMotion {
    /// From `start_s` on, q_d = base + rate (t − start_s), stopping at `stop_s` (Section 4.4.4).
    Ramp { rate: f64, start_s: f64, stop_s: f64 },
    /// q_d = base + amplitude sin(2π frequency t).
    Sine { amplitude: f64, frequency_hz: f64 },
    /// Back and forth between `min` and `max` at constant speed, starting at the base position
    /// going up (the identification profiles of Section 5.2, Table 5.2).
    Sawtooth { min: f64, max: f64, speed: f64 },
    /// The sawtooth of the identification campaign (Table 5.2): one back-and-forth cycle at
    /// `speed`, the next at `speed + speed_step`, and so on up to `speed_max`, which the last
    /// cycles keep. A cycle starts and ends at `min`; the first starts at the base going up.
    SawtoothSteps { min: f64, max: f64, speed: f64, speed_step: f64, speed_max: f64 },
    /// Open loop: the motor voltage rises as `rate_v_per_s` t and the joint's PI is bypassed
    /// (the breakaway experiment of Section 5.3, 0.05 V/s); the reference is the base.
    VoltageRamp { rate_v_per_s: f64 },
}

/// Position on a sawtooth between `min` and `max` at `speed`, `s` seconds after leaving `min`
/// going up (one cycle lasts 2 (max − min) / speed).
fn sawtooth_at(min: f64, max: f64, speed: f64, s: f64) -> f64 {
    let span = max - min;
    let s = s.rem_euclid(2.0 * span / speed);
    if s * speed <= span {
        min + s * speed
    } else {
        max - (s * speed - span)
    }
}

impl JointMotion {
    pub fn value(&self, base: f64, t: f64) -> f64 {
        match *self {
            JointMotion::Ramp { rate, start_s, stop_s } => base + rate * (t.clamp(start_s, stop_s) - start_s),
            JointMotion::Sine { amplitude, frequency_hz } => base + amplitude * (TAU * frequency_hz * t).sin(),
            // Phase so that t = 0 is at `base`, moving up.
            JointMotion::Sawtooth { min, max, speed } => sawtooth_at(min, max, speed, (base - min) / speed + t),
            JointMotion::SawtoothSteps { min, max, speed, speed_step, speed_max } => {
                let mut s = (base - min) / speed + t;
                let mut v = speed;
                // Whole cycles at the increasing speeds, then the last speed for ever.
                while v < speed_max && s >= 2.0 * (max - min) / v {
                    s -= 2.0 * (max - min) / v;
                    v = (v + speed_step).min(speed_max);
                }
                sawtooth_at(min, max, v, s)
            }
            JointMotion::VoltageRamp { .. } => base,
        }
    }

    /// The open-loop voltage at t of a [`JointMotion::VoltageRamp`], None for a position motion.
    pub fn open_loop_voltage(&self, t: f64) -> Option<f64> {
        match *self {
            JointMotion::VoltageRamp { rate_v_per_s } => Some(rate_v_per_s * t),
            _ => None,
        }
    }
}

/// Base joint positions with optional motions per joint.
#[derive(Clone, Debug, PartialEq)]
pub struct JointReferences {
    pub base: [f64; JOINTS],
    pub motions: Vec<(usize, JointMotion)>,
}

impl ReferenceSource for JointReferences {
    fn reference(&mut self, t: f64) -> [f64; JOINTS] {
        let mut r = self.base;
        for (k, m) in &self.motions {
            r[*k] = m.value(self.base[*k], t);
        }
        r
    }
    fn open_loop_voltage(&self, k: usize, t: f64) -> Option<f64> {
        self.motions.iter().find(|(j, _)| *j == k).and_then(|(_, m)| m.open_loop_voltage(t))
    }
}

/// 18 digital PI position loops with antiwindup at the supply voltage (Section 4.4.5).
pub struct JointPiController<R: ReferenceSource> {
    pub pis: [DigitalPi; JOINTS],
    pub references: R,
}

impl<R: ReferenceSource> Controller for JointPiController<R> {
    fn update(&mut self, m: &Measurements) -> Command {
        let mut references = self.references.reference(m.t);
        let voltages = std::array::from_fn(|k| match self.references.open_loop_voltage(k, m.t) {
            Some(u) => {
                references[k] = m.positions[k];
                u.clamp(-m.supply_voltage, m.supply_voltage)
            }
            None => self.pis[k].update(references[k] - m.positions[k], m.supply_voltage),
        });
        Command { voltages, references, goals: None }
    }
}

/// Feeds the references to a plant whose joint controllers are continuous and internal (the
/// 96-DOF model, Table 3.5); no voltage is computed here.
pub struct ReferenceFeed<R: ReferenceSource>(pub R);

impl<R: ReferenceSource> Controller for ReferenceFeed<R> {
    fn update(&mut self, m: &Measurements) -> Command {
        Command { voltages: [0.0; JOINTS], references: self.0.reference(m.t), goals: None }
    }
}

/// No power: all voltages zero (the unpowered robot of Section 6.2). References are the
/// measured positions.
pub struct Unpowered;

impl Controller for Unpowered {
    fn update(&mut self, m: &Measurements) -> Command {
        Command { voltages: [0.0; JOINTS], references: m.positions, goals: None }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn sawtooth_starts_at_base_and_stays_in_range() {
        let m = JointMotion::Sawtooth { min: 0.04, max: 0.075, speed: 0.008 };
        assert_relative_eq!(m.value(0.05, 0.0), 0.05, epsilon = 1e-15);
        assert_relative_eq!(m.value(0.05, 1.0), 0.058, epsilon = 1e-12);
        for i in 0..1000 {
            let v = m.value(0.05, i as f64 * 0.01);
            assert!((0.04 - 1e-12..=0.075 + 1e-12).contains(&v));
        }
        // Period 2 span / speed.
        assert_relative_eq!(m.value(0.05, 3.3), m.value(0.05, 3.3 + 2.0 * 0.035 / 0.008), epsilon = 1e-12);
    }

    #[test]
    fn sawtooth_steps_raise_the_speed_every_cycle() {
        // Table 5.2 for q_v: 0.5 to 8 mm/s by 0.5 mm/s over [0.04, 0.075] m.
        let m = JointMotion::SawtoothSteps { min: 0.04, max: 0.075, speed: 0.0005, speed_step: 0.0005, speed_max: 0.008 };
        let cycle = |v: f64| 2.0 * 0.035 / v;
        assert_relative_eq!(m.value(0.04, 1.0), 0.0405, epsilon = 1e-12);
        // Second cycle at 1 mm/s: 1 s after its start the reference has risen 1 mm.
        let t1 = cycle(0.0005);
        assert_relative_eq!(m.value(0.04, t1 + 1.0), 0.041, epsilon = 1e-12);
        // After the 16 increasing cycles the speed stays at 8 mm/s.
        let t16: f64 = (1..=16).map(|k| cycle(0.0005 * k as f64)).sum();
        assert_relative_eq!(m.value(0.04, t16 - 1.0), 0.04 + 0.008, epsilon = 1e-9);
        assert_relative_eq!(m.value(0.04, t16 + 1.0), 0.04 + 0.008, epsilon = 1e-9);
        assert_relative_eq!(m.value(0.04, t16 + cycle(0.008) + 2.0), 0.04 + 0.016, epsilon = 1e-9);
    }

    #[test]
    fn voltage_ramp_bypasses_the_pi() {
        use crate::control::Measurements;
        let motions = vec![(4, JointMotion::VoltageRamp { rate_v_per_s: 0.05 })];
        let mut c = JointPiController { pis: std::array::from_fn(|_| DigitalPi::new(500.0, 0.5, 0.01)), references: JointReferences { base: [0.05; JOINTS], motions } };
        let m = Measurements { t: 10.0, positions: [0.04; JOINTS], currents: [0.0; JOINTS], supply_voltage: 12.0, pose: None, foot_normal_forces: None };
        let cmd = c.update(&m);
        assert_relative_eq!(cmd.voltages[4], 0.5, epsilon = 1e-12);
        assert_eq!(cmd.references[4], 0.04);
        // The other joints are still held by their PI (error 0.01 m -> a positive voltage).
        assert!(cmd.voltages[5] > 0.0);
    }

    #[test]
    fn ramp_holds_outside_its_window() {
        let m = JointMotion::Ramp { rate: 0.01, start_s: 1.0, stop_s: 2.0 };
        assert_eq!(m.value(0.05, 0.5), 0.05);
        assert_relative_eq!(m.value(0.05, 1.5), 0.055, epsilon = 1e-15);
        assert_relative_eq!(m.value(0.05, 5.0), 0.06, epsilon = 1e-15);
    }
}
