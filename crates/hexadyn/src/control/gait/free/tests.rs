//! The free gait on the ideal plant (the joints are their references, the body follows its
//! desired pose, flat ground at z = 0): the kinematic level of Section 7.7.3's rules.

use nalgebra::Vector3;
use rand::Rng;

use super::*;
use crate::control::gait::controller::joints_at;
use crate::control::gait::heading::{Constant, Heading};
use crate::control::gait::pattern::FootPhase;
use crate::control::{joint_pis, Controller, Measurements};
use crate::description::RobotDescription;
use crate::hexapod::{LegKinematics, Workspace, JOINTS};
use crate::test_util::rng;

struct Setup {
    legs: [LegKinematics; 6],
    workspaces: [Workspace; 6],
    height: f64,
    description: RobotDescription,
}

fn setup() -> Setup {
    let description = RobotDescription::amru5();
    let legs = LegKinematics::hexapod_from_description(&description).unwrap();
    let height = -legs[0].foot(&Vector3::new(0.0, 0.06, 0.035)).z;
    let workspaces = std::array::from_fn(|l| legs[l].workspace_for_body_height(height, 0.045).unwrap());
    Setup { legs, workspaces, height, description }
}

fn options(s: &Setup, dt: f64, failed_leg: Option<usize>) -> FreeGaitOptions {
    FreeGaitOptions { body_height: s.height, lift: 0.045, takeoff_time: 1.0, swing_time: 3.0, posture_time: 2.0, failed_leg, stability_margin: 0.02, energy_margin: 0.0, dt, elevator: Some(THESIS_CURRENT_THRESHOLD) }
}

/// The ideal plant: joints = references, the body where the controller wants it, a foot on the
/// ground (z <= 0) carries 100 N.
fn run(c: &mut FreeGaitController, joints: [f64; JOINTS], s: &Setup, dt: f64, duration: f64, mut each: impl FnMut(&FreeGaitController, f64) -> bool) {
    let mut m = Measurements { t: 0.0, positions: joints, currents: [0.0; JOINTS], supply_voltage: 12.0, pose: None, foot_normal_forces: Some([100.0; 6]) };
    for k in 0..(duration / dt).round() as usize {
        m.t = k as f64 * dt;
        let command = c.update(&m);
        if !each(c, m.t) {
            return;
        }
        m.positions = command.references;
        let body = c.desired_pose().unwrap().htm();
        m.foot_normal_forces = Some(std::array::from_fn(|l| {
            let q = Vector3::new(m.positions[3 * l], m.positions[3 * l + 1], m.positions[3 * l + 2]);
            let z = body.compose(&s.legs[l].body_from_leg()).apply(&s.legs[l].foot(&q)).z;
            if z <= 1e-9 { 100.0 } else { 0.0 }
        }));
    }
}

fn controller(s: &Setup, options: FreeGaitOptions, heading: Heading) -> FreeGaitController {
    let pis = joint_pis(&s.description.joint_pi_gains(), options.dt);
    FreeGaitController::new(options, s.legs.clone(), s.workspaces, pis, Box::new(Constant(heading)), Box::new(NormalForce { threshold: THESIS_FORCE_THRESHOLD }))
}

