//! The ground detection experiment of Section 5.6.3 as a controller: one leg at a time is
//! lifted, then lowered onto the ground in a sawtooth of its vertical joint (on AMRU5; of its
//! foot's height on other legs, [`LoweredLeg`]); when the
//! [`GroundDetector`] reports the ground the reference stops where the joint is, and the motion
//! resumes as soon as the sawtooth reference rises above that point (the reference q_v* goes on
//! being computed meanwhile). Every other joint holds its initial position; all 18 joints are
//! driven by the digital PI loops of Section 4.4.
//!
//! Schedule of one tested leg, with the sawtooth of Table 5.6 for q_v (amplitude A = 0.01 m,
//! period P = 8 s, so the speed is 4A/P = 5 mm/s):
//! 1. lift, P/4: from the stance q_v,0 up to q_v,0 − A (the foot about 6 cm above the ground);
//! 2. `thresholds.len() × trials` sawtooth periods from q_v,0 − A down to q_v,0 + A and back,
//!    the first `trials` with the first threshold, and so on;
//! 3. lower, P/4, back to q_v,0, and rest for [`REST_S`].
//!
//! INTERPRETATION: Fig. 5.16 and 5.17 are lost. The text gives contact at about 2 s and the
//! restart at about 6 s for a stop at 40 N on leg 0: a descent of the foot from 6 cm above the
//! ground at 5 mm/s of q_v reaches the ground at 2 s and the rising reference passes the stop
//! point again at 6 s, which is this schedule with the Table 5.6 sawtooth. The robot stands on
//! its other five legs (the thesis does not say how it was held).

use std::cell::RefCell;
use std::rc::Rc;

use serde::{Deserialize, Serialize};

use nalgebra::Vector3;

use super::ground_detection::{GroundDetector, GroundSensingLeg, LegDetection};
use super::interface::{Command, Controller, Measurements};
use super::low_pass::settling_time;
use super::{joint_command, DigitalPi, FrictionFeedForward};
use crate::hexapod::{Leg, LegChain, LegKinematics, SerialLegKinematics, JOINTS, LEG_COUNT};

/// Rest after each tested leg is put back on the ground (s).
pub const REST_S: f64 = 1.0;

/// How the experiment lowers a leg: its descent s (> 0 further down) and the joints that put
/// the foot at a given descent.
pub trait LoweredLeg: GroundSensingLeg {
    /// s at the joints `q` of the leg.
    fn descent(&self, q: &Vector3<f64>) -> f64;
    /// The joints at the descent `s`, the others as in `stance`.
    fn lowered(&self, stance: &Vector3<f64>, s: f64) -> Vector3<f64>;
}

/// AMRU5's pantograph: s = q_v, the vertical joint of Section 5.6.3 (the foot about 6 q_v down,
/// Eq. B.2).
impl LoweredLeg for LegKinematics {
    fn descent(&self, q: &Vector3<f64>) -> f64 {
        q[1]
    }
    fn lowered(&self, stance: &Vector3<f64>, s: f64) -> Vector3<f64> {
        Vector3::new(stance[0], s, stance[2])
    }
}

/// A serial leg: s = −z of the foot in the leg frame, the foot moved straight down from its
/// stance by the inverse kinematics of Eq. 7.7 (the closest point within the joint ranges
/// where it does not reach).
impl LoweredLeg for SerialLegKinematics {
    fn descent(&self, q: &Vector3<f64>) -> f64 {
        -self.foot(q).z
    }
    fn lowered(&self, stance: &Vector3<f64>, s: f64) -> Vector3<f64> {
        let p = self.foot(stance);
        Leg::inverse(self, &Vector3::new(p.x, p.y, -s), stance).map_or(*stance, |ik| ik.joints)
    }
}

/// The `[ground_detection]` table of a scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundExperiment {
    /// Tested legs, in order.
    #[serde(default = "all_legs")]
    pub legs: Vec<usize>,
    /// Detection thresholds F_z (N), Table 5.7.
    #[serde(default = "table_5_7_thresholds", rename = "thresholds_n")]
    pub thresholds: Vec<f64>,
    /// Trials per threshold (4 in Table 5.7).
    #[serde(default = "four")]
    pub trials: usize,
    /// Sawtooth amplitude A of q_v (m), Table 5.6 (of the foot's height on other legs).
    #[serde(default = "table_5_6_amplitude", rename = "amplitude_m")]
    pub amplitude: f64,
    /// Sawtooth period P (s), Table 5.6.
    #[serde(default = "table_5_6_period", rename = "period_s")]
    pub period: f64,
    /// What stops the leg: the ground force estimated from the motor currents (the thesis'
    /// experiment) or the simulated foot force (an ideal foot sensor).
    #[serde(default)]
    pub stop_on: StopOn,
    /// Whether the master adds its friction feed-forward to the servo goals (as
    /// `gait.friction_feedforward`; position servos only).
    #[serde(default)]
    pub friction_feedforward: bool,
    /// The feed-forward the scenario built for `friction_feedforward` (from the robot as its
    /// file describes it).
    #[serde(skip)]
    pub feedforward: Option<FrictionFeedForward>,
}

