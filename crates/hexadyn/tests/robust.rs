//! Robust under abuse (issue 17): validation that stays cheap whatever the duration, ranges of
//! the numerical settings, errors that name the table or key, bounded input files, and the
//! chunked run that streams a long series.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use hexadyn::control::gait::heading::{Constant, Heading, HeadingSource, Segments, Series, Spline, SPLINE_SAMPLES};
use hexadyn::robot::recorder::TimeSeries;
use hexadyn::scenario::{run_scenario_chunked, run_scenario_until, Record, Scenario, ScenarioError};

fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/hexadyn/scenarios")
}

fn with(name: &str, from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(scenarios_dir().join(format!("{name}.toml"))).unwrap();
    assert!(text.contains(from), "`{from}` not in {name}.toml");
    text.replacen(from, to, 1)
}

fn parse(text: &str) -> Result<Scenario, ScenarioError> {
    Scenario::from_str(text, "bad.toml", &scenarios_dir())
}

fn rejected(text: &str, field: &str) -> String {
    let e = parse(text).expect_err("must be rejected");
    let s = e.to_string();
    assert_eq!(e.field(), Some(field), "{s}");
    assert!(s.starts_with("bad.toml") && !s.contains('\n'), "{s}");
    s
}

/// The stride check looks at a number of instants independent of the duration: a walk of
/// 1e9 s is validated (the check used to loop over its 1e11 control periods).
#[test]
fn validation_does_not_scale_with_the_duration() {
    for name in ["validation_tripod_1_5cm", "path_back_and_forth", "path_straight_lines", "path_spline"] {
        let text = std::fs::read_to_string(scenarios_dir().join(format!("{name}.toml"))).unwrap();
        let line = text.lines().find(|l| l.starts_with("duration_s")).unwrap();
        let s = parse(&text.replacen(line, "duration_s = 1e9", 1)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(s.duration, 1e9);
    }
}

/// The instants of the stride check hold the largest heading of the run: a piecewise-linear
/// heading's extremes are at its knots; the spline is sampled at most SPLINE_SAMPLES times per
/// knot interval. Checked against every control instant of a short run.
#[test]
fn stride_check_instants_hold_the_largest_heading() {
    let dt = 0.01;
    let norm = |h: Heading| h.velocity.norm() + 0.3 * h.yaw_rate.abs();
    let series = Series { t: vec![1.234, 5.0, 7.777], headings: vec![Heading::new(0.01, 0.0, 0.0), Heading::new(0.0, 0.03, 0.1), Heading::new(-0.02, 0.0, 0.0)] };
    let sources: Vec<Box<dyn HeadingSource>> = vec![
        Box::new(Constant(Heading::new(0.01, 0.0, 0.0))),
        Box::new(Segments::back_and_forth()),
        Box::new(Segments::square(1.0, 0.02)),
        Box::new(series),
        Box::new(Spline::section_7_5_3()),
    ];
    for mut source in sources {
        let end = 220.0;
        let instants = source.extreme_times(end, dt);
        assert!(instants.len() <= 8 * SPLINE_SAMPLES, "{} instants", instants.len());
        assert!(instants.iter().all(|&t| (0.0..=end + 1e-9).contains(&t)));
        let sampled = instants.iter().map(|&t| norm(source.heading(t))).fold(0.0, f64::max);
        let every = (0..=(end / dt).round() as usize).map(|k| norm(source.heading(k as f64 * dt))).fold(0.0, f64::max);
        // The spline's samples are 3 control periods apart at most: its speed (< 2 cm/s, slowly
        // varying over 50 s intervals) changes by far less than 0.1 % between them.
        assert!(sampled >= every * (1.0 - 1e-3), "{sampled} < {every}");
    }
}

#[test]
fn numerical_settings_have_documented_ranges() {
    let s = rejected(&with("stand_six_legs", "[model]", "[integrator]\ntolerance = 1e6\n[model]"), "integrator.tolerance");
    assert!(s.contains("1000000") && s.contains("[1e-4, 10]"), "{s}");
    let s = rejected(&with("stand_six_legs", "[model]", "[integrator]\nh_max_s = 1e-9\n[model]"), "integrator.h_max_s");
    assert!(s.contains("0.00001"), "{s}");
    let s = rejected(&with("stand_six_legs", "[model]", "[model]\nsupply_voltage_v = 1e6"), "model.supply_voltage_v");
    assert!(s.contains("1000000") && s.contains(", 30] V") && s.contains("nominal voltage"), "{s}");
    let s = rejected(&with("stand_six_legs", "[model]", "[model]\nmu = 1e9"), "model.mu");
    assert!(s.contains("[0, 5]"), "{s}");
    let s = rejected(&with("leg_sine", "frequency_hz = 0.25", "frequency_hz = 1e9"), "control.motion[0].frequency_hz");
    assert!(s.contains("Nyquist") && s.contains("50"), "{s}");
    // The shipped values and the bounds themselves are accepted.
    for (from, to) in [("[model]", "[integrator]\ntolerance = 10.0\nh_max_s = 1e-5\n[model]"), ("[model]", "[model]\nsupply_voltage_v = 30.0\nmu = 5.0\nk_gnd = 1e9")] {
        parse(&with("stand_six_legs", from, to)).unwrap();
    }
}

#[test]
fn a_misspelt_table_is_an_unknown_table() {
    let s = rejected(&with("validation_tripod_1_5cm", "[gait]\n", "[giat]\n"), "giat");
    assert!(s.contains("unknown table") && s.contains("gait") && s.contains("scenario"), "{s}");
    let s = rejected(&with("stand_six_legs", "[control]", "[contorl]"), "contorl");
    assert!(s.contains("unknown table"), "{s}");
}

/// `ground_detection.stop_on` is one of its two words; anything else is named with them.
#[test]
fn an_unknown_stop_of_the_ground_experiment_is_named() {
    let s = rejected(&with("ground_detection", "period_s = 8.0", "period_s = 8.0\nstop_on = \"contact\""), "ground_detection.stop_on");
    assert!(s.contains("contact") && s.contains("estimate") && s.contains("foot_force"), "{s}");
    assert!(parse(&with("ground_detection", "period_s = 8.0", "period_s = 8.0\nstop_on = \"foot_force\"")).is_ok());
}

#[test]
fn a_duplicate_key_is_named() {
    for (text, key) in [(with("stand_six_legs", "duration_s = 10.0", "duration_s = 10.0\nduration_s = 1.0"), "duration_s"), (with("stand_six_legs", "[control]", "[model]\n[control]"), "model")] {
        let s = parse(&text).unwrap_err().to_string();
        assert!(s.contains(&format!("duplicate key `{key}`")) && !s.contains('\n'), "{s}");
    }
}

/// A named pipe named as any input file is refused at once, saying what it is (opening one for
/// reading used to wait for a writer, for ever and deaf to Ctrl-C). The reads run on a thread
/// so that a hang fails the test instead of blocking it.
#[test]
fn named_pipes_are_refused_without_waiting() {
    let dir = std::env::temp_dir().join(format!("hexadyn-fifo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("pipe");
    let name = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o600) }, 0, "mkfifo");
    let shown = fifo.display().to_string();
    let cases = [
        ("scenario.robot", with("stand_six_legs", "robot = \"amru5\"", &format!("robot = \"{shown}\""))),
        ("terrain.file", with("free_gait_rough_spline", "file = \"terrains/rough_ground.ply\"", &format!("file = \"{shown}\""))),
        ("terrain.file", with("stand_six_legs", "[control]", &format!("[terrain]\nkind = \"heightfield\"\nfile = \"{shown}\"\nspacing_m = 0.1\n\n[control]"))),
        ("gait.heading.file", with("validation_tripod_1_5cm", "kind = \"constant\"\nvx_m_s = 0.015\nvy_m_s = 0.0\nomega_z_rad_s = 0.0", &format!("kind = \"csv\"\nfile = \"{shown}\"\n"))),
    ];
    let (sender, receiver) = std::sync::mpsc::channel();
    let path = fifo.clone();
    std::thread::spawn(move || {
        let mut messages: Vec<String> = cases.iter().map(|(field, text)| rejected(text, field)).collect();
        messages.push(Scenario::from_file(&path).unwrap_err().to_string());
        messages.push(hexadyn::link::LinkConfig::from_file(&path).unwrap_err().to_string());
        sender.send(messages).unwrap();
    });
    let messages = receiver.recv_timeout(std::time::Duration::from_secs(60)).expect("reading a named pipe blocked");
    for m in &messages {
        assert!(m.contains(&format!("{shown}: ")) || m.contains(&format!("\"{shown}\"")), "{m}");
        assert!(m.contains("a named pipe (FIFO), not a regular file; allowed: a regular file of at most "), "{m}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn input_files_are_bounded_regular_files() {
    // A device: refused at once instead of read until memory runs out.
    let s = rejected(&with("stand_six_legs", "robot = \"amru5\"", "robot = \"/dev/zero\""), "scenario.robot");
    assert!(s.contains("not a regular file"), "{s}");
    let e = Scenario::from_file("/dev/zero").unwrap_err().to_string();
    assert!(e.contains("not a regular file"), "{e}");
    // The terrain files too: a PLY mesh and a CSV of heights.
    let s = rejected(&with("free_gait_rough_spline", "file = \"terrains/rough_ground.ply\"", "file = \"/dev/zero\""), "terrain.file");
    assert!(s.contains("not a regular file"), "{s}");
    let heights = with("stand_six_legs", "[control]", "[terrain]\nkind = \"heightfield\"\nfile = \"/dev/zero\"\nspacing_m = 0.1\n\n[control]");
    let s = rejected(&heights, "terrain.file");
    assert!(s.contains("not a regular file"), "{s}");
    let dir = std::env::temp_dir().join(format!("hexadyn-robust-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let e = Scenario::from_file(&dir).unwrap_err().to_string();
    assert!(e.contains("a directory"), "{e}");
    let latin1 = dir.join("latin1.toml");
    std::fs::write(&latin1, b"[scenario]\nname = \"caf\xe9\"\n").unwrap();
    let e = Scenario::from_file(&latin1).unwrap_err().to_string();
    assert!(e.contains("not UTF-8") && e.contains("offset 22"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A byte order mark is accepted (and kept in the text the results store).
#[test]
fn a_byte_order_mark_is_accepted() {
    let text = format!("\u{feff}{}", with("stand_six_legs", "duration_s = 10.0", "duration_s = 0.05"));
    let s = parse(&text).unwrap();
    assert!(!Scenario::model_flags(&s.text, "stored").unwrap().inductance);
}

/// The chunked run hands out exactly the rows of the whole run: the first row alone, then
/// chunks of the given size, bit-identical to the recorded series.
#[test]
fn chunks_are_the_series() {
    let s = parse(&with("leg_sine", "duration_s = ", "duration_s = 0.25 #")).unwrap();
    let whole = run_scenario_until(&s, Record::TimeSeries, |_| ControlFlow::Continue(())).unwrap();
    let mut chunks: Vec<TimeSeries> = Vec::new();
    let summary = run_scenario_chunked(&s, 7, |c| {
        chunks.push(c);
        ControlFlow::Continue(())
    }, |_| ControlFlow::Continue(()))
    .unwrap();
    let lengths: Vec<usize> = chunks.iter().map(TimeSeries::len).collect();
    assert_eq!(lengths[0], 1);
    assert!(lengths[1..lengths.len() - 1].iter().all(|&n| n == 7), "{lengths:?}");
    assert_eq!(lengths.iter().sum::<usize>(), whole.series.len());
    for column in &whole.series.columns {
        let joined: Vec<f64> = chunks.iter().flat_map(|c| c.values(&column.name).unwrap().to_vec()).collect();
        assert_eq!(joined, column.values, "{}", column.name);
    }
    assert_eq!(summary.energy_electrical_j, whole.summary.energy_electrical_j);
    // A sink that breaks stops the run.
    let e = run_scenario_chunked(&s, 7, |_| ControlFlow::Break(()), |_| ControlFlow::Continue(())).unwrap_err();
    assert!(matches!(e, ScenarioError::Stopped { .. }), "{e}");
}