/// Section 7.7.3: "The combination of these two criteria converges to a tripod gait on flat
/// ground in most of the cases", and [PORT04] "proves that tripod convergence is reached with
/// rule 2 and some priority assignments on neighboring legs". From 1000 random postures (every
/// foot uniformly in its workspace disc on the ground) and random walking directions at 1 cm/s,
/// (a) every start settles within its first 10 steps (a step: the legs that lift together) into
/// a periodic gait in which every leg lifts equally often, with no deadlock that does not clear,
/// and (b) at least 95 % of them (the criterion) into the alternating tripods
/// {0, 3, 4}, {1, 2, 5} (NOTES.md numbering), strictly: the steps alternate between exactly
/// these two sets of three legs to the end of the run.
///
/// Measured: 1000/1000 tripods with the priority of [`super::rules::swing_candidates`]. By the
/// margins alone the rules settle into the tripod from 56.5 % of the starts (Rule 3 literally;
/// the rest settle into the wave of the circuit's opposite pairs {0, 5}, {2, 3}, {1, 4} or into
/// staggered tripods, two legs of a tripod at a time) and from 86.7 % with the priority among
/// the legs that satisfy Rule 2 (the rest: the wave, a fixed point of any priority by margin on
/// the two-neighbour circuit of Fig. 7.27).
#[test]
fn rules_2_and_3_settle_into_a_tripod_from_95_percent_of_random_starts() {
    let s = setup();
    let dt = 0.05;
    let mut r = rng(11);
    let (cases, mut tripod, mut periodic) = (1000, 0, 0);
    let mut longest_deadlock = 0.0f64;
    let tripods = [[true, false, false, true, true, false], [false, true, true, false, false, true]];
    for _ in 0..cases {
        let feet: [Vector3<f64>; 6] = std::array::from_fn(|l| {
            let w = &s.workspaces[l];
            let (rho, a) = (w.radius * r.random_range(0.0f64..1.0).sqrt(), r.random_range(0.0..std::f64::consts::TAU));
            w.centre_at(-s.height) + Vector3::new(rho * a.cos(), rho * a.sin(), 0.0)
        });
        let direction = r.random_range(0.0..std::f64::consts::TAU);
        let heading = Heading::new(0.01 * direction.cos(), 0.01 * direction.sin(), 0.0);
        let mut c = controller(&s, options(&s, dt, None), heading);
        let mut steps: Vec<[bool; 6]> = Vec::new();
        let mut previous = [FootPhase::Support; 6];
        let mut deadlock = 0.0;
        run(&mut c, joints_at(&s.legs, &feet).unwrap(), &s, dt, 400.0, |c, _| {
            deadlock = if c.state().deadlock { deadlock + dt } else { 0.0 };
            longest_deadlock = longest_deadlock.max(deadlock);
            let phases = c.phases();
            let lifted: [bool; 6] = std::array::from_fn(|l| phases[l] == FootPhase::Takeoff && previous[l] != FootPhase::Takeoff);
            if lifted.iter().any(|&x| x) {
                steps.push(lifted);
            }
            previous = phases;
            steps.len() < 24
        });
        assert_eq!(steps.len(), 24, "a start that stops stepping (permanent deadlock)");
        // Settled at step i < 10 into a cycle of p steps: the steps repeat with period p to the
        // end, and every leg lifts as often as the others in a cycle.
        let settles = |i: usize, p: usize| {
            let count = |l: usize| (i..i + p).filter(|&j| steps[j][l]).count();
            let even = count(0) > 0 && (1..6).all(|l| count(l) == count(0));
            even && (i..steps.len() - p).all(|j| steps[j] == steps[j + p])
        };
        let is_tripod = (0..10).any(|i| tripods.contains(&steps[i]) && settles(i, 2));
        let is_periodic = (0..10).any(|i| [2, 3, 6].iter().any(|&p| settles(i, p)));
        tripod += usize::from(is_tripod);
        periodic += usize::from(is_periodic);
        if !is_periodic {
            let names: Vec<String> = steps.iter().map(|st| (0..6).filter(|&l| st[l]).map(|l| l.to_string()).collect::<String>()).collect();
            println!("not periodic: direction {direction:.2}: {names:?}");
        }
    }
    println!("Rules 2-3: {tripod}/{cases} random starts settle into a tripod within 10 steps, {periodic}/{cases} into a periodic gait; longest deadlock {longest_deadlock:.2} s");
    assert_eq!(periodic, cases);
    assert!(100 * tripod >= 95 * cases, "{tripod}/{cases} tripods");
}

