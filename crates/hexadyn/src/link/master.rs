//! The master side of the link: the deadline loop of Section 2.3.2 (the pseudo-code under
//! Fig. 2.17). At each deadline of an absolute monotonic clock the master broadcasts the 18
//! setpoints (motor duties, or servo goals: the master is generic over the [`Setpoint`]), then
//! collects the six slave packets; the period is complete when the last
//! one arrives, and the controller runs at once (in [`super::UdpPlant`]). On the robot, waiting
//! is precise ([`super::clock::wait_readable`]): `ppoll` up to the deadline minus a spin
//! margin, then a spin. On a [`Clock::Virtual`] the same loop runs in lock-step with emulated
//! slaves ([`super::virtual_clock`]): the same packets, sockets and checks, in virtual time.
//!
//! Freshness: a slave packet is used only if it comes from the configured address of its leg,
//! decodes (size, CRC, version, ranges), names that leg and echoes the sequence number of the
//! current period, for the first time. Everything else is counted, logged and dropped: a stale
//! or out-of-order packet is never taken as fresh.
//!
//! Run number: the master draws a random 32-bit run number when it binds and puts it in every
//! command; the slaves follow the address, port and run of their handshake, the first zero
//! command they take ([`super::slave`]). The start ([`Master::connect`]) broadcasts the zero
//! command every period until the six slaves answer one period on time; slaves that answer only
//! after the period are refused at once with their delays, a run with them could not keep one
//! period.
//!
//! Safety: a slave silent for `safety.missing_periods` periods in a row (3 by default) while the
//! master kept its deadlines, the master's own overrun — its command not ready at the deadline
//! (the controller), or the master itself late for a deadline by more than its slaves' replies
//! leave in the period (stopped, descheduled), which is never blamed on the slaves — or an
//! interrupt broadcasts the zero command (0 V to every motor, every servo's torque off) and stops
//! the run with a [`SafetyStop`] naming which. Dropping a master that has not stopped does the
//! same.

use std::marker::PhantomData;
use std::net::{SocketAddr, UdpSocket};
use std::os::fd::AsRawFd;
use std::time::{Duration, Instant};

use super::clock::{Clock, Wake};
use super::config::LinkConfig;
use super::protocol::{seq_distance, Commands, PacketErrorCounts, Setpoint, SlaveReply, COMMAND_SIZE, RECEIVE_BUFFER};
use super::LinkError;
use crate::hexapod::{JOINTS, LEG_COUNT};

/// How many link events a run keeps (the counters go on counting).
const MAX_EVENTS: usize = 200;
/// How many times the stop command (0 V) is sent, back to back, with the same sequence number.
const STOP_REPEATS: usize = 3;
/// How many of the last broadcasts the start remembers, to time the slaves' late answers.
const SENT_HISTORY: usize = 16;

/// Why the master stopped the robot.
#[derive(Clone, Debug, PartialEq)]
pub enum StopReason {
    /// These slaves' packets were missing for `periods` periods in a row, the master on time.
    MissingReplies { legs: Vec<usize>, periods: u32 },
    /// The master's overrun in its controller: the command was ready `late_s` after its deadline.
    ControllerOverrun { late_s: f64 },
    /// The master's own overrun: it reached a deadline `late_s` late, more than the `slack_s`
    /// its slaves' replies leave in the period (its thread did not run in time).
    MasterOverrun { late_s: f64, slack_s: f64 },
    /// The user asked to stop.
    Interrupted,
    /// The link failed (a socket error) during the run.
    LinkFailure { error: String },
}

impl StopReason {
    /// A name for the results' summary (`safety_stop_reason`).
    pub fn kind(&self) -> &'static str {
        match self {
            StopReason::MissingReplies { .. } => "missing_replies",
            StopReason::ControllerOverrun { .. } => "controller_overrun",
            StopReason::MasterOverrun { .. } => "master_overrun",
            StopReason::Interrupted => "interrupted",
            StopReason::LinkFailure { .. } => "link_failure",
        }
    }
}

/// A safety stop: every motor was put to 0 V (every servo's torque off) at `period`.
#[derive(Clone, Debug, PartialEq)]
pub struct SafetyStop {
    pub period: u64,
    pub reason: StopReason,
}

