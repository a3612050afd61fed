//! The free gait of Section 7.7 with the full dynamic model (LuGre joint friction, compliant
//! ground; landing detected from the motor currents at 40 N, Section 5.6.3, or on the slope
//! from the simulated normal force at 10 N): the shipped scenarios walk without falling, every
//! landing is detected and none in the air, and on the 20° slope the posture control keeps the
//! body parallel to the slope at its clearance (Section 7.7.5, case 2).

use std::path::{Path, PathBuf};

use hexadyn::robot::recorder::TimeSeries;
use hexadyn::scenario::{run_scenario, Scenario};

fn scenario(name: &str) -> Scenario {
    Scenario::from_file(scenarios().join(format!("{name}.toml"))).unwrap_or_else(|e| panic!("{e}"))
}

fn scenarios() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/hexadyn/scenarios")
}

/// A shipped scenario with its text edited.
fn edited(name: &str, edit: impl FnOnce(&str) -> String) -> Scenario {
    let path = scenarios().join(format!("{name}.toml"));
    let text = std::fs::read_to_string(&path).unwrap();
    Scenario::from_str(&edit(&text), &path.display().to_string(), &scenarios()).unwrap_or_else(|e| panic!("{e}"))
}

/// The first `duration` seconds of a shipped scenario.
fn prefix(name: &str, duration: f64) -> Scenario {
    edited(name, |text| {
        let at = text.lines().find(|l| l.starts_with("duration_s")).expect("a duration");
        text.replacen(at, &format!("duration_s = {duration:.1}"), 1)
    })
}

/// Simulated time of case 3 in the suite (s): a 1000 s run takes about 130 s.
const CASE_3_PREFIX_S: f64 = 300.0;

fn column<'a>(s: &'a TimeSeries, name: &str) -> &'a [f64] {
    s.values(name).unwrap_or_else(|| panic!("no column {name}"))
}

/// No fall: the body height stays within 5 cm of its start and the body roll and pitch stay
/// within 5° of the ground's. Returns the fewest feet with a normal force at an instant.
fn assert_no_fall(s: &TimeSeries, pitch0: f64, what: &str) -> usize {
    assert_no_fall_within(s, pitch0, 5f64.to_radians(), what)
}

/// [`assert_no_fall`] with the body roll and pitch within `max_tilt` (rad) of the ground's.
fn assert_no_fall_within(s: &TimeSeries, pitch0: f64, max_tilt: f64, what: &str) -> usize {
    let z = column(s, "Z");
    let (pitch, roll) = (column(s, "pitch"), column(s, "roll"));
    let lowest = z.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(lowest > z[0] - 0.05, "{what}: the body fell to {lowest} m (start {} m)", z[0]);
    let tilt = pitch.iter().zip(roll).map(|(p, r)| (p - pitch0).abs().max(r.abs())).fold(0.0, f64::max);
    assert!(tilt < max_tilt, "{what}: the body tilted by {:.1}°", tilt.to_degrees());
    (0..s.len()).map(|t| (0..6).filter(|f| column(s, &format!("Fn[{f}]"))[t] > 0.0).count()).min().unwrap_or(0)
}

/// The landings of a free gait run.
struct Landings {
    /// Landings begun.
    count: usize,
    /// True normal force on the foot at each detection (N).
    forces: Vec<f64>,
    /// Longest time from the start of a landing to its detection, or to the end of the run (s).
    longest: f64,
}

