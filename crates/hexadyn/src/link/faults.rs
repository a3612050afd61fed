//! Faults the emulator injects into the slave packets it sends, to test the master against a
//! link worse than the thesis' ("it has been checked experimentally that the communication
//! protocol is very reliable and never loss data", Section 2.3.2): loss, delay and jitter,
//! duplicates, reordering, corrupted bytes, wrong sizes and a slave that stops answering.
//! Draws come from a seeded generator: a run's faults are reproducible.

use std::time::Duration;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::hexapod::LEG_COUNT;

/// Delay of a duplicate after the original packet.
const DUPLICATE_GAP: Duration = Duration::from_micros(50);

/// What goes wrong with the slave packets; probabilities are per packet.
#[derive(Clone, Debug, PartialEq)]
pub struct Faults {
    /// Probability that a packet is lost.
    pub loss: f64,
    /// Extra delay of every packet.
    pub delay: Duration,
    /// Extra delay drawn uniformly in [0, jitter] per packet.
    pub jitter: Duration,
    /// Probability that a packet is sent twice.
    pub duplicate: f64,
    /// Probability that a packet is held back and sent after the same slave's next packet.
    pub reorder: f64,
    /// Probability that one byte of a packet is replaced by another value.
    pub corrupt: f64,
    /// Probability that a packet is sent cut short or with bytes appended (never also
    /// corrupted, so each fault is counted once by the master).
    pub wrong_size: f64,
    /// At most this many packets of one slave in a row are destroyed (lost, corrupted or
    /// resized); `None`: no limit. With i.i.d. loss p, some slave loses 3 packets in a row about
    /// every 1 / (6 · 100 Hz · p³) s (13 s at 5 %), which stops the robot by design; a limit of 2
    /// keeps random loss within what the master rides through.
    pub max_consecutive: Option<u32>,
    /// This slave (leg) stops answering after the given number of commands.
    pub silent_slave: Option<(usize, u64)>,
    pub seed: u64,
}

impl Default for Faults {
    fn default() -> Self {
        Faults { loss: 0.0, delay: Duration::ZERO, jitter: Duration::ZERO, duplicate: 0.0, reorder: 0.0, corrupt: 0.0, wrong_size: 0.0, max_consecutive: None, silent_slave: None, seed: 0 }
    }
}

impl Faults {
    /// Checks the probabilities (in [0, 1]) and the silent slave (a leg 0..5).
    pub fn validate(&self) -> Result<(), String> {
        for (name, p) in [("loss", self.loss), ("duplicate", self.duplicate), ("reorder", self.reorder), ("corrupt", self.corrupt), ("wrong_size", self.wrong_size)] {
            if !(0.0..=1.0).contains(&p) {
                return Err(format!("fault {name} = {p}: a probability in [0, 1]"));
            }
        }
        match self.silent_slave {
            Some((leg, _)) if leg >= LEG_COUNT => Err(format!("silent slave {leg}: a leg 0..5")),
            _ => Ok(()),
        }
    }
}

/// How many packets each fault touched.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FaultCounts {
    pub lost: u64,
    pub silenced: u64,
    pub duplicated: u64,
    pub reordered: u64,
    pub corrupted: u64,
    pub wrong_size: u64,
}

/// A packet to send `delay` after the command was received.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Outgoing {
    pub leg: usize,
    pub delay: Duration,
    pub bytes: Vec<u8>,
}

/// Applies [`Faults`] to the packets of one emulator run.
pub struct FaultInjector {
    faults: Faults,
    rng: ChaCha8Rng,
    held: [Option<Vec<u8>>; LEG_COUNT],
    /// Packets of each slave destroyed in a row so far.
    destroyed: [u32; LEG_COUNT],
    pub counts: FaultCounts,
}

impl FaultInjector {
    pub fn new(faults: Faults) -> Self {
        let rng = ChaCha8Rng::seed_from_u64(faults.seed);
        FaultInjector { faults, rng, held: Default::default(), destroyed: [0; LEG_COUNT], counts: FaultCounts::default() }
    }

