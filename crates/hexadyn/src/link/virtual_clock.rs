//! A virtual clock on which a master and an emulator in one process run in lock-step: the
//! deadline loop of Section 2.3.2 with the same packets on the same loopback sockets, but time
//! advances only when everything due before it has happened, so that no verdict depends on the
//! scheduler.
//!
//! The master owns the time. When it waits for a deadline ([`super::clock::Clock::wait_readable`]),
//! the clock first waits until the emulated slaves have taken in every command the master sent
//! (their packets are then on the [`Agenda`], due at t_s0 + l Δt_s plus any injected delay
//! after the broadcast, Figs. 2.21-2.22), then steps from one due time to the next: it sends
//! the packets due from the slaves' sockets and lets the master read them, until the next one
//! is due at or after the deadline. A packet due after the deadline is late, in virtual time,
//! exactly as a packet arriving after it on the robot. Neither side waits on the wall clock
//! except for a datagram already sent on loopback, or a command already broadcast, to arrive:
//! if one does not within [`DELIVERY_LIMIT`], the wait fails.
//!
//! A test can make the master late: [`VirtualClock::stall`] freezes it at an instant for a
//! while, wherever it is then (a stopped or descheduled process), and [`VirtualClock::advance`]
//! lets time pass without it (a master that died). Meanwhile the slaves' packets are sent when
//! due and wait in the master's socket; the emulated slaves see the time and their watchdog.

use std::io;
use std::net::UdpSocket;
use std::os::fd::RawFd;
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

use super::agenda::{Agenda, Datagram};
use super::clock::{wait_readable, Wake};

/// How long a datagram sent on loopback, or a command broadcast to the emulated slaves, may
/// take to arrive before the clock gives up (wall time; on an idle machine microseconds).
pub const DELIVERY_LIMIT: Duration = Duration::from_secs(30);

/// The virtual time of a master and the emulated slaves it drives.
#[derive(Debug)]
pub struct VirtualClock {
    state: Mutex<State>,
    changed: Condvar,
}

#[derive(Debug)]
struct State {
    now: Instant,
    /// Command datagrams the master sent, and datagrams the emulated slaves took in.
    commands_sent: u64,
    commands_taken: u64,
    /// The emulated slaves' sockets while they run.
    slaves: Option<Arc<Vec<UdpSocket>>>,
    agenda: Agenda,
    /// Slave datagrams sent and not yet read by the master.
    in_flight: u64,
    /// Slave datagrams sent.
    sent: u64,
    /// The first slave datagram that could not be sent.
    error: Option<String>,
    /// The master freezes at this instant for this long (once).
    stall: Option<(Instant, Duration)>,
}

impl VirtualClock {
    /// A clock at the current instant, standing still until a master waits on it.
    pub fn new() -> Arc<Self> {
        let state = State { now: Instant::now(), commands_sent: 0, commands_taken: 0, slaves: None, agenda: Agenda::default(), in_flight: 0, sent: 0, error: None, stall: None };
        Arc::new(VirtualClock { state: Mutex::new(state), changed: Condvar::new() })
    }

    pub fn now(&self) -> Instant {
        self.lock().now
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The emulated slaves listen, and send their packets from `slaves` (legs 0..5).
    pub(crate) fn attach(&self, slaves: Arc<Vec<UdpSocket>>) {
        self.lock().slaves = Some(slaves);
    }

    /// The emulated slaves stopped: the master no longer waits for them to take its commands.
    pub(crate) fn detach(&self) {
        self.lock().slaves = None;
        self.changed.notify_all();
    }

    /// A datagram was sent to the slaves' command port: by the master, or by a test posing as
    /// another sender (counted before it is sent). The master's next wait lets the slaves take it
    /// first.
    pub fn command_sent(&self) {
        self.lock().commands_sent += 1;
    }

    /// The master freezes at `at` for `duration`, wherever it is then (waiting for its deadline,
    /// collecting the slaves' packets), as a stopped or descheduled process: at its first wait
    /// that reaches `at`, time jumps by `duration`.
    pub fn stall(&self, at: Instant, duration: Duration) {
        self.lock().stall = Some((at, duration));
    }

    /// Lets `duration` pass without the master (a master that died): once the slaves took every
    /// command sent, the packets due meanwhile are sent (they wait in the master's socket).
    pub fn advance(&self, duration: Duration) -> io::Result<()> {
        let mut s = self.taken()?;
        let until = s.now + duration;
        s.pass(until);
        Ok(())
    }

    /// The state once the emulated slaves took every command sent (or stopped listening).
    fn taken(&self) -> io::Result<MutexGuard<'_, State>> {
        let (s, waited) = self.changed.wait_timeout_while(self.lock(), DELIVERY_LIMIT, |s| s.slaves.is_some() && s.commands_taken < s.commands_sent).unwrap_or_else(PoisonError::into_inner);
        if waited.timed_out() {
            return Err(io::Error::new(io::ErrorKind::TimedOut, format!("the emulated slaves took no command within {} s of its broadcast", DELIVERY_LIMIT.as_secs())));
        }
        Ok(s)
    }

    /// The emulated slaves took in a datagram, after scheduling their answers.
    pub(crate) fn command_taken(&self) {
        self.lock().commands_taken += 1;
        self.changed.notify_all();
    }

