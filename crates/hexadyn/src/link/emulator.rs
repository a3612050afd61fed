//! Six slave boards emulated on the simulated robot, for testing the master and a scenario's
//! controller without the robot.
//!
//! Each command packet is handled as a board does (Section 2.3.2, Fig. 2.19): the boards apply
//! the 18 duties (with servos, the 18 goals: [`super::drive`]) and latch what they measure at
//! that instant — the encoder counts (500 per motor revolution on AMRU5; with servos, their
//! present positions), the motor currents and the supply voltage of the simulated robot — then
//! the slave of leg l sends its packet t_s0 + l Δt_s after the broadcast (2.5 ms + l × 0.5 ms,
//! Figs. 2.21-2.22) to the address the command came from. Meanwhile the multiphysics model
//! advances one control period with the applied voltages (duty / 1023 × its supply) or goals. The
//! currents are those at the end of the previous period (the model has no time between the
//! PWM update and the A/D conversion).
//!
//! The boards take the commands by the rules of [`super::slave`]: they follow the master of
//! their handshake (its address, port and run number), apply its new commands only and count
//! every other datagram by reason; their watchdog sets every output to 0 V (every servo's torque
//! off) 50 ms after the last command applied and forgets the master. Faults
//! ([`super::faults`]) are applied to the outgoing packets.
//!
//! On the monotonic clock, two threads: the model thread receives the commands, latches,
//! schedules the packets and steps the model; the sender thread sends each packet at its time.
//! With a real-time priority in the configuration, the sender runs at it and the model thread
//! one below; the model thread wakes for the watchdog when it is due (`ppoll`). On a virtual
//! clock ([`EmulatorOptions::clock`]) the model thread is the same and the packets go to the
//! clock's agenda, sent as the master's virtual time passes their due time
//! ([`super::virtual_clock`]); the watchdog is checked against that time before each datagram,
//! every 20 ms of wall time and at the end, and fires dated when it was due. The emulator stops
//! on [`Emulator::stop`], or by itself after `idle_timeout` (wall time) without a command once
//! the first one came.

use std::net::{SocketAddr, UdpSocket};
use std::os::fd::AsRawFd;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::agenda::{Agenda, Datagram};
use super::clock::{realtime_thread, sleep_until, wait_readable, Clock, Percentiles, Wake};
use super::config::LinkConfig;
use super::drive::{Drive, JointScale};
use super::faults::{FaultCounts, FaultInjector, Faults, Outgoing};
use super::protocol::{Commands, Duty, Goal, Protocol, Setpoint, SlaveReply, RECEIVE_BUFFER};
use super::slave::{RefusalCounts, Slave, WatchdogTrip};
use super::virtual_clock::VirtualClock;
use super::LinkError;
use crate::control::{Command, Plant};
use crate::hexapod::{JOINTS, LEG_COUNT};
use crate::robot::simulation::SimulatedRobot;
use crate::scenario::{settled_robot, Scenario};

/// How often a blocked thread checks whether it must stop.
const STOP_POLL: Duration = Duration::from_millis(20);

/// Options of an emulator run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EmulatorOptions {
    pub faults: Faults,
    /// Stop after this long without a command, once the first came; `None`: run until stopped.
    pub idle_timeout: Option<Duration>,
    /// Keep the per-period history (tests and comparisons).
    pub history: bool,
    /// The slaves' time: [`Clock::Monotonic`] answers in real time (`hexadyn robot emulate`); a
    /// [`Clock::Virtual`] in lock-step with a master on the same clock.
    pub clock: Clock,
}

/// One applied command and what the boards latched when applying it.
#[derive(Clone, Debug, PartialEq)]
pub struct EmulatedPeriod {
    pub seq: u16,
    /// The setpoint bits of each command word (bits 0-11; all 0: the zero command).
    pub setpoints: [u16; JOINTS],
    /// The position counts latched (encoder counts, or servo positions), joint k = 3 leg + j.
    pub counts: [i32; JOINTS],
    /// The body pose X, Y, Z, yaw, pitch, roll of the simulated robot at the latch.
    pub body: [f64; 6],
    /// Simulated time at the latch (s).
    pub t: f64,
}