/// What stops the tested leg in the experiment.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopOn {
    /// The [`GroundDetector`] of Section 5.6.3: the vertical ground force estimated from the
    /// encoders and the motor currents reaches the threshold.
    #[default]
    Estimate,
    /// Beyond the thesis: the simulated normal force on the foot
    /// ([`Measurements::foot_normal_forces`]) reaches the threshold, read at the control
    /// instants as an ideal foot sensor would be: the reference against which an estimator's
    /// stops are measured (the force still rises between two instants; docs/ground-detection.md).
    /// Simulation only: the real robot has no foot sensors.
    FootForce,
}

fn all_legs() -> Vec<usize> {
    (0..LEG_COUNT).collect()
}
fn table_5_7_thresholds() -> Vec<f64> {
    vec![40.0, 50.0, 60.0]
}
fn four() -> usize {
    4
}
fn table_5_6_amplitude() -> f64 {
    0.01
}
fn table_5_6_period() -> f64 {
    8.0
}

impl Default for GroundExperiment {
    fn default() -> Self {
        GroundExperiment { legs: all_legs(), thresholds: table_5_7_thresholds(), trials: 4, amplitude: table_5_6_amplitude(), period: table_5_6_period(), stop_on: StopOn::Estimate, friction_feedforward: false, feedforward: None }
    }
}

impl GroundExperiment {
    /// Speed of the sawtooth, 4A/P (m/s).
    pub fn speed(&self) -> f64 {
        4.0 * self.amplitude / self.period
    }

    /// Duration of the test of one leg (s).
    pub fn leg_duration(&self) -> f64 {
        self.period / 2.0 + (self.thresholds.len() * self.trials) as f64 * self.period + REST_S
    }

    /// Duration of the whole experiment (s).
    pub fn duration(&self) -> f64 {
        self.legs.len() as f64 * self.leg_duration()
    }

    /// Where the schedule is at `t`, `stance` the descent s_0 of each leg at the start (q_v,0).
    fn phase(&self, t: f64, stance: &[f64; LEG_COUNT]) -> Option<Phase> {
        let d = self.leg_duration();
        let index = (t / d).floor() as usize;
        let leg = *self.legs.get(index)?;
        let stance = stance[leg];
        let tau = t - index as f64 * d;
        let (a, p, v) = (self.amplitude, self.period, self.speed());
        let cycles = self.thresholds.len() * self.trials;
        let lift = p / 4.0;
        let (reference, trial) = if tau < lift {
            (stance - v * tau, None)
        } else if tau < lift + cycles as f64 * p {
            let c = (((tau - lift) / p).floor() as usize).min(cycles - 1);
            let s = tau - lift - c as f64 * p;
            let r = if s < p / 2.0 { stance - a + v * s } else { stance + a - v * (s - p / 2.0) };
            (r, Some((c / self.trials, c % self.trials, s < p / 2.0)))
        } else {
            (stance - a + v * (tau - lift - cycles as f64 * p).min(lift), None)
        };
        Some(Phase { leg, reference, trial })
    }
}

struct Phase {
    leg: usize,
    /// Sawtooth reference s* of the tested leg (q_v* on AMRU5, m).
    reference: f64,
    /// (threshold index, trial, descending) during the sawtooth periods.
    trial: Option<(usize, usize, bool)>,
}

/// A stop of the tested leg on a detection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stop {
    pub t: f64,
    pub leg: usize,
    pub threshold: f64,
    pub trial: usize,
    /// F̂_z,gnd at the stop (N).
    pub estimate: f64,
}

/// What the experiment publishes after each update.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GroundExperimentState {
    /// The detector's output for the six legs.
    pub detections: [LegDetection; LEG_COUNT],
    /// Tested leg, threshold (N) and trial of the current sawtooth period, if any.
    pub trial: Option<(usize, f64, usize)>,
    /// Whether the tested leg is stopped on a detection.
    pub holding: bool,
    /// The stop that happened at this instant.
    pub stop: Option<Stop>,
    /// Every stop so far.
    pub stops: Vec<Stop>,
}

/// The experiment controller on legs `L`.
pub struct GroundExperimentController<L> {
    pub experiment: GroundExperiment,
    pub pis: [DigitalPi; JOINTS],
    /// Joint positions held.
    pub base: [f64; JOINTS],
    /// The descent of each leg at `base`.
    stance: [f64; LEG_COUNT],
    pub detector: GroundDetector<L>,
    legs: [L; LEG_COUNT],
    /// The descent where the tested leg stopped.
    hold: Option<f64>,
    /// When the descending half of the current sawtooth period began (s).
    descent_start: Option<f64>,
    state: Rc<RefCell<GroundExperimentState>>,
}