/// Section 7.7.4, a constructed deadlock: leg 1 lifts first (lowest margin); leg 0, its
/// neighbour, reaches its workspace boundary while leg 1 is in the air and cannot lift (Rule 2).
/// The support legs halt (body and support foot references frozen) while leg 1 finishes its
/// swing and landing; when it is down, leg 0 lifts, the deadlock clears and the body walks on.
/// Leg 0's foot never overruns its workspace by more than one control step.
#[test]
fn deadlock_halts_the_support_legs_until_it_clears() {
    let s = setup();
    let dt = 0.01;
    let v = 0.01;
    let feet: [Vector3<f64>; 6] = std::array::from_fn(|l| {
        let w = &s.workspaces[l];
        // The foot moves along −x in every leg frame rotated by −α: put legs 0 and 1 back
        // along their motion.
        let back = match l {
            0 => 0.7,
            1 => 0.8,
            _ => 0.0,
        };
        let motion = s.legs[l].direction_to_leg(&Vector3::new(-1.0, 0.0, 0.0));
        w.centre_at(-s.height) + motion * (back * w.radius)
    });
    let mut c = controller(&s, options(&s, dt, None), Heading::new(v, 0.0, 0.0));
    let (mut started, mut cleared, mut halted_steps) = (None, None, 0usize);
    let mut last: Option<(Vector3<f64>, [Vector3<f64>; 6], [FootPhase; 6])> = None;
    // Consecutive instants deadlocked before this one: the body halts from the second (the
    // first step after the deadlock still integrates the last velocity by the trapezoidal rule).
    let mut halted_before = 0usize;
    let mut worst_overrun = 0.0f64;
    let mut leg1_moved_while_halted = false;
    run(&mut c, joints_at(&s.legs, &feet).unwrap(), &s, dt, 30.0, |c, t| {
        let state = c.state();
        let pose = c.desired_pose().unwrap().position;
        let refs = c.foot_references();
        let phases = c.phases();
        if phases[0] == FootPhase::Support {
            worst_overrun = worst_overrun.max(s.workspaces[0].distance_outside(&Vector3::new(refs[0].x, refs[0].y, s.workspaces[0].z_min)));
        }
        if let Some((p, r, ph)) = &last {
            if halted_before >= 2 {
                halted_steps += 1;
                assert!((pose - p).norm() < 1e-12, "the body moves while deadlocked at t = {t}");
                for l in (0..6).filter(|&l| ph[l] == FootPhase::Support && phases[l] == FootPhase::Support) {
                    assert!((refs[l] - r[l]).norm() < 1e-12, "support leg {l} moves while deadlocked at t = {t}");
                }
                leg1_moved_while_halted |= (refs[1] - r[1]).norm() > 1e-9;
            }
        }
        if state.deadlock && started.is_none() {
            started = Some(t);
            assert_eq!(phases[0], FootPhase::Support);
            assert_ne!(phases[1], FootPhase::Support);
        }
        if started.is_some() && !state.deadlock && cleared.is_none() {
            cleared = Some(t);
            assert_eq!(phases[1], FootPhase::Support, "leg 1 down");
            assert_eq!(phases[0], FootPhase::Takeoff, "leg 0 lifts");
        }
        last = Some((pose, refs, phases));
        halted_before = if state.deadlock { halted_before + 1 } else { 0 };
        true
    });
    let (started, cleared) = (started.expect("a deadlock"), cleared.expect("the deadlock clears"));
    println!("deadlock from {started:.2} s to {cleared:.2} s ({halted_steps} halted control periods), leg 0 overran its workspace by {worst_overrun:.2e} m");
    assert!(halted_steps > 50 && leg1_moved_while_halted);
    assert!(worst_overrun <= v * dt + 1e-12);
    // Walking resumed: the body moved on after the deadlock.
    assert!(c.desired_pose().unwrap().position.x > v * (30.0 - (cleared - started)) * 0.9 - 1e-3);
}

/// A five-legged walk (`failed` held up) straight ahead at 0.5 cm/s (the shipped five-leg
/// scenario) for 300 s on the ideal plant, every foot starting at its workspace centre: the
/// distance walked (m), the longest deadlock (s), whether it ends deadlocked, and the smallest
/// stability margin (m) of the body centre over the feet in support at any instant.
fn five_legged_walk(failed: usize) -> (f64, f64, bool, f64) {
    let s = setup();
    let dt = 0.05;
    let (v, duration) = (0.005, 300.0);
    let mut c = controller(&s, options(&s, dt, Some(failed)), Heading::new(v, 0.0, 0.0));
    let feet: [Vector3<f64>; 6] = std::array::from_fn(|l| s.workspaces[l].centre_at(-s.height));
    let (mut longest, mut current, mut worst_margin) = (0.0f64, 0.0f64, f64::INFINITY);
    run(&mut c, joints_at(&s.legs, &feet).unwrap(), &s, dt, duration, |c, _| {
        current = if c.state().deadlock { current + dt } else { 0.0 };
        longest = longest.max(current);
        let body = c.desired_pose().unwrap().htm();
        let phases = c.phases();
        let down: Vec<nalgebra::Vector2<f64>> = (0..6)
            .filter(|&l| l != failed && phases[l] == FootPhase::Support)
            .map(|l| body.compose(&s.legs[l].body_from_leg()).apply(&c.foot_references()[l]).xy())
            .collect();
        worst_margin = worst_margin.min(super::rules::stability_margin(&body.translation.xy(), &down, &[]));
        true
    });
    let walked = c.desired_pose().unwrap().position.x;
    println!("five legs, leg {failed} failed: walked {walked:.3} m of {:.3} m, longest deadlock {longest:.1} s, smallest stability margin {:.1} mm", v * duration, 1e3 * worst_margin);
    (walked, longest, current > 0.0, worst_margin)
}

