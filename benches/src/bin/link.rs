//! Link timing benchmark (thesis Section 2.3.2, Figs. 2.21-2.22): 10^4 control periods at
//! 100 Hz of the master driving the standing robot's 18 PI loops against the slave emulator on
//! the loopback interface. For each broadcast, its lateness against its deadline on the
//! absolute monotonic clock; for each period, when the last slave packet arrived and how long
//! the controller took. Target: p99 lateness under 100 µs and no missed period on an idle
//! machine. `link N` runs N periods. The link threads ask for SCHED_FIFO priority 40 and run
//! on the normal scheduler when that is not permitted (the output says which). This is the one
//! real-time measurement of the link, on the monotonic clock: its figures are quoted, never
//! asserted (the tests run the link in lock-step on a virtual clock, `tests/link.rs`).

use std::ops::ControlFlow;
use std::path::Path;
use std::time::Duration;

use hexadyn::link::clock::{Clock, Percentiles};
use hexadyn::link::emulator::{Emulator, EmulatorOptions};
use hexadyn::link::run::run_robot;
use hexadyn::link::LinkConfig;
use hexadyn::scenario::{Override, Scenario};

fn main() {
    let periods: u64 = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(10_000);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../python/hexadyn/scenarios/stand_six_legs.toml");
    let duration = periods as f64 * 0.01;
    let s = Scenario::from_file_with(&path, &[Override { field: "scenario.duration_s".into(), value: toml::Value::Float(duration) }]).expect("shipped scenario");
    let mut config = LinkConfig::loopback(0);
    config.timing.realtime_priority = Some(40);
    let emulator = Emulator::start(&s, &config, EmulatorOptions { idle_timeout: Some(Duration::from_secs(5)), ..Default::default() }).expect("emulator");
    config.broadcast.set_port(emulator.command_address().port());
    println!("hexadyn link benchmark: {periods} periods at 100 Hz, master + 6 emulated slaves on loopback ({} s)", duration);
    let run = run_robot(&s, &config, Clock::Monotonic, |_| ControlFlow::Continue(())).expect("linked run");
    let report = emulator.stop();
    let st = &run.stats;
    let us = |p: Percentiles| format!("p50 {:8.1} us   p99 {:8.1} us   max {:8.1} us", p.p50 * 1e6, p.p99 * 1e6, p.max * 1e6);
    println!("  real-time threads     master {}, emulator {}", st.realtime, report.realtime);
    println!("  broadcast lateness    {}   ({} broadcasts)", us(Percentiles::of(&st.lateness)), st.broadcasts);
    println!("  last slave packet     {}   after the broadcast (Fig. 2.22: 5 ms + jitter)", us(Percentiles::of(&st.last_reply)));
    println!("  emulator model period {}", us(report.step_time));
    println!("  missed periods        {}   safety stop: {}", st.missed_periods, run.stop.map_or_else(|| "none".to_string(), |s| s.to_string()));
    println!("  dropped packets       {} (stale {}, duplicates {}, rejected {})", st.dropped(), st.stale, st.duplicates, st.rejected.total());
    let p99 = Percentiles::of(&st.lateness).p99;
    println!("  target p99 < 100 us, no missed period: {}", if p99 < 100e-6 && st.missed_periods == 0 { "met" } else { "NOT met" });
}
