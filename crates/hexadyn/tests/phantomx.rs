//! The second shipped robot, the PhantomX Mark II (robots/phantomx/phantomx.toml): serial legs
//! read from its description, Dynamixel AX-12A position servos, and its shipped walks.

use hexadyn::description::serial::mechanism_toml;
use hexadyn::description::urdf::serial_hexapod_from_file;
use hexadyn::description::{Robot, SerialRobot, PHANTOMX_TOML};
use hexadyn::hexapod::SerialHexapod;
use hexadyn::physics::terrain::generate::PHANTOMX_ROUGH;
use hexadyn::scenario::{run_scenario, HeadingSpec, Override, Scenario, Summary, SummaryValue};

fn phantomx() -> SerialRobot {
    match Robot::from_str(PHANTOMX_TOML, "phantomx.toml").unwrap() {
        Robot::Serial(s) => s,
        Robot::Pantograph(_) => panic!("a serial robot"),
    }
}

fn root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The largest difference between two mechanisms' numbers.
fn difference(a: &SerialHexapod, b: &SerialHexapod) -> f64 {
    let mut d = (a.base.mass - b.base.mass).abs().max((a.base.com - b.base.com).amax()).max((a.base.inertia - b.base.inertia).amax());
    for (la, lb) in a.legs.iter().zip(&b.legs) {
        d = d.max((la.foot - lb.foot).amax()).max((la.foot_radius - lb.foot_radius).abs());
        for (ja, jb) in la.joints.iter().zip(&lb.joints) {
            assert_eq!((&ja.name, ja.kind), (&jb.name, jb.kind));
            d = d.max((ja.origin.rotation - jb.origin.rotation).amax()).max((ja.origin.translation - jb.origin.translation).amax());
            d = d.max((ja.axis - jb.axis).amax()).max((ja.lower - jb.lower).abs()).max((ja.upper - jb.upper).abs());
        }
        for (ka, kb) in la.links.iter().zip(&lb.links) {
            d = d.max((ka.mass - kb.mass).abs()).max((ka.com - kb.com).amax()).max((ka.inertia - kb.inertia).amax());
        }
    }
    d
}

/// The shipped description's mechanism is its URDF's (SOURCES.md), and a description written
/// back to TOML reads as the same robot.
#[test]
fn the_description_is_its_urdf_and_round_trips() {
    let robot = phantomx();
    let urdf = serial_hexapod_from_file(root().join("robots/phantomx/phantomx.urdf")).unwrap();
    let d = difference(&robot.hexapod, &urdf);
    assert!(d < 1e-12, "the description differs from the URDF by {d}");
    let again = match Robot::from_str(&robot.to_toml(), "written").unwrap() {
        Robot::Serial(s) => s,
        _ => unreachable!(),
    };
    assert!(difference(&again.hexapod, &robot.hexapod) < 1e-12);
    assert_eq!((again.drives, again.joints, again.period, again.supply_voltage, again.ground), (robot.drives.clone(), robot.joints.clone(), robot.period, robot.supply_voltage, robot.ground.clone()));
    assert!(robot.monte_carlo.is_some());
    assert_eq!(again.monte_carlo, robot.monte_carlo);
    let names = ["coxa", "femur", "tibia"].map(String::from);
    assert!(robot.to_toml().starts_with(&mechanism_toml(&robot.hexapod, &names)));
    assert!((robot.total_mass_kg() - 1.8428).abs() < 1e-9, "{}", robot.total_mass_kg());
}

/// The robot written as URDF reads back as the same mechanism (`hexadyn export-urdf`).
#[test]
fn the_urdf_export_reads_back_as_the_same_robot() {
    let robot = phantomx();
    let text = robot.to_urdf();
    let again = hexadyn::description::urdf::serial_hexapod_from_urdf(&text, "exported.urdf").unwrap();
    let d = difference(&again, &robot.hexapod);
    assert!(d < 1e-12, "the exported URDF differs by {d}");
    // The AX-12A's limits: stall torque 1.39 N m/A x 11.1 V / 8 ohm, no-load speed 11.1 V / 1.39.
    assert!(text.contains("effort=\"1.93") && text.contains("velocity=\"7.96"), "{}", &text[..600]);
}