/// What an emulator run did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EmulatorReport {
    /// Commands applied (each advanced the model by one period).
    pub commands: u64,
    /// Datagrams of the command port not applied, by reason: not decoded, old, not from the
    /// boards' master.
    pub refused: RefusalCounts,
    /// Each time the watchdog set the outputs to 0 V: on the monotonic clock `at` is when the
    /// model thread did it, on a virtual clock when it was due.
    pub watchdog: Vec<WatchdogTrip>,
    /// The setpoint bits the boards hold at the end (all 0: every output at 0 V).
    pub held: [u16; JOINTS],
    /// Datagrams sent by the six slaves (faults included).
    pub sent: u64,
    pub faults: FaultCounts,
    /// Whether the threads ran with a real-time priority.
    pub realtime: bool,
    /// Wall time the model took per period (s): above the period minus the replies' timing, the
    /// emulator cannot keep up in real time.
    pub step_time: Percentiles,
    /// The applied commands in order, with `history`.
    pub history: Vec<EmulatedPeriod>,
    /// Body pose of the simulated robot at the end (X, Y, Z, yaw, pitch, roll).
    pub body: [f64; 6],
    /// Simulated time at the end (s).
    pub t: f64,
    /// Why the emulator stopped early: the model failed, or a socket error.
    pub error: Option<String>,
}

/// Six slaves running on their threads.
pub struct Emulator {
    stop: Arc<AtomicBool>,
    model: Option<JoinHandle<EmulatorReport>>,
    sender: Option<JoinHandle<Result<u64, String>>>,
    clock: Clock,
    command_address: SocketAddr,
}

impl Emulator {
    /// Settles the scenario's robot, binds the command socket (the configuration's broadcast
    /// address and port; port 0 picks a free one, see [`Self::command_address`]) and the six
    /// slave sockets, and starts answering.
    pub fn start(s: &Scenario, config: &LinkConfig, options: EmulatorOptions) -> Result<Emulator, LinkError> {
        options.faults.validate().map_err(LinkError::Emulator)?;
        let protocol = super::run::check_robot(s)?;
        let robot = settled_robot(s)?;
        let socket_error = |what, address: String| move |source| LinkError::Socket { what, address, source };
        let commands = UdpSocket::bind(config.broadcast).map_err(socket_error("cannot listen for the commands on", config.broadcast.to_string()))?;
        commands.set_read_timeout(Some(STOP_POLL)).map_err(socket_error("cannot set a timeout on", config.broadcast.to_string()))?;
        let command_address = commands.local_addr().map_err(socket_error("cannot read the address of", config.broadcast.to_string()))?;
        let mut slaves = Vec::with_capacity(LEG_COUNT);
        for (leg, a) in config.slaves.iter().enumerate() {
            let what = if leg == 0 { "cannot open the slave socket" } else { "cannot open a slave socket" };
            slaves.push(UdpSocket::bind(a).map_err(socket_error(what, a.to_string()))?);
        }
        let stop = Arc::new(AtomicBool::new(false));
        let timing = config.timing;
        let clock = options.clock.clone();
        let (outbox, sender) = match &clock {
            Clock::Monotonic => {
                let (jobs, queue) = mpsc::channel::<Datagram>();
                let stop_sender = stop.clone();
                let sender = std::thread::Builder::new()
                    .name("hexadyn-slaves".into())
                    .spawn(move || {
                        realtime_thread(timing.realtime_priority);
                        send_loop(&slaves, &queue, &stop_sender)
                    })
                    .map_err(|e| LinkError::Emulator(format!("cannot start the sender thread: {e}")))?;
                (Outbox::Sender(jobs), Some(sender))
            }
            Clock::Virtual(v) => {
                v.attach(Arc::new(slaves));
                (Outbox::Virtual(v.clone()), None)
            }
        };
        let model = match protocol {
            Protocol::Motors => spawn_model::<Duty>(robot, s.initial.joints, commands, outbox, stop.clone(), timing, options),
            Protocol::Servos => spawn_model::<Goal>(robot, s.initial.joints, commands, outbox, stop.clone(), timing, options),
        }
        .map_err(|e| LinkError::Emulator(format!("cannot start the emulator thread: {e}")))?;
        Ok(Emulator { stop, model: Some(model), sender, clock, command_address })
    }