/// The landings of a run; at every detection the foot truly touches the ground (normal force
/// > 0: no false detection in the air).
fn landings(s: &TimeSeries, what: &str) -> Landings {
    let t = column(s, "t");
    let mut l = Landings { count: 0, forces: Vec::new(), longest: 0.0 };
    for leg in 0..6 {
        let (phase, touchdown, fn_) = (column(s, &format!("phase[{leg}]")), column(s, &format!("touchdown[{leg}]")), column(s, &format!("Fn[{leg}]")));
        let mut start = None;
        for k in 1..s.len() {
            if phase[k] == 3.0 && phase[k - 1] != 3.0 {
                start = Some(t[k]);
                l.count += 1;
            }
            if touchdown[k] != 0.0 {
                assert!(fn_[k] > 0.0, "{what}: leg {leg} detected on the ground at {} s with the foot in the air", t[k]);
                l.forces.push(fn_[k]);
                if let Some(t0) = start.take() {
                    l.longest = l.longest.max(t[k] - t0);
                }
            }
        }
        if let Some(t0) = start {
            l.longest = l.longest.max(t[s.len() - 1] - t0);
        }
    }
    l
}

impl Landings {
    fn report(&self) -> String {
        let mean = self.forces.iter().sum::<f64>() / self.forces.len().max(1) as f64;
        let max = self.forces.iter().cloned().fold(0.0, f64::max);
        format!("{} landings, {} detected, longest {:.2} s, true normal force at the detection {mean:.1} N mean, {max:.1} N max", self.count, self.forces.len(), self.longest)
    }
}

/// Flat ground, 1 cm/s for 200 s, no navigation, landings from the motor currents: no fall,
/// 2 m walked, every landing detected (within 1 s of a descent that meets the ground after
/// about 0.5 s) and none in the air, the XY error at the end under 2 cm.
#[test]
fn free_gait_walks_straight_on_flat_ground() {
    let s = scenario("free_gait_straight");
    let r = run_scenario(&s, |_| {}).unwrap();
    let feet = assert_no_fall(&r.series, 0.0, "flat");
    let l = landings(&r.series, "flat");
    println!("free gait, flat ground, current landing at 40 N: {}", l.report());
    // Every landing detected: the foot, lifted by 4.5 cm, descends at 4.5 cm/s onto flat ground.
    assert!(l.count >= 40 && l.forces.len() + 6 >= l.count && l.longest < 2.0, "{}", l.report());
    let g = r.summary.gait.as_ref().unwrap();
    let deadlocked = column(&r.series, "deadlock").iter().filter(|&&d| d != 0.0).count();
    println!(
        "free gait, flat ground, 200 s at 1 cm/s: XY error at the end {:.2} mm, max {:.2} mm, walked {:.3} m, {deadlocked} deadlocked control periods, at least {feet} feet down",
        1e3 * g.tracking_error_xy_final_m,
        1e3 * g.tracking_error_xy_max_m,
        g.distance_walked_m
    );
    assert!(feet >= 3);
    assert!(g.distance_walked_m > 1.9, "{}", g.distance_walked_m);
    assert!(g.tracking_error_xy_final_m < 0.02, "{}", g.tracking_error_xy_final_m);
    // Deadlocks (the start from the workspace centres) clear: under 5 % of the walk.
    assert!(deadlocked * 20 < r.series.len(), "{deadlocked} deadlocked periods");
}

