//! The link configuration file: where the master and the six slave boards are, the control
//! period and the reply timing of Fig. 2.21, and the safety limits. Errors name the file, the
//! line, the field, the value and what is allowed, like the robot description and scenarios.
//!
//! ```toml
//! [master]
//! address = "127.0.0.1:47100"          # the master's socket: commands leave from it, the slave
//!                                      #   packets come back to it (port 0: any free port)
//! broadcast = "127.255.255.255:47101"  # the commands are broadcast to this address; every
//!                                      #   slave listens on its port
//! [slaves]
//! addresses = ["127.0.0.10:0", "127.0.0.11:0", "127.0.0.12:0",
//!              "127.0.0.13:0", "127.0.0.14:0", "127.0.0.15:0"]
//!                                      # board of leg 0..5: the address its packets come from
//!                                      #   (port 0: any port of that IP)
//! [timing]
//! period_s = 0.01                      # control period Δt (100 Hz, Section 2.3.2)
//! first_reply_s = 0.0025               # t_s0: slave 0 answers 2.5 ms after the broadcast
//! reply_interval_s = 0.0005            # Δt_s: the next slave 500 µs later (Fig. 2.21-2.22)
//! spin_s = 0.0002                      # precise wait: poll until the deadline minus this, spin
//! realtime_priority = 0                # SCHED_FIFO priority 1..99 of the link threads; 0: none
//! [safety]
//! missing_periods = 3                  # a slave silent this many periods in a row stops the robot
//! connect_timeout_s = 5.0              # the six slaves must answer within this at the start
//! overrun_tolerance_s = 0.0            # a command ready later than this after its deadline
//!                                      #   is a controller overrun (stop)
//! ```

use std::net::{Ipv4Addr, SocketAddr, SocketAddrV4};
use std::path::Path;
use std::time::Duration;

use serde::Deserialize;

use crate::fields::{Ctx, DescriptionError, SpanIndex};
use crate::hexapod::LEG_COUNT;

/// Where "missing field" errors send the reader.
const REFERENCE: &str = "the module docs of hexadyn::link::config, docs/protocol.md or the shipped loopback.toml";

/// A link configuration that could not be read or is invalid.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ConfigError {
    #[error("{file}: cannot read the link configuration: {reason}")]
    Io { file: String, reason: String },
    /// Syntax or field error (the message names the file, line and field).
    #[error("{0}")]
    Invalid(DescriptionError),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawConfig {
    master: RawMaster,
    slaves: RawSlaves,
    #[serde(default)]
    timing: RawTiming,
    #[serde(default)]
    safety: RawSafety,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMaster {
    address: String,
    broadcast: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSlaves {
    addresses: Vec<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, default)]
struct RawTiming {
    period_s: f64,
    first_reply_s: f64,
    reply_interval_s: f64,
    spin_s: f64,
    realtime_priority: i64,
}

impl Default for RawTiming {
    fn default() -> Self {
        let t = Timing::default();
        RawTiming { period_s: t.period.as_secs_f64(), first_reply_s: t.first_reply.as_secs_f64(), reply_interval_s: t.reply_interval.as_secs_f64(), spin_s: t.spin.as_secs_f64(), realtime_priority: 0 }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, default)]
struct RawSafety {
    missing_periods: i64,
    connect_timeout_s: f64,
    overrun_tolerance_s: f64,
}

impl Default for RawSafety {
    fn default() -> Self {
        let s = Safety::default();
        RawSafety { missing_periods: i64::from(s.missing_periods), connect_timeout_s: s.connect_timeout.as_secs_f64(), overrun_tolerance_s: s.overrun_tolerance.as_secs_f64() }
    }
}

/// The timing of the master/slave exchange (Section 2.3.2, Fig. 2.21).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    /// Control period Δt: one broadcast per period, on an absolute clock.
    pub period: Duration,
    /// t_s0: when slave 0 answers after the broadcast (2.5 ms on AMRU5).
    pub first_reply: Duration,
    /// Δt_s: between two slaves' answers (500 µs on AMRU5).
    pub reply_interval: Duration,
    /// Precise waits poll until the deadline minus `spin`, then spin on the clock.
    pub spin: Duration,
    /// SCHED_FIFO priority of the master thread and the emulator's threads (1..99); `None`:
    /// the normal scheduler.
    pub realtime_priority: Option<u8>,
}

impl Default for Timing {
    fn default() -> Self {
        Timing { period: Duration::from_millis(10), first_reply: Duration::from_micros(2500), reply_interval: Duration::from_micros(500), spin: Duration::from_micros(200), realtime_priority: None }
    }
}

impl Timing {
    /// When the slave of `leg` answers after receiving the broadcast.
    pub fn reply_delay(&self, leg: usize) -> Duration {
        self.first_reply + self.reply_interval * leg as u32
    }
}

