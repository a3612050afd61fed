//! The real robot as a [`Plant`] (architecture principle 3): the controller that drives the
//! simulated robot drives the six slave boards through the [`Master`], unchanged.
//!
//! Timing as on AMRU5 (Section 2.3.2): the command computed from the measurements of period k
//! is broadcast at the deadline of period k + 1, where the boards apply it and latch the
//! encoders, currents and supply of period k + 1 ("position used in the master control update
//! is stored as soon as the PWM signal has been applied"). So [`Plant::actuate`] stores the
//! command and [`Plant::wait_period`] broadcasts it at the next deadline and returns as soon as
//! the six fresh packets of that period are in. A period with a packet missing does not run
//! the controller: the same command is broadcast again at the next deadline (the thesis: "the
//! update cycle will be missed, but corrected during the next cycle").
//!
//! Conversions, per joint k = 3 leg + j ([`super::drive`]): position = counts · 2π / (500 n)
//! (the robot's encoder of the joint; with servos, from the middle of the servo's sensor); the
//! voltage u becomes the duty round(u / U · 1023) with U the supply measured by that leg's
//! board, or, with servos, the goal (the reference without a friction feed-forward) the
//! nearest register; the supply the controller sees is the lowest of the six.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use super::clock::Clock;
use super::config::LinkConfig;
use super::drive::{Drive, JointScale};
use super::master::{LinkEvent, LinkStats, Master, SafetyStop, StopReason};
use super::protocol::SlaveReply;
use super::LinkError;
use crate::control::{Command, Measurements, Plant};
use crate::hexapod::{JOINTS, LEG_COUNT};

/// A period whose slave packets did not all arrive: no measurements, the controller did not run.
#[derive(Clone, Debug, PartialEq)]
pub struct MissedPeriod {
    pub t: f64,
    pub period: u64,
    /// The voltages held over the period that ended then (the last supplies measured).
    pub voltages: [f64; JOINTS],
    /// Lateness of its broadcast (s).
    pub lateness: f64,
}

/// The robot behind the master/slave link, its boards driven by setpoints `S`.
pub struct UdpPlant<S: Drive> {
    master: Master<S>,
    scales: [JointScale; JOINTS],
    dt: f64,
    replies: [SlaveReply; LEG_COUNT],
    measurements: Measurements,
    /// The controller's command, to broadcast at the next deadline.
    next: [S; JOINTS],
    /// The last broadcast, and the one before: held over the period ending at the measurements.
    broadcast: [S; JOINTS],
    held: [S; JOINTS],
    ready_at: Instant,
    /// The period of the first measurements: t = 0 there.
    origin: u64,
    /// The periods missed just before the current measurements.
    missed: Vec<MissedPeriod>,
    /// Time from the last packet of a period to the controller's command (controller and
    /// recording), per complete period (s).
    pub controller_time: Vec<f64>,
    interrupt: Arc<AtomicBool>,
}

impl<S: Drive> UdpPlant<S> {
    /// Opens the link with deadlines on `clock` and waits for the six slaves (the zero command
    /// broadcast until they all answer); `scales`: the joints' position counts. `interrupt`
    /// stops the robot at the next period when set.
    pub fn connect(config: &LinkConfig, clock: Clock, scales: [JointScale; JOINTS], interrupt: Arc<AtomicBool>) -> Result<Self, LinkError> {
        let mut master = Master::bind(config, clock)?;
        master.start_clock();
        let replies = master.connect()?;
        let mut plant = UdpPlant {
            master,
            scales,
            dt: config.timing.period.as_secs_f64(),
            replies,
            measurements: Measurements::default(),
            next: [S::default(); JOINTS],
            broadcast: [S::default(); JOINTS],
            held: [S::default(); JOINTS],
            ready_at: Instant::now(),
            origin: 0,
            missed: Vec::new(),
            controller_time: Vec::new(),
            interrupt,
        };
        plant.origin = plant.master.period();
        plant.accept(replies);
        Ok(plant)
    }

