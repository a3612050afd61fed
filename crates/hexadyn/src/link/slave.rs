//! What a slave board does with the datagrams of its command port (docs/protocol.md, "What a
//! slave does"), without sockets or clock: the emulated boards ([`super::emulator`]) run it, and
//! it is the rule a board's firmware implements.
//!
//! - A board follows one master: the address and port of the command that was its handshake, and
//!   the run number that command carried (chosen by the master at its start). Only the zero
//!   command (every output at 0 V, every servo's torque off) is a handshake, and only on a board
//!   that follows no master: taking a board over can stop the robot, never move it.
//! - Its master's commands are applied when their sequence number is after the last one applied
//!   (serial number arithmetic: at most 32767 ahead); a duplicate or an earlier one is ignored.
//! - Anything else is refused, whatever its CRC: a command from another address or port, or of
//!   another run (an earlier run of a master at the same address, a restarted master before the
//!   watchdog let it in).
//! - **Watchdog**: [`WATCHDOG`] (50 ms) without a command applied, the board sets its outputs to
//!   0 V (every servo's torque off) and forgets its master, so that the next master's handshake
//!   is taken: a master that died is replaced cleanly, one still alive cannot be.
//!
//! The six boards see the same broadcasts and decide alike: one [`Slave`] stands for the six.

use std::net::SocketAddr;
use std::time::{Duration, Instant};

use super::protocol::{seq_distance, Commands, PacketError, PacketErrorCounts, Setpoint};

/// No command applied for this long: outputs at 0 V, the master forgotten.
pub const WATCHDOG: Duration = Duration::from_millis(50);

/// The master a board follows: fixed by its handshake.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MasterId {
    /// The source address and port of the handshake.
    pub address: SocketAddr,
    /// The run number of the handshake.
    pub run: u32,
}

/// Why a board did not apply a datagram.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Refusal {
    /// Not a command packet of the board's kind (size, CRC, version, ranges).
    Packet(PacketError),
    /// From its master, numbered like the last command applied or before it.
    Old,
    /// From another address or port than its master's.
    OtherSender,
    /// From its master's address and port, of another run.
    OtherRun,
    /// A board without a master takes only the zero command (the handshake).
    NoHandshake,
}

/// The datagrams a board did not apply, by reason.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RefusalCounts {
    /// Not decoded, by kind.
    pub rejected: PacketErrorCounts,
    /// Duplicated or earlier commands of the board's master.
    pub old: u64,
    pub other_sender: u64,
    pub other_run: u64,
    pub no_handshake: u64,
}

impl RefusalCounts {
    fn count(&mut self, r: &Refusal) {
        match r {
            Refusal::Packet(e) => self.rejected.count(e),
            Refusal::Old => self.old += 1,
            Refusal::OtherSender => self.other_sender += 1,
            Refusal::OtherRun => self.other_run += 1,
            Refusal::NoHandshake => self.no_handshake += 1,
        }
    }

    /// Commands refused for not coming from the board's master (sender, run, no handshake).
    pub fn foreign(&self) -> u64 {
        self.other_sender + self.other_run + self.no_handshake
    }

    pub fn total(&self) -> u64 {
        self.rejected.total() + self.old + self.foreign()
    }
}

/// The watchdog fired: the outputs went to 0 V at `at`, [`WATCHDOG`] after the last command
/// applied (sequence number `last_seq`, applied at `last`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WatchdogTrip {
    pub last_seq: u16,
    pub last: Instant,
    pub at: Instant,
}

/// A board's state for its command port.
#[derive(Clone, Debug, Default)]
pub struct Slave {
    master: Option<MasterId>,
    /// Sequence number and time of the last command applied.
    last: Option<(u16, Instant)>,
    /// Commands applied.
    pub applied: u64,
    pub refused: RefusalCounts,
}

impl Slave {
    /// The master the board follows, if any.
    pub fn master(&self) -> Option<MasterId> {
        self.master
    }

    /// Takes in a datagram of the command port from `from` at `now` (call [`Self::expire`]
    /// first): the command to apply, or why not (counted).
    pub fn take<S: Setpoint>(&mut self, bytes: &[u8], from: SocketAddr, now: Instant) -> Result<Commands<S>, Refusal> {
        let verdict = self.judge(bytes, from);
        match &verdict {
            Ok(c) => {
                self.master = Some(MasterId { address: from, run: c.run });
                self.last = Some((c.seq, now));
                self.applied += 1;
            }
            Err(r) => self.refused.count(r),
        }
        verdict
    }

