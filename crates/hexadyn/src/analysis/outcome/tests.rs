//! The judgement on runs whose fate is known by construction: a body that sinks onto the
//! ground, tips, stands on two feet, stays deadlocked or does not advance, against a walk that
//! does none of these.

use super::*;
use crate::physics::{FlatGround, Slope};
use crate::robot::recorder::Column;

const DT: f64 = 0.01;
/// Body centre height of a standing robot (m): well above the bottom plate's depth.
const STANDING_Z: f64 = 0.2;

fn body() -> BodyBottom {
    BodyBottom::of(&RobotDescription::amru5())
}

/// A walk along +x at 1 cm/s for `duration` s; `edit(t, row)` changes a row's values, in the
/// order t, X, Y, Z, yaw, pitch, roll, deadlock, Fn[0..6].
fn walk(duration: f64, edit: impl Fn(f64, &mut [f64; 14])) -> TimeSeries {
    let names = ["t", "X", "Y", "Z", "yaw", "pitch", "roll", "deadlock", "Fn[0]", "Fn[1]", "Fn[2]", "Fn[3]", "Fn[4]", "Fn[5]"];
    let mut columns: Vec<Column> = names.iter().map(|n| Column { name: n.to_string(), unit: "", description: String::new(), values: Vec::new() }).collect();
    let rows = (duration / DT).round() as usize + 1;
    for k in 0..rows {
        let t = k as f64 * DT;
        // A tripod: feet 0, 3, 4 then 1, 2, 5 swing, every other 5 s; three always loaded.
        let swinging = |f: usize| ((t / 5.0) as usize).is_multiple_of(2) == [0, 3, 4].contains(&f);
        let mut row = [t, 0.01 * t, 0.0, STANDING_Z, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        for f in 0..6 {
            row[8 + f] = if swinging(f) { 0.0 } else { 40.0 };
        }
        edit(t, &mut row);
        for (c, v) in columns.iter_mut().zip(row) {
            c.values.push(v);
        }
    }
    TimeSeries { columns }
}

fn verdict(series: &TimeSeries, terrain: &dyn Terrain, normal: Vector3<f64>) -> Verdict {
    judge(series, terrain, normal, body(), Bounds::default(), 0.01 * series.values("t").unwrap().last().unwrap()).unwrap()
}

const FLAT: FlatGround = FlatGround { height: 0.0 };

#[test]
fn a_tripod_walk_on_flat_ground_succeeds() {
    let v = verdict(&walk(60.0, |_, _| {}), &FLAT, Vector3::z());
    assert_eq!(v.failure, None);
    assert!((v.walked_m - 0.6).abs() < 1e-9, "walked {}", v.walked_m);
    assert_eq!(v.deadlock_s, 0.0);
}

#[test]
fn a_body_sinking_onto_the_ground_falls_when_its_plate_touches() {
    // Z sinks at 1 cm/s from 20 s: the plate (depth H/2 + e_b = 0.077 m) touches at
    // Z = 0.077 m, 12.3 s later.
    let v = verdict(&walk(60.0, |t, r| r[3] = STANDING_Z - 0.01 * (t - 20.0).max(0.0)), &FLAT, Vector3::z());
    let touch = 20.0 + (STANDING_Z - body().depth) / 0.01;
    match v.failure {
        Some(Failure::BodyOnGround { t, depth }) => {
            assert!((t - touch).abs() <= DT + 1e-9, "touched at {t} s, expected {touch} s");
            assert!(depth <= 0.01 * DT + 1e-12, "judged {depth} m deep: at the first row below");
        }
        other => panic!("expected the body on the ground, got {other:?}"),
    }
}

#[test]
fn a_body_rolling_over_tips_at_thirty_degrees_and_its_rim_touches_a_raised_ground() {
    // Roll grows at 1 deg/s from 10 s: tipped at 40 s, before the rim (0.175 m out, 0.077 m
    // down) reaches the ground at asin((0.2 - 0.077 cos) / 0.175) ~ 44 deg.
    let v = verdict(&walk(60.0, |t, r| r[6] = (t - 10.0).max(0.0).to_radians()), &FLAT, Vector3::z());
    assert!(matches!(v.failure, Some(Failure::Tipped { t, .. }) if (t - 40.0).abs() <= DT + 1e-9), "{v:?}");
    // On ground 10 cm higher the rim touches first: 0.1 = 0.175 sin(roll) + 0.077 cos(roll).
    let raised = FlatGround { height: 0.1 };
    let v = verdict(&walk(60.0, |t, r| r[6] = (t - 10.0).max(0.0).to_radians()), &raised, Vector3::z());
    let b = body();
    let roll = (1..4000).map(|i| (i as f64 * 0.01).to_radians()).find(|a| STANDING_Z - b.radius * a.sin() - b.depth * a.cos() < 0.1).unwrap();
    assert!(matches!(v.failure, Some(Failure::BodyOnGround { t, .. }) if (t - 10.0 - roll.to_degrees()).abs() < 0.05), "{v:?}, roll at touch {}", roll.to_degrees());
}

#[test]
fn a_body_parallel_to_a_steep_slope_stands_and_a_level_one_on_it_is_judged_by_the_slope() {
    // A 25 deg slope rising along +x, the body pitched with it (pitch < 0 raises x_b's nose
    // with T^Ry) at the same clearance: upright against the slope's normal.
    let angle = 25f64.to_radians();
    let slope = Slope::from_angle(0.0, angle, 0.0);
    let normal = slope.height_normal(0.0, 0.0).1;
    let on_slope = |_: f64, r: &mut [f64; 14]| {
        r[3] = slope.height_normal(r[1], 0.0).0 + STANDING_Z / angle.cos();
        r[5] = -angle;
    };
    assert_eq!(verdict(&walk(60.0, on_slope), &slope, normal).failure, None);
    // The same body level (pitch 0) leans 25 deg from the slope's normal: below the bound;
    // against a 35 deg slope's normal it leans more than 30 deg.
    let level = |_: f64, r: &mut [f64; 14]| r[3] = r[1] * angle.tan() + 0.3;
    assert_eq!(verdict(&walk(60.0, level), &slope, normal).failure, None);
    let steeper = Slope::from_angle(0.0, 35f64.to_radians(), 0.0);
    let v = verdict(&walk(60.0, |_, r| r[3] = 0.3 + 0.7 * r[1]), &steeper, steeper.height_normal(0.0, 0.0).1);
    assert!(matches!(v.failure, Some(Failure::Tipped { t, tilt }) if t == 0.0 && (tilt.to_degrees() - 35.0).abs() < 1e-9), "{v:?}");
}

#[test]
fn two_loaded_feet_lose_the_support_only_when_it_lasts_longer_than_the_bound() {
    let two_feet = |from: f64, to: f64| {
        move |t: f64, r: &mut [f64; 14]| {
            if (from..to).contains(&t) {
                r[8..].copy_from_slice(&[40.0, 40.0, 0.0, 0.0, 0.0, 0.0]);
            }
        }
    };
    assert_eq!(verdict(&walk(60.0, two_feet(20.0, 20.9)), &FLAT, Vector3::z()).failure, None);
    let v = verdict(&walk(60.0, two_feet(20.0, 25.0)), &FLAT, Vector3::z());
    assert!(matches!(v.failure, Some(Failure::SupportLost { t }) if (t - 20.0).abs() < 1e-9), "{v:?}");
}

#[test]
fn a_deadlock_is_permanent_when_on_at_the_end_for_twenty_seconds_and_is_timed() {
    let deadlock = |from: f64, to: f64| move |t: f64, r: &mut [f64; 14]| r[7] = f64::from(u8::from((from..=to).contains(&t)));
    // Cleared after 10 s: a success with 10 s of deadlock.
    let v = verdict(&walk(60.0, deadlock(20.0, 30.0 - DT / 2.0)), &FLAT, Vector3::z());
    assert_eq!(v.failure, None);
    assert!((v.deadlock_s - 10.0).abs() < 1e-9, "{} s", v.deadlock_s);
    // Still on at the end after 10 s: may yet clear; after 30 s: permanent.
    assert_eq!(verdict(&walk(60.0, deadlock(50.0, 60.0)), &FLAT, Vector3::z()).failure, None);
    let v = verdict(&walk(60.0, deadlock(30.0, 60.0)), &FLAT, Vector3::z());
    assert!(matches!(v.failure, Some(Failure::Deadlock { t }) if (t - 30.0).abs() < 1e-9), "{v:?}");
}

#[test]
fn a_robot_that_advances_less_than_half_the_commanded_distance_stalled() {
    let v = verdict(&walk(60.0, |t, r| r[1] = 0.01 * t.min(25.0)), &FLAT, Vector3::z());
    assert!(matches!(v.failure, Some(Failure::Stalled { walked, commanded }) if (walked - 0.25).abs() < 1e-9 && (commanded - 0.6).abs() < 1e-9), "{v:?}");
    assert_eq!(verdict(&walk(60.0, |t, r| r[1] = 0.01 * t.min(35.0)), &FLAT, Vector3::z()).failure, None);
}

#[test]
fn the_judgement_stops_at_the_first_fall_and_names_a_missing_column() {
    let series = walk(60.0, |t, r| r[3] = if t >= 30.0 { 0.0 } else { STANDING_Z });
    let mut j = Judge::new(&FLAT, Vector3::z(), body(), Bounds::default());
    assert_eq!(j.observe(&series), Ok(ControlFlow::Break(())));
    let mut missing = series.clone();
    missing.columns.retain(|c| c.name != "Fn[3]");
    let e = Judge::new(&FLAT, Vector3::z(), body(), Bounds::default()).observe(&missing).unwrap_err();
    assert_eq!(e, MissingColumn("Fn[3]".into()));
}