    fn accept(&mut self, replies: [SlaveReply; LEG_COUNT]) {
        self.replies = replies;
        let m = &mut self.measurements;
        m.t = (self.master.period() - self.origin) as f64 * self.dt;
        for k in 0..JOINTS {
            let r = &replies[k / 3];
            m.positions[k] = self.scales[k].position(r.counts[k % 3]);
            m.currents[k] = r.currents()[k % 3];
        }
        m.supply_voltage = replies.iter().map(SlaveReply::supply_voltage).fold(f64::INFINITY, f64::min);
        m.pose = None;
        self.ready_at = Instant::now();
    }

    /// The periods missed just before the current measurements, in order.
    pub fn missed(&self) -> &[MissedPeriod] {
        &self.missed
    }

    /// Index of the period of the current measurements.
    pub fn period_index(&self) -> u64 {
        self.master.period()
    }

    /// The slave packets of the current measurements.
    pub fn replies(&self) -> &[SlaveReply; LEG_COUNT] {
        &self.replies
    }

    /// The voltages held over the period that ended at the current measurements: the duties
    /// broadcast then, times the supply each board measured (NaN with servos).
    pub fn held_voltages(&self) -> [f64; JOINTS] {
        std::array::from_fn(|k| self.held[k].held_voltage(self.replies[k / 3].supply_voltage()))
    }

    /// The servo goals `command` becomes, to be broadcast at the next deadline (rad or m, whole
    /// registers; NaN with motors).
    pub fn goals(&self, command: &Command) -> [f64; JOINTS] {
        std::array::from_fn(|k| S::commanded(command, k, &self.scales[k], self.replies[k / 3].supply_voltage()).goal(&self.scales[k]))
    }

    /// The run number in the master's commands.
    pub fn run(&self) -> u32 {
        self.master.run()
    }

    /// The link failed with `error` during the run: every motor to 0 V, and the stop that says so.
    pub fn fail(&mut self, error: &LinkError) -> SafetyStop {
        self.master.stop_for(StopReason::LinkFailure { error: error.to_string() })
    }

    pub fn stats(&self) -> &LinkStats {
        &self.master.stats
    }

    pub fn events(&self) -> &[LinkEvent] {
        &self.master.events
    }

    /// When the last packet of the current period arrived after its broadcast (s).
    pub fn last_reply(&self) -> f64 {
        self.master.arrivals().iter().max().map_or(0.0, |d| d.as_secs_f64())
    }

    /// Lateness of the current period's broadcast (s).
    pub fn lateness(&self) -> f64 {
        self.master.stats.lateness.last().copied().unwrap_or(0.0)
    }

    /// Puts every motor to 0 V, every servo's torque off (the end of a run), counts what arrives during one more period,
    /// and returns what the master counted.
    pub fn finish(mut self) -> (LinkStats, Vec<LinkEvent>, Vec<f64>) {
        self.master.stop();
        self.master.linger(self.master.config().timing.period);
        (std::mem::take(&mut self.master.stats), std::mem::take(&mut self.master.events), std::mem::take(&mut self.controller_time))
    }
}

impl<S: Drive> Plant for UdpPlant<S> {
    type Error = LinkError;

    fn period(&self) -> f64 {
        self.dt
    }

    fn measure(&mut self) -> Measurements {
        self.measurements.clone()
    }

    fn actuate(&mut self, command: &Command) {
        self.next = std::array::from_fn(|k| S::commanded(command, k, &self.scales[k], self.replies[k / 3].supply_voltage()));
    }

    fn wait_period(&mut self) -> Result<(), LinkError> {
        self.controller_time.push(self.ready_at.elapsed().as_secs_f64());
        if self.interrupt.load(Ordering::Relaxed) {
            return Err(self.master.safety_stop(StopReason::Interrupted));
        }
        self.master.check_overrun()?;
        let setpoints = self.next;
        self.missed.clear();
        loop {
            let outcome = self.master.run_period(&setpoints);
            self.held = self.broadcast;
            self.broadcast = setpoints;
            if let Some(replies) = outcome? {
                self.accept(replies);
                return Ok(());
            }
            let period = self.master.period();
            self.missed.push(MissedPeriod { t: (period - self.origin) as f64 * self.dt, period, voltages: self.held_voltages(), lateness: self.lateness() });
            if self.interrupt.load(Ordering::Relaxed) {
                return Err(self.master.safety_stop(StopReason::Interrupted));
            }
        }
    }
}
