//! Scenario files: validation errors that name the file, the field, the value and what is
//! allowed; the shipped scenarios; deterministic runs recorded into columns with units.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use hexadyn::control::gait::controller::AepMode;
use hexadyn::control::gait::pattern::FootCycle;
use hexadyn::robot::model::FrictionModel;
use hexadyn::description::{Robot, AMRU5_TOML};
use hexadyn::scenario::{run_scenario, run_scenario_until, specific_resistance, ControlMode, GaitLegs, HeadingSpec, LandingSpec, Override, Record, Scenario, ScenarioError, Summary, SummaryValue};
use hexadyn::sim::NewmarkOptions;
use hexadyn::hexapod::PantographJoint;

fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/hexadyn/scenarios")
}

fn shipped(name: &str) -> String {
    std::fs::read_to_string(scenarios_dir().join(format!("{name}.toml"))).unwrap()
}

fn parse(text: &str) -> Result<Scenario, ScenarioError> {
    Scenario::from_str(text, "bad.toml", Path::new("."))
}

/// The text of a shipped scenario with `from` replaced by `to` (which must occur).
fn with(name: &str, from: &str, to: &str) -> String {
    let text = shipped(name);
    assert!(text.contains(from), "`{from}` not in {name}.toml");
    text.replacen(from, to, 1)
}

/// The error of an invalid scenario, checked to start with the file name and to name the field.
fn field_error(text: &str, field: &str) -> String {
    let e = parse(text).expect_err("must be rejected");
    let s = e.to_string();
    assert!(s.starts_with("bad.toml:"), "{s}");
    assert_eq!(e.field(), Some(field), "{s}");
    assert!(!s.contains('\n'), "one line: {s}");
    s
}