impl std::fmt::Display for SafetyStop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.reason {
            StopReason::MissingReplies { legs, periods } => write!(f, "safety stop at period {}: no packet from the slave(s) of leg(s) {legs:?} for {periods} periods, the master on time; every motor set to 0 V", self.period),
            StopReason::ControllerOverrun { late_s } => write!(f, "safety stop at period {}: master overrun in the controller: its command was ready {:.3} ms after the deadline; every motor set to 0 V", self.period, late_s * 1e3),
            StopReason::MasterOverrun { late_s, slack_s } => write!(
                f,
                "safety stop at period {}: master overrun: the master itself reached its deadline {:.3} ms late (its thread did not run in time), more than the {:.3} ms its slaves' replies leave in the period; not a slave's fault; every motor set to 0 V",
                self.period,
                late_s * 1e3,
                slack_s * 1e3
            ),
            StopReason::Interrupted => write!(f, "stopped at period {} on request; every motor set to 0 V", self.period),
            StopReason::LinkFailure { error } => write!(f, "safety stop at period {}: link failure: {error}; the stop command sent, and the boards' watchdog sets every motor to 0 V 50 ms after the last command in any case", self.period),
        }
    }
}

/// A datagram the master dropped, with the period it came in.
#[derive(Clone, Debug, PartialEq)]
pub struct LinkEvent {
    pub period: u64,
    pub message: String,
}

/// What the master counted and measured.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LinkStats {
    /// Broadcasts at a deadline (the stop commands excluded).
    pub broadcasts: u64,
    pub complete_periods: u64,
    /// Periods at whose end a slave packet was missing (the controller did not run).
    pub missed_periods: u64,
    /// Lateness of each broadcast against its deadline (s).
    pub lateness: Vec<f64>,
    /// For each complete period, when the last packet arrived after the broadcast (s).
    pub last_reply: Vec<f64>,
    /// Packets that did not decode, by kind.
    pub rejected: PacketErrorCounts,
    /// Packets whose leg field is not the leg of their source address.
    pub wrong_leg: u64,
    /// Packets of an earlier period (late, reordered).
    pub stale: u64,
    /// Packets numbered after the current period.
    pub future: u64,
    /// Second packets of a slave in one period.
    pub duplicates: u64,
    /// Datagrams from an address that is no configured slave.
    pub unknown_source: u64,
    /// Whether the master thread ran with a real-time priority.
    pub realtime: bool,
    /// Events beyond [`MAX_EVENTS`] that were counted but not kept.
    pub events_dropped: u64,
}

impl LinkStats {
    /// Datagrams that never reached the controller.
    pub fn dropped(&self) -> u64 {
        self.rejected.total() + self.wrong_leg + self.stale + self.future + self.duplicates + self.unknown_source
    }
}

/// A slave's answers that came after their period, at the start.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Late {
    /// Late answers since its last answer on time.
    count: u32,
    /// The delay of the last one after its broadcast.
    delay: Duration,
}

/// The master's socket, clock and per-period bookkeeping, for the packets of `S`.
pub struct Master<S: Setpoint> {
    socket: UdpSocket,
    config: LinkConfig,
    clock: Clock,
    /// The run number in every command.
    run: u32,
    /// Receives any datagram whole (its true size in the logs).
    buffer: Box<[u8]>,
    /// Index of the current period (the last broadcast at a deadline).
    period: u64,
    started: bool,
    /// At the start: the slaves' late answers, and when the last broadcasts went (by sequence
    /// number modulo [`SENT_HISTORY`]).
    connecting: bool,
    late: [Late; LEG_COUNT],
    sent: [Instant; SENT_HISTORY],
    next_deadline: Instant,
    broadcast_at: Instant,
    replies: [Option<SlaveReply>; LEG_COUNT],
    arrivals: [Duration; LEG_COUNT],
    missing: [u32; LEG_COUNT],
    stopped: bool,
    pub stats: LinkStats,
    pub events: Vec<LinkEvent>,
    kind: PhantomData<S>,
}