    /// The address the emulator listens on for the commands.
    pub fn command_address(&self) -> SocketAddr {
        self.command_address
    }

    /// Whether the emulator stopped by itself (idle timeout or failure).
    pub fn is_finished(&self) -> bool {
        self.model.as_ref().is_none_or(JoinHandle::is_finished)
    }

    /// Stops the slaves and returns the report.
    pub fn stop(mut self) -> EmulatorReport {
        self.shutdown()
    }

    /// Waits until the emulator stops by itself (idle timeout) or `interrupt` is set.
    pub fn wait(mut self, interrupt: &AtomicBool) -> EmulatorReport {
        while !self.is_finished() && !interrupt.load(Ordering::Relaxed) {
            std::thread::sleep(STOP_POLL);
        }
        self.shutdown()
    }

    fn shutdown(&mut self) -> EmulatorReport {
        self.stop.store(true, Ordering::Relaxed);
        let mut report = match self.model.take().map(JoinHandle::join) {
            Some(Ok(r)) => r,
            _ => EmulatorReport { error: Some("the emulator thread panicked".into()), ..Default::default() },
        };
        if let Clock::Virtual(v) = &self.clock {
            let (sent, error) = v.sent();
            report.sent = sent;
            report.error = report.error.or(error);
        }
        match self.sender.take().map(JoinHandle::join) {
            None => {}
            Some(Ok(Ok(sent))) => report.sent = sent,
            Some(Ok(Err(e))) => report.error = report.error.or(Some(e)),
            _ => report.error = report.error.or(Some("the sender thread panicked".into())),
        }
        report
    }
}

impl Drop for Emulator {
    fn drop(&mut self) {
        if self.model.is_some() {
            self.shutdown();
        }
    }
}

/// Where the model thread posts the slave packets, and the slaves' time.
enum Outbox {
    /// The sender thread, which sends each packet at its time on the monotonic clock.
    Sender(Sender<Datagram>),
    /// The agenda of a virtual clock, sent as its master's time passes.
    Virtual(Arc<VirtualClock>),
}

impl Outbox {
    fn now(&self) -> Instant {
        match self {
            Outbox::Sender(_) => Instant::now(),
            Outbox::Virtual(v) => v.now(),
        }
    }

    fn post(&self, d: Datagram) {
        match self {
            // The sender outlives the model thread unless it failed; then packets are moot.
            Outbox::Sender(jobs) => {
                let _ = jobs.send(d);
            }
            Outbox::Virtual(v) => v.schedule(d),
        }
    }

    /// When the model thread wakes next at the latest: `watchdog` (when due) on the monotonic
    /// clock; on a virtual clock its time comes from the master, checked every [`STOP_POLL`].
    fn wake(&self, watchdog: Option<Instant>) -> Instant {
        let poll = Instant::now() + STOP_POLL;
        match (self, watchdog) {
            (Outbox::Sender(_), Some(due)) => poll.min(due),
            _ => poll,
        }
    }

    /// When outputs set for an event `due` then change: now on the monotonic clock (the thread
    /// woke for it), `due` on a virtual clock.
    fn fired(&self, due: Instant) -> Instant {
        match self {
            Outbox::Sender(_) => Instant::now(),
            Outbox::Virtual(_) => due,
        }
    }

    /// The slaves took in a datagram of the command port (a valid command's packets posted).
    fn taken(&self) {
        if let Outbox::Virtual(v) = self {
            v.command_taken();
        }
    }

    /// The slaves stopped listening.
    fn close(&self) {
        if let Outbox::Virtual(v) = self {
            v.detach();
        }
    }
}

