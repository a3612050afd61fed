//! The free gait of Section 7.7 over a step higher than its foot lift (issue 11): the shipped
//! `free_gait_straight.toml` (lift `clearance_m` = 4.5 cm, landing detected from the motor
//! currents at 40 N) walks at 1 cm/s onto an 8 cm step drawn by the terrain-class benchmark
//! (`physics::terrain::classes`, the class "step 8 cm"), with the navigation system as in the
//! benchmark, judged as there (`analysis::outcome`: no fall, no permanent deadlock, not
//! stalled). The swing of the thesis keeps the foot 4.5 cm above its old foothold and the riser
//! stops it; the elevator reflex (`control::gait::free::elevator`, from the motor currents)
//! lifts it over.

use std::path::Path;

use hexadyn::analysis::outcome::{BodyBottom, Bounds, Judge, Verdict};
use hexadyn::physics::terrain::classes::TerrainClass;
use hexadyn::scenario::{run_scenario, Override, Scenario};

/// Walking speed of the benchmark (m/s).
const SPEED: f64 = 0.01;

/// The benchmark's run of `free_gait_straight.toml` on the step class `rise` drawn from `seed`,
/// with or without the elevator reflex: the verdict and what the seed drew.
fn walk_onto(rise: f64, seed: u64, elevator: bool) -> (Verdict, String) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/hexadyn/scenarios/free_gait_straight.toml");
    let seeded = TerrainClass::Step { rise }.generate(seed).unwrap();
    let duration = (seeded.crossing_m / SPEED + 20.0).round();
    let overrides = [
        Override::new("scenario.duration_s", duration),
        Override::new("gait.navigation", true),
        Override::new("gait.heading.vx_m_s", SPEED),
        Override::new("gait.free.elevator", elevator),
    ];
    let mut s = Scenario::from_file_with(&path, &overrides).unwrap_or_else(|e| panic!("{e}"));
    s.terrain = seeded.terrain.clone();
    let r = run_scenario(&s, |_| {}).unwrap();
    let mut judge = Judge::new(seeded.terrain.as_ref(), seeded.nominal_normal, BodyBottom::of(s.robot.pantograph().expect("the AMRU5 free-gait scenario")), Bounds::default());
    let _ = judge.observe(&r.series).unwrap();
    (judge.finish(SPEED * duration), seeded.drawn)
}

/// An 8 cm step up, met square (seed 6 of the class: edge normal at −1°, 11 cm ahead of the
/// front feet), with the shipped 4.5 cm lift: crossed with the elevator reflex (the
/// benchmark's success: no fall, no deadlock left at the end, not stalled), a failure without
/// it, which also walks at least 30 cm less.
#[test]
fn the_elevator_reflex_crosses_an_8_cm_step_up_with_the_4_5_cm_lift() {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/hexadyn/scenarios/free_gait_straight.toml")).unwrap();
    assert!(text.contains("clearance_m = 0.045"), "the shipped lift is 4.5 cm");
    let (with, drawn) = walk_onto(0.08, 6, true);
    println!("{drawn}: with the elevator reflex {with:?}");
    assert!(drawn.starts_with("up 80 mm"), "{drawn}");
    assert!(with.failure.is_none(), "with the reflex: {with:?}");
    let (without, _) = walk_onto(0.08, 6, false);
    println!("{drawn}: without {without:?}");
    assert!(without.failure.is_some(), "without the reflex the riser stops the 4.5 cm swing: {without:?}");
    assert!(with.walked_m > without.walked_m + 0.3, "walked {} m with the reflex, {} m without", with.walked_m, without.walked_m);
}