/// Beyond the thesis: five legs, leg `failed` held up ([`five_legged_walk`]). The walk never
/// stops for good (no deadlock at the end), the body covers at least 95 % of the commanded
/// 1.5 m, and the feet left on the ground always keep the body centre inside their support
/// polygon (the 2 cm stability margin is required when a leg lifts; the body moves on while it
/// is in the air).
fn assert_five_legs_walk(failed: usize) {
    let (walked, _, stuck, worst_margin) = five_legged_walk(failed);
    assert!(!stuck, "leg {failed} failed: deadlocked at the end");
    assert!(walked > 0.95 * 1.5, "leg {failed} failed: walked {walked} m");
    assert!(worst_margin > 0.0, "leg {failed} failed: stability margin {worst_margin} m");
}

#[test]
fn five_legs_walk_with_leg_0_failed() {
    assert_five_legs_walk(0);
}

#[test]
fn five_legs_walk_with_leg_1_failed() {
    assert_five_legs_walk(1);
}

#[test]
fn five_legs_walk_with_leg_2_failed() {
    assert_five_legs_walk(2);
}

#[test]
fn five_legs_walk_with_leg_3_failed() {
    assert_five_legs_walk(3);
}

#[test]
fn five_legs_walk_with_leg_4_failed() {
    assert_five_legs_walk(4);
}

#[test]
fn five_legs_walk_with_leg_5_failed() {
    assert_five_legs_walk(5);
}

/// Beyond the thesis (its conclusion's stability in the choice of the swinging leg): on six
/// legs, straight ahead at 1 cm/s for 60 s on the ideal plant from the feet at their workspace
/// centres, the normalized energy stability margin of the feet left in support at each lift
/// ([`FreeGaitState::stability_margin`] at the updates where a leg enters its takeoff), and the
/// distance walked.
fn margins_at_lifts(energy_margin: f64) -> (f64, f64) {
    let s = setup();
    let dt = 0.05;
    let mut c = controller(&s, FreeGaitOptions { energy_margin, ..options(&s, dt, None) }, Heading::new(0.01, 0.0, 0.0));
    let feet: [Vector3<f64>; 6] = std::array::from_fn(|l| s.workspaces[l].centre_at(-s.height));
    let mut previous = [FootPhase::Support; 6];
    let mut lowest = f64::INFINITY;
    run(&mut c, joints_at(&s.legs, &feet).unwrap(), &s, dt, 60.0, |c, _| {
        let phases = c.phases();
        if (0..6).any(|l| phases[l] == FootPhase::Takeoff && previous[l] != FootPhase::Takeoff) {
            lowest = lowest.min(c.state().stability_margin);
        }
        previous = phases;
        true
    });
    (lowest, c.desired_pose().unwrap().position.x)
}

/// The tripods of the thesis' rules lift with the margin they have; asked for 5 mm more than
/// that, a leg lifts only when the feet left keep it (smaller groups of legs), and the robot
/// still walks.
#[test]
fn lifts_keep_the_energy_stability_margin_on_six_legs() {
    let (tripod, walked) = margins_at_lifts(0.0);
    assert!(tripod > 0.0 && tripod.is_finite(), "margin of the thesis' lifts: {tripod} m");
    let bound = tripod + 0.005;
    let (kept, walked_kept) = margins_at_lifts(bound);
    println!("margin at the lifts: {:.1} mm (walked {walked:.3} m); asked {:.1} mm: {:.1} mm (walked {walked_kept:.3} m)", 1e3 * tripod, 1e3 * bound, 1e3 * kept);
    assert!(kept >= bound, "a lift left {kept} m < {bound} m");
    assert!(walked_kept > 0.5 * walked, "walked {walked_kept} m against {walked} m");
}