/// Section 7.7.5, case 2 on the shipped 20° slope: the square of 100 s lines at 1 cm/s. The
/// pitch settles at 20 ± 1° (the body parallel to the slope) and the true clearance, the
/// distance of the body centre from the slope plane, stays within 5 mm of its start for the
/// whole walk after the first 20 s, climbing and descending (the X lines) as well as crossing
/// the slope (the Y lines): the heading moves the body in its own plane, which the posture
/// keeps parallel to the slope (Section 7.7.2, [`hexadyn::control::gait::free::velocity`]).
/// With the heading kept horizontal the clearance drifted by ±3.4 mm/s between touchdowns
/// climbing and descending (10 s means 12.5 mm off). No fall; the XY error is reported.
#[test]
fn free_gait_keeps_its_posture_on_a_20_degree_slope() {
    let s = scenario("free_gait_slope_square");
    let r = run_scenario(&s, |_| {}).unwrap();
    let slope = 20f64.to_radians();
    assert_no_fall(&r.series, -slope, "slope");
    let (t, x, z, pitch) = (column(&r.series, "t"), column(&r.series, "X"), column(&r.series, "Z"), column(&r.series, "pitch"));
    // Distance from the plane z = tan(20°) x, along its normal (oracle independent of the
    // controller's estimate).
    let clearance: Vec<f64> = x.iter().zip(z).map(|(x, z)| (z - slope.tan() * x) * slope.cos()).collect();
    let after = t.iter().position(|&t| t >= 20.0).unwrap();
    let worst_pitch = pitch[after..].iter().map(|p| (p.abs() - slope).abs()).fold(0.0, f64::max);
    // Averages over 10 s windows (a tripod step and its posture correction).
    let window = (10.0 / s.period()).round() as usize;
    let means: Vec<f64> = clearance[after..].chunks(window).map(|c| c.iter().sum::<f64>() / c.len() as f64).collect();
    let worst_mean = means.iter().map(|m| (m - clearance[0]).abs()).fold(0.0, f64::max);
    // Crossing the slope: the Y lines, 100-200 s and 300-400 s, 20 s after each turn.
    let crossing = t.iter().zip(&clearance).filter(|(t, _)| (120.0..200.0).contains(*t) || (320.0..400.0).contains(*t)).map(|(_, c)| (c - clearance[0]).abs()).fold(0.0, f64::max);
    let worst = clearance[after..].iter().map(|c| (c - clearance[0]).abs()).fold(0.0, f64::max);
    let (lo, hi) = clearance[after..].iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &c| (a.min(c), b.max(c)));
    let g = r.summary.gait.as_ref().unwrap();
    println!(
        "free gait, 20° slope square: pitch within {:.3}° of 20° after 20 s; clearance {:.4} m at the start, within {:.2} mm of it after 20 s, {:.2} mm crossing the slope, 10 s means within {:.2} mm of it, range [{:.4}, {:.4}] m; XY error at the end {:.2} mm, max {:.2} mm",
        worst_pitch.to_degrees(),
        clearance[0],
        1e3 * worst,
        1e3 * crossing,
        1e3 * worst_mean,
        lo,
        hi,
        1e3 * g.tracking_error_xy_final_m,
        1e3 * g.tracking_error_xy_max_m
    );
    assert!(worst_pitch < 1f64.to_radians(), "pitch off 20° by {:.2}°", worst_pitch.to_degrees());
    assert!(worst < 0.005, "clearance off by {worst} m");
    // The body climbed: without the posture control it could not follow the slope 0.36 m up.
    assert!(z.iter().cloned().fold(0.0, f64::max) > z[0] + 0.3);
}