    /// A slave packet to send at its due time.
    pub(crate) fn schedule(&self, d: Datagram) {
        self.lock().agenda.push(d);
    }

    /// The master read a datagram.
    pub(crate) fn datagram_received(&self) {
        let mut s = self.lock();
        s.in_flight = s.in_flight.saturating_sub(1);
    }

    /// Slave datagrams sent so far, and the first send error.
    pub(crate) fn sent(&self) -> (u64, Option<String>) {
        let s = self.lock();
        (s.sent, s.error.clone())
    }

    /// The master's wait: until a slave datagram is readable on `fd`, or virtual time reaches
    /// `deadline`.
    pub(crate) fn wait_readable(&self, fd: RawFd, deadline: Instant) -> io::Result<Wake> {
        loop {
            let mut s = self.taken()?;
            if s.in_flight > 0 {
                drop(s);
                return match wait_readable(fd, Instant::now() + DELIVERY_LIMIT, Duration::ZERO)? {
                    Wake::Readable => Ok(Wake::Readable),
                    Wake::Deadline => Err(io::Error::new(io::ErrorKind::TimedOut, format!("a slave packet sent on loopback did not arrive within {} s", DELIVERY_LIMIT.as_secs()))),
                };
            }
            let next = s.agenda.next_due().filter(|&due| due < deadline);
            if let Some((at, duration)) = s.stall.filter(|&(at, _)| at <= next.unwrap_or(deadline)) {
                s.stall = None;
                let until = s.now.max(at) + duration;
                s.pass(until);
                continue;
            }
            match next {
                Some(due) => {
                    s.now = s.now.max(due);
                    s.send_due();
                }
                None => {
                    s.now = s.now.max(deadline);
                    return Ok(Wake::Deadline);
                }
            }
        }
    }
}

impl State {
    /// Time passes until `until`: the datagrams due meanwhile are sent at their times.
    fn pass(&mut self, until: Instant) {
        while let Some(due) = self.agenda.next_due().filter(|&due| due <= until) {
            self.now = self.now.max(due);
            self.send_due();
        }
        self.now = self.now.max(until);
    }

    /// Sends every datagram due now from the slaves' sockets.
    fn send_due(&mut self) {
        while let Some(d) = self.agenda.pop_due(self.now) {
            let Some(slaves) = &self.slaves else { continue };
            match d.send(slaves) {
                Ok(()) => {
                    self.sent += 1;
                    self.in_flight += 1;
                }
                Err(e) => self.error = self.error.take().or(Some(e)),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::fd::AsRawFd;

    #[test]
    fn time_steps_through_the_due_packets_to_the_deadline() {
        let clock = VirtualClock::new();
        let master = UdpSocket::bind("127.0.0.1:0").expect("bind");
        master.set_nonblocking(true).expect("nonblocking");
        let slaves = Arc::new((0..2).map(|_| UdpSocket::bind("127.0.0.1:0").expect("bind")).collect::<Vec<_>>());
        clock.attach(slaves);
        let t0 = clock.now();
        let ms = |n| t0 + Duration::from_millis(n);
        let to = master.local_addr().expect("address");
        clock.command_sent();
        for (due, leg) in [(3, 1), (12, 0), (2, 0)] {
            clock.schedule(Datagram { due: ms(due), leg, to, bytes: vec![leg as u8] });
        }
        clock.command_taken();
        let fd = master.as_raw_fd();
        let mut seen = Vec::new();
        let mut buf = [0u8; 8];
        while clock.wait_readable(fd, ms(10)).expect("wait") == Wake::Readable {
            while let Ok((n, _)) = master.recv_from(&mut buf) {
                clock.datagram_received();
                seen.push((buf[..n].to_vec(), clock.now() - t0));
            }
        }
        assert_eq!(seen, [(vec![0], Duration::from_millis(2)), (vec![1], Duration::from_millis(3))]);
        assert_eq!(clock.now(), ms(10));
        // The packet due at 12 ms is late for the deadline at 10 ms: it comes in the next wait.
        assert_eq!(clock.wait_readable(fd, ms(20)).expect("wait"), Wake::Readable);
        assert_eq!((clock.now(), clock.sent()), (ms(12), (3, None)));
        let _ = master.recv_from(&mut buf).expect("the packet due at 12 ms");
        clock.datagram_received();
        // Frozen at 22 ms for 10 ms while it waits for its deadline at 30 ms: the packet due at
        // 25 ms waits in its socket, and the master wakes at 32 ms, late.
        clock.schedule(Datagram { due: ms(25), leg: 1, to, bytes: vec![1] });
        clock.stall(ms(22), Duration::from_millis(10));
        assert_eq!(clock.wait_readable(fd, ms(30)).expect("wait"), Wake::Readable);
        assert_eq!((clock.now(), clock.sent()), (ms(32), (4, None)));
        let _ = master.recv_from(&mut buf).expect("the packet due at 25 ms");
        clock.datagram_received();
        assert_eq!(clock.wait_readable(fd, ms(30)).expect("wait"), Wake::Deadline);
        clock.advance(Duration::from_millis(3)).expect("advance");
        assert_eq!(clock.now(), ms(35));
    }
}