impl<S: Setpoint> Master<S> {
    /// Binds the master socket (broadcast allowed); the deadlines on `clock` start with
    /// [`Self::start_clock`].
    pub fn bind(config: &LinkConfig, clock: Clock) -> Result<Self, LinkError> {
        let socket_error = |source| LinkError::Socket { what: "cannot open the master socket", address: config.master.to_string(), source };
        let socket = UdpSocket::bind(config.master).map_err(socket_error)?;
        socket.set_broadcast(true).map_err(socket_error)?;
        socket.set_nonblocking(true).map_err(socket_error)?;
        let now = clock.now();
        Ok(Master {
            socket,
            config: config.clone(),
            clock,
            run: rand::random(),
            buffer: vec![0; RECEIVE_BUFFER].into_boxed_slice(),
            period: 0,
            started: false,
            connecting: false,
            late: [Late::default(); LEG_COUNT],
            sent: [now; SENT_HISTORY],
            next_deadline: now,
            broadcast_at: now,
            replies: [None; LEG_COUNT],
            arrivals: [Duration::ZERO; LEG_COUNT],
            missing: [0; LEG_COUNT],
            stopped: false,
            stats: LinkStats::default(),
            events: Vec::new(),
            kind: PhantomData,
        })
    }

    pub fn local_addr(&self) -> std::io::Result<SocketAddr> {
        self.socket.local_addr()
    }

    pub fn config(&self) -> &LinkConfig {
        &self.config
    }

    /// The run number the master chose: in every command it sends.
    pub fn run(&self) -> u32 {
        self.run
    }

    /// How late the master may reach a deadline: the time its slaves' replies leave in the
    /// period, Δt − (t_s0 + 5 Δt_s) (5 ms on AMRU5). Later, its slaves cannot answer before the
    /// next deadline: the master overran.
    pub fn slack(&self) -> Duration {
        let t = &self.config.timing;
        t.period.saturating_sub(t.reply_delay(LEG_COUNT - 1))
    }

    /// The first deadline is one period from now.
    pub fn start_clock(&mut self) {
        self.next_deadline = self.clock.now() + self.config.timing.period;
    }

    /// Index of the current period.
    pub fn period(&self) -> u64 {
        self.period
    }

    /// When the next broadcast is due.
    pub fn next_deadline(&self) -> Instant {
        self.next_deadline
    }

    /// Per slave, when its packet of the current period arrived after the broadcast.
    pub fn arrivals(&self) -> [Duration; LEG_COUNT] {
        self.arrivals
    }

    fn event(&mut self, message: String) {
        if self.events.len() < MAX_EVENTS {
            self.events.push(LinkEvent { period: self.period, message });
        } else {
            self.stats.events_dropped += 1;
        }
    }

    /// One period: waits for the deadline, broadcasts `setpoints`, collects the slave packets.
    /// Returns them when all six came fresh before the next deadline, `None` when some are
    /// missing; stops the robot when a slave has been missing too long.
    pub fn run_period(&mut self, setpoints: &[S; JOINTS]) -> Result<Option<[SlaveReply; LEG_COUNT]>, LinkError> {
        self.wait(self.next_deadline)?;
        self.check_on_time()?;
        self.broadcast(setpoints)?;
        self.collect()?;
        // A master that overslept the end of the period cannot blame its slaves for it.
        self.check_on_time()?;
        let mut silent = Vec::new();
        for leg in 0..LEG_COUNT {
            if self.replies[leg].is_some() {
                self.missing[leg] = 0;
            } else {
                self.missing[leg] += 1;
                if self.missing[leg] >= self.config.safety.missing_periods {
                    silent.push(leg);
                }
            }
        }
        if !silent.is_empty() {
            let periods = self.config.safety.missing_periods;
            return Err(self.safety_stop(StopReason::MissingReplies { legs: silent, periods }));
        }
        match self.replies {
            [Some(a), Some(b), Some(c), Some(d), Some(e), Some(f)] => {
                self.stats.complete_periods += 1;
                let last = self.arrivals.iter().max().copied().unwrap_or_default();
                self.stats.last_reply.push(last.as_secs_f64());
                Ok(Some([a, b, c, d, e, f]))
            }
            _ => {
                self.stats.missed_periods += 1;
                let legs: Vec<usize> = (0..LEG_COUNT).filter(|&l| self.replies[l].is_none()).collect();
                self.event(format!("period missed: no fresh packet from leg(s) {legs:?} before the deadline"));
                Ok(None)
            }
        }
    }

