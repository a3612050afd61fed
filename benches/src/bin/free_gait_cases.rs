//! The free-gait cases of Section 7.7.5 run whole, end to end through the shipped scenarios
//! (landings from the motor currents): case 1, 400 s past the 8 cm step; case 3, the 1000 s
//! spline over the rough ground with and without navigation (the test suite runs a prefix of
//! case 3, `crates/hexadyn/tests/free_gait.rs`). Each is quoted as wall time and real-time
//! factor against the baseline measured in the same run, the 200 s free gait on flat ground
//! (`free_gait_straight`), per simulated second; its outcome is printed alongside: the XY
//! tracking error, the distance walked against the reference, the time deadlocked and whether
//! the run ends deadlocked (Section 7.7.4), the landings detected.
//! `free_gait_cases [case]` runs only the baseline and the case of that index (0, 1, 2).

use std::path::Path;
use std::time::Instant;

use hexadyn::robot::recorder::TimeSeries;
use hexadyn::scenario::{run_scenario, Scenario};

fn scenario(name: &str) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../python/hexadyn/scenarios").join(format!("{name}.toml"));
    Scenario::from_file(&path).expect("valid shipped scenario")
}

fn column<'a>(s: &'a TimeSeries, name: &str) -> &'a [f64] {
    s.values(name).expect("free gait column")
}

/// Runs a case: wall time (s) per simulated second, and its outcome.
fn run(name: &str) -> (f64, String) {
    let s = scenario(name);
    let start = Instant::now();
    let r = run_scenario(&s, |_| {}).expect("the run completes");
    let wall = start.elapsed().as_secs_f64();
    let g = r.summary.gait.as_ref().expect("a walk");
    let deadlock = column(&r.series, "deadlock");
    let deadlocked = deadlock.iter().filter(|&&d| d != 0.0).count() as f64 * s.period();
    let detections: f64 = (0..6).map(|l| column(&r.series, &format!("touchdown[{l}]")).iter().sum::<f64>()).sum();
    let outcome = format!(
        "XY error end {:.2} mm, max {:.2} mm; walked {:.3} of {:.3} m; deadlocked {deadlocked:.1} s in all{}; {detections} landings detected",
        1e3 * g.tracking_error_xy_final_m,
        1e3 * g.tracking_error_xy_max_m,
        g.distance_walked_m,
        g.reference_distance_m,
        if deadlock[deadlock.len() - 1] != 0.0 { ", ENDS DEADLOCKED" } else { "" }
    );
    println!("  {name}: {:.0} s simulated in {wall:.1} s (real-time factor {:.1})", s.duration, s.duration / wall);
    (wall / s.duration, outcome)
}

fn main() {
    let only: Option<usize> = std::env::args().nth(1).and_then(|a| a.parse().ok());
    let cases = ["free_gait_step", "free_gait_rough_spline", "free_gait_rough_spline_no_navigation"];
    println!("free gait, Section 7.7.5 cases (landing from the motor currents), against the flat free gait:");
    let (baseline, outcome) = run("free_gait_straight");
    println!("    {outcome}");
    for (i, name) in cases.iter().enumerate() {
        if only.is_some_and(|o| o != i) {
            continue;
        }
        let (per_second, outcome) = run(name);
        println!("    cost per simulated second {:.2} x the flat free gait; {outcome}", per_second / baseline);
    }
}
