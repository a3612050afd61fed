//! A scenario's controller driving the robot through the link, recorded like a simulation
//! (`hexadyn robot run`): the same controller as [`crate::scenario::run_scenario`], built by
//! [`ScenarioController`], on the [`UdpPlant`] instead of the simulated robot, on a dedicated
//! thread (real-time when the configuration asks for it).
//!
//! One row per period, what the master saw (a missed period has NaN measurements and
//! references):
//!
//! | columns | unit | |
//! | --- | --- | --- |
//! | `t` | s | period index × Δt of the measurements |
//! | `period` | 1 | index of the period (its command's sequence number modulo 2^16) |
//! | `q_r[i]`, `q_v[i]`, `q_h[i]` | rad, m, m | encoder positions |
//! | `q_r_ref[i]` ... | rad, m | joint references computed at t (modes `pi` and `gait`) |
//! | gait columns | | as in a simulation (`X_ref` ... `phase[l]` ... `foot_ref_z[l]`) |
//! | `q_r_goal[i]` ... | rad, m | with servos: the goal sent at the next deadline (the nearest register) |
//! | `u_q_v[i]` ... | V | voltage held over the period ending at t: duty / 1023 × the board's supply (NaN with servos) |
//! | `i_q_v[i]` ... | A | motor current measured by the board |
//! | `u_supply` | V | lowest supply voltage of the six boards |
//! | `E_el_q_v[i]`, `E_joule_q_v[i]` | J | cumulative Σ u i Δt (NaN with servos) and Σ (R + R_bridge) i² Δt of the samples |
//! | `E_fric_q_v[i]` | J | not measured on the robot: NaN |
//! | `lateness` | s | lateness of the broadcast of the period against its deadline |
//! | `last_reply` | s | when the last slave packet of the period arrived after the broadcast |
//! | `missed_periods` | 1 | periods missed so far (a slave packet missing at the deadline) |
//!
//! The joint columns are named after the robot's joints (`coxa[i]` ... on the PhantomX); with
//! servos the voltage figures of the summary are NaN (the servos' own loops set the voltages).
//!
//! The run makes as many controller updates as the simulation of the scenario; each missed
//! period (no update) adds a period, so the last row's t exceeds the duration by the missed
//! periods. A safety stop ends the run early with the rows up to it; the summary says why
//! (`safety_stop`, its message, and `safety_stop_reason`: `missing_replies`,
//! `controller_overrun`, `master_overrun`, `interrupted` or `link_failure`, a socket error
//! during the run; `none` without a stop).

use std::borrow::Cow;
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::clock::{realtime_thread, Clock, Percentiles};
use super::config::LinkConfig;
use super::drive::{Drive, JointScale};
use super::master::{LinkEvent, LinkStats, SafetyStop};
use super::protocol::{Duty, Goal, Protocol, COUNT_MAX, COUNT_MIN, GOAL_MAX};
use super::{LinkError, UdpPlant};
use crate::control::{Command, Measurements, StopOn};
use crate::description::serial::DriveControl;
use crate::description::Robot;
use crate::hexapod::{LegJoints, JOINTS};
use crate::robot::recorder::{Recorder, TimeSeries};
use crate::robot::simulation::run_until;
use crate::scenario::{per_joint_entries, GaitColumns, Scenario, ScenarioController, SummaryValue};

/// How often [`run_robot`] reports progress.
const PROGRESS_INTERVAL: Duration = Duration::from_millis(50);