    /// The datagrams that go out for the packet of `leg` answering command number `command`
    /// (counted from 0), due `delay` after the command: none, one, or more.
    pub fn apply(&mut self, leg: usize, command: u64, delay: Duration, packet: &[u8]) -> Vec<Outgoing> {
        let f = &self.faults;
        if f.silent_slave.is_some_and(|(l, after)| l == leg && command >= after) {
            self.counts.silenced += 1;
            return Vec::new();
        }
        let may_destroy = f.max_consecutive.is_none_or(|n| self.destroyed[leg] < n);
        let (lost, corrupt, resize) = (self.rng.random_bool(f.loss), self.rng.random_bool(f.corrupt), self.rng.random_bool(f.wrong_size));
        if !may_destroy || !(lost || corrupt || resize) {
            self.destroyed[leg] = 0;
        } else {
            self.destroyed[leg] += 1;
        }
        if lost && may_destroy {
            self.counts.lost += 1;
            return Vec::new();
        }
        let mut bytes = packet.to_vec();
        if corrupt && may_destroy {
            let at = self.rng.random_range(0..bytes.len());
            bytes[at] ^= self.rng.random_range(1..=255u8);
            self.counts.corrupted += 1;
        } else if resize && may_destroy {
            if self.rng.random_bool(0.5) {
                bytes.truncate(self.rng.random_range(0..bytes.len()));
            } else {
                let extra = self.rng.random_range(1..=8);
                bytes.extend((0..extra).map(|_| self.rng.random::<u8>()));
            }
            self.counts.wrong_size += 1;
        }
        let jitter = if f.jitter > Duration::ZERO { f.jitter.mul_f64(self.rng.random::<f64>()) } else { Duration::ZERO };
        let due = delay + f.delay + jitter;
        let mut out = Vec::new();
        let duplicate = self.rng.random_bool(f.duplicate);
        if self.rng.random_bool(f.reorder) && self.held[leg].is_none() {
            self.held[leg] = Some(bytes);
            self.counts.reordered += 1;
            return out;
        }
        out.push(Outgoing { leg, delay: due, bytes: bytes.clone() });
        if duplicate {
            out.push(Outgoing { leg, delay: due + DUPLICATE_GAP, bytes });
            self.counts.duplicated += 1;
        }
        if let Some(held) = self.held[leg].take() {
            out.push(Outgoing { leg, delay: due + DUPLICATE_GAP, bytes: held });
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faults_are_counted_and_reproducible() {
        let faults = Faults { loss: 0.1, duplicate: 0.1, reorder: 0.1, corrupt: 0.1, wrong_size: 0.1, silent_slave: Some((2, 500)), seed: 7, ..Default::default() };
        let run = || {
            let mut f = FaultInjector::new(faults.clone());
            let mut sent = 0;
            for command in 0..1000 {
                for leg in 0..LEG_COUNT {
                    sent += f.apply(leg, command, Duration::ZERO, &[0u8; 20]).len();
                }
            }
            (f.counts, sent)
        };
        let (c, sent) = run();
        assert_eq!(run(), (c, sent));
        assert_eq!(c.silenced, 500);
        for n in [c.lost, c.duplicated, c.reordered, c.corrupted, c.wrong_size] {
            assert!((300..700).contains(&n), "{c:?}");
        }
        // Every packet not lost nor silenced goes out once, plus the duplicates; held packets
        // go out with the next one (at most one per slave may still be held at the end).
        let expected = 6000 - c.lost - c.silenced + c.duplicated;
        assert!((expected - 6..=expected).contains(&(sent as u64)), "{sent} sent, {c:?}");
        assert!(Faults { loss: 1.5, ..Default::default() }.validate().is_err());
    }

    #[test]
    fn destroyed_packets_are_limited_in_a_row() {
        let mut f = FaultInjector::new(Faults { loss: 0.5, corrupt: 0.3, max_consecutive: Some(2), seed: 3, ..Default::default() });
        let mut run = 0;
        for command in 0..10_000 {
            let out = f.apply(4, command, Duration::ZERO, &[0u8; 20]);
            let intact = out.iter().any(|o| o.bytes == [0u8; 20]);
            run = if intact { 0 } else { run + 1 };
            assert!(run <= 2, "command {command}: {run} destroyed in a row");
        }
        assert!(f.counts.lost > 3000 && f.counts.corrupted > 500, "{:?}", f.counts);
    }
}
