//! The clock of the deadline loop of Section 2.3.2: [`Clock`], the monotonic clock of the robot
//! or a [`VirtualClock`] for a master and an emulator run in lock-step; precise waits on the
//! monotonic clock.
//!
//! Socket read timeouts (SO_RCVTIMEO) run on the scheduler tick and come back milliseconds
//! late. Like the thesis' master, which blocks in `select()` on the slaves' socket with a
//! timeout up to the deadline, [`wait_readable`] blocks in `ppoll` (a high-resolution timer)
//! until a datagram arrives or the deadline minus a short spin margin, then spins on the clock
//! for the rest: the wake-up latency of the scheduler is paid before the deadline, not after.
//! [`realtime_thread`] lowers the timer slack of the calling thread to 1 ns and, when asked
//! and permitted, gives it a SCHED_FIFO priority.

use std::io;
use std::os::fd::RawFd;
use std::sync::Arc;
use std::time::{Duration, Instant};

pub use super::virtual_clock::VirtualClock;

/// The time of the master and of the emulated slaves.
#[derive(Clone, Debug, Default)]
pub enum Clock {
    /// The monotonic clock, waited on precisely ([`wait_readable`]): the robot, `hexadyn robot
    /// run` and `emulate`, the `link` benchmark.
    #[default]
    Monotonic,
    /// Virtual time shared by a master and an emulator in one process (the tests).
    Virtual(Arc<VirtualClock>),
}

impl Clock {
    /// A new virtual clock.
    pub fn virtual_time() -> Self {
        Clock::Virtual(VirtualClock::new())
    }

    pub fn now(&self) -> Instant {
        match self {
            Clock::Monotonic => Instant::now(),
            Clock::Virtual(v) => v.now(),
        }
    }

    /// The master's wait: until `fd` is readable or `deadline` is reached (`spin`: the last part
    /// of a wait on the monotonic clock spent spinning).
    pub fn wait_readable(&self, fd: RawFd, deadline: Instant, spin: Duration) -> io::Result<Wake> {
        match self {
            Clock::Monotonic => wait_readable(fd, deadline, spin),
            Clock::Virtual(v) => v.wait_readable(fd, deadline),
        }
    }

    /// The master sent a command datagram.
    pub(crate) fn command_sent(&self) {
        if let Clock::Virtual(v) = self {
            v.command_sent();
        }
    }

    /// The master read a datagram.
    pub(crate) fn datagram_received(&self) {
        if let Clock::Virtual(v) = self {
            v.datagram_received();
        }
    }
}

impl PartialEq for Clock {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (Clock::Monotonic, Clock::Monotonic) => true,
            (Clock::Virtual(a), Clock::Virtual(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }
}

/// What ended a [`wait_readable`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wake {
    /// A datagram is waiting on the socket.
    Readable,
    /// The deadline has come.
    Deadline,
}

/// Blocks until `fd` is readable or `deadline` is reached, whichever is first. The socket is
/// polled until `deadline - spin`; the last `spin` is spent spinning on the clock (a datagram
/// arriving then is seen at the next wait).
pub fn wait_readable(fd: RawFd, deadline: Instant, spin: Duration) -> io::Result<Wake> {
    loop {
        let now = Instant::now();
        if now >= deadline {
            return Ok(Wake::Deadline);
        }
        let left = deadline - now;
        if left <= spin {
            while Instant::now() < deadline {
                std::hint::spin_loop();
            }
            return Ok(Wake::Deadline);
        }
        let timeout = left - spin;
        let ts = libc::timespec { tv_sec: timeout.as_secs() as libc::time_t, tv_nsec: timeout.subsec_nanos() as libc::c_long };
        let mut pfd = libc::pollfd { fd, events: libc::POLLIN, revents: 0 };
        // SAFETY: one valid pollfd, a valid timespec and no signal mask.
        let n = unsafe { libc::ppoll(&mut pfd, 1, &ts, std::ptr::null()) };
        if n > 0 {
            return Ok(Wake::Readable);
        }
        if n < 0 {
            let e = io::Error::last_os_error();
            if e.kind() != io::ErrorKind::Interrupted {
                return Err(e);
            }
        }
    }
}

/// Sleeps until `deadline` with the same precision (no socket).
pub fn sleep_until(deadline: Instant, spin: Duration) {
    loop {
        let now = Instant::now();
        if now >= deadline {
            return;
        }
        let left = deadline - now;
        if left <= spin {
            while Instant::now() < deadline {
                std::hint::spin_loop();
            }
            return;
        }
        std::thread::sleep(left - spin);
    }
}

/// Prepares the calling thread for deadlines: 1 ns timer slack (the default 50 µs would add to
/// every wake-up) and, with `priority` 1..99, the SCHED_FIFO real-time class. Returns whether
/// the thread runs real-time (false when not asked, or not permitted: then it runs on the
/// normal scheduler).
pub fn realtime_thread(priority: Option<u8>) -> bool {
    // SAFETY: prctl and sched_setscheduler on the calling thread with valid arguments.
    unsafe {
        libc::prctl(libc::PR_SET_TIMERSLACK, 1 as libc::c_ulong, 0 as libc::c_ulong, 0 as libc::c_ulong, 0 as libc::c_ulong);
        match priority {
            Some(p) => {
                let param = libc::sched_param { sched_priority: libc::c_int::from(p.clamp(1, 99)) };
                libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) == 0
            }
            None => false,
        }
    }
}

/// Percentiles of a sample (nearest rank), e.g. the lateness of the broadcasts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Percentiles {
    pub count: usize,
    pub p50: f64,
    pub p99: f64,
    pub max: f64,
}

impl Percentiles {
    pub fn of(samples: &[f64]) -> Self {
        if samples.is_empty() {
            return Percentiles::default();
        }
        let mut s = samples.to_vec();
        s.sort_by(f64::total_cmp);
        let rank = |p: f64| s[((p * s.len() as f64).ceil() as usize).clamp(1, s.len()) - 1];
        Percentiles { count: s.len(), p50: rank(0.5), p99: rank(0.99), max: s[s.len() - 1] }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_by_nearest_rank() {
        let s: Vec<f64> = (1..=200).map(f64::from).collect();
        let p = Percentiles::of(&s);
        assert_eq!((p.count, p.p50, p.p99, p.max), (200, 100.0, 198.0, 200.0));
        assert_eq!(Percentiles::of(&[]), Percentiles::default());
    }

    #[test]
    fn waits_never_end_early() {
        let socket = std::net::UdpSocket::bind("127.0.0.1:0").expect("bind");
        use std::os::fd::AsRawFd;
        for spin in [Duration::ZERO, Duration::from_micros(200)] {
            let deadline = Instant::now() + Duration::from_millis(2);
            assert_eq!(wait_readable(socket.as_raw_fd(), deadline, spin).expect("poll"), Wake::Deadline);
            assert!(Instant::now() >= deadline);
            let deadline = Instant::now() + Duration::from_millis(1);
            sleep_until(deadline, spin);
            assert!(Instant::now() >= deadline);
        }
        socket.send_to(b"x", socket.local_addr().expect("address")).expect("send");
        assert_eq!(wait_readable(socket.as_raw_fd(), Instant::now() + Duration::from_secs(5), Duration::ZERO).expect("poll"), Wake::Readable);
    }
}