/// The outcome of a run on the robot.
#[derive(Clone, Debug)]
pub struct RobotRun {
    pub series: TimeSeries,
    /// Totals and link figures, names with their unit as suffix.
    pub summary: Vec<(Cow<'static, str>, SummaryValue)>,
    /// Why the master stopped the robot early, if it did.
    pub stop: Option<SafetyStop>,
    pub stats: LinkStats,
    /// The dropped datagrams and missed periods, as logged (the first 200).
    pub events: Vec<LinkEvent>,
}

/// The packets of the scenario's robot: motor duties for DC motors (AMRU5's boards, serial
/// legs under the master's PI), servo goals for position servos. Refuses a robot whose counts
/// the packets cannot carry: servo sensors of more than 2048 counts (11-bit positions), or
/// joint ranges beyond the packets' counts.
pub(crate) fn check_robot(s: &Scenario) -> Result<Protocol, LinkError> {
    let Robot::Serial(r) = &s.robot else { return Ok(Protocol::Motors) };
    let protocol = if r.has_servos() { Protocol::Servos } else { Protocol::Motors };
    let file = s.robot.origin();
    for (drive, name) in r.drives.iter().zip(r.joints.names()) {
        if let DriveControl::Servo(servo) = &drive.control {
            let counts = servo.sensor_counts;
            if counts.fract() != 0.0 || counts > f64::from(GOAL_MAX) + 1.0 {
                return Err(LinkError::Mismatch(format!("{file}: drives.{name}.servo.sensor_counts = {counts}: not a servo position the link carries; allowed: a whole number of counts up to 2048 (the 11-bit positions of docs/protocol.md, servo variant)")));
            }
        }
    }
    let (low, high) = match protocol {
        Protocol::Motors => (i64::from(COUNT_MIN), i64::from(COUNT_MAX)),
        Protocol::Servos => (0, i64::from(GOAL_MAX)),
    };
    let encoders = s.robot.parts(&s.model).encoders;
    for k in 0..JOINTS {
        let scale = JointScale::new(protocol, encoders[k]);
        let (lower, upper) = s.robot.joint_range(k);
        for (end, q) in [("lower", lower), ("upper", upper)] {
            let count = scale.count(q);
            if !(low..=high).contains(&count) {
                return Err(LinkError::Mismatch(format!(
                    "{file}: legs[{}].joints[{}].{end} = {q}: count {count} of the joint's position sensor, beyond the link's packets; allowed: a joint range within counts {low}..{high} (docs/protocol.md)",
                    k / 3,
                    k % 3
                )));
            }
        }
    }
    Ok(protocol)
}

/// Checks that the scenario can run on the link: a robot whose counts the packets carry, the
/// same control period, and no navigation system (the robot has none, Section 2.3.2: level A
/// is not implemented). Returns the packets of the robot.
pub fn check(s: &Scenario, config: &LinkConfig) -> Result<Protocol, LinkError> {
    let protocol = check_robot(s)?;
    let link = config.timing.period.as_secs_f64();
    if (link - s.period()).abs() > 1e-9 * s.period() {
        return Err(LinkError::Mismatch(format!(
            "{}: field `timing.period_s` = {link}: not the control period of scenario {} ({} s); allowed: {} s (the controller's Δt)",
            config.origin,
            s.origin,
            s.period(),
            s.period()
        )));
    }
    if s.ground_detection.as_ref().is_some_and(|g| g.stop_on == StopOn::FootForce) {
        return Err(LinkError::Mismatch(format!("{}: ground_detection.stop_on = \"foot_force\", but the robot has no foot force sensors; allowed: stop_on = \"estimate\" (the ground force estimated from the motor currents)", s.origin)));
    }
    if s.gait.as_ref().is_some_and(|g| g.navigation) {
        return Err(LinkError::Mismatch(format!("{}: gait.navigation = true, but the robot has no navigation system; allowed: a scenario with navigation = false", s.origin)));
    }
    Ok(protocol)
}

/// A run on its master thread.
pub struct RunHandle {
    thread: JoinHandle<Result<RobotRun, LinkError>>,
    periods: Arc<AtomicU64>,
    interrupt: Arc<AtomicBool>,
    period: f64,
}

impl RunHandle {
    /// Time of the last recorded measurements (s).
    pub fn t(&self) -> f64 {
        self.periods.load(Ordering::Relaxed) as f64 * self.period
    }

    /// Asks the master to stop the robot at the next period (0 V, then the run ends).
    pub fn interrupt(&self) {
        self.interrupt.store(true, Ordering::Relaxed);
    }

    pub fn is_finished(&self) -> bool {
        self.thread.is_finished()
    }

