//! Scenarios on terrain: the `[terrain]` table's validation, the flat default kept bit for bit,
//! a mesh of the flat ground walking like the flat ground, the shipped terrain walks.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use hexadyn::physics::terrain::{generate, ply};
use hexadyn::scenario::{run_scenario, run_scenario_until, Record, Scenario, ScenarioError, SummaryValue};

fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/hexadyn/scenarios")
}

fn shipped(name: &str) -> String {
    std::fs::read_to_string(scenarios_dir().join(format!("{name}.toml"))).unwrap()
}

fn parse_in(text: &str, dir: &Path) -> Result<Scenario, ScenarioError> {
    Scenario::from_str(text, "bad.toml", dir)
}

/// A 12 s tripod walk (one cycle) of the validation case with `terrain` appended.
fn short_walk(terrain: &str) -> String {
    shipped("validation_tripod_1_5cm").replace("duration_s = 60.0", "duration_s = 12.0") + terrain
}

fn number(s: &hexadyn::scenario::Summary, name: &str) -> f64 {
    match s.entries().into_iter().find(|(n, _)| n == name).map(|(_, v)| v) {
        Some(SummaryValue::Number(x)) => x,
        v => panic!("{name}: {v:?}"),
    }
}

fn field_error(text: &str, dir: &Path, field: &str) -> String {
    let e = parse_in(text, dir).expect_err("must be rejected");
    let s = e.to_string();
    assert!(s.starts_with("bad.toml:"), "{s}");
    assert_eq!(e.field(), Some(field), "{s}");
    assert!(!s.contains('\n'), "one line: {s}");
    s
}

