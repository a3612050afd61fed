//! Terrain-class benchmark (issue 11): the free gait of Section 7.7 walks the full dynamic
//! model across seeded terrains of each class (steps of 0-10 cm, slopes of 0-25°, rough ground
//! of 0-3 cm RMS; `physics::terrain::classes` says what each seed draws) and each run is judged
//! (`analysis::outcome`: no fall, no permanent deadlock, not stalled). Per class: the success
//! rate, the causes of the failures, the mean deadlock time, the distance walked over the
//! commanded one and the mean wall time of a run, quoted against the flat class of the same
//! kind measured in the same run (the baseline). Target: at least 95 % up to 8 cm steps, 20°
//! slopes and 2 cm RMS.
//!
//! Each run is the shipped `free_gait_straight.toml` (1 cm/s straight ahead, takeoff 1 s,
//! swing 3 s, t_post 2 s, friction 0.7, landing detected from the motor currents at 40 N as on
//! the real robot, with the elevator reflex of the swing) on the drawn terrain,
//! with the navigation system (on a slope the controller cannot otherwise know its attitude,
//! as in `free_gait_slope_square.toml`), for the class's crossing distance at 1 cm/s plus
//! 20 s. Runs are independent and spread over every core.
//!
//! `terrain_classes [--quick] [--seeds N] [--kind step|slope|rough] [--class LABEL]`:
//! 20 seeds per class by default (380 runs), 3 with `--quick`; `--class "step 8 cm"` runs one
//! class and lists every run.

use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use hexadyn::analysis::outcome::{BodyBottom, Bounds, Judge, Verdict};
use hexadyn::physics::terrain::classes::TerrainClass;
use hexadyn::scenario::{run_scenario_chunked, Override, Scenario, ScenarioError};

/// Walking speed (m/s): the thesis' cases 1 and 2 (Section 7.7.5).
const SPEED: f64 = 0.01;
/// Time walked after the crossing (s): every leg's last step onto the far side settles.
const MARGIN_S: f64 = 20.0;
const FULL_SEEDS: u64 = 20;
const QUICK_SEEDS: u64 = 3;

fn classes() -> Vec<TerrainClass> {
    let steps = (0..=5).map(|k| TerrainClass::Step { rise: 0.02 * k as f64 });
    let slopes = (0..=5).map(|k| TerrainClass::Slope { angle: (5.0 * k as f64).to_radians() });
    let rough = (0..=6).map(|k| TerrainClass::Rough { rms: 0.005 * k as f64 });
    steps.chain(slopes).chain(rough).collect()
}

fn kind(c: &TerrainClass) -> &'static str {
    match c {
        TerrainClass::Step { .. } => "step",
        TerrainClass::Slope { .. } => "slope",
        TerrainClass::Rough { .. } => "rough",
    }
}

/// Inside the target of issue 11.
fn in_target(c: &TerrainClass) -> bool {
    match *c {
        TerrainClass::Step { rise } => rise <= 0.08 + 1e-9,
        TerrainClass::Slope { angle } => angle <= 20f64.to_radians() + 1e-9,
        TerrainClass::Rough { rms } => rms <= 0.02 + 1e-9,
    }
}

struct RunResult {
    class: usize,
    seed: u64,
    drawn: String,
    /// The verdict, or the simulation's error.
    verdict: Result<Verdict, String>,
    wall_s: f64,
    simulated_s: f64,
}