    fn judge<S: Setpoint>(&self, bytes: &[u8], from: SocketAddr) -> Result<Commands<S>, Refusal> {
        let command = Commands::<S>::decode(bytes).map_err(Refusal::Packet)?;
        let Some(master) = self.master else {
            return if command.is_zero() { Ok(command) } else { Err(Refusal::NoHandshake) };
        };
        if from != master.address {
            return Err(Refusal::OtherSender);
        }
        if command.run != master.run {
            return Err(Refusal::OtherRun);
        }
        match self.last {
            Some((seq, _)) if seq_distance(command.seq, seq) <= 0 => Err(Refusal::Old),
            _ => Ok(command),
        }
    }

    /// When the watchdog fires if no command is applied before.
    pub fn watchdog_due(&self) -> Option<Instant> {
        self.master.and(self.last).map(|(_, at)| at + WATCHDOG)
    }

    /// Fires the watchdog if it is due at `now`: the outputs go to 0 V and the master is
    /// forgotten. Returns the trip, dated when it was due.
    pub fn expire(&mut self, now: Instant) -> Option<WatchdogTrip> {
        let due = self.watchdog_due().filter(|&due| now >= due)?;
        let (last_seq, last) = self.last?;
        self.master = None;
        Some(WatchdogTrip { last_seq, last, at: due })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hexapod::JOINTS;
    use crate::link::protocol::{Duty, MotorCommands};
    use crate::link::virtual_clock::VirtualClock;
    use rand::{Rng, SeedableRng};

    const RUN: u32 = 0x5EED_0001;

    fn master() -> SocketAddr {
        "127.0.0.1:47100".parse().expect("address")
    }

    fn command(seq: u16, run: u32, duty: i16) -> [u8; 36] {
        MotorCommands { seq, run, setpoints: [Duty::new(duty).expect("a duty"); JOINTS] }.encode()
    }

    /// A board following `master()` in run `RUN` since `t`, its last command number 1.
    fn bound(t: Instant) -> Slave {
        let mut s = Slave::default();
        assert!(s.take::<Duty>(&command(0, RUN, 0), master(), t).is_ok());
        assert!(s.take::<Duty>(&command(1, RUN, 300), master(), t).is_ok());
        s
    }

    /// 10^5 CRC-valid commands forged or replayed while the master drives the board: its own
    /// commands mutated (duties, sequence numbers up to 32767 ahead, the zero stop) sent from
    /// another port or another address, and commands of earlier runs from the master's own
    /// address and port. None is applied, whatever it carries; every command of the master is,
    /// its zero stops too, though forged commands numbered ahead of it came first.
    #[test]
    fn forged_and_replayed_commands_are_never_applied() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(39);
        let clock = VirtualClock::new();
        let mut t = clock.now();
        let mut s = bound(t);
        let others: [SocketAddr; 3] = ["127.0.0.1:47101".parse().unwrap(), "127.0.0.2:47100".parse().unwrap(), "10.0.0.1:47100".parse().unwrap()];
        let (mut seq, mut master_commands) = (1u16, 2u64);
        for n in 0..100_000u32 {
            if n % 10 == 0 {
                // The master's next period, 1 ms of virtual time per forged datagram.
                seq = seq.wrapping_add(1);
                let stop = n % 1000 == 0;
                let duty = if stop { 0 } else { rng.random_range(-1023..=1023) };
                assert!(s.take::<Duty>(&command(seq, RUN, duty), master(), t).is_ok(), "the master's command {seq}");
                master_commands += 1;
            }
            t += Duration::from_millis(1);
            assert_eq!(s.expire(t), None, "the master keeps the watchdog fed");
            let duty = rng.random_range(-1023..=1023) * i16::from(n % 7 != 0); // every 7th a forged zero command (handshake, stop)
            let ahead = if n % 3 == 0 { 100 } else { rng.random_range(1..=32767) };
            let (bytes, from) = match n % 4 {
                0 | 1 => (command(seq.wrapping_add(ahead), RUN, duty), others[n as usize % 3]),
                2 => (command(seq.wrapping_add(ahead), rng.random_range(0..RUN), duty), master()),
                _ => (command(rng.random(), RUN - 1 - rng.random_range(0..1000), duty), master()),
            };
            let refused = s.take::<Duty>(&bytes, from, t).expect_err("a forged or replayed command");
            assert!(matches!(refused, Refusal::OtherSender | Refusal::OtherRun), "{refused:?}");
        }
        assert_eq!(s.applied, master_commands);
        assert_eq!((s.refused.foreign(), s.refused.other_sender, s.refused.total()), (100_000, 50_000, 100_000));
        assert_eq!(s.master(), Some(MasterId { address: master(), run: RUN }));
    }