#[test]
fn terrain_errors_name_the_field() {
    let dir = scenarios_dir();
    let s = field_error(&short_walk("\n[terrain]\nkind = \"lava\"\n"), &dir, "terrain.kind");
    assert!(s.contains("`flat`") && s.contains("`mesh`"), "{s}");
    let s = field_error(&short_walk("\n[terrain]\nkind = \"flat\"\nrise_m = 0.1\n"), &dir, "terrain.rise_m");
    assert!(s.contains("not a field of kind = \"flat\"") && s.contains("height_m"), "{s}");
    let s = field_error(&short_walk("\n[terrain]\nkind = \"step\"\nedge_m = 1.0\n"), &dir, "terrain.rise_m");
    assert!(s.contains("missing"), "{s}");
    let s = field_error(&short_walk("\n[terrain]\nkind = \"step\"\nrise_m = -0.1\nedge_m = 1.0\n"), &dir, "terrain.rise_m");
    assert!(s.contains("-0.1"), "{s}");
    let s = field_error(&short_walk("\n[terrain]\nkind = \"mesh\"\nfile = \"terrains/none.ply\"\n"), &dir, "terrain.file");
    assert!(s.contains("none.ply") && s.contains("allowed: a PLY file"), "{s}");
    let s = field_error(&short_walk("\n[terrain]\nkind = \"slope\"\nangle_deg = 75.0\n"), &dir, "terrain.angle_deg");
    assert!(s.contains("(-60, 60)"), "{s}");
    let s = field_error(&short_walk("").replacen("friction = \"lugre\"\n", "friction = \"lugre\"\nfoot_radius_m = -0.01\n", 1), &dir, "model.foot_radius_m");
    assert!(s.contains("[0, 0.05]"), "{s}");

    // A malformed PLY file: its name and the element at fault in the scenario's error.
    let tmp = std::env::temp_dir().join(format!("hexadyn-terrain-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n";
    std::fs::write(tmp.join("broken.ply"), text).unwrap();
    let s = field_error(&short_walk("\n[terrain]\nkind = \"mesh\"\nfile = \"broken.ply\"\n"), &tmp, "terrain.file");
    assert!(s.contains("broken.ply: face 0: [0, 1, 9]: vertex index 9 out of range"), "{s}");
    std::fs::write(tmp.join("heights.csv"), "0, 0, 0\n0, x, 0\n").unwrap();
    let s = field_error(&short_walk("\n[terrain]\nkind = \"heightfield\"\nfile = \"heights.csv\"\nspacing_m = 0.5\n"), &tmp, "terrain.file");
    assert!(s.contains("heights.csv:2: column 2: `x` is not a number"), "{s}");
    std::fs::remove_dir_all(&tmp).unwrap();
}

/// Without a `[terrain]` table the ground is flat at z = 0, and `kind = "flat"` is the same
/// ground: the same walk to the last bit.
#[test]
fn flat_terrain_table_walks_bit_for_bit_like_the_default() {
    let run = |text: &str| run_scenario(&parse_in(text, &scenarios_dir()).unwrap(), |_| {}).unwrap();
    let (a, b) = (run(&short_walk("")), run(&short_walk("\n[terrain]\nkind = \"flat\"\nheight_m = 0.0\n")));
    assert_eq!(a.series.columns.len(), b.series.columns.len());
    for (x, y) in a.series.columns.iter().zip(&b.series.columns) {
        assert!(x.values.iter().zip(&y.values).all(|(u, v)| u.to_bits() == v.to_bits()), "{}", x.name);
    }
}

/// The flat ground as a PLY mesh of 2 x 40 x 40 triangles walks like the analytic flat ground:
/// the contact forces are the same (to rounding), so is the walk.
#[test]
fn a_mesh_of_the_flat_ground_walks_like_the_flat_ground() {
    let tmp = std::env::temp_dir().join(format!("hexadyn-flat-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let lines: Vec<f64> = (0..=40).map(|k| -2.0 + 0.1 * k as f64).collect();
    let tiles = generate::terraces(&lines, &lines, |_, _| 0.0);
    let mut bytes = Vec::new();
    ply::write(&tiles, ply::PlyFormat { encoding: ply::Encoding::BinaryBigEndian, double: true }, &mut bytes).unwrap();
    std::fs::write(tmp.join("flat.ply"), bytes).unwrap();
    let run = |text: &str, dir: &Path| run_scenario_until(&parse_in(text, dir).unwrap(), Record::SummaryOnly, |_| ControlFlow::Continue(())).unwrap().summary;
    let flat = run(&short_walk(""), &scenarios_dir());
    let mesh = run(&short_walk("\n[terrain]\nkind = \"mesh\"\nfile = \"flat.ply\"\n"), &tmp);
    std::fs::remove_dir_all(&tmp).unwrap();
    for name in ["distance_walked_m", "energy_electrical_j", "max_penetration_m", "body_height_change_m"] {
        let (a, b) = (number(&flat, name), number(&mesh, name));
        assert!((a - b).abs() <= 1e-6 * (1.0 + a.abs()), "{name}: flat {a} vs mesh {b}");
    }
}

/// The shipped terrain walks: onto the 3 cm step the body rises with the feet that climbed,
/// over the rough ground it keeps walking; no foot sinks more than the Hertz contact allows
/// under the whole robot (Table 3.3: 34 kg on one foot, about 4.8 mm).
#[test]
fn shipped_terrain_walks() {
    for (name, rise) in [("tripod_low_step", Some(0.03)), ("tripod_rough_ground", None)] {
        let s = Scenario::from_file(scenarios_dir().join(format!("{name}.toml"))).unwrap();
        let sm = run_scenario_until(&s, Record::SummaryOnly, |_| ControlFlow::Continue(())).unwrap().summary;
        let walked = number(&sm, "distance_walked_m");
        assert!(walked > 0.8, "{name}: walked {walked} m of 0.9 m");
        assert!(number(&sm, "max_penetration_m") < 4.8e-3, "{name}");
        if let Some(rise) = rise {
            // At the end the front and middle feet are on the step, the rear ones not yet.
            let dz = number(&sm, "body_height_change_m");
            assert!(dz > 0.5 * rise && dz < rise + 5e-3, "{name}: body rose {dz} m");
        }
    }
}

/// A mesh must cover the ground under the robot (issue 37): one that does not cover the start
/// is refused before the settling, naming the foot, where it stands and the mesh file; a walk
/// that leaves the mesh records the first foot beyond it and when (`hexadyn.health` warns).
#[test]
fn a_mesh_that_does_not_cover_the_feet_is_named() {
    let tmp = std::env::temp_dir().join(format!("hexadyn-partial-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let write = |name: &str, xs: &[f64]| {
        let ys: Vec<f64> = (0..=40).map(|k| -2.0 + 0.1 * k as f64).collect();
        let mut bytes = Vec::new();
        ply::write(&generate::terraces(xs, &ys, |_, _| 0.0), ply::PlyFormat { encoding: ply::Encoding::Ascii, double: false }, &mut bytes).unwrap();
        std::fs::write(tmp.join(name), bytes).unwrap();
    };
    // Ahead of the robot only.
    write("ahead.ply", &[1.0, 1.5, 2.0]);
    let e = parse_in(&short_walk("\n[terrain]\nkind = \"mesh\"\nfile = \"ahead.ply\"\n"), &tmp).and_then(|s| run_scenario(&s, |_| {}).map(|_| ())).expect_err("refused");
    let message = e.to_string();
    assert!(matches!(e, ScenarioError::OffTerrain { .. }) && message.contains("ahead.ply") && message.contains("beyond the border of the terrain mesh") && !message.contains('\n'), "{message}");
    // Up to 2 cm ahead of the front feet: the 12 s walk at 1.5 cm/s leaves it.
    let flat = run_scenario(&parse_in(&short_walk(""), &scenarios_dir()).unwrap(), |_| {}).unwrap();
    let front = (0..6).map(|f| flat.series.column(&format!("foot_x[{f}]")).unwrap().values[0]).fold(f64::NEG_INFINITY, f64::max);
    write("short.ply", &[-2.0, -1.0, 0.0, front + 0.02]);
    let r = run_scenario(&parse_in(&short_walk("\n[terrain]\nkind = \"mesh\"\nfile = \"short.ply\"\n"), &tmp).unwrap(), |_| {}).unwrap();
    std::fs::remove_dir_all(&tmp).unwrap();
    let t = number(&r.summary, "foot_left_terrain_t_s");
    assert!(t > 0.0 && t < 12.0, "left at {t} s");
    assert!(!flat.summary.entries().iter().any(|(n, _)| n == "foot_left_terrain_t_s"));
}
