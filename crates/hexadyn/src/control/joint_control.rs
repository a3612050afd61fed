//! Joint-space control: 18 digital PI loops (Eq. 4.18-4.20) tracking joint references.

use std::f64::consts::TAU;

use super::interface::{Command, Controller, Measurements};
use super::DigitalPi;
use crate::description::RobotDescription;
use crate::hexapod::{Joint, JOINTS};

/// The 18 digital PI of a robot (gains K, T_i of its description, Table 4.1 for AMRU5) at the
/// control period `dt`, joint k = 3 leg + (0: q_r, 1: q_v, 2: q_h).
pub fn joint_pis(robot: &RobotDescription, dt: f64) -> [DigitalPi; JOINTS] {
    std::array::from_fn(|k| {
        let g = robot.pi_gains(Joint::ALL[k % 3]);
        DigitalPi::new(g.k, g.t_i, dt)
    })
}

/// Joint references q_d(t).
pub trait ReferenceSource {
    fn reference(&mut self, t: f64) -> [f64; JOINTS];
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
}

impl JointMotion {
    pub fn value(&self, base: f64, t: f64) -> f64 {
        match *self {
            JointMotion::Ramp { rate, start_s, stop_s } => base + rate * (t.clamp(start_s, stop_s) - start_s),
            JointMotion::Sine { amplitude, frequency_hz } => base + amplitude * (TAU * frequency_hz * t).sin(),
            JointMotion::Sawtooth { min, max, speed } => {
                let span = max - min;
                let period = 2.0 * span / speed;
                // Phase so that t = 0 is at `base`, moving up.
                let s = ((base - min) / speed + t).rem_euclid(period);
                if s * speed <= span {
                    min + s * speed
                } else {
                    max - (s * speed - span)
                }
            }
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
}

/// 18 digital PI position loops with antiwindup at the supply voltage (Section 4.4.5).
pub struct JointPiController<R: ReferenceSource> {
    pub pis: [DigitalPi; JOINTS],
    pub references: R,
}

impl<R: ReferenceSource> Controller for JointPiController<R> {
    fn update(&mut self, m: &Measurements) -> Command {
        let references = self.references.reference(m.t);
        let voltages = std::array::from_fn(|k| self.pis[k].update(references[k] - m.positions[k], m.supply_voltage));
        Command { voltages, references }
    }
}

/// Feeds the references to a plant whose joint controllers are continuous and internal (the
/// 96-DOF model, Table 3.5); no voltage is computed here.
pub struct ReferenceFeed<R: ReferenceSource>(pub R);

impl<R: ReferenceSource> Controller for ReferenceFeed<R> {
    fn update(&mut self, m: &Measurements) -> Command {
        Command { voltages: [0.0; JOINTS], references: self.0.reference(m.t) }
    }
}

/// No power: all voltages zero (the unpowered robot of Section 6.2). References are the
/// measured positions.
pub struct Unpowered;

impl Controller for Unpowered {
    fn update(&mut self, m: &Measurements) -> Command {
        Command { voltages: [0.0; JOINTS], references: m.positions }
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
    fn ramp_holds_outside_its_window() {
        let m = JointMotion::Ramp { rate: 0.01, start_s: 1.0, stop_s: 2.0 };
        assert_eq!(m.value(0.05, 0.5), 0.05);
        assert_relative_eq!(m.value(0.05, 1.5), 0.055, epsilon = 1e-15);
        assert_relative_eq!(m.value(0.05, 5.0), 0.06, epsilon = 1e-15);
    }
}