/// A broken serial description is refused in one line naming the field and what is allowed.
#[test]
fn a_broken_serial_description_names_its_field() {
    let cases = [
        ("sigma_0 = 5900.0", "sigma_0 = -1.0", "drives.coxa.friction.sigma_0"),
        ("[drives.tibia.servo]", "[drives.tibia.pi]\nk = 1.0\nt_i_s = 1.0\nbridge_resistance_ohm = 0.0\nencoder_counts_per_rev = 500.0\n[drives.tibia.unused]", "drives.tibia"),
        ("names = [\"coxa\", \"femur\", \"tibia\"]", "names = [\"coxa\", \"femur\", \"knee\"]", "drives.knee"),
        ("foot_radius_m = 0.01\n", "foot_radius_m = 0.02\n", "legs[1].foot_radius_m"),
        ("mass_kg = 0.0696", "mass_kg = -0.0696", "legs[0].joints[0].link.mass_kg"),
        ("upper = 1.413717", "upper = -2.0", "legs[0].joints[0].upper"),
        ("punch = 0.031280547", "punch = 2.0", "drives.coxa.servo.punch"),
        ("[monte_carlo.friction.tibia]", "[monte_carlo.friction.knee]", "monte_carlo.friction.knee"),
        ("tau_f_d = { mu = 0.590, sigma = 0.248 }", "tau_f_d = { mu = 0.590, sigma = -0.248 }", "monte_carlo.friction.coxa.tau_f_d"),
        ("tau_f_d = { mu = 0.590, sigma = 0.248 }", "tau_f_d_plus = { mu = 0.590, sigma = 0.248 }", "monte_carlo.friction.coxa.tau_f_d_plus"),
        ("runs_per_velocity = 1000", "runs_per_velocity = 0", "monte_carlo.runs_per_velocity"),
        ("velocities_m_per_s = [0.02, 0.03, 0.04, 0.05]", "velocities_m_per_s = []", "monte_carlo.velocities_m_per_s"),
    ];
    for (from, to, field) in cases {
        assert!(PHANTOMX_TOML.contains(from), "{from}");
        let text = PHANTOMX_TOML.replacen(from, to, 1);
        let e = Robot::from_str(&text, "broken.toml").expect_err(to);
        let message = e.to_string();
        assert!(!message.contains('\n'), "{message}");
        assert!(message.contains(field) && message.starts_with("broken.toml"), "{to}: {message}");
    }
}

fn number(s: &Summary, key: &str) -> f64 {
    match s.entries().into_iter().find(|(k, _)| k == key).unwrap_or_else(|| panic!("no {key}")).1 {
        SummaryValue::Number(v) => v,
        SummaryValue::Count(n) => n as f64,
        other => panic!("{key}: {other:?}"),
    }
}

/// The shipped walks of the issue: 0 clamped IK references, the energy account closed within
/// 0.1 % of the electrical energy, the body where the gait took it (within 3 %: the feet slip
/// and the servos lag at the stops) and, with a navigation system, on its path within 3 mm.
#[test]
fn the_shipped_walks_walk() {
    for name in ["phantomx_tripod", "phantomx_wave", "phantomx_spline"] {
        let s = Scenario::from_file(root().join(format!("python/hexadyn/scenarios/{name}.toml"))).unwrap();
        let r = run_scenario(&s, |_| {}).unwrap();
        let summary = &r.summary;
        let (walked, reference) = (number(summary, "distance_walked_m"), number(summary, "reference_distance_m"));
        let balance = number(summary, "energy_balance_error_relative");
        let clamped = number(summary, "clamped_ik_references");
        let path = number(summary, "tracking_error_xy_max_m");
        println!("{name}: walked {walked:.4} m of {reference:.4} m, balance {balance:.2e}, clamped {clamped}, path error {path:.4} m");
        assert_eq!(clamped, 0.0, "{name}");
        assert!(balance.abs() < 1e-3, "{name}: energy balance {balance}");
        assert!((walked / reference - 1.0).abs() < 0.03, "{name}: {walked} m of {reference} m");
        if s.gait.as_ref().is_some_and(|g| g.navigation) {
            assert!(path < 3e-3, "{name}: path error {path} m");
        }
    }
}

