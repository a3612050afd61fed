//! The real-time link to the robot (thesis Section 2.3.2, Figs. 2.17-2.22): the master PC
//! broadcasts the 18 motor commands (or servo goals) to the six slave boards over UDP every 10 ms and collects
//! their sensor packets; the same controller that drives the simulated robot drives the real
//! one (architecture principle 3).
//!
//! - [`protocol`]: the 36-byte command and 20-byte slave packets (layout, scaling, CRC), for
//!   DC motors (PWM duties, encoder counts) or position servos (goals, present positions);
//! - [`drive`]: a joint's counts and setpoints in the controller's units;
//! - [`config`]: the link configuration file (addresses, period, Fig. 2.21 timing, safety);
//! - [`clock`]: the clock of the deadline loop, monotonic (precise waits) or virtual (the master
//!   and the emulator in lock-step, [`virtual_clock`]);
//! - [`master`]: the deadline loop, the run number, packet freshness and the safety stops;
//! - [`slave`]: what a slave board does with the commands (its master, the watchdog);
//! - [`UdpPlant`]: the robot behind the link as a [`crate::control::Plant`];
//! - [`emulator`]: six slaves answering like the boards, backed by the simulated robot, with
//!   injectable faults ([`faults`]);
//! - [`run`]: a scenario's controller driving the robot through the link, recorded like a
//!   simulation.
//!
//! The link sits above [`crate::scenario`]: it runs a scenario's controller, and the emulator
//! the scenario's simulated robot.

mod agenda;
pub mod clock;
pub mod config;
pub mod drive;
pub mod emulator;
pub mod faults;
pub mod master;
pub mod protocol;
pub mod run;
pub mod slave;
mod udp_plant;
pub mod virtual_clock;

pub use config::{ConfigError, LinkConfig, Safety, Timing};
pub use master::{SafetyStop, StopReason};
pub use udp_plant::{MissedPeriod, UdpPlant};

use crate::scenario::ScenarioError;

/// What can go wrong on the link.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    #[error("{0}")]
    Config(#[from] ConfigError),
    #[error("{0}")]
    Scenario(#[from] ScenarioError),
    #[error("{what} {address}: {source}")]
    Socket { what: &'static str, address: String, source: std::io::Error },
    /// The scenario and the link configuration do not fit together.
    #[error("{0}")]
    Mismatch(String),
    #[error("no answer from the slave(s) of leg(s) {legs:?} within {timeout_s} s of commands broadcast to {broadcast}: check that the boards (or `hexadyn robot emulate`) run with this link configuration, and that no other master drives them (a board follows one master until 50 ms after its last command)")]
    NoAnswer { legs: Vec<usize>, timeout_s: f64, broadcast: String },
    /// Slaves answer the start's commands, but only after the period.
    #[error(
        "{origin}: the slave(s) of leg(s) {legs:?} answer {} ms after the broadcast, up to {beyond_ms:.2} ms after their slots (t_s0 + leg × Δt_s): later than the period of {period_ms} ms (`timing.period_s`), never before the next deadline; allowed: every slave packet within the period (boards that answer sooner, or a longer period)",
        milliseconds(.delays_ms)
    )]
    LateReplies { legs: Vec<usize>, delays_ms: Vec<f64>, beyond_ms: f64, period_ms: f64, origin: String },
    /// The master stopped the robot (every motor at 0 V).
    #[error("{0}")]
    Stopped(SafetyStop),
    /// The emulator's simulated robot failed.
    #[error("the emulated robot failed: {0}")]
    Emulator(String),
}

/// Times in ms, two decimals, comma-separated.
fn milliseconds(values: &[f64]) -> String {
    values.iter().map(|v| format!("{v:.2}")).collect::<Vec<_>>().join(", ")
}