    /// The start, the slaves' handshake: broadcasts the zero command every period until the six
    /// slaves answer in one period, for at most the configured connect timeout (a missing slave
    /// is no safety stop yet). Slaves whose answers come, but only after their period, for
    /// `safety.missing_periods` periods in a row are refused at once ([`LinkError::LateReplies`]).
    pub fn connect(&mut self) -> Result<[SlaveReply; LEG_COUNT], LinkError> {
        let give_up = self.clock.now() + self.config.safety.connect_timeout;
        self.connecting = true;
        let outcome = loop {
            self.wait(self.next_deadline)?;
            self.broadcast(&[S::default(); JOINTS])?;
            self.collect()?;
            if let [Some(a), Some(b), Some(c), Some(d), Some(e), Some(f)] = self.replies {
                self.stats.complete_periods += 1;
                break Ok([a, b, c, d, e, f]);
            }
            let legs: Vec<usize> = (0..LEG_COUNT).filter(|&l| self.replies[l].is_none()).collect();
            let late = |limit: u32| legs.iter().all(|&l| self.late[l].count >= limit);
            if late(self.config.safety.missing_periods) || (self.clock.now() >= give_up && late(1)) {
                self.stop();
                break Err(self.late_replies(legs));
            }
            if self.clock.now() >= give_up {
                self.stop();
                break Err(LinkError::NoAnswer { legs, timeout_s: self.config.safety.connect_timeout.as_secs_f64(), broadcast: self.config.broadcast.to_string() });
            }
        };
        self.connecting = false;
        outcome
    }

    /// The refusal of slaves that answer after their period.
    fn late_replies(&self, legs: Vec<usize>) -> LinkError {
        let t = &self.config.timing;
        let delays_ms = legs.iter().map(|&l| self.late[l].delay.as_secs_f64() * 1e3).collect();
        let beyond_ms = legs.iter().map(|&l| self.late[l].delay.saturating_sub(t.reply_delay(l)).as_secs_f64() * 1e3).fold(0.0, f64::max);
        LinkError::LateReplies { legs, delays_ms, beyond_ms, period_ms: t.period.as_secs_f64() * 1e3, origin: self.config.origin.clone() }
    }

    /// Stops the robot if the next deadline has passed (the controller overran); call when the
    /// controller's command is ready.
    pub fn check_overrun(&mut self) -> Result<(), LinkError> {
        let now = self.clock.now();
        if self.started && now > self.next_deadline + self.config.safety.overrun_tolerance {
            let late_s = (now - self.next_deadline).as_secs_f64();
            return Err(self.safety_stop(StopReason::ControllerOverrun { late_s }));
        }
        Ok(())
    }

    /// Stops the robot if the master itself is later for its next deadline than [`Self::slack`].
    fn check_on_time(&mut self) -> Result<(), LinkError> {
        let late = self.clock.now().saturating_duration_since(self.next_deadline);
        let slack = self.slack();
        if late > slack {
            return Err(self.safety_stop(StopReason::MasterOverrun { late_s: late.as_secs_f64(), slack_s: slack.as_secs_f64() }));
        }
        Ok(())
    }

    /// Broadcasts the zero command at once and returns the stop as an error.
    pub fn safety_stop(&mut self, reason: StopReason) -> LinkError {
        LinkError::Stopped(self.stop_for(reason))
    }

    /// Broadcasts the zero command at once and logs the stop.
    pub fn stop_for(&mut self, reason: StopReason) -> SafetyStop {
        self.stop();
        let stop = SafetyStop { period: self.period, reason };
        self.event(stop.to_string());
        stop
    }

    /// Puts every motor to 0 V (every servo's torque off) now: the zero command sent three
    /// times, one sequence number.
    pub fn stop(&mut self) {
        if self.stopped {
            return;
        }
        self.stopped = true;
        let seq = if self.started { self.period.wrapping_add(1) as u16 } else { 0 };
        let bytes = Commands::<S>::zero(seq, self.run).encode();
        for _ in 0..STOP_REPEATS {
            match self.socket.send_to(&bytes, self.config.broadcast) {
                Ok(_) => self.clock.command_sent(),
                Err(e) => self.event(format!("the stop command could not be sent: {e}")),
            }
        }
    }

    /// Reads and counts what still arrives during `duration` (after a stop: the slaves' late
    /// packets and their answers to the stop command), so that the counters see every packet.
    pub fn linger(&mut self, duration: Duration) {
        let until = self.clock.now() + duration;
        while let Ok(Wake::Readable) = self.poll(until) {
            self.drain();
        }
    }

    pub fn is_stopped(&self) -> bool {
        self.stopped
    }

    /// Waits until `deadline`, dropping (and counting) whatever arrives meanwhile.
    fn wait(&mut self, deadline: Instant) -> Result<(), LinkError> {
        while self.poll(deadline)? == Wake::Readable {
            self.drain();
        }
        Ok(())
    }