/// The safety limits of the master (Section 2.3.2: "if necessary, the robot is stopped").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Safety {
    /// A slave whose packet is missing this many periods in a row stops the robot.
    pub missing_periods: u32,
    /// At the start, the six slaves must answer within this time.
    pub connect_timeout: Duration,
    /// A controller command ready later than this after its deadline is an overrun (0: any
    /// lateness); within it, the command is broadcast late.
    pub overrun_tolerance: Duration,
}

impl Default for Safety {
    fn default() -> Self {
        Safety { missing_periods: 3, connect_timeout: Duration::from_secs(5), overrun_tolerance: Duration::ZERO }
    }
}

/// A validated link configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct LinkConfig {
    /// The master's socket: commands leave from it, slave packets arrive on it.
    pub master: SocketAddrV4,
    /// Where the commands are broadcast; every slave listens on its port.
    pub broadcast: SocketAddrV4,
    /// The address each board sends from, leg 0..5 (port 0: any port of that IP).
    pub slaves: [SocketAddrV4; LEG_COUNT],
    pub timing: Timing,
    pub safety: Safety,
    /// The file it was read from (or an origin name).
    pub origin: String,
}

impl LinkConfig {
    /// A configuration on the loopback interface: the master on 127.0.0.1, the slaves on
    /// 127.0.0.10..15, the commands broadcast to 127.255.255.255 on `broadcast_port`; any
    /// free ports elsewhere. The AMRU5 timing and safety limits.
    pub fn loopback(broadcast_port: u16) -> Self {
        LinkConfig {
            master: SocketAddrV4::new(Ipv4Addr::LOCALHOST, 0),
            broadcast: SocketAddrV4::new(Ipv4Addr::new(127, 255, 255, 255), broadcast_port),
            slaves: std::array::from_fn(|leg| SocketAddrV4::new(Ipv4Addr::new(127, 0, 0, 10 + leg as u8), 0)),
            timing: Timing::default(),
            safety: Safety::default(),
            origin: "loopback".into(),
        }
    }

    pub fn from_file(path: impl AsRef<Path>) -> Result<Self, ConfigError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let text = crate::fields::read_input(path).map_err(|reason| ConfigError::Io { file: file.clone(), reason })?;
        Self::from_str(&text, &file)
    }

    /// Parses and validates a configuration; `origin` names it in errors.
    #[allow(clippy::should_implement_trait)]
    pub fn from_str(text: &str, origin: &str) -> Result<Self, ConfigError> {
        let index = SpanIndex::build_for(text, origin, REFERENCE).map_err(ConfigError::Invalid)?;
        let raw: RawConfig = toml::from_str(text).map_err(|e| ConfigError::Invalid(index.serde_error(&e)))?;
        let c = Ctx { file: origin, index: Some(&index) };
        validate(&raw, &c).map_err(ConfigError::Invalid)
    }

    /// The leg whose board sends from `from`, if any.
    pub fn leg_of(&self, from: SocketAddr) -> Option<usize> {
        let SocketAddr::V4(from) = from else { return None };
        self.slaves.iter().position(|s| s.ip() == from.ip() && (s.port() == 0 || s.port() == from.port()))
    }
}

fn address(c: &Ctx, field: &str, text: &str) -> Result<SocketAddrV4, DescriptionError> {
    text.parse().map_err(|_| c.err(field, format!("{text:?}"), "not an IPv4 socket address", "\"a.b.c.d:port\", e.g. \"127.0.0.1:47100\""))
}

