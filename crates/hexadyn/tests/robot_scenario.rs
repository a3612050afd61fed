//! Scenario files: validation errors that name the file, the field, the value and what is
//! allowed; the shipped scenarios; deterministic runs recorded into columns with units.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use hexadyn::robot::scenario::{run_scenario, run_scenario_until, ControlMode, Scenario, ScenarioError};
use hexadyn::robot::{Joint, AMRU5_TOML};

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

const ALL: [&str; 8] = ["stand_six_legs", "stand_three_legs", "unpowered_none", "unpowered_dry_viscous", "unpowered_lugre", "leg_ramp", "leg_sine", "leg_sawtooth"];

#[test]
fn shipped_scenarios_are_valid() {
    let mut found: Vec<String> = std::fs::read_dir(scenarios_dir())
        .unwrap()
        .filter_map(|e| e.ok()?.path().file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    found.sort();
    let mut expected: Vec<String> = ALL.iter().map(|s| s.to_string()).collect();
    expected.sort();
    assert_eq!(found, expected);
    for name in ALL {
        let s = Scenario::from_file(scenarios_dir().join(format!("{name}.toml"))).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.name, name);
        assert!(s.text.lines().next().unwrap().starts_with('#'), "{name}: comment header");
        assert!(s.text.contains("Section"), "{name}: cites the thesis");
    }
    let s = Scenario::from_file(scenarios_dir().join("leg_ramp.toml")).unwrap();
    assert_eq!(s.control, ControlMode::Pi);
    assert_eq!(s.motions.len(), 1);
    assert_eq!((s.motions[0].leg, s.motions[0].joint), (1, Joint::Vertical));
    assert_eq!(s.initial.lifted_legs, vec![1, 2, 5]);
    assert_eq!(s.model.supply_voltage, 15.0);
    // 0.8 x the no-load speed (Section 4.4.3).
    let d = &s.robot;
    let rate = 0.8 * d.motor.no_load_speed_rad_per_s() / d.reduction(Joint::Vertical);
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
    assert!(s.contains("-1000000") && s.contains("> 0"), "{s}");

    let s = field_error(&with("stand_six_legs", "[model]", "[integrator]\nh_max_s = 0.1\n[model]"), "integrator.h_max_s");
    assert!(s.contains("0.1") && s.contains("(0, 0.01]"), "{s}");

    let s = field_error(&with("unpowered_none", "friction = \"none\"", "friction = \"none\"\nload_dependence = true"), "model.load_dependence");
    assert!(s.contains("friction"), "{s}");
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
    assert!(sm.energy_electrical_j > 0.0 && sm.energy_balance_error_relative.abs() < 0.01, "{sm:?}");
    let names: Vec<&str> = sm.entries().iter().map(|(n, _)| *n).collect();
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
    let e = run_scenario_until(&s, |t| if t >= 0.095 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }).unwrap_err();
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
