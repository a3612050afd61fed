//! The slave packets waiting for their send time (t_s0 + l Δt_s after the command, plus the
//! injected delays, Figs. 2.21-2.22), in order: the emulator's sender thread takes them on the
//! monotonic clock, a [`super::virtual_clock::VirtualClock`] on virtual time.

use std::collections::BTreeMap;
use std::net::{SocketAddr, UdpSocket};
use std::time::Instant;

/// A datagram slave `leg` sends to `to` at `due`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Datagram {
    pub due: Instant,
    pub leg: usize,
    pub to: SocketAddr,
    pub bytes: Vec<u8>,
}

impl Datagram {
    /// Sends it from its slave's socket.
    pub fn send(&self, slaves: &[UdpSocket]) -> Result<(), String> {
        slaves[self.leg].send_to(&self.bytes, self.to).map(|_| ()).map_err(|e| format!("slave {} could not send to {}: {e}", self.leg, self.to))
    }
}

/// Datagrams by due time; those due at the same instant in the order they were scheduled.
#[derive(Debug, Default)]
pub(crate) struct Agenda {
    pending: BTreeMap<(Instant, u64), Datagram>,
    scheduled: u64,
}

impl Agenda {
    pub fn push(&mut self, d: Datagram) {
        self.pending.insert((d.due, self.scheduled), d);
        self.scheduled += 1;
    }

    /// When the first datagram is due.
    pub fn next_due(&self) -> Option<Instant> {
        self.pending.first_key_value().map(|((due, _), _)| *due)
    }

    /// The first datagram, if it is due at `now`.
    pub fn pop_due(&mut self, now: Instant) -> Option<Datagram> {
        if self.next_due()? > now {
            return None;
        }
        self.pending.pop_first().map(|(_, d)| d)
    }

    pub fn is_empty(&self) -> bool {
        self.pending.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn datagrams_come_out_by_due_time_then_in_order() {
        let t = Instant::now();
        let to: SocketAddr = "127.0.0.1:9".parse().expect("address");
        let mut a = Agenda::default();
        for (ms, leg) in [(3, 0), (1, 1), (3, 2), (2, 3)] {
            a.push(Datagram { due: t + Duration::from_millis(ms), leg, to, bytes: Vec::new() });
        }
        assert_eq!(a.pop_due(t), None);
        let legs: Vec<usize> = std::iter::from_fn(|| a.pop_due(t + Duration::from_millis(3)).map(|d| d.leg)).collect();
        assert_eq!(legs, [1, 3, 0, 2]);
        assert!(a.is_empty() && a.next_due().is_none());
    }
}