fn run(class: &TerrainClass, seed: u64) -> (String, Result<Verdict, String>, f64) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../python/hexadyn/scenarios/free_gait_straight.toml");
    let seeded = match class.generate(seed) {
        Ok(s) => s,
        Err(e) => return (String::new(), Err(format!("terrain: {e}")), 0.0),
    };
    let duration = (seeded.crossing_m / SPEED + MARGIN_S).round();
    let overrides = [
        Override::new("scenario.duration_s", duration),
        Override::new("gait.navigation", true),
        Override::new("gait.heading.vx_m_s", SPEED),
    ];
    let mut s = Scenario::from_file_with(&path, &overrides).expect("the shipped free-gait scenario with valid overrides");
    s.terrain = seeded.terrain.clone();
    let mut judge = Judge::new(seeded.terrain.as_ref(), seeded.nominal_normal, BodyBottom::of(s.robot.pantograph().expect("the AMRU5 free-gait scenario")), Bounds::default());
    let mut missing = None;
    let mut last_t = 0.0;
    let outcome = run_scenario_chunked(
        &s,
        2000,
        |chunk| {
            last_t = chunk.values("t").and_then(|t| t.last().copied()).unwrap_or(last_t);
            judge.observe(&chunk).unwrap_or_else(|e| {
                missing = Some(e.to_string());
                ControlFlow::Break(())
            })
        },
        |_| ControlFlow::Continue(()),
    );
    let verdict = match (outcome, missing) {
        (_, Some(e)) => Err(e),
        (Ok(_) | Err(ScenarioError::Stopped { .. }), None) => Ok(judge.finish(SPEED * duration)),
        (Err(e), None) => Err(format!("at t = {last_t:.1} s: {e}")),
    };
    (seeded.drawn, verdict, last_t)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str| args.iter().position(|a| a == flag).and_then(|i| args.get(i + 1)).cloned();
    let seeds = value("--seeds").map(|n| n.parse::<u64>().expect("--seeds N: a whole number")).unwrap_or(if args.iter().any(|a| a == "--quick") { QUICK_SEEDS } else { FULL_SEEDS });
    let only_kind = value("--kind");
    let only_class = value("--class");
    let classes: Vec<TerrainClass> = classes()
        .into_iter()
        .filter(|c| only_kind.as_deref().is_none_or(|k| k == kind(c)))
        .filter(|c| only_class.as_deref().is_none_or(|l| l == c.label()))
        .collect();
    assert!(!classes.is_empty(), "no class matches --kind {only_kind:?} --class {only_class:?} (labels such as \"step 8 cm\", \"slope 20 deg\", \"rough 2.0 cm RMS\")");
    let jobs: Vec<(usize, u64)> = (0..classes.len()).flat_map(|c| (0..seeds).map(move |s| (c, s))).collect();
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get()).min(jobs.len());
    println!("hexadyn terrain-class benchmark: free gait (Section 7.7), full dynamic model, {SPEED} m/s, {} classes x {seeds} seeds on {workers} threads", classes.len());

    let next = AtomicUsize::new(0);
    let results = Mutex::new(Vec::new());
    let started = Instant::now();
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| {
                while let Some(&(class, seed)) = jobs.get(next.fetch_add(1, Ordering::Relaxed)) {
                    let start = Instant::now();
                    let (drawn, verdict, simulated_s) = run(&classes[class], seed);
                    let wall_s = start.elapsed().as_secs_f64();
                    let mut r = results.lock().expect("no worker panicked");
                    r.push(RunResult { class, seed, drawn, verdict, wall_s, simulated_s });
                    eprint!("\r{} / {} runs, {:.0} s", r.len(), jobs.len(), started.elapsed().as_secs_f64());
                }
            });
        }
    });
    eprintln!();
    let mut results = results.into_inner().expect("no worker panicked");
    results.sort_by_key(|r| (r.class, r.seed));
    report(&classes, &results, only_class.is_some());
    println!("total wall time {:.0} s for {} runs ({:.0} s of simulated walking)", started.elapsed().as_secs_f64(), results.len(), results.iter().map(|r| r.simulated_s).sum::<f64>());
}

fn report(classes: &[TerrainClass], results: &[RunResult], every_run: bool) {
    println!("{:<18} {:>6} {:>9} {:>7} {:>11} {:>8} {:>8} {:>8}  failures", "class", "target", "success", "runs", "walked/cmd", "dlock s", "wall s", "x flat");
    let mut flat_wall: BTreeMap<&str, f64> = BTreeMap::new();
    for (i, c) in classes.iter().enumerate() {
        let runs: Vec<&RunResult> = results.iter().filter(|r| r.class == i).collect();
        let n = runs.len() as f64;
        let mut causes: BTreeMap<String, usize> = BTreeMap::new();
        let (mut successes, mut walked, mut deadlock) = (0, 0.0, 0.0);
        for r in &runs {
            match &r.verdict {
                Ok(v) => {
                    walked += v.walked_m / (SPEED * (r.simulated_s.max(1.0)));
                    deadlock += v.deadlock_s;
                    match v.failure {
                        None => successes += 1,
                        Some(f) => *causes.entry(f.cause().to_string()).or_default() += 1,
                    }
                }
                Err(_) => *causes.entry("simulation error".to_string()).or_default() += 1,
            }
        }
        let wall = runs.iter().map(|r| r.wall_s).sum::<f64>() / n;
        let flat = *flat_wall.entry(kind(c)).or_insert(wall);
        let rate = 100.0 * successes as f64 / n;
        let target = if in_target(c) { if rate >= 95.0 { "met" } else { "MISSED" } } else { "-" };
        let failures: Vec<String> = causes.iter().map(|(k, v)| format!("{k} {v}")).collect();
        println!("{:<18} {:>6} {:>8.0}% {:>7} {:>11.2} {:>8.1} {:>8.1} {:>8.2}  {}", c.label(), target, rate, runs.len(), walked / n, deadlock / n, wall, wall / flat, failures.join(", "));
        for r in runs.iter().filter(|r| every_run || !matches!(&r.verdict, Ok(v) if v.failure.is_none())) {
            let what = match &r.verdict {
                Ok(Verdict { failure: Some(f), .. }) => format!("{f:?}"),
                Ok(v) => format!("success, walked {:.2} m, {:.0} s in deadlock", v.walked_m, v.deadlock_s),
                Err(e) => e.clone(),
            };
            println!("    seed {:>2} ({}): {what}", r.seed, r.drawn);
        }
    }
}