/// The shipped scenarios: every `*.toml` of the package's scenario folder, sorted (the one list,
/// enumerated by the Python tests too).
fn shipped_names() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(scenarios_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn shipped_scenarios_are_valid() {
    let names = shipped_names();
    assert!(names.len() >= 30 && names.iter().any(|n| n == "validation_tripod_1_5cm"), "{names:?}");
    for name in &names {
        let s = Scenario::from_file(scenarios_dir().join(format!("{name}.toml"))).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(&s.name, name);
        assert!(s.text.lines().next().unwrap().starts_with('#'), "{name}: comment header");
        assert!(s.text.contains("Section"), "{name}: cites the thesis");
    }
    let s = Scenario::from_file(scenarios_dir().join("leg_ramp.toml")).unwrap();
    assert_eq!(s.control, ControlMode::Pi);
    assert_eq!(s.motions.len(), 1);
    assert_eq!((s.motions[0].leg, s.motions[0].joint), (1, PantographJoint::Vertical as usize));
    assert_eq!(s.initial.lifted_legs, vec![1, 2, 5]);
    assert_eq!(s.model.supply_voltage, 15.0);
    // 0.8 x the no-load speed (Section 4.4.3).
    let d = s.robot.pantograph().expect("AMRU5");
    let rate = 0.8 * d.motor.no_load_speed_rad_per_s() / d.reduction(PantographJoint::Vertical);
    match s.motions[0].motion {
        hexadyn::control::JointMotion::Ramp { rate: r, .. } => assert!((r - rate).abs() < 1e-6 * rate, "{r} vs {rate}"),
        m => panic!("{m:?}"),
    }
    let s = Scenario::from_file(scenarios_dir().join("unpowered_lugre.toml")).unwrap();
    assert_eq!((s.control, s.duration), (ControlMode::Unpowered, 10.0));
}

#[test]
fn errors_name_file_line_field_value_and_allowed() {
    let s = field_error(&with("stand_six_legs", "friction = \"lugre\"", "friction = \"coulomb\""), "model.friction");
    assert!(s.contains("coulomb") && s.contains("none") && s.contains("dry_viscous") && s.contains("lugre"), "{s}");
    let line = shipped("stand_six_legs").lines().position(|l| l.starts_with("friction")).unwrap() + 1;
    assert!(s.starts_with(&format!("bad.toml:{line}:")), "{s}");

    let s = field_error(&with("stand_six_legs", "duration_s = 10.0", "duration_s = 0.0"), "scenario.duration_s");
    assert!(s.contains("0") && s.contains(">= 0.01"), "{s}");
    let s = field_error(&with("stand_six_legs", "duration_s = 10.0", "duration_s = -1"), "scenario.duration_s");
    assert!(s.contains("-1"), "{s}");

    let s = field_error(&with("stand_six_legs", "duration_s = 10.0", "duration_s = 10.0\nduration = 3.0"), "scenario.duration");
    assert!(s.contains("unknown field") && s.contains("3.0") && s.contains("duration_s"), "{s}");

    let s = field_error(&with("stand_six_legs", "q_v_m = 0.06", "q_v_m = 0.09"), "initial.q_v_m");
    assert!(s.contains("0.09") && s.contains("[0.04, 0.075]"), "{s}");

    let s = field_error(&with("stand_six_legs", "q_r_deg = 0.0", "q_r_deg = 30"), "initial.q_r_deg");
    assert!(s.contains("30") && s.contains("[-25, 25] deg"), "{s}");

    let s = field_error(&with("stand_three_legs", "lifted_legs = [1, 2, 5]", "lifted_legs = [1, 6]"), "initial.lifted_legs[1]");
    assert!(s.contains('6') && s.contains("0..5"), "{s}");

    let s = field_error(&with("stand_three_legs", "lifted_legs = [1, 2, 5]", "lifted_legs = [0, 1, 2, 5]"), "initial.lifted_legs");
    assert!(s.contains("at most 3"), "{s}");

    let s = field_error(&with("stand_three_legs", "q_v_lifted_m = 0.045", "q_v_lifted_m = 0.07"), "initial.q_v_lifted_m");
    assert!(s.contains("0.07") && s.contains("< initial.q_v_m"), "{s}");

    let s = field_error(&with("stand_six_legs", "mode = \"pi\"", "mode = \"torque\""), "control.mode");
    assert!(s.contains("torque") && s.contains("pi") && s.contains("unpowered"), "{s}");

    let s = field_error(&with("stand_six_legs", "robot = \"amru5\"", "robot = \"no_such_robot.toml\""), "scenario.robot");
    assert!(s.contains("no_such_robot.toml") && s.contains("amru5"), "{s}");

    let s = field_error(&with("stand_six_legs", "[model]", "[model]\nk_gnd = -1e6"), "model.k_gnd");
    assert!(s.contains("-1000000") && s.contains("[1000, 1e9]"), "{s}");

    let s = field_error(&with("stand_six_legs", "[model]", "[integrator]\nh_max_s = 0.1\n[model]"), "integrator.h_max_s");
    assert!(s.contains("0.1") && s.contains("[0.00001, 0.01]"), "{s}");

    let s = field_error(&with("unpowered_none", "friction = \"none\"", "friction = \"none\"\nload_dependence = true"), "model.load_dependence");
    assert!(s.contains("friction"), "{s}");

    let s = field_error(&with("stand_six_legs", "[model]", "[integrator]\nsurrogate_iterations = 51\n[model]"), "integrator.surrogate_iterations");
    assert!(s.contains("51") && s.contains("50"), "{s}");

    let s = field_error(&with("stand_six_legs", "[model]", "[integrator]\nunverified_steps = 1001\n[model]"), "integrator.unverified_steps");
    assert!(s.contains("1001") && s.contains("1000"), "{s}");
}

/// 2 s of the validation walk with the integrator option `field` (read back by `option`) at 0
/// and at its default, 8: the two summaries.
fn two_seconds_at_zero_and_default(field: &str, option: impl Fn(&NewmarkOptions) -> usize) -> (Summary, Summary) {
    let run = |value: Option<usize>| {
        let mut overrides = vec![Override::new("scenario.duration_s", 2.0)];
        overrides.extend(value.map(|n| Override::new(field, n as i64)));
        let s = overridden(&overrides).unwrap();
        assert_eq!(option(&s.plant.integrator), value.unwrap_or(8), "{field}");
        run_scenario(&s, |_| {}).unwrap().summary
    };
    (run(Some(0)), run(None))
}

/// Steps are accepted on the surrogate's Newton test in runs of at most 8 by default
/// (`[integrator] unverified_steps`); 0 verifies every step by an evaluation of the residual.
/// 2 s of the validation walk: fewer residual evaluations, the same walk to 0.1 mm (the tracking
/// error and the distance), and the energy account closed as well (its error at the robot's
/// tolerance, 0.05 % of the electrical energy on the 75 s walk, is the integration's: both
/// within 0.5 % here, over the start's transient).
#[test]
fn steps_accepted_on_the_surrogate_default_to_runs_of_eight_and_zero_verifies_every_step() {
    let (verified, trusted) = two_seconds_at_zero_and_default("integrator.unverified_steps", |o| o.unverified_steps);
    assert_eq!(verified.unverified_steps, 0);
    assert!(trusted.unverified_steps > trusted.integration_steps / 4, "{} of {} steps accepted on the surrogate", trusted.unverified_steps, trusted.integration_steps);
    assert!(trusted.residual_evaluations < verified.residual_evaluations, "{} against {} evaluations", trusted.residual_evaluations, verified.residual_evaluations);
    let (a, b) = (verified.gait.as_ref().unwrap(), trusted.gait.as_ref().unwrap());
    eprintln!("distance {} vs {}, XY tracking {} vs {}; evaluations {} vs {}; balance {} vs {}", a.distance_walked_m, b.distance_walked_m, a.tracking_error_xy_max_m, b.tracking_error_xy_max_m, verified.residual_evaluations, trusted.residual_evaluations, verified.energy_balance_error_relative, trusted.energy_balance_error_relative);
    assert!((a.distance_walked_m - b.distance_walked_m).abs() < 1e-4 && (a.tracking_error_xy_max_m - b.tracking_error_xy_max_m).abs() < 1e-4, "{a:?} vs {b:?}");
    assert!(verified.energy_balance_error_relative.abs() < 5e-3 && trusted.energy_balance_error_relative.abs() < 5e-3, "{} and {}", verified.energy_balance_error_relative, trusted.energy_balance_error_relative);
}

/// The robot iterates on its surrogate residual by default (`[integrator] surrogate_iterations`
/// 8); 0 is the thesis' Newton iteration on f alone. 2 s of the validation walk: the surrogate
/// takes fewer residual evaluations for the same walk to 0.1 mm (the tracking error and the
/// distance).
#[test]
fn surrogate_iterations_default_to_eight_and_zero_iterates_on_f_alone() {
    let (plain, surrogate) = two_seconds_at_zero_and_default("integrator.surrogate_iterations", |o| o.surrogate_iterations);
    assert_eq!(plain.surrogate_evaluations, 0);
    assert!(surrogate.surrogate_evaluations > 0 && surrogate.residual_evaluations < plain.residual_evaluations, "{} and {} surrogate against {} evaluations", surrogate.residual_evaluations, surrogate.surrogate_evaluations, plain.residual_evaluations);
    let (a, b) = (plain.gait.unwrap(), surrogate.gait.unwrap());
    eprintln!("distance {} vs {}, XY tracking {} vs {}; evaluations {} vs {} + {}", a.distance_walked_m, b.distance_walked_m, a.tracking_error_xy_max_m, b.tracking_error_xy_max_m, plain.residual_evaluations, surrogate.residual_evaluations, surrogate.surrogate_evaluations);
    assert!((a.distance_walked_m - b.distance_walked_m).abs() < 1e-4 && (a.tracking_error_xy_max_m - b.tracking_error_xy_max_m).abs() < 1e-4, "{a:?} vs {b:?}");
}

#[test]
fn motion_errors() {
    let s = field_error(&with("leg_sine", "amplitude = 0.004", "amplitude = 0.01"), "control.motion[1].amplitude");
    assert!(s.contains("0.01") && s.contains("q_v stroke [0.04, 0.075] m"), "{s}");
    let line = shipped("leg_sine").lines().position(|l| l.starts_with("amplitude = 0.004")).unwrap() + 1;
    assert!(s.starts_with(&format!("bad.toml:{line}:")), "{s}");

    // q_r motions are in radians: 10 "degrees" is far outside the range.
    let s = field_error(&with("leg_sine", "amplitude = 0.15", "amplitude = 10"), "control.motion[0].amplitude");
    assert!(s.contains("rad"), "{s}");

    let s = field_error(&with("leg_sine", "amplitude = 0.15", "amplitud = 0.15"), "control.motion[0].amplitud");
    assert!(s.contains("unknown field") && s.contains("amplitude"), "{s}");

    let s = field_error(&with("leg_sine", "frequency_hz = 0.25", "frequency_hz = 0.25\nrate = 1.0"), "control.motion[0].rate");
    assert!(s.contains("not a field of kind = \"sine\"") && s.contains("amplitude, frequency_hz"), "{s}");

    let s = field_error(&with("leg_sine", "amplitude = 0.15      # rad\n", ""), "control.motion[0].amplitude");
    assert!(s.contains("<missing>") && s.contains("amplitude, frequency_hz"), "{s}");

    let s = field_error(&with("leg_sine", "leg = 1", "leg = 7"), "control.motion[0].leg");
    assert!(s.contains('7') && s.contains("0..5"), "{s}");

    let s = field_error(&with("leg_sine", "joint = \"q_r\"", "joint = \"q_x\""), "control.motion[0].joint");
    assert!(s.contains("q_x") && s.contains("q_r") && s.contains("q_v") && s.contains("q_h"), "{s}");

    let s = field_error(&with("leg_sine", "kind = \"sine\"", "kind = \"square\""), "control.motion[0].kind");
    assert!(s.contains("square") && s.contains("ramp") && s.contains("sawtooth"), "{s}");

    let s = field_error(&with("leg_sine", "joint = \"q_v\"", "joint = \"q_r\""), "control.motion[1].joint");
    assert!(s.contains("one motion per (leg, joint)"), "{s}");

    // The ramp must end within the stroke: 0.045 + 0.0085699 * 4 s > 0.075.
    let s = field_error(&with("leg_ramp", "stop_s = 1.5", "stop_s = 4.5\n").replace("duration_s = 2.5", "duration_s = 5.0"), "control.motion[0].rate");
    assert!(s.contains("rate in [") && s.contains("q_v stroke"), "{s}");

    let s = field_error(&with("leg_sawtooth", "max = 0.055           # m", "max = 0.08"), "control.motion[1].max");
    assert!(s.contains("0.08") && s.contains("0.075"), "{s}");

    let s = field_error(&with("unpowered_lugre", "mode = \"unpowered\"", "mode = \"unpowered\"\n[[control.motion]]\nleg = 0\njoint = \"q_v\"\nkind = \"sine\"\namplitude = 0.001\nfrequency_hz = 1.0"), "control.motion");
    assert!(s.contains("mode = \"pi\""), "{s}");
}

#[test]
fn syntax_and_io_errors() {
    let e = parse("[scenario]\nname = = 1\n").unwrap_err();
    assert!(matches!(e, ScenarioError::Syntax { line: 2, .. }), "{e}");
    assert!(e.to_string().starts_with("bad.toml:2:"), "{e}");

    let e = parse("[scenario]\nname = \"x\"\n").unwrap_err();
    assert_eq!(e.field(), Some("scenario.duration_s"), "{e}");
    assert!(e.to_string().contains("<missing>"), "{e}");

    let e = parse("[initial]\nsettle = true\n").unwrap_err();
    assert_eq!(e.field(), Some("scenario"), "{e}");

    let e = Scenario::from_file("no/such/scenario.toml").unwrap_err();
    assert!(matches!(e, ScenarioError::Io { .. }) && e.to_string().starts_with("no/such/scenario.toml: cannot read"), "{e}");
}

#[test]
fn robot_path_relative_to_the_scenario() {
    let dir = std::env::temp_dir().join(format!("hexadyn-scenario-test-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("robots")).unwrap();
    std::fs::write(dir.join("robots/copy.toml"), AMRU5_TOML).unwrap();
    std::fs::write(dir.join("robots/bad.toml"), AMRU5_TOML.replacen("resistance_ohm = 0.334", "resistance_ohm = -1.0", 1)).unwrap();
    let text = shipped("stand_six_legs").replace("robot = \"amru5\"", "robot = \"robots/copy.toml\"");
    std::fs::write(dir.join("s.toml"), &text).unwrap();
    let s = Scenario::from_file(dir.join("s.toml")).unwrap();
    assert_eq!(s.robot_text, AMRU5_TOML);
    assert!(s.robot_source.ends_with("copy.toml"));

    std::fs::write(dir.join("s.toml"), text.replace("copy.toml", "bad.toml")).unwrap();
    let e = Scenario::from_file(dir.join("s.toml")).unwrap_err();
    assert!(matches!(e, ScenarioError::Robot(_)), "{e}");
    let s = e.to_string();
    assert!(s.contains("bad.toml") && s.contains("motor.resistance_ohm") && s.contains("-1"), "{s}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A short run of a scenario with every kind of column (lifted legs, motions, LuGre).
fn short(name: &str, duration: f64) -> Scenario {
    let text = shipped(name);
    let line = text.lines().find(|l| l.starts_with("duration_s")).unwrap();
    parse(&text.replacen(line, &format!("duration_s = {duration}"), 1)).unwrap()
}

#[test]
fn runs_are_deterministic_and_recorded_with_units() {
    let s = short("leg_sine", 0.2);
    let mut calls = Vec::new();
    let a = run_scenario(&s, |t| calls.push(t)).unwrap();
    let b = run_scenario(&s, |_| {}).unwrap();
    assert_eq!(a.series.columns.len(), b.series.columns.len());
    for (x, y) in a.series.columns.iter().zip(&b.series.columns) {
        assert_eq!(x.name, y.name);
        let same = x.values.iter().zip(&y.values).all(|(u, v)| u.to_bits() == v.to_bits());
        assert!(same && x.values.len() == y.values.len(), "column {} differs between two runs", x.name);
    }

    let series = &a.series;
    assert_eq!(series.len(), 21, "0.2 s at 10 ms: 21 instants");
    assert_eq!(calls.len(), 21);
    let t = series.values("t").unwrap();
    for (k, t) in t.iter().enumerate() {
        assert!((t - 0.01 * k as f64).abs() < 1e-12, "t[{k}] = {t}");
    }
    let units = [
        ("t", "s"),
        ("Z", "m"),
        ("roll", "rad"),
        ("Z_dot", "m/s"),
        ("q_r[1]", "rad"),
        ("q_v[2]", "m"),
        ("q_h[5]", "m"),
        ("q_r_dot[0]", "rad/s"),
        ("q_v_dot[2]", "m/s"),
        ("q_v_ref[1]", "m"),
        ("u_q_v[2]", "V"),
        ("i_q_v[2]", "A"),
        ("tau_m_q_r[0]", "Nm"),
        ("tau_f_q_r[0]", "Nm"),
        ("tau_f_q_v[2]", "N"),
        ("z_q_r[3]", "rad"),
        ("z_q_v[2]", "m"),
        ("Fx[0]", "N"),
        ("Fz[2]", "N"),
        ("Fn[4]", "N"),
        ("penetration[3]", "m"),
        ("foot_z[1]", "m"),
        ("E_el_q_v[1]", "J"),
        ("E_joule_q_h[0]", "J"),
        ("E_fric_q_r[5]", "J"),
        ("E_kin", "J"),
        ("E_pot", "J"),
        ("E_balance", "J"),
    ];
    for (name, unit) in units {
        assert_eq!(series.unit(name), Some(unit), "{name}");
        assert_eq!(series.values(name).unwrap().len(), 21, "{name}");
    }
    for c in &series.columns {
        assert!(c.values.iter().all(|v| v.is_finite()), "{} has non-finite values", c.name);
        assert!(!c.description.is_empty(), "{}", c.name);
    }
    // Leg 1 is lifted, the tripod 0-3-4 carries the weight.
    let fz = |f: usize| *series.values(&format!("Fz[{f}]")).unwrap().last().unwrap();
    assert_eq!(fz(1), 0.0);
    let weight = 34.447 * 9.81;
    assert!(((fz(0) + fz(3) + fz(4)) - weight).abs() < 0.02 * weight);
    // The references follow the sine of leg 1's q_v.
    let r = series.values("q_v_ref[1]").unwrap();
    assert!((r[20] - (0.045 + 0.004 * (std::f64::consts::TAU * 0.25 * 0.2).sin())).abs() < 1e-12);

    let sm = &a.summary;
    assert_eq!((sm.rows, sm.control_periods), (21, 20));
    assert!((sm.duration_s - 0.2).abs() < 1e-12);
    // A sanity bound: over these 0.2 s the leg's drop makes a transient (kinetic change about
    // 2.2 J of 3.9 J electrical) whose balance error at the robot's integration tolerance is the
    // step sequence's, -0.7 % to +1.0 % over 0.2-2 s with every step verified on f or some
    // accepted on the surrogate (sessions 32-33); the account itself closes to 0.1 % when the
    // integration converges (`walking_energy_account_closes_when_the_integration_converges`).
    assert!(sm.energy_electrical_j > 0.0 && sm.energy_balance_error_relative.abs() < 0.02, "{sm:?}");
    let entries = sm.entries();
    let names: Vec<&str> = entries.iter().map(|(n, _)| n.as_ref()).collect();
    for n in ["duration_s", "wall_time_s", "integration_steps", "energy_electrical_j", "energy_balance_error_j", "body_height_change_m", "max_tracking_error_q_v_m"] {
        assert!(names.contains(&n), "{n} missing from the summary");
    }
}

#[test]
fn column_sets_follow_the_model() {
    let s = short("unpowered_none", 0.05);
    let r = run_scenario(&s, |_| {}).unwrap();
    assert!(r.series.column("z_q_v[0]").is_none(), "no bristles without LuGre");
    assert!(r.series.column("q_v_ref[0]").is_none(), "no references when unpowered");
    assert!(r.series.values("u_q_v[0]").unwrap().iter().all(|&u| u == 0.0));
    assert!(r.summary.max_tracking_error.is_none());
}

/// Section 6.2, shortened to 1 s: LuGre holds the body, dry/viscous slows the descent, no
/// friction sinks fastest.
#[test]
fn unpowered_scenarios_order_the_friction_models() {
    let sink: Vec<f64> = ["unpowered_lugre", "unpowered_dry_viscous", "unpowered_none"]
        .iter()
        .map(|n| {
            let r = run_scenario(&short(n, 1.0), |_| {}).unwrap();
            -r.summary.body_height_change_m
        })
        .collect();
    assert!(sink[0] < 0.02e-3 && sink[0] < sink[1] && sink[1] < sink[2], "{sink:?}");
}

#[test]
fn progress_can_stop_a_run() {
    let s = short("stand_six_legs", 1.0);
    let e = run_scenario_until(&s, Record::TimeSeries, |t| if t >= 0.095 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }).unwrap_err();
    match e {
        ScenarioError::Stopped { t, .. } => assert!((t - 0.1).abs() < 1e-9, "{t}"),
        e => panic!("{e}"),
    }
}

/// Standing on three legs of one side cannot be settled: one line naming the stage and a hint.
#[test]
fn settling_failures_are_reported() {
    let s = parse(&with("stand_three_legs", "lifted_legs = [1, 2, 5]", "lifted_legs = [0, 2, 4]")).unwrap();
    let e = run_scenario(&s, |_| {}).unwrap_err();
    let m = e.to_string();
    assert!(matches!(e, ScenarioError::Simulation { .. } | ScenarioError::Tipped { .. }), "{m}");
    assert!(m.starts_with("bad.toml: settling") && m.contains("initial.lifted_legs") && !m.contains('\n'), "{m}");
}

// =============================================================================================
// Gait mode
// =============================================================================================

#[test]
fn walking_scenarios_parse() {
    let s = Scenario::from_file(scenarios_dir().join("validation_tripod_1_5cm.toml")).unwrap();
    assert_eq!(s.control, ControlMode::Gait);
    assert_eq!((s.duration, s.model.friction), (60.0, FrictionModel::LuGre));
    let g = s.gait.as_ref().unwrap();
    assert_eq!(g.options.period, 12.0);
    assert_eq!((g.options.pattern.name.as_str(), g.options.pattern.beta), ("tripod", 0.5));
    assert_eq!(g.options.cycle, FootCycle::Enhanced { overlap: 0.05 });
    assert_eq!((g.options.aep, g.options.lift, g.navigation), (AepMode::Periodic, 0.105, false));
    match &g.heading {
        HeadingSpec::Constant(h) => assert_eq!((h.velocity.x, h.velocity.y, h.yaw_rate), (0.015, 0.0, 0.0)),
        h => panic!("{h:?}"),
    }
    // The default body height: q_v = 0.06 m (about 0.414 m); the legs start where the steady
    // gait has them (issue 18): legs 0, 3, 4 begin their support 2Δφ T = 1.2 s after their
    // AEP, V_x ((β + 4Δφ)/2 − 2Δφ) T = 0.015 x 3 s = 4.5 cm ahead of their workspace centres;
    // legs 1, 2, 5 are 0.1 T before their PEP, 4.5 cm behind.
    assert!((g.body_height - 0.414).abs() < 1e-3, "{}", g.body_height);
    assert_eq!(s.initial.joints, g.joints);
    assert!(s.initial.settle && s.initial.lifted_legs.is_empty());
    let GaitLegs::Pantograph(legs) = &g.legs else { panic!("AMRU5's pantograph legs") };
    for l in 0..6 {
        let q = nalgebra::Vector3::new(g.joints[3 * l], g.joints[3 * l + 1], g.joints[3 * l + 2]);
        let foot = legs[l].foot_in_body(&q);
        let ahead = if [0, 3, 4].contains(&l) { 0.045 } else { -0.045 };
        let expected = legs[l].to_body(&g.workspaces[l].centre_at(-g.body_height)) + nalgebra::Vector3::new(ahead, 0.0, 0.0);
        assert!((foot - expected).norm() < 1e-6, "leg {l}: {foot:?} instead of {expected:?}");
    }
    assert!(!s.plant.navigation);

    let s = Scenario::from_file(scenarios_dir().join("path_spline.toml")).unwrap();
    let g = s.gait.as_ref().unwrap();
    assert!(matches!(g.heading, HeadingSpec::Spline { built_in: true, .. }));
    assert_eq!((g.options.aep, g.navigation, s.plant.navigation), (AepMode::Omnidirectional, true, true));
    assert_eq!(s.model.friction, FrictionModel::None);
    let s = Scenario::from_file(scenarios_dir().join("soft_ground_plain.toml")).unwrap();
    let g = s.gait.as_ref().unwrap();
    assert_eq!((s.model.ground.k_gnd, g.options.lift, g.options.cycle), (1e4, 0.1, FootCycle::Plain));
    let s = Scenario::from_file(scenarios_dir().join("gait_changes.toml")).unwrap();
    let g = s.gait.as_ref().unwrap();
    let changes: Vec<(f64, &str, f64)> = g.changes.iter().map(|c| (c.at, c.pattern.name.as_str(), c.pattern.beta)).collect();
    assert_eq!(changes, vec![(20.0, "wave", 0.75), (50.0, "tripod", 0.5)]);
    let s = Scenario::from_file(scenarios_dir().join("path_straight_lines_no_navigation.toml")).unwrap();
    assert!(matches!(s.gait.as_ref().unwrap().heading, HeadingSpec::Square { side: 0.375, speed: 0.015 }));
    assert!(!s.plant.navigation);

    // The free gait's landing: from the motor currents by default (40 N, Section 5.6.3), the
    // simulated normal force when asked (10 N, Section 7.7).
    let landing = |text: &str| parse(text).unwrap().gait.unwrap().free.unwrap().landing;
    assert_eq!(landing(&shipped("free_gait_straight")), LandingSpec::Current { threshold: 40.0 });
    assert_eq!(landing(&shipped("free_gait_five_legs")), LandingSpec::Current { threshold: 40.0 });
    assert_eq!(landing(&shipped("free_gait_slope_square")), LandingSpec::Force { threshold: 10.0 });
    assert_eq!(landing(&with("free_gait_slope_square", "landing_threshold_n = 10.0\n", "")), LandingSpec::Force { threshold: 10.0 });
    assert_eq!(landing(&with("free_gait_straight", "landing = \"current\"", "landing = \"force\"").replace("landing_threshold_n = 40.0", "")), LandingSpec::Force { threshold: 10.0 });
    assert_eq!(landing(&with("free_gait_slope_square", "landing = \"force\"\nlanding_threshold_n = 10.0\n", "")), LandingSpec::Current { threshold: 40.0 });
    // On serial legs the same detections, at the thesis' thresholds scaled from AMRU5's weight
    // to the robot's (2.14 N and 0.54 N on the PhantomX).
    let px = "phantomx_free_gait_rough";
    let terrain = format!("file = \"{}/terrains/", scenarios_dir().display());
    let px_with = |from: &str, to: &str| with(px, from, to).replace("file = \"terrains/", &terrain);
    let (m, m_amru5) = (Robot::from_str(hexadyn::description::PHANTOMX_TOML, "phantomx").unwrap().total_mass_kg(), Robot::from_str(AMRU5_TOML, "amru5").unwrap().total_mass_kg());
    let (current, force) = (40.0 * m / m_amru5, 10.0 * m / m_amru5);
    assert!((current - 2.14).abs() < 0.005 && (force - 0.535).abs() < 0.001, "{current} {force}");
    assert_eq!(landing(&px_with("", "")), LandingSpec::Current { threshold: current });
    assert_eq!(landing(&px_with("landing = \"current\"", "")), LandingSpec::Current { threshold: current });
    assert_eq!(landing(&px_with("landing = \"current\"", "landing = \"force\"")), LandingSpec::Force { threshold: force });
    assert_eq!(landing(&px_with("landing = \"current\"", "landing = \"force\"\nlanding_threshold_n = 10.0")), LandingSpec::Force { threshold: 10.0 });

    // Waypoints of a spline.
    let text = with("path_spline", "kind = \"spline\"", "kind = \"spline\"\nt_s = [0.0, 50.0, 100.0]\nx_m = [0.0, 0.5, 1.0]\ny_m = [0.0, 0.2, 0.0]");
    assert!(matches!(parse(&text).unwrap().gait.unwrap().heading, HeadingSpec::Spline { built_in: false, .. }));
}

#[test]
fn gait_errors_name_the_field() {
    let v = "validation_tripod_1_5cm";
    let s = field_error(&with(v, "pattern = \"tripod\"", "pattern = \"trot\""), "gait.pattern");
    assert!(s.contains("trot") && s.contains("tripod") && s.contains("wave") && s.contains("equal_phase"), "{s}");
    let line = shipped(v).lines().position(|l| l.starts_with("pattern")).unwrap() + 1;
    assert!(s.starts_with(&format!("bad.toml:{line}:")), "{s}");

    let s = field_error(&with(v, "pattern = \"tripod\"", "pattern = \"tripod\"\nduty_factor = 0.6"), "gait.duty_factor");
    assert!(s.contains("0.6") && s.contains("0.5"), "{s}");
    let s = field_error(&with(v, "pattern = \"tripod\"", "pattern = \"wave\"\nduty_factor = 0.9"), "gait.duty_factor");
    assert!(s.contains("0.9") && s.contains("[0.5, 0.8)"), "{s}");
    let s = field_error(&with(v, "cycle = \"enhanced\"", "cycle = \"plain\""), "gait.overlap");
    assert!(s.contains("plain"), "{s}");
    let s = field_error(&with(v, "cycle = \"enhanced\"", "cycle = \"fancy\""), "gait.cycle");
    assert!(s.contains("fancy") && s.contains("enhanced") && s.contains("plain"), "{s}");
    let s = field_error(&with(v, "aep = \"periodic\"", "aep = \"free\""), "gait.aep");
    assert!(s.contains("periodic") && s.contains("omnidirectional"), "{s}");
    let s = field_error(&with(v, "overlap = 0.05", "overlap = 0.2"), "gait.overlap");
    assert!(s.contains("(0, 0.125)"), "{s}");
    let s = field_error(&with(v, "period_s = 12.0", "period_s = 0.1"), "gait.period_s");
    assert!(s.contains("0.1") && s.contains(">= 0.1333"), "{s}");
    let s = field_error(&with(v, "period_s = 12.0", "period = 12.0"), "gait.period");
    assert!(s.contains("unknown field") && s.contains("period_s"), "{s}");
    let s = field_error(&with(v, "clearance_m = 0.105", "clearance_m = 0.3"), "gait.clearance_m");
    assert!(s.contains("0.3") && s.contains("a clearance in (0, 0.12"), "{s}");
    let s = field_error(&with(v, "clearance_m = 0.105", "clearance_m = 0.105\nbody_height_m = 0.6"), "gait.body_height_m");
    assert!(s.contains("0.6") && s.contains("(0.2939, 0.5040)"), "{s}");
    // AMRU5's joints are PI loops: no servo goals to lead.
    let s = field_error(&with(v, "clearance_m = 0.105", "clearance_m = 0.105\nfriction_feedforward = true"), "gait.friction_feedforward");
    assert!(s.contains("PI loops") && s.contains("position servos"), "{s}");

    // The stroke must fit the workspace: 5 cm/s x 8.4 s = 0.42 m > 2 x 0.148 m.
    let s = field_error(&with(v, "vx_m_s = 0.015", "vx_m_s = 0.05"), "gait.heading");
    assert!(s.contains("does not fit the workspace") && s.contains("0.42") && s.contains("|v_C| <= 0.0352"), "{s}");
    let line = shipped(v).lines().position(|l| l.starts_with("[gait.heading]")).unwrap() + 1;
    assert!(s.starts_with(&format!("bad.toml:{line}:")), "{s}");

    let s = field_error(&with(v, "omega_z_rad_s = 0.0", "omega_z_rad_s = 0.0\nside_m = 1.0"), "gait.heading.side_m");
    assert!(s.contains("not a field of kind = \"constant\"") && s.contains("vx_m_s, vy_m_s, omega_z_rad_s"), "{s}");
    let s = field_error(&with("path_straight_lines", "side_m = 0.375\n", ""), "gait.heading.side_m");
    assert!(s.contains("<missing>") && s.contains("side_m, speed_m_s"), "{s}");
    let s = field_error(&with("path_straight_lines", "speed_m_s = 0.015", "speed_m_s = -0.015"), "gait.heading.speed_m_s");
    assert!(s.contains("> 0"), "{s}");
    let s = field_error(&with(v, "kind = \"constant\"", "kind = \"joystick\""), "gait.heading.kind");
    assert!(s.contains("joystick") && s.contains("back_and_forth") && s.contains("csv"), "{s}");
    let s = field_error(&with("path_spline", "kind = \"spline\"", "kind = \"spline\"\nt_s = [0.0, 10.0]"), "gait.heading.x_m");
    assert!(s.contains("<missing>") && s.contains("built-in"), "{s}");
    let s = field_error(&with("path_spline", "kind = \"spline\"", "kind = \"spline\"\nt_s = [0.0, 10.0, 5.0]\nx_m = [0, 0.1, 0.2]\ny_m = [0, 0, 0]"), "gait.heading.t_s[2]");
    assert!(s.contains("strictly increasing"), "{s}");
    let s = field_error(&with(v, "kind = \"constant\"", "kind = \"csv\"\nfile = \"no_such.csv\"").replace("vx_m_s = 0.015\nvy_m_s = 0.0\nomega_z_rad_s = 0.0\n", ""), "gait.heading.file");
    assert!(s.contains("no_such.csv") && s.contains("cannot read") && s.contains("t,vx,vy,omega_z"), "{s}");

    let s = field_error(&with("free_gait_straight", "landing_threshold_n = 40.0", "landing_threshold_n = -5.0"), "gait.free.landing_threshold_n");
    assert!(s.contains("-5") && s.contains("landing = \"current\"") && s.contains("40 N"), "{s}");
    let s = field_error(&with("free_gait_straight", "landing = \"current\"", "landing = \"switch\""), "gait.free.landing");
    assert!(s.contains("switch") && s.contains("current") && s.contains("force"), "{s}");

    let s = field_error(&with("gait_changes", "at_s = 50.0", "at_s = 90.0"), "gait.change[1].at_s");
    assert!(s.contains("90") && s.contains("(20, 80)"), "{s}");
    let s = field_error(&with("gait_changes", "pattern = \"wave\"", "pattern = \"wave\"\nspeed = 1"), "gait.change[0].speed");
    assert!(s.contains("unknown field"), "{s}");

    // Gait mode and the other tables.
    let s = field_error(&with(v, "settle = true", "settle = true\nq_v_m = 0.06"), "initial.q_v_m");
    assert!(s.contains("not used in gait mode") && s.contains("gait.body_height_m"), "{s}");
    let s = field_error(&with(v, "settle = true", "lifted_legs = [1]"), "initial.lifted_legs");
    assert!(s.contains("not used in gait mode"), "{s}");
    let s = field_error(&with(v, "mode = \"gait\"", "mode = \"pi\""), "gait");
    assert!(s.contains("control.mode = \"gait\""), "{s}");
    let s = field_error(&with("stand_six_legs", "mode = \"pi\"", "mode = \"gait\""), "gait");
    assert!(s.contains("<missing>") && s.contains("[gait]"), "{s}");
    let s = field_error(&with(v, "mode = \"gait\"", "mode = \"gait\"\n[[control.motion]]\nleg = 0\njoint = \"q_v\"\nkind = \"sine\"\namplitude = 0.001\nfrequency_hz = 1.0"), "control.motion");
    assert!(s.contains("mode = \"pi\""), "{s}");

    // The experiment of Section 5.6.3 on serial legs: a foot height the leg reaches up and down,
    // thresholds below the robot's weight (AMRU5's Table 5.7 forces are not the PhantomX's),
    // the feed-forward for servos only.
    let px = "phantomx_ground_detection";
    let s = field_error(&with(px, "amplitude_m = 0.03       #", "amplitude_m = 0.5 #"), "ground_detection.amplitude_m");
    assert!(s.contains("0.5") && s.contains("reaches above and below"), "{s}");
    let s = field_error(&with(px, "thresholds_n = [2.14, 2.68, 3.21]", "thresholds_n = [40.0]"), "ground_detection.thresholds_n[0]");
    assert!(s.contains("40") && s.contains("below the robot's weight"), "{s}");
    let s = field_error(&with("ground_detection", "period_s = 8.0", "period_s = 8.0\nfriction_feedforward = true"), "ground_detection.friction_feedforward");
    assert!(s.contains("PI loops"), "{s}");
}

/// A heading from a CSV file next to the scenario; a malformed file is reported with its line.
#[test]
fn csv_heading_relative_to_the_scenario() {
    let dir = std::env::temp_dir().join(format!("hexadyn-gait-csv-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("paths")).unwrap();
    std::fs::write(dir.join("paths/h.csv"), "t,vx,vy,omega_z\n0,0.01,0,0\n10,0.01,0.005,0.001\n").unwrap();
    let text = shipped("validation_tripod_1_5cm").replace("kind = \"constant\"\nvx_m_s = 0.015\nvy_m_s = 0.0\nomega_z_rad_s = 0.0", "kind = \"csv\"\nfile = \"paths/h.csv\"");
    std::fs::write(dir.join("s.toml"), &text).unwrap();
    let s = Scenario::from_file(dir.join("s.toml")).unwrap();
    match &s.gait.unwrap().heading {
        HeadingSpec::Csv { file, series } => assert!(file.ends_with("h.csv") && series.t == vec![0.0, 10.0], "{file}"),
        h => panic!("{h:?}"),
    }
    std::fs::write(dir.join("paths/h.csv"), "t,vx,vy,omega_z\n0,0.01,0,0\n10,fast,0,0\n").unwrap();
    let e = Scenario::from_file(dir.join("s.toml")).unwrap_err().to_string();
    assert!(e.contains("gait.heading.file") && e.contains("h.csv:3") && e.contains("\"fast\" is not a number"), "{e}");
    // Too fast for the workspace somewhere in the file.
    std::fs::write(dir.join("paths/h.csv"), "t,vx,vy,omega_z\n0,0.01,0,0\n10,0.01,0.05,0\n").unwrap();
    let e = Scenario::from_file(dir.join("s.toml")).unwrap_err();
    assert_eq!(e.field(), Some("gait.heading"), "{e}");
    assert!(e.to_string().contains("csv heading") && e.to_string().contains("t = 10.00 s"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A run that keeps only its summary builds no time series and sums up the same run: every
/// summary value but the wall time is bit-identical, the penetration and row count included.
#[test]
fn summary_only_runs_sum_up_the_same_run() {
    let s = short("validation_tripod_1_5cm", 2.0);
    let full = run_scenario(&s, |_| {}).unwrap();
    let bare = run_scenario_until(&s, Record::SummaryOnly, |_| ControlFlow::Continue(())).unwrap();
    assert_eq!(bare.series.len(), 0);
    assert_eq!(bare.series.columns.len(), 0);
    assert_eq!(full.summary.rows as usize, full.series.len());
    let penetration = (0..6).flat_map(|f| full.series.values(&format!("penetration[{f}]")).unwrap().to_vec()).fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(full.summary.max_penetration_m, penetration);
    assert!(penetration > 0.0, "the feet are in the ground");
    for ((name, a), (_, b)) in full.summary.entries().into_iter().zip(bare.summary.entries()).filter(|((name, _), _)| name != "wall_time_s") {
        let same = match (&a, &b) {
            (SummaryValue::Number(x), SummaryValue::Number(y)) => x.to_bits() == y.to_bits(),
            _ => a == b,
        };
        assert!(same, "{name}: {a:?} with the time series, {b:?} without");
    }
}

/// 5 s of the validation walk: the gait columns are recorded with units, the foot phases go
/// through support, takeoff, swing and landing, the body follows its reference; two runs are
/// bit-identical.
#[test]
fn gait_runs_record_the_walk_deterministically() {
    let s = short("validation_tripod_1_5cm", 5.0);
    let a = run_scenario(&s, |_| {}).unwrap();
    let b = run_scenario(&s, |_| {}).unwrap();
    assert_eq!(a.series.columns.len(), b.series.columns.len());
    for (x, y) in a.series.columns.iter().zip(&b.series.columns) {
        assert_eq!(x.name, y.name);
        let same = x.values.iter().zip(&y.values).all(|(u, v)| u.to_bits() == v.to_bits());
        assert!(same && x.values.len() == y.values.len(), "column {} differs between two runs", x.name);
    }
    let series = &a.series;
    assert_eq!(series.len(), 501);
    let units = [
        ("X_ref", "m"),
        ("Y_ref", "m"),
        ("Z_ref", "m"),
        ("yaw_ref", "rad"),
        ("pitch_ref", "rad"),
        ("roll_ref", "rad"),
        ("X_dot_ref", "m/s"),
        ("omega_z_ref", "rad/s"),
        ("duty_factor", "1"),
        ("phase[0]", "1"),
        ("phase[5]", "1"),
        ("foot_ref_x[0]", "m"),
        ("foot_ref_z[5]", "m"),
        ("q_v_ref[3]", "m"),
        ("z_q_v[2]", "m"),
    ];
    for (name, unit) in units {
        assert_eq!(series.unit(name), Some(unit), "{name}");
    }
    for c in &series.columns {
        assert!(c.values.iter().all(|v| v.is_finite()), "{} has non-finite values", c.name);
    }
    // Tripod {1, 2, 5} starts at phase 0.5: support to 0.3 s, takeoff to 1.2 s, swing to 4.8 s,
    // then landing; tripod {0, 3, 4} stays in support.
    let phase = |l: usize| series.values(&format!("phase[{l}]")).unwrap();
    let at = |t: f64| (t / 0.01).round() as usize;
    for l in [1, 2, 5] {
        assert_eq!([phase(l)[at(0.1)], phase(l)[at(0.5)], phase(l)[at(3.0)], phase(l)[at(4.95)]], [0.0, 1.0, 2.0, 3.0], "leg {l}");
    }
    for l in [0, 3, 4] {
        assert!(phase(l).iter().all(|&p| p == 0.0), "leg {l}");
    }
    let (x, x_ref) = (series.values("X").unwrap(), series.values("X_ref").unwrap());
    assert!((x_ref[500] - 0.015 * (5.0 - 0.005)).abs() < 1e-9, "{}", x_ref[500]);
    assert!((x[500] - x_ref[500]).abs() < 2e-3, "{} vs {}", x[500], x_ref[500]);
    assert!(series.values("duty_factor").unwrap().iter().all(|&b| b == 0.5));
    // Leg 1 lifts its foot reference by the clearance (10.5 cm, docs/validation-walk.md) at
    // mid-swing (t = 3 s).
    let z = series.values("foot_ref_z[1]").unwrap();
    assert!((z[at(3.0)] - z[0] - 0.105).abs() < 1e-3, "{}", z[at(3.0)] - z[0]);

    let g = a.summary.gait.as_ref().expect("gait summary");
    assert!(g.tracking_error_xy_max_m < 2e-3 && g.tracking_error_xy_final_m <= g.tracking_error_xy_max_m, "{g:?}");
    assert!((g.reference_distance_m - 0.015 * 4.995).abs() < 1e-6, "{g:?}");
    assert!((g.distance_walked_m - g.reference_distance_m).abs() < 3e-3, "{g:?}");
    assert_eq!((g.clamped_ik_references, g.gait_switches, g.min_feet_on_ground), (0, 0, 3));
    assert!(g.max_foot_reference_outside_workspace_m < 1e-6, "{g:?}");
    let entries = a.summary.entries();
    let names: Vec<&str> = entries.iter().map(|(n, _)| n.as_ref()).collect();
    for n in ["tracking_error_xy_max_m", "tracking_error_xy_final_m", "distance_walked_m", "clamped_ik_references", "gait_switches", "min_feet_on_ground"] {
        assert!(names.contains(&n), "{n} missing from the summary");
    }
    assert_eq!(a.summary.control, "gait");
}

/// Issue 18: every shipped walk respects its workspaces from the first step: no foot
/// reference clamped by the inverse kinematics, none more than 1 µm outside its workspace
/// cylinder on AMRU5 (the encoders' quantization of the start posture is below that); on a
/// serial robot, one count of its position sensors at the leg's full reach (the PhantomX's
/// 0.29° at 0.25 m: 1.3 mm). The periodic
/// walks only: the free gait's feet leave the flat-ground cylinder's height range by design
/// (posture, uneven ground), its horizontal boundary is kept by the deadlock rule (tested in
/// `control::gait::free`).
#[test]
fn every_shipped_walk_keeps_its_feet_in_the_workspaces() {
    let walks: Vec<Scenario> = shipped_names().iter().map(|name| Scenario::from_file(scenarios_dir().join(format!("{name}.toml"))).unwrap()).filter(|s| s.gait.as_ref().is_some_and(|g| g.free.is_none())).collect();
    assert!(walks.len() >= 14, "{} shipped walks", walks.len());
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    std::thread::scope(|scope| {
        for chunk in walks.chunks(walks.len().div_ceil(threads)) {
            scope.spawn(move || {
                for s in chunk {
                    let run = run_scenario_until(s, Record::SummaryOnly, |_| ControlFlow::Continue(())).unwrap();
                    let g = run.summary.gait.as_ref().expect("gait summary");
                    assert_eq!(g.clamped_ik_references, 0, "{}: {g:?}", s.name);
                    let bound = match &s.robot {
                        Robot::Pantograph(_) => {
                            // The references start from the encoders' reading of the initial
                            // posture: a count of q_v or q_h is about 6 counts at the foot
                            // (z_foot ~ -6 q_v, Eq. B.1); 4 times coarser on the backdrivable
                            // drives' quarter ratios.
                            let count = s.model().encoders.iter().enumerate().filter(|(k, _)| k % 3 != 0).map(|(_, e)| e.resolution()).fold(0.0, f64::max);
                            1e-6f64.max(6.0 * count)
                        }
                        Robot::Serial(r) => {
                            let count = s.model().encoders.iter().map(|e| e.resolution()).fold(0.0, f64::max);
                            let reach = r.hexapod.legs.iter().map(|l| l.joints[1].origin.translation.norm() + l.joints[2].origin.translation.norm() + l.foot.norm()).fold(0.0, f64::max);
                            count * reach
                        }
                    };
                    assert!(g.max_foot_reference_outside_workspace_m <= bound, "{}: {g:?}", s.name);
                }
            });
        }
    });
}

/// A gait change requested at 1 s is made once all six feet are down (the tripod's double
/// support around t = 6 s): the duty factor column switches from 0.5 to 0.75.
#[test]
fn gait_changes_are_scheduled() {
    let text = with("gait_changes", "duration_s = 80.0", "duration_s = 7.0")
        .replace("at_s = 20.0", "at_s = 1.0")
        .replace("[[gait.change]]\nat_s = 50.0\npattern = \"tripod\"\n", "");
    let s = parse(&text).unwrap();
    assert_eq!(s.gait.as_ref().unwrap().changes.len(), 1);
    let r = run_scenario(&s, |_| {}).unwrap();
    let beta = r.series.values("duty_factor").unwrap();
    let t = r.series.values("t").unwrap();
    let switch = beta.iter().position(|&b| b == 0.75).expect("switched to the wave gait");
    assert!(beta[..switch].iter().all(|&b| b == 0.5) && beta[switch..].iter().all(|&b| b == 0.75));
    assert!(t[switch] > 5.5 && t[switch] < 6.5, "switched at {}", t[switch]);
    let g = r.summary.gait.unwrap();
    assert_eq!((g.gait_switches, g.min_feet_on_ground), (1, 3));
}

/// The validation scenario under overrides, as the friction comparison and the Monte Carlo
/// campaigns run it.
fn overridden(overrides: &[Override]) -> Result<Scenario, ScenarioError> {
    Scenario::from_file_with(scenarios_dir().join("validation_tripod_1_5cm.toml"), overrides)
}

#[test]
fn overrides_set_fields_and_joint_friction_for_every_leg() {
    let s = overridden(&[
        Override::new("model.friction", "dry_viscous"),
        Override::new("model.load_dependence", true),
        Override::new("gait.heading.vx_m_s", 0.01),
        Override::new("model.joint_friction.q_r.tau_f_d_plus", 8.04),
        Override::new("model.joint_friction.q_r.f_v_minus", 16.17),
        Override::new("model.joint_friction.q_h.f_v_plus", 0.0),
        Override::new("model.joint_friction.q_h.a_2_plus", 5.5),
        Override::new("model.joint_friction.q_h.a_1_minus", -2.0),
    ])
    .unwrap();
    assert_eq!(s.model.friction, FrictionModel::DryViscous);
    assert!(s.model.load_dependence);
    match &s.gait.as_ref().unwrap().heading {
        HeadingSpec::Constant(h) => assert_eq!(h.velocity.x, 0.01),
        other => panic!("constant heading expected, got {other:?}"),
    }
    let unchanged = Scenario::from_file(scenarios_dir().join("validation_tripod_1_5cm.toml")).unwrap();
    for leg in 0..6 {
        let (f, g) = (s.robot.pantograph().unwrap().friction(leg, PantographJoint::Rotation), unchanged.robot.pantograph().unwrap().friction(leg, PantographJoint::Rotation));
        assert_eq!((f.tau_f_d_plus, f.f_v_minus), (8.04, 16.17));
        assert_eq!((f.tau_f_d_minus, f.f_v_plus), (g.tau_f_d_minus, g.f_v_plus), "keys left out keep the per-leg values");
        let h = s.robot.pantograph().unwrap().friction(leg, PantographJoint::Horizontal);
        let a = h.load_dependence.unwrap();
        assert_eq!((h.f_v_plus, a.a_2_plus, a.a_1_minus), (0.0, 5.5, -2.0));
        assert_eq!(a.a_2_minus, unchanged.robot.pantograph().unwrap().friction(leg, PantographJoint::Horizontal).load_dependence.unwrap().a_2_minus);
    }
    // The effective text is kept (results folders hold what ran) and reads back the same.
    assert!(s.text.contains("vx_m_s = 0.01") && s.text.starts_with('#'), "{}", s.text);
    let again = Scenario::from_str(&s.text, "effective.toml", &scenarios_dir()).unwrap();
    assert_eq!(again.robot.pantograph().unwrap().friction(3, PantographJoint::Horizontal), s.robot.pantograph().unwrap().friction(3, PantographJoint::Horizontal));
}

/// `friction = "efficiency"` takes the robot's `[friction.efficiency]`, which the scenario's
/// `[model.joint_friction.<joint>] eta_forward`, `eta_backward` replace; an efficiency outside
/// (0, 1] and the load dependence of Eq. 5.12 on top of the law are refused, naming the field.
#[test]
fn efficiency_friction_is_selected_overridden_and_checked() {
    let s = overridden(&[Override::new("model.friction", "efficiency"), Override::new("model.joint_friction.q_h.eta_backward", 0.7)]).unwrap();
    assert_eq!(s.model.friction, FrictionModel::Efficiency);
    let robot = s.robot.pantograph().unwrap();
    for leg in 0..6 {
        let (v, h, r) = (robot.friction(leg, PantographJoint::Vertical), robot.friction(leg, PantographJoint::Horizontal), robot.friction(leg, PantographJoint::Rotation));
        assert_eq!((v.eta_forward, v.eta_backward), (0.638, 0.453), "robots/amru5.toml [friction.efficiency]");
        assert_eq!((h.eta_forward, h.eta_backward), (0.638, 0.7));
        assert_eq!((r.eta_forward, r.eta_backward), (1.0, 1.0));
        assert_eq!(h.efficiency().no_load, h.dry_viscous(), "the no-load friction is Eq. 6.1 with Table 5.3");
    }
    let error = |o: &[Override]| overridden(o).expect_err("must be rejected").to_string();
    for (field, value) in [("q_v.eta_forward", 0.0), ("q_h.eta_backward", 1.5), ("q_r.eta_forward", -0.2)] {
        let s = error(&[Override::new(format!("model.joint_friction.{field}"), value)]);
        assert!(s.contains(&format!("model.joint_friction.{field}")) && s.contains("(0, 1]") && !s.contains('\n'), "{s}");
    }
    let s = error(&[Override::new("model.friction", "efficiency"), Override::new("model.load_dependence", true)]);
    assert!(s.contains("model.load_dependence") && s.contains("friction = \"efficiency\"") && !s.contains('\n'), "{s}");
}

#[test]
fn override_errors_name_the_override() {
    let error = |o: Override| overridden(&[o]).expect_err("must be rejected").to_string();
    let s = error(Override::new("model.frction", "dry_viscous"));
    assert!(s.contains("(with overrides)") && s.contains("model.frction") && s.contains("unknown field") && s.contains("friction"), "{s}");
    assert!(s.contains("(with overrides): field"), "no line of the effective text: {s}");
    let s = error(Override::new("model.friction", "coulomb"));
    assert!(s.contains("set by the override model.friction"), "{s}");
    let s = error(Override::new("scenario.name.x", 1));
    assert!(s.contains("scenario.name is not a table"), "{s}");
    let s = error(Override::new("model..friction", 1));
    assert!(s.contains("not a field path"), "{s}");
    let s = error(Override::new("model.joint_friction.q_r.a_2_plus", 1.0));
    assert!(s.contains("only in [model.joint_friction.q_h]"), "{s}");
    for (field, value) in [("q_h.tau_f_d_plus", -1.0), ("q_v.tau_f_d_minus", 1.0), ("q_r.f_v_plus", -0.5), ("q_h.a_2_minus", 0.3), ("q_h.a_1_plus", -1.0)] {
        let s = error(Override::new(format!("model.joint_friction.{field}"), value));
        assert!(s.contains(&format!("model.joint_friction.{field}")) && s.contains("out of range"), "{s}");
    }
}

/// One step of the validation walk (Section 6.3) with each friction model of the comparison of
/// Section 6.4 and the efficiency law, integrated to convergence (tolerance 0.01, h_max 1 ms): the energy account closes
/// within 0.1 % (electrical = Joule + friction + contact + Δ(T + V) + Δ stored; measured at most
/// 0.014 %, without friction). At the robot's tolerance the balance error is the integration
/// error of the step sequence, not a property of the account: without friction −0.104 J of
/// 17.5 J with Newton on f alone, −0.210 J with the surrogate iterations, +0.212 J on f alone
/// with h_max 1 ms (docs/performance-log.md, session 30); the walk at the robot's settings is
/// [`walking_orders_the_friction_models`].
#[test]
fn walking_energy_account_closes_when_the_integration_converges() {
    for (friction, load) in [("none", false), ("dry_viscous", false), ("dry_viscous", true), ("lugre", false), ("efficiency", false)] {
        let converged = [Override::new("integrator.tolerance", 0.01), Override::new("integrator.h_max_s", 1e-3)];
        let s = validation_step(friction, load, &converged);
        let e = s.energy_electrical_j;
        eprintln!("{friction} (load {load}): imbalance {:.3e} J of {e:.3} J", s.energy_balance_error_j);
        assert!(s.energy_balance_error_relative.abs() < 1e-3 && s.energy_balance_error_j.abs() < 1e-3 * e, "{friction} (load {load}): imbalance {} J of {e} J", s.energy_balance_error_j);
        assert!((s.energy_electrical_by_joint_j.iter().sum::<f64>() - e).abs() < 1e-9 * e.abs());
        assert!((s.average_power_w * s.duration_s - e).abs() < 1e-9 * e.abs());
    }
}

/// 12 s of the validation walk with `friction` and the load dependence `load`.
fn validation_step(friction: &str, load: bool, integrator: &[Override]) -> hexadyn::scenario::Summary {
    let mut overrides = vec![Override::new("model.friction", friction), Override::new("model.load_dependence", load), Override::new("scenario.duration_s", 12.0)];
    overrides.extend_from_slice(integrator);
    run_scenario(&overridden(&overrides).unwrap(), |_| {}).unwrap().summary
}

/// The same step at the robot's settings: friction orders the specific resistance (Eq. 6.6):
/// none < dry/viscous < dry/viscous with load (Section 6.4.4), with LuGre close to dry/viscous
/// (Section 6.4.5: "similar energy consumption"), and friction dominates the losses (Section 6.4).
#[test]
fn walking_orders_the_friction_models() {
    let xi = |s: &hexadyn::scenario::Summary| {
        let e = s.energy_electrical_j;
        assert!((s.robot_mass_kg - 34.447).abs() < 1e-9);
        let g = s.gait.as_ref().unwrap();
        assert!((g.distance_walked_m - 0.18).abs() < 0.005, "one step of 12 s at 1.5 cm/s: {}", g.distance_walked_m);
        specific_resistance(e, s.robot_mass_kg, g.distance_walked_m)
    };
    let none = validation_step("none", false, &[]);
    let dry = validation_step("dry_viscous", false, &[]);
    let (xi_none, xi_dry, xi_load, xi_lugre) = (xi(&none), xi(&dry), xi(&validation_step("dry_viscous", true, &[])), xi(&validation_step("lugre", false, &[])));
    println!("xi: none {xi_none:.3}, dry/viscous {xi_dry:.3}, dry/viscous + load {xi_load:.3}, LuGre {xi_lugre:.3}");
    assert!(xi_none > 0.0 && xi_dry > 2.0 * xi_none, "xi without friction {xi_none}, dry/viscous {xi_dry}");
    assert!(xi_load > 1.05 * xi_dry, "the load dependence raises xi: {xi_load} vs {xi_dry}");
    assert!((xi_lugre / xi_dry - 1.0).abs() < 0.15, "LuGre {xi_lugre} vs dry/viscous {xi_dry}");
    assert!(dry.energy_friction_j > 0.6 * dry.energy_electrical_j, "friction dominates (Section 6.4): {} of {} J", dry.energy_friction_j, dry.energy_electrical_j);
}

/// Every per-leg column that is not a joint's (`phase[l]`, `Fz[f]`, `F_gnd_est[l]`, ...) is a
/// name no joint may take (`hexapod::joints::RESERVED_NAMES`), and a joint's columns are its
/// name with a prefix or a suffix joined by `_`, which `LegJoints::new` keeps apart: so no two
/// of a robot's columns can share a name. Runs that record every column group: walking (gait),
/// ground detection and PI motions with LuGre bristles.
#[test]
fn per_leg_columns_outside_the_joints_are_reserved_names() {
    let joints = hexadyn::description::RobotDescription::amru5().joints.names;
    let mut quantities = std::collections::BTreeSet::new();
    for name in ["free_gait_five_legs", "ground_detection", "leg_sine"] {
        let r = run_scenario(&short(name, 0.05), |_| {}).unwrap();
        for c in &r.series.columns {
            let Some((quantity, _)) = c.name.split_once('[') else { continue };
            let of_a_joint = joints.names().any(|j| quantity == j || quantity.ends_with(&format!("_{j}")) || quantity.starts_with(&format!("{j}_")));
            if !of_a_joint {
                quantities.insert(quantity.to_string());
            }
        }
    }
    let unlisted: Vec<_> = quantities.iter().filter(|q| !hexadyn::hexapod::joints::RESERVED_NAMES.contains(&q.as_str())).collect();
    assert!(unlisted.is_empty(), "per-leg columns missing from RESERVED_NAMES: {unlisted:?}");
    assert!(quantities.len() >= 14, "{quantities:?}");
}