/// Starts the model thread of the boards of setpoints `S`; servos hold the joint positions
/// `initial` (the posture the robot settled in) until their first goals.
#[allow(clippy::too_many_arguments)]
fn spawn_model<S: Drive>(robot: SimulatedRobot, initial: [f64; JOINTS], commands: UdpSocket, outbox: Outbox, stop: Arc<AtomicBool>, timing: super::config::Timing, options: EmulatorOptions) -> std::io::Result<JoinHandle<EmulatorReport>> {
    std::thread::Builder::new().name("hexadyn-emulator".into()).spawn(move || {
        // Below the sender: a long model period must not delay the packets.
        let realtime = realtime_thread(timing.realtime_priority.map(|p| p.saturating_sub(1).max(1)));
        let scales = robot.robot.model.encoders.map(|e| JointScale::new(S::PROTOCOL, e));
        let applied = Command { goals: robot.robot.model.takes_references().then_some(initial), references: initial, ..Default::default() };
        let mut e = Slaves::<S> { robot, scales, applied, faults: FaultInjector::new(options.faults.clone()), outbox, report: EmulatorReport { realtime, ..Default::default() }, slave: Slave::default(), timing, history: options.history, step_times: Vec::new(), kind: std::marker::PhantomData };
        e.serve(&commands, &stop, options.idle_timeout);
        e.outbox.close();
        e.finish()
    })
}

/// The model side: commands of setpoints `S` in, latched packets out, one model period per
/// command.
struct Slaves<S> {
    robot: SimulatedRobot,
    scales: [JointScale; JOINTS],
    /// The command the boards apply to the simulated robot (a servo turned off keeps its goal).
    applied: Command,
    faults: FaultInjector,
    outbox: Outbox,
    report: EmulatorReport,
    /// The boards' rules for the command port.
    slave: Slave,
    timing: super::config::Timing,
    history: bool,
    /// Wall time of each model period (s).
    step_times: Vec<f64>,
    kind: std::marker::PhantomData<S>,
}