/// Beyond the thesis (issue 37): five legs, leg `failed` held up (the shipped scenario has leg
/// 3), 200 s at 0.5 cm/s on flat ground, forwards or `backwards`, with the landings detected
/// from the motor currents: no fall (the body within 10° of level), every landing detected and
/// none in the air, no deadlock at the end nor longer than the health check allows, never
/// fewer than three loaded feet for longer than it allows, at least 0.9 m of the commanded
/// 1 m covered along the command (the net advance), the stability margin of the feet in
/// support never below zero, no clamped reference; the failed foot never touches the ground.
fn assert_five_legs_walk(failed: usize, backwards: bool) {
    let s = edited("free_gait_five_legs", |text| {
        let text = text.replacen("failed_leg = 3", &format!("failed_leg = {failed}"), 1);
        if backwards { text.replacen("vx_m_s = 0.005", "vx_m_s = -0.005", 1) } else { text }
    });
    let what = format!("five legs, leg {failed} failed, {}", if backwards { "backwards" } else { "forwards" });
    let r = run_scenario(&s, |_| {}).unwrap();
    // The body leans towards the corner without a foot between touchdowns: up to 5.2° with a
    // rear leg failed.
    let feet = assert_no_fall_within(&r.series, 0.0, 10f64.to_radians(), &what);
    let l = landings(&r.series, &what);
    let (longest, stuck) = deadlocks(&r.series);
    let g = r.summary.gait.as_ref().unwrap();
    let x = column(&r.series, "X");
    let advance = (x[x.len() - 1] - x[0]) * if backwards { -1.0 } else { 1.0 };
    let margin = column(&r.series, "stability_margin").iter().cloned().fold(f64::INFINITY, f64::min);
    let lost = g.episodes.support_loss.longest.map_or(0.0, |(d, _)| d);
    println!(
        "free gait on {what}, 200 s at 0.5 cm/s: net advance {advance:.3} m (path {:.3} m), XY error at the end {:.2} mm, at least {feet} feet down, longest under three {lost:.2} s; {}; longest deadlock {longest:.2} s; smallest stability margin {:.1} mm; {} clamped references",
        g.distance_walked_m,
        1e3 * g.tracking_error_xy_final_m,
        l.report(),
        1e3 * margin,
        g.clamped_ik_references
    );
    assert!(column(&r.series, &format!("Fn[{failed}]")).iter().all(|&f| f == 0.0), "{what}: the failed foot touched the ground");
    assert!(column(&r.series, &format!("phase[{failed}]")).iter().all(|&p| p == 4.0));
    assert!(!stuck && longest < MAX_DEADLOCK_S, "{what}: longest deadlock {longest} s, deadlocked at the end: {stuck}");
    assert!(lost <= MAX_SUPPORT_LOSS_S, "{what}: fewer than three loaded feet for {lost} s");
    assert!(l.forces.len() + 5 >= l.count && l.count >= 40, "{what}: {}", l.report());
    assert!(advance > 0.9, "{what}: advanced {advance} m");
    assert!(margin >= 0.0, "{what}: stability margin {margin} m");
    assert_eq!(g.clamped_ik_references, 0, "{what}");
}

/// The health check's longest deadlock and loss of support in a healthy free gait (s,
/// python/hexadyn/health.py).
const MAX_DEADLOCK_S: f64 = 20.0;
const MAX_SUPPORT_LOSS_S: f64 = 0.2;

#[test]
fn free_gait_walks_on_five_legs() {
    assert_five_legs_walk(3, false);
}

#[test]
fn free_gait_walks_on_five_legs_leg_2_failed() {
    assert_five_legs_walk(2, false);
}

#[test]
fn free_gait_walks_on_five_legs_leg_0_failed() {
    assert_five_legs_walk(0, false);
}

#[test]
fn free_gait_walks_on_five_legs_leg_1_failed() {
    assert_five_legs_walk(1, false);
}

// A leg failed at the trailing end of the walk (4 or 5 forwards, 0 or 1 backwards; issue 37).
// Measured 2026-11-29 (2-core AMD EPYC container, 200 s at 0.5 cm/s, net advance of 1 m):
// before the landing feet's pushes entered the stability check (`FreeGaitController::
// landing_pushes`; 429615d) these walks covered 0.954, 0.957, 0.559 and 0.954 m with the body
// rocking onto two feet for 0.5-1.1 s, tilting up to 10°, and leg 0 backwards halting for
// good; the first support loss came before any drift of the controller's frame, a landing foot
// rolling the body over a diagonal of the three feet left, and the landings during the tips
// then drifted the frame (desired roll 4.4° and pitch 3.5° at 76 s with leg 4 failed, the real
// body level). Tried and not kept then: an inclinometer's pitch and roll in the estimated pose
// (all 12 cases 0.919-1.002 m but 0.7-2.6 s on two feet), or as the stability check's vertical
// only; the support feet from the encoders; the centre of mass one step ahead (the body's
// walk, the lifted leg's mass at its AEP). Before that, at a7912e7: the leading-end cases
// 0.819-0.885 m (no lift for the first 29.6 s: `FreeGaitController::lifting`), the trailing
// ones 0.497-0.862 m with deadlocks of 13-15 s (`FreeGaitController::sway`).
#[test]
fn free_gait_walks_on_five_legs_leg_4_failed() {
    assert_five_legs_walk(4, false);
}

