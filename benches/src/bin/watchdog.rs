//! Watchdog benchmark (docs/protocol.md, "What a slave does"): how soon after `kill -9` of the
//! master the emulated boards' outputs are at 0 V, on the monotonic clock, with real processes.
//! N times (`watchdog N`, 10 by default): this program, started again as `watchdog master
//! PORT`, drives the standing robot through the slave emulator of this process on loopback;
//! once it runs, it is killed with SIGKILL (no stop command) and the emulator's report says when
//! its watchdog set every output to 0 V. Target: within 60 ms of the kill (the 50 ms of the
//! watchdog after the last command, which precedes the kill, plus the wake-up). The figures are
//! quoted, never asserted: the watchdog's logic is tested on a virtual clock (`tests/link.rs`).

use std::io::{BufRead, BufReader, Write};
use std::ops::ControlFlow;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use hexadyn::link::clock::{Clock, Percentiles};
use hexadyn::link::emulator::{Emulator, EmulatorOptions};
use hexadyn::link::run::run_robot;
use hexadyn::link::LinkConfig;
use hexadyn::scenario::{Override, Scenario};

/// How long each master drives the robot before it is killed.
const RUNNING: Duration = Duration::from_millis(500);
/// How long the emulator runs on after the kill: far beyond the watchdog.
const AFTER: Duration = Duration::from_millis(300);

fn standing() -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../python/hexadyn/scenarios/stand_six_legs.toml");
    Scenario::from_file_with(&path, &[Override { field: "scenario.duration_s".into(), value: toml::Value::Float(3600.0) }]).expect("shipped scenario")
}

/// The master process: drives the robot through the emulator listening on `port` until killed,
/// and says "running" once it does.
fn master(port: u16) {
    let mut said = false;
    let run = run_robot(&standing(), &LinkConfig::loopback(port), Clock::Monotonic, |t| {
        if t > 0.0 && !said {
            println!("running");
            std::io::stdout().flush().expect("stdout");
            said = true;
        }
        ControlFlow::Continue(())
    });
    eprintln!("the master ended before it was killed: {:?}", run.map(|r| r.stop));
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let [role, port] = &args[..] {
        assert_eq!(role, "master", "usage: watchdog [N] | watchdog master PORT");
        return master(port.parse().expect("a port"));
    }
    let runs: usize = args.first().and_then(|a| a.parse().ok()).unwrap_or(10);
    let s = standing();
    println!("hexadyn watchdog benchmark: {runs} masters killed with SIGKILL while driving the emulated slaves on loopback");
    let (mut after_kill, mut after_command) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        let emulator = Emulator::start(&s, &LinkConfig::loopback(0), EmulatorOptions::default()).expect("emulator");
        let port = emulator.command_address().port().to_string();
        let mut child = Command::new(std::env::current_exe().expect("this program")).args(["master", &port]).stdout(Stdio::piped()).spawn().expect("the master process");
        let mut line = String::new();
        BufReader::new(child.stdout.take().expect("its stdout")).read_line(&mut line).expect("the master runs");
        std::thread::sleep(RUNNING);
        let killed = Instant::now();
        child.kill().expect("SIGKILL");
        child.wait().expect("the master's end");
        std::thread::sleep(AFTER);
        let report = emulator.stop();
        let [trip] = report.watchdog[..] else { panic!("one watchdog trip expected: {:?}", report.watchdog) };
        after_kill.push(trip.at.saturating_duration_since(killed).as_secs_f64());
        after_command.push((trip.at - trip.last).as_secs_f64());
    }
    let ms = |p: Percentiles| format!("p50 {:6.2} ms   p99 {:6.2} ms   max {:6.2} ms", p.p50 * 1e3, p.p99 * 1e3, p.max * 1e3);
    println!("  outputs at 0 V after the kill          {}", ms(Percentiles::of(&after_kill)));
    println!("  ... after the last command applied     {}   (the 50 ms watchdog + the wake-up)", ms(Percentiles::of(&after_command)));
    let worst = Percentiles::of(&after_kill).max;
    println!("  target: within 60 ms of the kill: {}", if worst < 0.060 { "met" } else { "NOT met" });
}