/// The joints of `leg` in the 18 joint values `q`.
fn leg_joints(q: &[f64; JOINTS], leg: usize) -> Vector3<f64> {
    Vector3::new(q[3 * leg], q[3 * leg + 1], q[3 * leg + 2])
}

impl<L: LoweredLeg + Clone> GroundExperimentController<L> {
    /// The controller on the legs of `detector` and the state it publishes.
    pub fn new(experiment: GroundExperiment, pis: [DigitalPi; JOINTS], base: [f64; JOINTS], detector: GroundDetector<L>) -> (Self, Rc<RefCell<GroundExperimentState>>) {
        let legs = detector.legs().clone();
        let stance = std::array::from_fn(|l| legs[l].descent(&leg_joints(&base, l)));
        let state = Rc::new(RefCell::new(GroundExperimentState::default()));
        (GroundExperimentController { experiment, pis, base, stance, detector, legs, hold: None, descent_start: None, state: state.clone() }, state)
    }
}

impl<L> GroundExperimentController<L> {
    /// Whether leg `l` stops at this instant ([`StopOn`]), the detector's `detections` of it.
    fn stops(&self, l: usize, threshold: f64, detections: &[LegDetection; LEG_COUNT], m: &Measurements) -> bool {
        match self.experiment.stop_on {
            StopOn::Estimate => detections[l].detected,
            StopOn::FootForce => m.foot_normal_forces.is_some_and(|f| f[l] >= threshold),
        }
    }
}

impl<L: LoweredLeg> Controller for GroundExperimentController<L> {
    fn update(&mut self, m: &Measurements) -> Command {
        let detections = self.detector.update(m);
        let mut references = self.base;
        let mut st = self.state.borrow_mut();
        st.stop = None;
        st.trial = None;
        if let Some(phase) = self.experiment.phase(m.t, &self.stance) {
            let l = phase.leg;
            match phase.trial {
                Some((threshold, trial, descending)) => {
                    self.descent_start = if descending { self.descent_start.or(Some(m.t)) } else { None };
                    // The filters follow the reversal at the top of the sawtooth (see
                    // SETTLING_TIME_CONSTANTS): no stop before.
                    let settled = self.descent_start.is_some_and(|t0| m.t - t0 >= settling_time() - 0.5 * self.pis[0].dt);
                    let threshold = self.experiment.thresholds[threshold];
                    self.detector.threshold = threshold;
                    st.trial = Some((l, threshold, trial));
                    match self.hold {
                        // Resume once the reference rises above the stop point.
                        Some(s) if phase.reference < s => self.hold = None,
                        Some(_) => {}
                        None if descending && settled && self.stops(l, threshold, &detections, m) => {
                            self.hold = Some(self.legs[l].descent(&leg_joints(&m.positions, l)));
                            let stop = Stop { t: m.t, leg: l, threshold, trial, estimate: detections[l].force };
                            st.stop = Some(stop);
                            st.stops.push(stop);
                        }
                        None => {}
                    }
                }
                None => (self.hold, self.descent_start) = (None, None),
            }
            let q = self.legs[l].lowered(&leg_joints(&self.base, l), self.hold.unwrap_or(phase.reference));
            references[3 * l..3 * l + 3].copy_from_slice(q.as_slice());
        }
        st.holding = self.hold.is_some();
        st.detections = detections;
        joint_command(&mut self.pis, self.experiment.feedforward.as_mut(), references, m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedule_of_table_5_6() {
        let e = GroundExperiment { legs: vec![2, 5], thresholds: vec![40.0, 60.0], trials: 2, ..Default::default() };
        assert!((e.speed() - 0.005).abs() < 1e-15);
        assert!((e.leg_duration() - (4.0 + 32.0 + REST_S)).abs() < 1e-12);
        let stance = 0.06;
        let base = [stance; LEG_COUNT];
        let at = |t: f64| e.phase(t, &base).unwrap();
        // Lift over P/4 = 2 s to q_v,0 − A.
        assert!((at(1.0).reference - 0.055).abs() < 1e-12 && at(1.0).trial.is_none());
        // Second sawtooth period (trial 1 of 40 N): down to q_v,0 + A at P/2, back at P.
        let p = at(2.0 + 8.0 + 4.0);
        assert_eq!((p.leg, p.trial.map(|t| (t.0, t.1))), (2, Some((0, 1))));
        assert!((p.reference - 0.07).abs() < 1e-12);
        assert!((at(2.0 + 8.0 + 6.0).reference - 0.06).abs() < 1e-12 && !at(2.0 + 8.0 + 6.0).trial.unwrap().2);
        // Third period: the second threshold.
        assert_eq!(at(2.0 + 16.0 + 1.0).trial.map(|t| t.0), Some(1));
        // Lowered back to the stance, then the next leg.
        assert!((at(2.0 + 32.0 + 2.5).reference - stance).abs() < 1e-12);
        assert_eq!(at(e.leg_duration() + 0.5).leg, 5);
        assert!(e.phase(e.duration() + 0.01, &base).is_none());
    }
}