impl<S: Drive> Slaves<S> {
    fn serve(&mut self, socket: &UdpSocket, stop: &AtomicBool, idle_timeout: Option<Duration>) {
        let mut buf = vec![0u8; RECEIVE_BUFFER];
        let mut last_command: Option<Instant> = None;
        while !stop.load(Ordering::Relaxed) {
            self.watchdog();
            let wake = self.outbox.wake(self.slave.watchdog_due());
            let received = match wait_readable(socket.as_raw_fd(), wake, Duration::ZERO) {
                Ok(Wake::Readable) => socket.recv_from(&mut buf),
                Ok(Wake::Deadline) => Err(std::io::ErrorKind::TimedOut.into()),
                Err(e) => Err(e),
            };
            let (n, from) = match received {
                Ok(r) => r,
                Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted) => {
                    if let (Some(limit), Some(at)) = (idle_timeout, last_command) {
                        if at.elapsed() >= limit {
                            break;
                        }
                    }
                    continue;
                }
                Err(e) => {
                    self.report.error = Some(format!("receiving the commands: {e}"));
                    break;
                }
            };
            self.watchdog();
            let applied = self.take(&buf[..n], from);
            self.outbox.taken();
            if applied {
                last_command = Some(Instant::now());
                if let Err(e) = self.step() {
                    self.report.error = Some(e);
                    break;
                }
            }
        }
        // The time that passed on a virtual clock until the end.
        self.watchdog();
    }

    /// Takes in a datagram of the command port as the boards do ([`Slave::take`]): a new command
    /// of their master is applied, what it latched posted as the six packets; anything else is
    /// counted. Returns whether it was applied.
    fn take(&mut self, bytes: &[u8], from: SocketAddr) -> bool {
        let now = self.outbox.now();
        match self.slave.take::<S>(bytes, from, now) {
            Ok(command) => {
                self.apply(&command, now, from);
                true
            }
            Err(_) => false,
        }
    }

    /// Fires the watchdog if it is due: every output at 0 V (every servo's torque off).
    fn watchdog(&mut self) {
        if let Some(mut trip) = self.slave.expire(self.outbox.now()) {
            trip.at = self.outbox.fired(trip.at);
            self.hold(&[S::default(); JOINTS]);
            self.report.watchdog.push(trip);
        }
    }

    /// The boards' outputs: `setpoints` applied to the model.
    fn hold(&mut self, setpoints: &[S; JOINTS]) {
        let supply = self.robot.robot.model.options.supply_voltage;
        for (k, setpoint) in setpoints.iter().enumerate() {
            setpoint.apply(k, &self.scales[k], supply, &mut self.applied);
        }
        self.robot.actuate(&self.applied);
        self.report.held = setpoints.map(Setpoint::bits);
    }

    /// Latches and posts the six packets, then applies the command to the model.
    fn apply(&mut self, command: &Commands<S>, received: Instant, to: SocketAddr) {
        let state = self.robot.state();
        let q = state.q.as_slice();
        let counts: [i64; JOINTS] = std::array::from_fn(|k| self.scales[k].count(q[self.robot.robot.model.drive_index(k)]));
        let currents = self.robot.robot.outputs.current;
        let supply = self.robot.robot.model.options.supply_voltage;
        let n = self.report.commands;
        let replies: [SlaveReply; LEG_COUNT] = std::array::from_fn(|leg| {
            let j = 3 * leg;
            SlaveReply::measured(S::PROTOCOL, leg, command.seq, [counts[j], counts[j + 1], counts[j + 2]], [currents[j], currents[j + 1], currents[j + 2]], supply)
        });
        for (leg, reply) in replies.iter().enumerate() {
            for Outgoing { leg, delay, bytes } in self.faults.apply(leg, n, self.timing.reply_delay(leg), &reply.encode(S::PROTOCOL)) {
                self.outbox.post(Datagram { due: received + delay, leg, to, bytes });
            }
        }
        if self.history {
            let body = std::array::from_fn(|i| q[i]);
            let counts = std::array::from_fn(|k| replies[k / 3].counts[k % 3]);
            self.report.history.push(EmulatedPeriod { seq: command.seq, setpoints: command.setpoints.map(Setpoint::bits), counts, body, t: state.t });
        }
        self.hold(&command.setpoints);
        self.report.commands += 1;
    }

    /// Advances the model one period with the applied command.
    fn step(&mut self) -> Result<(), String> {
        let stepping = Instant::now();
        let stepped = self.robot.wait_period();
        self.step_times.push(stepping.elapsed().as_secs_f64());
        stepped.map_err(|e| format!("the simulated robot failed at t = {:.3} s: {e}", self.robot.state().t))
    }

    fn finish(mut self) -> EmulatorReport {
        let s = self.robot.state();
        self.report.body = std::array::from_fn(|i| s.q[i]);
        self.report.t = s.t;
        self.report.faults = self.faults.counts;
        self.report.refused = self.slave.refused;
        self.report.step_time = Percentiles::of(&self.step_times);
        self.report
    }
}

/// Sends each packet at its due time on the monotonic clock until told to stop; returns the
/// datagrams sent. No spin: the boards themselves answer within ±300 µs (Δt_d, Section 2.3.2).
fn send_loop(slaves: &[UdpSocket], queue: &Receiver<Datagram>, stop: &AtomicBool) -> Result<u64, String> {
    let mut agenda = Agenda::default();
    let mut sent = 0u64;
    loop {
        // Wait for the next due packet, taking new ones as they come.
        let wake = agenda.next_due();
        let incoming = match wake {
            Some(due) => match due.checked_duration_since(Instant::now()) {
                Some(wait) if !wait.is_zero() => queue.recv_timeout(wait),
                _ => Err(RecvTimeoutError::Timeout),
            },
            None => queue.recv_timeout(STOP_POLL),
        };
        match incoming {
            Ok(d) => {
                agenda.push(d);
                continue;
            }
            Err(RecvTimeoutError::Disconnected) if agenda.is_empty() => return Ok(sent),
            Err(_) if wake.is_none() => {
                if stop.load(Ordering::Relaxed) {
                    return Ok(sent);
                }
                continue;
            }
            Err(_) => {}
        }
        let Some(due) = wake else { continue };
        sleep_until(due, Duration::ZERO);
        while let Some(d) = agenda.pop_due(due) {
            d.send(slaves)?;
            sent += 1;
        }
    }
}