fn validate(raw: &RawConfig, c: &Ctx) -> Result<LinkConfig, DescriptionError> {
    let master = address(c, "master.address", &raw.master.address)?;
    let broadcast = address(c, "master.broadcast", &raw.master.broadcast)?;
    if broadcast.port() == 0 {
        return Err(c.err("master.broadcast", format!("{:?}", raw.master.broadcast), "port 0", "a port 1..65535: the slaves listen on it"));
    }
    let s = &raw.slaves.addresses;
    if s.len() != LEG_COUNT {
        return Err(c.err("slaves.addresses", format!("{} addresses", s.len()), "not one per leg", "six addresses, the boards of legs 0..5 in order"));
    }
    let mut slaves = [SocketAddrV4::new(Ipv4Addr::UNSPECIFIED, 0); LEG_COUNT];
    for (leg, text) in s.iter().enumerate() {
        let field = format!("slaves.addresses[{leg}]");
        let a = address(c, &field, text)?;
        if let Some(other) = slaves[..leg].iter().position(|b| b.ip() == a.ip() && (a.port() == 0 || b.port() == 0 || a.port() == b.port())) {
            return Err(c.err(&field, format!("{text:?}"), &format!("the address of leg {other} too"), "six addresses that tell the boards apart (distinct IPs, or distinct non-zero ports)"));
        }
        slaves[leg] = a;
    }

    let t = &raw.timing;
    c.check(t.period_s > 0.0 && t.period_s <= 1.0, "timing.period_s", t.period_s, "a period in (0, 1] s (0.01 on AMRU5)")?;
    c.non_negative("timing.first_reply_s", t.first_reply_s)?;
    c.non_negative("timing.reply_interval_s", t.reply_interval_s)?;
    let last = t.first_reply_s + (LEG_COUNT - 1) as f64 * t.reply_interval_s;
    c.check(last < t.period_s, "timing.reply_interval_s", t.reply_interval_s, &format!("first_reply_s + 5 reply_interval_s < period_s = {} s: the six replies fit in a period", t.period_s))?;
    c.check(t.spin_s >= 0.0 && t.spin_s <= 0.5 * t.period_s, "timing.spin_s", t.spin_s, "a time in [0, period_s / 2] s")?;
    if !(0..=99).contains(&t.realtime_priority) {
        return Err(c.err("timing.realtime_priority", t.realtime_priority, "out of range", "0 (normal scheduling) or a SCHED_FIFO priority 1..99"));
    }
    let r = &raw.safety;
    if !(1..=1000).contains(&r.missing_periods) {
        return Err(c.err("safety.missing_periods", r.missing_periods, "out of range", "a number of periods 1..1000 (3 by default)"));
    }
    c.check(r.connect_timeout_s > 0.0 && r.connect_timeout_s <= 3600.0, "safety.connect_timeout_s", r.connect_timeout_s, "a time in (0, 3600] s")?;
    c.check(r.overrun_tolerance_s >= 0.0 && r.overrun_tolerance_s < t.period_s, "safety.overrun_tolerance_s", r.overrun_tolerance_s, "a time in [0, period_s) s")?;
    Ok(LinkConfig {
        master,
        broadcast,
        slaves,
        timing: Timing {
            period: Duration::from_secs_f64(t.period_s),
            first_reply: Duration::from_secs_f64(t.first_reply_s),
            reply_interval: Duration::from_secs_f64(t.reply_interval_s),
            spin: Duration::from_secs_f64(t.spin_s),
            realtime_priority: (t.realtime_priority > 0).then_some(t.realtime_priority as u8),
        },
        safety: Safety { missing_periods: r.missing_periods as u32, connect_timeout: Duration::from_secs_f64(r.connect_timeout_s), overrun_tolerance: Duration::from_secs_f64(r.overrun_tolerance_s) },
        origin: c.file.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
[master]
address = "127.0.0.1:47100"
broadcast = "127.255.255.255:47101"
[slaves]
addresses = ["127.0.0.10:0", "127.0.0.11:0", "127.0.0.12:0", "127.0.0.13:0", "127.0.0.14:0", "127.0.0.15:0"]
[timing]
period_s = 0.01
"#;

    #[test]
    fn reads_a_configuration() {
        let c = LinkConfig::from_str(GOOD, "link.toml").expect("valid");
        assert_eq!(c.broadcast.port(), 47101);
        assert_eq!(c.timing.reply_delay(5), Duration::from_micros(5000));
        assert_eq!(c.safety.missing_periods, 3);
        assert_eq!(c.leg_of("127.0.0.13:5555".parse().expect("address")), Some(3));
        assert_eq!(c.leg_of("127.0.0.1:5555".parse().expect("address")), None);
    }

    #[test]
    fn errors_name_file_line_field_value_and_allowed() {
        let bad = GOOD.replace("127.0.0.12:0", "127.0.0.300:0");
        let e = LinkConfig::from_str(&bad, "link.toml").expect_err("invalid").to_string();
        assert!(e.starts_with("link.toml:6: field `slaves.addresses[2]` = \"127.0.0.300:0\": not an IPv4 socket address; allowed:"), "{e}");
        let bad = GOOD.replace("period_s = 0.01", "period_s = 0.004");
        let e = LinkConfig::from_str(&bad, "link.toml").expect_err("invalid").to_string();
        assert!(e.contains("field `timing.reply_interval_s`") && e.contains("fit in a period"), "{e}");
        let bad = GOOD.replace("127.0.0.15:0", "127.0.0.10:0");
        let e = LinkConfig::from_str(&bad, "link.toml").expect_err("invalid").to_string();
        assert!(e.contains("the address of leg 0 too"), "{e}");
        let e = LinkConfig::from_str(&GOOD.replace("[timing]", "[timing]\nperiod = 1"), "link.toml").expect_err("invalid").to_string();
        assert!(e.contains("unknown field"), "{e}");
    }
}