#[test]
fn free_gait_walks_on_five_legs_leg_5_failed() {
    assert_five_legs_walk(5, false);
}

#[test]
fn free_gait_walks_backwards_on_five_legs_leg_0_failed() {
    assert_five_legs_walk(0, true);
}

#[test]
fn free_gait_walks_backwards_on_five_legs_leg_1_failed() {
    assert_five_legs_walk(1, true);
}

#[test]
fn free_gait_walks_backwards_on_five_legs_leg_2_failed() {
    assert_five_legs_walk(2, true);
}

#[test]
fn free_gait_walks_backwards_on_five_legs_leg_3_failed() {
    assert_five_legs_walk(3, true);
}

#[test]
fn free_gait_walks_backwards_on_five_legs_leg_4_failed() {
    assert_five_legs_walk(4, true);
}

#[test]
fn free_gait_walks_backwards_on_five_legs_leg_5_failed() {
    assert_five_legs_walk(5, true);
}

/// The deadlock periods of a run (Section 7.7.4): the longest one (s) and whether the run ends
/// deadlocked.
fn deadlocks(s: &TimeSeries) -> (f64, bool) {
    let (t, d) = (column(s, "t"), column(s, "deadlock"));
    let (mut longest, mut start) = (0.0f64, None);
    for k in 0..s.len() {
        match (d[k] != 0.0, start) {
            (true, None) => start = Some(t[k]),
            (false, Some(t0)) => {
                longest = longest.max(t[k] - t0);
                start = None;
            }
            _ => {}
        }
    }
    if let Some(t0) = start {
        longest = longest.max(t[s.len() - 1] - t0);
    }
    (longest, d[s.len() - 1] != 0.0)
}

/// Section 7.7.5, case 1: 400 s at 1 cm/s past the 8 cm step on the right
/// (terrains/step_8cm.ply: x in [1, 3] m, y < −0.1 m), landings from the motor currents, no
/// navigation. No fall (the body rolls by the step over the leg span, under 10°), every
/// landing detected and none in the air, the body climbs: while the right feet stand on the
/// step (body x in [1.8, 2.2] m) the body rises by the height of the ground plane under its
/// centre, half the step (the left feet stay on the ground), and comes back down at the end;
/// the XY error at the end is under 2 cm.
#[test]
fn free_gait_climbs_the_8_cm_step() {
    let s = scenario("free_gait_step");
    let started = std::time::Instant::now();
    let r = run_scenario(&s, |_| {}).unwrap();
    let elapsed = started.elapsed().as_secs_f64();
    let feet = assert_no_fall_within(&r.series, 0.0, 10f64.to_radians(), "step");
    let l = landings(&r.series, "step");
    let (x, z, roll, pitch) = (column(&r.series, "X"), column(&r.series, "Z"), column(&r.series, "roll"), column(&r.series, "pitch"));
    let on_step: Vec<usize> = (0..r.series.len()).filter(|&k| (1.8..2.2).contains(&x[k])).collect();
    let rise = on_step.iter().map(|&k| z[k] - z[0]).sum::<f64>() / on_step.len().max(1) as f64;
    let roll_on = on_step.iter().map(|&k| roll[k]).sum::<f64>() / on_step.len().max(1) as f64;
    let (max_pitch, max_roll) = (pitch.iter().fold(0.0f64, |a, p| a.max(p.abs())), roll.iter().fold(0.0f64, |a, p| a.max(p.abs())));
    let end = z[r.series.len() - 1] - z[0];
    let g = r.summary.gait.as_ref().unwrap();
    let (longest, stuck) = deadlocks(&r.series);
    println!(
        "free gait, 8 cm step, 400 s at 1 cm/s: {}; body rise on the step {:.1} mm, roll there {:.2}°, max |roll| {:.2}°, max |pitch| {:.2}°, height change at the end {:.1} mm; walked {:.3} m; XY error at the end {:.2} mm, max {:.2} mm; longest deadlock {longest:.2} s; at least {feet} feet down; run {elapsed:.1} s",
        l.report(),
        1e3 * rise,
        roll_on.to_degrees(),
        max_roll.to_degrees(),
        max_pitch.to_degrees(),
        1e3 * end,
        g.distance_walked_m,
        1e3 * g.tracking_error_xy_final_m,
        1e3 * g.tracking_error_xy_max_m
    );
    assert!(!stuck, "deadlocked at the end");
    assert!(!on_step.is_empty() && g.distance_walked_m > 3.8, "walked {} m", g.distance_walked_m);
    // Down from the step the foot descends its 9 cm lift and the 8 cm step at 4.5 cm/s.
    assert!(l.forces.len() + 6 >= l.count && l.count >= 60 && l.longest < 5.0, "{}", l.report());
    assert!((rise - 0.04).abs() < 0.015, "the body rose by {rise} m on the step");
    assert!(end.abs() < 0.01, "the body height changed by {end} m at the end");
    assert!(g.tracking_error_xy_final_m < 0.02, "{}", g.tracking_error_xy_final_m);
    // The takeoffs from the step keep the feet inside their reach (issue 37: 1712 references
    // clamped by Eq. 7.7 and 546 limit-switch cuts when the takeoff rose by the lift wherever
    // the foot was).
    assert_eq!((g.clamped_ik_references, r.summary.limit_switch_cuts), (0, 0));
}

