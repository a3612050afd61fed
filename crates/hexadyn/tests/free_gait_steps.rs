//! The free gait of Section 7.7 over a step higher than its foot lift (issue 11): the shipped
//! `free_gait_straight.toml` (lift `clearance_m` = 4.5 cm, landing detected from the motor
//! currents at 40 N) walks at 1 cm/s onto an 8 cm step drawn by the terrain-class benchmark
//! (`physics::terrain::classes`, the class "step 8 cm"), with the navigation system as in the
//! benchmark, judged as there (`analysis::outcome`: no fall, no permanent deadlock, not
//! stalled). The swing of the thesis keeps the foot 4.5 cm above its old foothold and the riser
//! stops it; the elevator reflex (`control::gait::free::elevator`, from the motor currents)
//! lifts it over. And down a staircase (issue 37), where a landing foot the ground pushes up
//! has landed, and across a 20° slope, where a lift must not leave a support that a landing
//! tips, and down a staircase whose nosings the feet slide off; and across boulders higher than
//! a swinging foot can rise over.

use std::path::Path;

use hexadyn::analysis::outcome::{BodyBottom, Bounds, Judge, Verdict};
use hexadyn::physics::terrain::classes::TerrainClass;
use hexadyn::scenario::{run_scenario, Override, Scenario, Summary};

/// Walking speed of the benchmark (m/s).
const SPEED: f64 = 0.01;

/// The benchmark's run of `free_gait_straight.toml` on `class` drawn from `seed`, with the
/// scenario's fields `changed` (the elevator reflex off, the foot lift): the verdict, the
/// summary and what the seed drew.
fn walk_onto(class: TerrainClass, seed: u64, changed: &[Override]) -> (Verdict, Summary, String) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/hexadyn/scenarios/free_gait_straight.toml");
    let seeded = class.generate(seed).unwrap();
    let duration = (seeded.crossing_m / SPEED + 20.0).round();
    let mut overrides = vec![Override::new("scenario.duration_s", duration), Override::new("gait.navigation", true), Override::new("gait.heading.vx_m_s", SPEED)];
    overrides.extend_from_slice(changed);
    let mut s = Scenario::from_file_with(&path, &overrides).unwrap_or_else(|e| panic!("{e}"));
    s.terrain = seeded.terrain.clone();
    let r = run_scenario(&s, |_| {}).unwrap();
    let mut judge = Judge::new(seeded.terrain.as_ref(), seeded.nominal_normal, BodyBottom::of(s.robot.pantograph().expect("the AMRU5 free-gait scenario")), Bounds::default());
    let _ = judge.observe(&r.series).unwrap();
    (judge.finish(SPEED * duration), r.summary, seeded.drawn)
}

/// The benchmark's run on `class` drawn from `seed` with the fields `changed`, on a terrain whose
/// description contains `drawn`: issue 37's success (no fall, no permanent deadlock, not
/// stalled), never fewer than three loaded feet for more than 0.2 s, and no foot in its takeoff
/// or swing carrying more than 15 % of the weight for more than 0.3 s.
fn walks_without_stumbling(class: TerrainClass, seed: u64, changed: &[Override], drawn: &str) {
    let (v, summary, described) = walk_onto(class, seed, changed);
    let g = summary.gait.as_ref().expect("gait summary");
    let (lost, airborne) = (g.episodes.support_loss.longest, g.episodes.longest_airborne_load());
    println!("{described}: {v:?}; longest support loss {lost:?}, load in the air {airborne:?}");
    assert!(described.contains(drawn), "seed {seed} drew {described}, not {drawn}");
    assert!(v.failure.is_none(), "{described}: {v:?}");
    assert!(lost.is_none_or(|(d, _)| d <= 0.2), "{described}: fewer than three loaded feet: {lost:?}");
    assert!(airborne.is_none_or(|(d, _, _)| d <= 0.3), "{described}: a foot in the air carried the body: {airborne:?}");
}

/// An 8 cm step up, met square (seed 6 of the class: edge normal at −1°, 11 cm ahead of the
/// front feet), with the shipped 4.5 cm lift: crossed with the elevator reflex (the
/// benchmark's success: no fall, no deadlock left at the end, not stalled), a failure without
/// it, which also walks at least 30 cm less.
#[test]
fn the_elevator_reflex_crosses_an_8_cm_step_up_with_the_4_5_cm_lift() {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/hexadyn/scenarios/free_gait_straight.toml")).unwrap();
    assert!(text.contains("clearance_m = 0.045"), "the shipped lift is 4.5 cm");
    let step = TerrainClass::Step { rise: 0.08 };
    let (with, _, drawn) = walk_onto(step, 6, &[]);
    println!("{drawn}: with the elevator reflex {with:?}");
    assert!(drawn.starts_with("up 80 mm"), "{drawn}");
    assert!(with.failure.is_none(), "with the reflex: {with:?}");
    let (without, _, _) = walk_onto(step, 6, &[Override::new("gait.free.elevator", false)]);
    println!("{drawn}: without {without:?}");
    assert!(without.failure.is_some(), "without the reflex the riser stops the 4.5 cm swing: {without:?}");
    assert!(with.walked_m > without.walked_m + 0.3, "walked {} m with the reflex, {} m without", with.walked_m, without.walked_m);
}