/// The free gait of Section 7.7 on the PhantomX's serial legs over its rough ground
/// (`phantomx_free_gait_rough`: 1 cm/s along +x for 150 s, navigation, landings detected from
/// the motor currents, Section 5.6.3 on the leg's own Jacobian and dynamics). It walks the
/// commanded distance, its legs keep stepping, every landing is detected with the foot on the
/// ground (its true normal force positive) and before it carries a tripod's share of the weight,
/// the body keeps its height and attitude over the ground, the feet meet the relief, no foot
/// reference is clamped and the energy account closes. (With the normal-force landing at the
/// thesis' 10 N, 55 % of this robot's weight, the same run clamps 41 823 references and its body
/// halts after 0.10 m: measured.)
#[test]
fn the_free_gait_walks_over_rough_ground() {
    let s = Scenario::from_file(root().join("python/hexadyn/scenarios/phantomx_free_gait_rough.toml")).unwrap();
    let g = s.gait.as_ref().unwrap();
    let free = g.free.as_ref().expect("the free gait").options.clone();
    let v = match g.heading {
        HeadingSpec::Constant(h) => h.velocity.x,
        _ => panic!("a constant heading"),
    };
    let (height, radius, rms) = (g.body_height, g.workspaces[0].radius, PHANTOMX_ROUGH.rms);
    let started = std::time::Instant::now();
    let r = run_scenario(&s, |_| {}).unwrap();
    let elapsed = started.elapsed().as_secs_f64();
    let (summary, series) = (&r.summary, &r.series);
    let column = |name: &str| series.values(name).unwrap_or_else(|| panic!("no column {name}"));
    let t = column("t");
    let commanded = v * s.duration;
    let (walked, reference) = (number(summary, "distance_walked_m"), number(summary, "reference_distance_m"));
    let balance = number(summary, "energy_balance_error_relative");
    let clamped = number(summary, "clamped_ik_references");
    let deadlocked = column("deadlock").iter().filter(|&&d| d > 0.5).count() as f64 / t.len() as f64;
    // Every leg lands again before its foot could have crossed its whole workspace in support
    // (2R at v) and made a step (takeoff, swing, a landing as long as the takeoff): a leg held
    // longer has stopped stepping.
    let longest_gap = 2.0 * radius / v + 2.0 * free.takeoff_time + free.swing_time;
    let mut landings = 0;
    let mut heights = Vec::new();
    for l in 0..6 {
        let touchdowns: Vec<usize> = column(&format!("touchdown[{l}]")).iter().enumerate().filter(|(_, &d)| d > 0.5).map(|(k, _)| k).collect();
        let times: Vec<f64> = std::iter::once(0.0).chain(touchdowns.iter().map(|&k| t[k])).chain(std::iter::once(s.duration)).collect();
        let gap = times.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
        assert!(gap < longest_gap, "leg {l}: {gap:.1} s without a landing (at most {longest_gap:.1} s): {times:?}");
        landings += touchdowns.len();
        heights.extend(touchdowns.iter().map(|&k| column(&format!("foot_z[{l}]"))[k]));
        let weight = s.robot.total_mass_kg() * hexadyn::mbs::STANDARD_GRAVITY;
        for &k in &touchdowns {
            let fn_true = column(&format!("Fn[{l}]"))[k];
            assert!(fn_true > 0.0 && fn_true < weight / 2.0, "leg {l} at t = {} s: landing detected with a normal force of {fn_true} N", t[k]);
        }
    }
    let mean = heights.iter().sum::<f64>() / heights.len() as f64;
    let spread = (heights.iter().map(|z| (z - mean).powi(2)).sum::<f64>() / heights.len() as f64).sqrt();
    // The body over the plane of the contact points (Rule 1) after the first posture, and its
    // attitude as the controller knows it.
    let first = t.iter().position(|&t| t >= free.posture_time).unwrap();
    let clearance = column("body_clearance")[first..].iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &c| (a.min(c), b.max(c)));
    let tilt = ["posture_roll", "posture_pitch"].map(|c| column(c).iter().fold(0.0f64, |m, a| m.max(a.abs())));
    println!(
        "PhantomX free gait, rough ground: walked {walked:.4} m of {commanded:.4} m commanded ({reference:.4} m reference), {landings} landings, contact heights spread {:.1} mm, deadlocked {:.2} %, clearance [{:.4}, {:.4}] m for {height:.4} m, |roll| <= {:.2} deg, |pitch| <= {:.2} deg, balance {balance:.2e}, clamped {clamped}, {} integration steps, run {elapsed:.1} s",
        1e3 * spread,
        1e2 * deadlocked,
        clearance.0,
        clearance.1,
        tilt[0].to_degrees(),
        tilt[1].to_degrees(),
        number(summary, "integration_steps")
    );
    assert_eq!(clamped, 0.0);
    assert!(balance.abs() < 1e-3, "energy balance {balance}");
    // With navigation the body follows the heading: the distance within 5 %, the body halted
    // by deadlocks (Section 7.7.4) less than 5 % of the time.
    assert!((walked - commanded).abs() < 0.05 * commanded, "walked {walked} m of {commanded} m");
    assert!(reference > 0.95 * commanded && deadlocked < 0.05, "reference {reference} m, deadlocked {deadlocked}");
    assert!(number(summary, "min_feet_on_ground") >= 3.0);
    // The feet met the relief: the contact heights spread by at least half the RMS height.
    assert!(spread > 0.5 * rms, "contact heights spread {spread} m");
    // The body within two RMS heights of its height over the contact plane, and its plane
    // tilted no more than the feet's: 2 RMS up and down over the 0.4 m between opposite feet.
    assert!(clearance.0 > height - 2.0 * rms && clearance.1 < height + 2.0 * rms, "clearance {clearance:?} for {height} m");
    let tilt_max = (4.0 * rms / 0.4f64).atan();
    assert!(tilt.iter().all(|&a| a < tilt_max), "roll and pitch {tilt:?} rad (at most {tilt_max})");
}