/// Section 7.7.5, case 3: the spline over the rough ground with and without navigation,
/// landings from the motor currents, its first [`CASE_3_PREFIX_S`] (the whole 1000 s runs in
/// the benchmark `free_gait_cases`, `make bench`). No fall, every landing detected and none in
/// the air, no deadlock that does not clear (the run does not end deadlocked and walks the path
/// to 5 %); with navigation the XY error at the end is under 2 cm (without, it is reported).
#[test]
fn free_gait_follows_the_spline_over_rough_ground() {
    for (name, navigation) in [("free_gait_rough_spline", true), ("free_gait_rough_spline_no_navigation", false)] {
        let s = prefix(name, CASE_3_PREFIX_S);
        let started = std::time::Instant::now();
        let r = run_scenario(&s, |_| {}).unwrap();
        let elapsed = started.elapsed().as_secs_f64();
        let feet = assert_no_fall_within(&r.series, 0.0, 10f64.to_radians(), name);
        let l = landings(&r.series, name);
        let (longest, stuck) = deadlocks(&r.series);
        let deadlocked = column(&r.series, "deadlock").iter().filter(|&&d| d != 0.0).count();
        let g = r.summary.gait.as_ref().unwrap();
        println!(
            "{name}: {}; walked {:.3} m of {:.3} m; XY error at the end {:.2} mm, max {:.2} mm; yaw error max {:.2}°; {deadlocked} deadlocked periods, longest {longest:.2} s; at least {feet} feet down; run {elapsed:.1} s",
            l.report(),
            g.distance_walked_m,
            g.reference_distance_m,
            1e3 * g.tracking_error_xy_final_m,
            1e3 * g.tracking_error_xy_max_m,
            g.tracking_error_yaw_max_rad.to_degrees()
        );
        assert!(!stuck, "{name}: deadlocked at the end");
        assert!(l.forces.len() + 6 >= l.count && l.count >= 100 && l.longest < 3.0, "{name}: {}", l.report());
        assert!((g.distance_walked_m - g.reference_distance_m).abs() < 0.05 * g.reference_distance_m, "{name}: walked {} m of {} m", g.distance_walked_m, g.reference_distance_m);
        if navigation {
            assert!(g.tracking_error_xy_final_m < 0.02, "{name}: {}", g.tracking_error_xy_final_m);
        }
    }
}