    pub fn join(self) -> Result<RobotRun, LinkError> {
        self.thread.join().unwrap_or_else(|_| Err(LinkError::Emulator("the master thread panicked".into())))
    }
}

/// Starts the run on a dedicated master thread, its deadlines on `clock` (the robot:
/// [`Clock::Monotonic`]).
pub fn spawn_robot_run(s: Scenario, config: LinkConfig, clock: Clock) -> Result<RunHandle, LinkError> {
    let protocol = check(&s, &config)?;
    let periods = Arc::new(AtomicU64::new(0));
    let interrupt = Arc::new(AtomicBool::new(false));
    let period = s.period();
    let (p, i) = (periods.clone(), interrupt.clone());
    let thread = std::thread::Builder::new()
        .name("hexadyn-master".into())
        .spawn(move || match protocol {
            Protocol::Motors => master_thread::<Duty>(&s, &config, clock, &p, i),
            Protocol::Servos => master_thread::<Goal>(&s, &config, clock, &p, i),
        })
        .map_err(|e| LinkError::Emulator(format!("cannot start the master thread: {e}")))?;
    Ok(RunHandle { thread, periods, interrupt, period })
}

/// Runs the scenario's controller on the robot, deadlines on `clock`, and waits for the end;
/// `progress` is called with the time of the last measurements about every 50 ms and may stop
/// the run.
pub fn run_robot(s: &Scenario, config: &LinkConfig, clock: Clock, mut progress: impl FnMut(f64) -> ControlFlow<()>) -> Result<RobotRun, LinkError> {
    let handle = spawn_robot_run(s.clone(), config.clone(), clock)?;
    while !handle.is_finished() {
        std::thread::sleep(PROGRESS_INTERVAL);
        if progress(handle.t()).is_break() {
            handle.interrupt();
        }
    }
    handle.join()
}

fn master_thread<S: Drive>(s: &Scenario, config: &LinkConfig, clock: Clock, periods: &AtomicU64, interrupt: Arc<AtomicBool>) -> Result<RobotRun, LinkError> {
    let started = Instant::now();
    let realtime = realtime_thread(config.timing.realtime_priority);
    // Everything is built before the link starts: the first deadline must not wait on it.
    let mut controller = ScenarioController::new(s);
    let gait = controller.gait_columns();
    let pi = s.control.tracks_references();
    let parts = s.robot.parts(&s.model);
    let resistance = parts.motors.map(|m| m.r + m.r_bridge);
    let servos = S::PROTOCOL == Protocol::Servos;
    let mut row = Row { rec: Recorder::default(), joints: s.robot.joints().clone(), gait, pi, servos, resistance, last_t: None, e_el: [0.0; JOINTS], e_joule: [0.0; JOINTS], max_voltage: 0.0, saturated: 0, commands: 0, tracking: [0.0; 3] };
    let scales = parts.encoders.map(|e| JointScale::new(S::PROTOCOL, e));
    let mut plant = UdpPlant::<S>::connect(config, clock, scales, interrupt)?;
    // As many controller updates as in a simulation: the controllers count their updates (the
    // gait integrates its body reference by Δt per update), so a missed period, which runs no
    // update, lengthens the run by one period.
    let outcome = run_until(&mut plant, &mut controller, s.duration, |p, m, cmd| {
        row.record(p, m, cmd);
        periods.store((m.t / s.period()).round() as u64, Ordering::Relaxed);
        ControlFlow::Continue(())
    });
    let stop = match outcome {
        Ok(_) => None,
        Err(LinkError::Stopped(stop)) => Some(stop),
        Err(e) => Some(plant.fail(&e)),
    };
    let (mut stats, events, controller_time) = plant.finish();
    stats.realtime = realtime;
    let summary = row.summary(s, &stats, &controller_time, stop.as_ref(), started.elapsed().as_secs_f64());
    Ok(RobotRun { series: row.rec.finish(), summary, stop, stats, events })
}

/// What one row holds.
struct Sample<'a> {
    t: f64,
    period: u64,
    positions: &'a [f64; JOINTS],
    references: &'a [f64; JOINTS],
    goals: &'a [f64; JOINTS],
    voltages: &'a [f64; JOINTS],
    currents: &'a [f64; JOINTS],
    supply: f64,
    lateness: f64,
    last_reply: f64,
    missed: u64,
}