/// The friction feed-forward of the master takes out the lag a servo's dry friction leaves:
/// without it the AX-12A's 0.59 N m gear friction, which its compliance law balances only
/// 3.2 degrees from the goal, holds each joint until the goal has moved that far, and the
/// tripod walks a fifth less than commanded.
#[test]
fn the_friction_feedforward_takes_out_the_servo_lag() {
    let text = std::fs::read_to_string(root().join("python/hexadyn/scenarios/phantomx_tripod.toml")).unwrap();
    assert!(text.contains("friction_feedforward = true"));
    let walked = |text: &str| {
        let s = Scenario::from_str(text, "phantomx_tripod.toml", &root().join("python/hexadyn/scenarios")).unwrap();
        let r = run_scenario(&s, |_| {}).unwrap();
        number(&r.summary, "distance_walked_m") / number(&r.summary, "reference_distance_m")
    };
    let (with, without) = (walked(&text), walked(&text.replace("friction_feedforward = true", "friction_feedforward = false")));
    println!("tripod with the feed-forward {with:.4}, without {without:.4} of the commanded distance");
    assert!(with > 0.97 && without < 0.9, "with {with}, without {without}");
}

fn tripod_with(overrides: &[Override]) -> Result<Scenario, hexadyn::scenario::ScenarioError> {
    Scenario::from_file_with(root().join("python/hexadyn/scenarios/phantomx_tripod.toml"), overrides)
}