    /// The watchdog on the virtual clock: the outputs stay on until exactly 50 ms after the last
    /// command applied (refused datagrams do not feed it), then go to 0 V and the board forgets
    /// its master; then a new master's handshake (a zero command, another run, another port) is
    /// taken, a command that is not the zero command is not.
    #[test]
    fn the_watchdog_fires_exactly_50_ms_after_the_last_command() {
        let clock = VirtualClock::new();
        let t0 = clock.now();
        let mut s = bound(t0);
        let last = t0 + Duration::from_millis(10);
        assert!(s.take::<Duty>(&command(2, RUN, 500), master(), last).is_ok());
        let other: SocketAddr = "127.0.0.1:50000".parse().expect("address");
        assert_eq!(s.take::<Duty>(&command(3, RUN + 1, 0), other, last + Duration::from_millis(30)), Err(Refusal::OtherSender));
        assert_eq!(s.take::<Duty>(&command(2, RUN, 500), master(), last + Duration::from_millis(40)), Err(Refusal::Old));
        clock.advance(Duration::from_millis(10) + WATCHDOG - Duration::from_nanos(1)).expect("time passes");
        assert_eq!(s.watchdog_due(), Some(last + WATCHDOG));
        assert_eq!(s.expire(clock.now()), None);
        clock.advance(Duration::from_nanos(1)).expect("time passes");
        assert_eq!(s.expire(clock.now()), Some(WatchdogTrip { last_seq: 2, last, at: last + WATCHDOG }));
        assert_eq!((s.master(), s.watchdog_due(), s.expire(clock.now())), (None, None, None));
        // No master: only a handshake is taken, from anyone; then that master is followed.
        let later = clock.now() + Duration::from_millis(5);
        assert_eq!(s.take::<Duty>(&command(9, RUN + 1, 200), other, later), Err(Refusal::NoHandshake));
        assert!(s.take::<Duty>(&command(0, RUN + 1, 0), other, later).is_ok());
        assert_eq!(s.master(), Some(MasterId { address: other, run: RUN + 1 }));
        assert_eq!(s.take::<Duty>(&command(5, RUN, 200), master(), later), Err(Refusal::OtherSender));
        assert!(s.take::<Duty>(&command(1, RUN + 1, 200), other, later).is_ok());
        assert_eq!(s.watchdog_due(), Some(later + WATCHDOG));
        let r = s.refused;
        assert_eq!((r.other_sender, r.old, r.no_handshake, r.other_run, s.applied), (2, 1, 1, 0, 5));
    }

    #[test]
    fn a_restarted_master_at_the_same_address_is_refused_until_the_watchdog_fires() {
        let t0 = Instant::now();
        let mut s = bound(t0);
        let handshake = command(0, RUN + 7, 0);
        assert_eq!(s.take::<Duty>(&handshake, master(), t0 + Duration::from_millis(40)), Err(Refusal::OtherRun));
        let at = t0 + WATCHDOG;
        assert!(s.expire(at).is_some());
        assert!(s.take::<Duty>(&handshake, master(), at).is_ok());
        // The old run's commands, still in flight, are refused from now on, its stop too.
        assert_eq!(s.take::<Duty>(&command(2, RUN, 0), master(), at), Err(Refusal::OtherRun));
        let mut bad = command(3, RUN + 7, 0);
        bad[0] ^= 1;
        assert!(matches!(s.take::<Duty>(&bad, master(), at), Err(Refusal::Packet(PacketError::Checksum { .. }))));
    }
}