/// The recorder of a run and the totals it keeps.
struct Row {
    rec: Recorder,
    /// The robot's joint names and kinds (column names and units).
    joints: LegJoints,
    gait: GaitColumns,
    pi: bool,
    /// Position servos: the goal columns, no voltages.
    servos: bool,
    /// R + R_bridge of each joint's circuit (Ω).
    resistance: [f64; JOINTS],
    last_t: Option<f64>,
    e_el: [f64; JOINTS],
    e_joule: [f64; JOINTS],
    max_voltage: f64,
    saturated: u64,
    commands: u64,
    tracking: [f64; 3],
}

impl Row {
    fn record<S: Drive>(&mut self, p: &UdpPlant<S>, m: &Measurements, cmd: &Command) {
        let nan = [f64::NAN; JOINTS];
        for missed in p.missed() {
            self.put(&Sample { t: missed.t, period: missed.period, positions: &nan, references: &nan, goals: &nan, voltages: &missed.voltages, currents: &nan, supply: f64::NAN, lateness: missed.lateness, last_reply: f64::NAN, missed: p.stats().missed_periods });
        }
        let u = p.held_voltages();
        let dt = self.last_t.map_or(0.0, |t| m.t - t);
        self.last_t = Some(m.t);
        for k in 0..JOINTS {
            self.e_el[k] += u[k] * m.currents[k] * dt;
            self.e_joule[k] += self.resistance[k] * m.currents[k] * m.currents[k] * dt;
            self.max_voltage = self.max_voltage.max(u[k].abs());
            self.commands += 1;
            if cmd.voltages[k].abs() >= m.supply_voltage {
                self.saturated += 1;
            }
            if self.pi {
                self.tracking[k % 3] = self.tracking[k % 3].max((cmd.references[k] - m.positions[k]).abs());
            }
        }
        let goals = p.goals(cmd);
        self.put(&Sample { t: m.t, period: p.period_index(), positions: &m.positions, references: &cmd.references, goals: &goals, voltages: &u, currents: &m.currents, supply: m.supply_voltage, lateness: p.lateness(), last_reply: p.last_reply(), missed: p.stats().missed_periods });
    }

    /// One row. A missed period gets a row too (NaN where nothing was measured, the energies
    /// carried over, the gait columns of the last update) so that the rows stay one period
    /// apart.
    fn put(&mut self, x: &Sample) {
        let s = |x: &str| x.to_string();
        let rec = &mut self.rec;
        rec.begin_row();
        rec.put(x.t, || (s("t"), "s", s("control instant: period index times the control period")));
        rec.put(x.period as f64, || (s("period"), "1", s("period index (the command's sequence number modulo 2^16)")));
        for k in 0..JOINTS {
            rec.put(x.positions[k], || (self.joints.column("", k, ""), self.joints.unit(k, ("rad", "m")), format!("encoder position, leg {} (NaN: period missed)", k / 3)));
        }
        if self.pi {
            for k in 0..JOINTS {
                rec.put(x.references[k], || (self.joints.column("", k, "_ref"), self.joints.unit(k, ("rad", "m")), format!("PI reference computed at t, leg {} (NaN: period missed)", k / 3)));
            }
        }
        if self.servos {
            for k in 0..JOINTS {
                rec.put(x.goals[k], || (self.joints.column("", k, "_goal"), self.joints.unit(k, ("rad", "m")), format!("servo goal sent at the next deadline, the nearest position register, leg {} (NaN: period missed)", k / 3)));
            }
        }
        self.gait.record(rec);
        for k in 0..JOINTS {
            rec.put(x.voltages[k], || (self.joints.column("u_", k, ""), "V", s("voltage held over the period ending at t: PWM duty / 1023 times the board's supply")));
        }
        for k in 0..JOINTS {
            rec.put(x.currents[k], || (self.joints.column("i_", k, ""), "A", s("motor current measured by the slave board (NaN: period missed)")));
        }
        rec.put(x.supply, || (s("u_supply"), "V", s("lowest supply voltage measured by the six boards")));
        for k in 0..JOINTS {
            rec.put(self.e_el[k], || (self.joints.column("E_el_", k, ""), "J", s("cumulative electrical energy of the samples, sum of u i dt")));
        }
        for k in 0..JOINTS {
            rec.put(self.e_joule[k], || (self.joints.column("E_joule_", k, ""), "J", s("cumulative Joule losses of the samples, sum of (R + R_bridge) i^2 dt")));
        }
        for k in 0..JOINTS {
            rec.put(f64::NAN, || (self.joints.column("E_fric_", k, ""), "J", s("friction work: not measured on the robot (NaN)")));
        }
        rec.put(x.lateness, || (s("lateness"), "s", s("lateness of the period's broadcast against its deadline")));
        rec.put(x.last_reply, || (s("last_reply"), "s", s("arrival of the period's last slave packet after the broadcast (NaN: period missed)")));
        rec.put(x.missed as f64, || (s("missed_periods"), "1", s("periods missed so far (a slave packet missing at the deadline)")));
        rec.end_row();
    }