    fn poll(&self, deadline: Instant) -> Result<Wake, LinkError> {
        self.clock.wait_readable(self.socket.as_raw_fd(), deadline, self.config.timing.spin).map_err(|source| LinkError::Socket { what: "cannot poll the master socket", address: self.config.master.to_string(), source })
    }

    fn broadcast(&mut self, setpoints: &[S; JOINTS]) -> Result<(), LinkError> {
        if self.started {
            self.period += 1;
        }
        let seq = self.period as u16;
        let bytes: [u8; COMMAND_SIZE] = Commands { seq, run: self.run, setpoints: *setpoints }.encode();
        let now = self.clock.now();
        self.socket.send_to(&bytes, self.config.broadcast).map_err(|source| LinkError::Socket { what: "cannot broadcast the commands to", address: self.config.broadcast.to_string(), source })?;
        self.clock.command_sent();
        let deadline = self.next_deadline;
        self.stats.lateness.push(now.saturating_duration_since(deadline).as_secs_f64());
        self.stats.broadcasts += 1;
        self.started = true;
        self.broadcast_at = now;
        self.sent[usize::from(seq) % SENT_HISTORY] = now;
        self.next_deadline = deadline + self.config.timing.period;
        self.replies = [None; LEG_COUNT];
        self.arrivals = [Duration::ZERO; LEG_COUNT];
        Ok(())
    }

    /// Collects packets until the six of this period are in or the next deadline comes; at the
    /// deadline, what came during the last spin of the wait is read too (it came within the
    /// period).
    fn collect(&mut self) -> Result<(), LinkError> {
        while self.replies.iter().any(Option::is_none) {
            if self.poll(self.next_deadline)? == Wake::Deadline {
                self.drain();
                break;
            }
            self.drain();
        }
        Ok(())
    }

    /// Reads every datagram waiting on the socket.
    fn drain(&mut self) {
        let mut buf = std::mem::take(&mut self.buffer);
        loop {
            match self.socket.recv_from(&mut buf) {
                Ok((n, from)) => {
                    self.clock.datagram_received();
                    let at = self.clock.now();
                    self.receive(&buf[..n], from, at);
                }
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => break,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => {
                    // ICMP errors (a slave's port unreachable) surface here on Linux.
                    self.event(format!("receive error: {e}"));
                    break;
                }
            }
        }
        self.buffer = buf;
    }

    /// Classifies one datagram; only a fresh packet of this period is kept.
    fn receive(&mut self, bytes: &[u8], from: SocketAddr, at: Instant) {
        let Some(leg) = self.config.leg_of(from) else {
            self.stats.unknown_source += 1;
            self.event(format!("{} bytes from {from}, no configured slave: dropped", bytes.len()));
            return;
        };
        let reply = match SlaveReply::decode(bytes, S::PROTOCOL) {
            Ok(r) => r,
            Err(e) => {
                self.stats.rejected.count(&e);
                self.event(format!("packet of leg {leg} rejected: {e}"));
                return;
            }
        };
        if usize::from(reply.leg) != leg {
            self.stats.wrong_leg += 1;
            self.event(format!("packet from leg {leg}'s address names leg {}: dropped", reply.leg));
            return;
        }
        let d = seq_distance(reply.seq, self.period as u16);
        if !self.started || d < 0 {
            self.stats.stale += 1;
            self.event(format!("stale packet of leg {leg} (sequence {}, {} period(s) old): dropped", reply.seq, -d));
            if self.connecting && self.started && -d < SENT_HISTORY as i32 {
                let late = &mut self.late[leg];
                late.count += 1;
                late.delay = at.saturating_duration_since(self.sent[usize::from(reply.seq) % SENT_HISTORY]);
            }
        } else if d > 0 {
            self.stats.future += 1;
            self.event(format!("packet of leg {leg} numbered {} period(s) ahead: dropped", d));
        } else if self.replies[leg].is_some() {
            self.stats.duplicates += 1;
        } else {
            self.replies[leg] = Some(reply);
            self.arrivals[leg] = at.saturating_duration_since(self.broadcast_at);
            self.late[leg].count = 0;
        }
    }
}

impl<S: Setpoint> Drop for Master<S> {
    fn drop(&mut self) {
        self.stop();
    }
}