fn serial(s: &Scenario) -> &SerialRobot {
    match &s.robot {
        Robot::Serial(r) => r,
        Robot::Pantograph(_) => panic!("a serial robot"),
    }
}

/// `[model.joint_friction.<joint>]` on serial legs, keyed by the robot's joint names: the
/// fields set replace the drive's friction of that joint (every leg's), the others are kept.
#[test]
fn joint_friction_overrides_the_drive_friction_of_a_serial_joint() {
    let plain = tripod_with(&[]).unwrap();
    let s = tripod_with(&[Override::new("model.joint_friction.femur.tau_f_d", 1.18), Override::new("model.joint_friction.tibia.f_v", 0.01), Override::new("model.joint_friction.coxa.sigma_0", 1000)]).unwrap();
    let (a, b) = (serial(&plain), serial(&s));
    assert_eq!(b.drives[1].friction.tau_f_d, 1.18);
    assert_eq!(b.drives[2].friction.f_v, 0.01);
    assert_eq!(b.drives[0].friction.sigma_0, 1000.0);
    assert_eq!((b.drives[0].friction.tau_f_d, b.drives[2].friction.tau_f_d, b.drives[1].friction.f_v), (a.drives[0].friction.tau_f_d, a.drives[2].friction.tau_f_d, a.drives[1].friction.f_v));
    assert_eq!(b.drives[1].friction.linear_zone, a.drives[1].friction.linear_zone);
    // The master's friction feed-forward is the robot's as described, not the override's.
    assert_eq!(s.gait.as_ref().unwrap().friction_feedforward, plain.gait.as_ref().unwrap().friction_feedforward);
    assert!(plain.gait.as_ref().unwrap().friction_feedforward.is_some());
    // The effective text reads back the same.
    let again = Scenario::from_str(&s.text, "effective.toml", &root().join("python/hexadyn/scenarios")).unwrap();
    assert_eq!(serial(&again).drives, b.drives);
}

#[test]
fn joint_friction_errors_on_serial_legs_are_one_line() {
    let cases: [(Override, &str, &str); 6] = [
        (Override::new("model.joint_friction.knee.tau_f_d", 1.0), "model.joint_friction.knee", "[model.joint_friction.coxa], [model.joint_friction.femur], [model.joint_friction.tibia]"),
        (Override::new("model.joint_friction.q_r.tau_f_d_plus", 1.0), "model.joint_friction.q_r", "[model.joint_friction.coxa]"),
        (Override::new("model.joint_friction.femur.tau_f_d_plus", 1.0), "model.joint_friction.femur.tau_f_d_plus", "one of tau_f_d, f_v, sigma_0, sigma_1, v_d"),
        (Override::new("model.joint_friction.femur.tau_f_d", -0.5), "model.joint_friction.femur.tau_f_d", ">= 0"),
        (Override::new("model.joint_friction.tibia.v_d", 0.0), "model.joint_friction.tibia.v_d", "> 0"),
        (Override::new("model.joint_friction.coxa.f_v", "much"), "model.joint_friction.coxa.f_v", "not a number"),
    ];
    for (o, field, allowed) in cases {
        let message = tripod_with(std::slice::from_ref(&o)).expect_err(&o.field).to_string();
        assert!(!message.contains('\n'), "{message}");
        assert!(message.contains("phantomx_tripod.toml") && message.contains(&format!("field `{field}`")) && message.contains(allowed), "{message}");
    }
    let message = tripod_with(&[Override::new("model.load_dependence", true)]).unwrap_err().to_string();
    assert!(message.contains("no load dependence on serial legs"), "{message}");
}