    fn summary(&self, s: &Scenario, stats: &LinkStats, controller_time: &[f64], stop: Option<&SafetyStop>, wall: f64) -> Vec<(Cow<'static, str>, SummaryValue)> {
        use SummaryValue::{Count, Flag, Number, Text};
        let rows = self.rec.rows() as u64;
        // Rows of missed periods included: one row per period.
        let duration = self.last_t.unwrap_or(0.0);
        let energy: f64 = self.e_el.iter().sum();
        let lateness = Percentiles::of(&stats.lateness);
        let last_reply = Percentiles::of(&stats.last_reply);
        let controller = Percentiles::of(controller_time);
        let entries = [
            ("scenario", Text(s.name.clone())),
            ("control", Text(s.control.name().to_string())),
            ("plant", Text("robot link".to_string())),
            ("duration_s", Number(duration)),
            ("wall_time_s", Number(wall)),
            ("control_periods", Count(rows.saturating_sub(1))),
            ("rows", Count(rows)),
            ("safety_stop", Text(stop.map_or_else(|| "none".to_string(), ToString::to_string))),
            ("safety_stop_reason", Text(stop.map_or("none", |s| s.reason.kind()).to_string())),
            ("realtime", Flag(stats.realtime)),
            ("broadcasts", Count(stats.broadcasts)),
            ("missed_periods", Count(stats.missed_periods)),
            ("lateness_p50_s", Number(lateness.p50)),
            ("lateness_p99_s", Number(lateness.p99)),
            ("lateness_max_s", Number(lateness.max)),
            ("last_reply_p50_s", Number(last_reply.p50)),
            ("last_reply_max_s", Number(last_reply.max)),
            ("controller_p99_s", Number(controller.p99)),
            ("controller_max_s", Number(controller.max)),
            ("packets_rejected_size", Count(stats.rejected.size)),
            ("packets_rejected_checksum", Count(stats.rejected.checksum)),
            ("packets_rejected_version", Count(stats.rejected.version)),
            ("packets_rejected_range", Count(stats.rejected.range + stats.wrong_leg)),
            ("packets_stale", Count(stats.stale + stats.future)),
            ("packets_duplicate", Count(stats.duplicates)),
            ("packets_unknown_source", Count(stats.unknown_source)),
            ("robot_mass_kg", Number(s.robot.total_mass_kg())),
            ("energy_electrical_j", Number(energy)),
            ("average_power_w", Number(if duration > 0.0 { energy / duration } else { 0.0 })),
            ("max_abs_voltage_v", Number(if self.servos { f64::NAN } else { self.max_voltage })),
            ("saturated_fraction", Number(if self.servos { f64::NAN } else if self.commands > 0 { self.saturated as f64 / self.commands as f64 } else { 0.0 })),
        ];
        let mut v: Vec<_> = entries.into_iter().map(|(n, x)| (Cow::Borrowed(n), x)).collect();
        if self.pi {
            v.extend(per_joint_entries(&self.joints, "max_tracking_error", self.tracking, ("rad", "m")));
        }
        v
    }
}