/// Down three 6 cm risers (seed 0 of the class "stairs down 6 cm": treads 510 mm, edges at
/// 12.5° to the heading) with the shipped 4.5 cm lift: crossed, and no foot in its takeoff or
/// swing carries more than 15 % of the weight for 0.3 s (issue 37's criterion). Before a
/// landing foot pushed up by the ground counted as landed (`LandingDetector::pushed_up`), the
/// first landing on the lower tread went undetected at the bottom of its reach while the body
/// came down to it, and a swinging foot carried the body for 2.2 s from t = 16.8 s.
#[test]
fn a_staircase_down_is_walked_without_load_in_the_air() {
    let (v, summary, drawn) = walk_onto(TerrainClass::Stairs { riser: 0.06, up: false }, 0, &[]);
    let g = summary.gait.as_ref().expect("gait summary");
    let airborne = g.episodes.longest_airborne_load();
    println!("{drawn}: {v:?}; longest load in the air {airborne:?}");
    assert!(drawn.starts_with("down 3 x 60 mm"), "{drawn}");
    assert!(v.failure.is_none(), "{v:?}");
    assert!(airborne.is_none_or(|(d, _, _)| d <= 0.3), "a foot in the air carried the body: {airborne:?}");
}

/// Across a 20° slope (seeds 2 and 8 of the class "slope 20 deg": uphill at 317° and 26° from
/// the heading) with the shipped 4.5 cm lift: walked with never fewer than three loaded feet for
/// 0.2 s and no foot in its takeoff or swing carrying the body for 0.3 s (issue 37's criteria).
/// Before a lift on six legs had to leave a support that the push of the feet in the air, at the
/// landing threshold, does not tip (`rules::stability_margin`, 67e0c60), the body rolled off
/// the support: seed 2 onto a swinging foot for 1.4 s from 31.8 s and onto two feet for 0.8 s
/// from 38.8 s, seed 8 onto a swinging foot for 1.5 s from 18.8 s (measured 2026-11-29 with the
/// check removed; now no support loss, 0.04 s of load in the air at the start).
#[test]
fn a_20_degree_slope_is_walked_without_tipping_onto_a_lifting_foot() {
    for seed in [2, 8] {
        walks_without_stumbling(TerrainClass::Slope { angle: 20f64.to_radians() }, seed, &[], "20.0 deg");
    }
}

/// Down three 4 cm risers (seed 9 of the class "stairs down 4 cm": treads 403 mm, edges at
/// −23.2° to the heading) with the shipped 4.5 cm lift: feet that land on a tread's nosing slide
/// off it down the riser when a neighbour lifts, and must land again rather than leave the
/// lifting foot carrying the body (`OFF_FOOTHOLD`). Before (measured 2026-11-29 with the slip not
/// seen), a support foot slid 32 mm down at 108.0 s and 39 mm at 138.8 s while legs 3 and 0
/// lifted, and each of those feet, still on the ground in its takeoff, carried 67-95 N for
/// 0.5-0.6 s as the body sank 11-15 mm.
#[test]
fn a_foot_sliding_off_a_nosing_lands_again_instead_of_a_lifting_foot_carrying_the_body() {
    walks_without_stumbling(TerrainClass::Stairs { riser: 0.04, up: false }, 9, &[], "down 3 x 40 mm");
}

/// A boulder field of 3 cm RMS (seed 5 of the class "boulders 3.0 cm RMS") at the thesis'
/// 10.5 cm lift: crossed, with no foot in its swing carrying the body. A swinging foot meets a
/// boulder face higher than the leg can rise to; before it backed off and landed in front of it
/// (`elevator`, measured 2026-11-30 without), the swing went on pushing: up to 123 N on the foot
/// of leg 3 for 2.0 s from 88.2 s, the support feet slid 20 cm back, the body turned 10° and
/// stayed 12 cm behind its desired pose, and the walk deadlocked for good at 102.2 s with legs
/// 0, 3 and 4 landing short of their footholds in that desired frame and lifting again.
#[test]
fn a_swinging_foot_against_a_boulder_above_its_reach_lands_in_front_of_it() {
    walks_without_stumbling(TerrainClass::Boulders { rms: 0.03 }, 5, &[Override::new("gait.clearance_m", 0.105)], "RMS 30.0 mm");
}

/// Up three 8 cm risers (seed 10 of the class "stairs up 8 cm": treads 462 mm) at the thesis'
/// 10.5 cm lift: a support foot lifted off its foothold by the body tipping lands again
/// (`OFF_FOOTHOLD`, up as well as down). Before (measured 2026-11-30 with only a foot gone down
/// seen), a swinging rear foot met a riser at 139.6 s, the rear foot beside it slid 8 cm off a
/// nosing, the body pitched from −7° to −13.7° and lifted the front right foot 4.4 cm off its
/// tread, still in support for the controller; the middle foot beside it then lifted and, in
/// its takeoff, carried 72-127 N for 0.4 s from 140.3 s.
#[test]
fn a_support_foot_lifted_off_its_foothold_lands_again() {
    walks_without_stumbling(TerrainClass::Stairs { riser: 0.08, up: true }, 10, &[Override::new("gait.clearance_m", 0.105)], "up 3 x 80 mm");
}
