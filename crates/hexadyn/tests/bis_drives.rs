//! The "AMRU5 bis" drive variants of issue 40 (the thesis' conclusion): the low-ratio,
//! backdrivable drives (`robots/amru5_backdrivable.toml`) and the series-elastic transmissions
//! (`robots/amru5_series_elastic.toml`). Their energy account closes on a walk (the springs'
//! energy in it), the unpowered robot of Section 6.2 sinks on the backdrivable drives where
//! AMRU5 stands, and a series spring deflects by its load over its stiffness.

use std::path::{Path, PathBuf};

use hexadyn::description::{Robot, RobotDescription, AMRU5_SERIES_ELASTIC_TOML};
use hexadyn::hexapod::{PantographJoint, StillBody, JOINTS};
use hexadyn::mbs::Data;
use hexadyn::scenario::{run_scenario, Override, Scenario, Summary};
use nalgebra::Vector3;

fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/hexadyn/scenarios")
}

/// A shipped scenario under `overrides`, run to its summary.
fn summary(name: &str, overrides: &[Override]) -> Summary {
    let s = Scenario::from_file_with(scenarios_dir().join(format!("{name}.toml")), overrides).unwrap();
    run_scenario(&s, |_| {}).unwrap().summary
}

/// One 12 s step of the variant's validation walk, integrated to convergence as
/// `robot_scenario.rs`'s AMRU5 check (tolerance 0.01, h_max 1 ms): electrical = Joule + friction
/// + contact + Δ(T + V) + Δ stored within 0.1 %.
fn assert_walk_balance_closes(scenario: &str) {
    let s = summary(scenario, &[Override::new("scenario.duration_s", 12.0), Override::new("integrator.tolerance", 0.01), Override::new("integrator.h_max_s", 1e-3)]);
    let e = s.energy_electrical_j;
    eprintln!("{scenario}: imbalance {:.3e} J of {e:.3} J", s.energy_balance_error_j);
    assert!(e > 10.0, "{scenario}: the step draws energy: {e} J");
    assert!(s.energy_balance_error_relative.abs() < 1e-3 && s.energy_balance_error_j.abs() < 1e-3 * e, "{scenario}: imbalance {} J of {e} J", s.energy_balance_error_j);
}

#[test]
fn backdrivable_walk_energy_account_closes() {
    assert_walk_balance_closes("backdrivable_tripod_1_5cm");
}

/// Section 6.2 on both robots, 3 s: AMRU5's friction holds the unpowered body (LuGre, within
/// 0.02 mm), the backdrivable drives' does not: the body sinks, braked by the back-emf of the
/// closed motor circuits, the potential energy going into friction and Joule losses.
#[test]
fn the_unpowered_backdrivable_robot_sinks_where_amru5_stands() {
    let short = [Override::new("scenario.duration_s", 3.0)];
    let amru5 = summary("unpowered_lugre", &short);
    let bis = summary("backdrivable_unpowered", &short);
    eprintln!("height change: AMRU5 {:.3e} m, backdrivable {:.3e} m", amru5.body_height_change_m, bis.body_height_change_m);
    assert!(amru5.body_height_change_m.abs() < 0.02e-3, "AMRU5 stands: {}", amru5.body_height_change_m);
    assert!(bis.body_height_change_m < -1e-3, "the backdrivable robot sinks: {}", bis.body_height_change_m);
    assert!(bis.potential_change_j < 0.0 && bis.energy_joule_j > 0.0 && bis.energy_friction_j > 0.0);
    assert_eq!(bis.energy_electrical_j, 0.0);
}

#[test]
fn series_elastic_walk_energy_account_closes() {
    assert_walk_balance_closes("series_elastic_tripod_1_5cm");
}

/// The unpowered robot on series-elastic transmissions (3 s, LuGre): the transmissions' friction
/// holds the drives and the vertical nuts' springs carry the robot's weight at their static
/// deflection, load / stiffness. The load is the multibody model's own statics at the final
/// state (the joint forces the legs need on the still body under the recorded foot forces,
/// Eq. 3.37); the body then rests, sunk by the springs' deflection alone. The q_r and q_h
/// springs carry only the ground's hyperstatic tangential reactions (under 2 N at a nut, the
/// feet creeping in the contact's friction law): no static load to compare with.
#[test]
fn series_springs_deflect_by_load_over_stiffness() {
    let s = Scenario::from_file_with(scenarios_dir().join("series_elastic_unpowered.toml"), &[Override::new("scenario.duration_s", 3.0)]).unwrap();
    let r = run_scenario(&s, |_| {}).unwrap();
    let last = |name: &str| *r.series.values(name).unwrap_or_else(|| panic!("no column {name}")).last().unwrap();
    let description = RobotDescription::from_str(AMRU5_SERIES_ELASTIC_TOML, "amru5_series_elastic.toml").unwrap();
    let joints = description.joints.names.clone();
    let q: [f64; JOINTS] = std::array::from_fn(|k| last(&joints.column("", k, "")));
    let feet: [Vector3<f64>; 6] = std::array::from_fn(|f| Vector3::new(last(&format!("Fx[{f}]")), last(&format!("Fy[{f}]")), last(&format!("Fz[{f}]"))));
    let dynamics = Robot::Pantograph(description.clone()).leg_dynamics();
    let body = StillBody { pitch: last("pitch"), roll: last("roll") };
    let load = dynamics.joint_torques(&mut Data::new(&dynamics.model), body, &q, &[0.0; JOINTS], &[0.0; JOINTS], Some(&feet));
    let spring = description.series_spring(PantographJoint::Vertical).unwrap();
    for leg in 0..6 {
        let k = 3 * leg + 1;
        let deflection = last(&joints.column("drive_", k, "")) - q[k];
        let expected = spring.static_deflection(load[k]);
        assert!(load[k] > 250.0, "leg {leg}: the nut carries the body: {} N", load[k]);
        assert!((deflection / expected - 1.0).abs() < 1e-3, "leg {leg}: q_v deflection {deflection:.5e} m vs load / stiffness {expected:.5e} m ({} N / {} N/m)", load[k], spring.stiffness);
    }
    let velocity = last("Z_dot").abs();
    assert!(velocity < 1e-4, "the body rests on the springs: Z' = {velocity} m/s");
}

/// A bad spring in a description is one line naming the file, the field, the value and what is
/// allowed.
#[test]
fn bad_springs_are_one_line_errors() {
    let with = |from: &str, to: &str| {
        assert!(AMRU5_SERIES_ELASTIC_TOML.contains(from), "{from}");
        RobotDescription::from_str(&AMRU5_SERIES_ELASTIC_TOML.replacen(from, to, 1), "sea.toml").unwrap_err().to_string()
    };
    let line = |key: &str| AMRU5_SERIES_ELASTIC_TOML.lines().position(|l| l.starts_with(key)).unwrap() + 1;
    for (from, to, field, allowed) in [
        ("stiffness_n_per_m = 3.86e5", "stiffness_n_per_m = -3.86e5", "series_elastic.q_v.stiffness_n_per_m", "> 0"),
        ("stiffness_nm_per_rad = 1.37e3", "stiffness_nm_per_rad = 0.0", "series_elastic.q_r.stiffness_nm_per_rad", "> 0"),
        ("damping_ns_per_m = 3440.0", "damping_ns_per_m = -1.0", "series_elastic.q_h.damping_ns_per_m", ">= 0"),
        ("damping_ns_per_m = 2530.0", "damping_ns_per_m = nan", "series_elastic.q_v.damping_ns_per_m", "finite"),
    ] {
        let s = with(from, to);
        let key = from.split(' ').next().unwrap();
        let at = if field.contains("q_h") { AMRU5_SERIES_ELASTIC_TOML.lines().enumerate().filter(|(_, l)| l.starts_with(key)).nth(1).unwrap().0 + 1 } else { line(key) };
        assert!(s.starts_with(&format!("sea.toml:{at}: field `{field}`")) && s.contains(allowed) && !s.contains('\n'), "{s}");
    }
    let s = with("[series_elastic.q_h]", "[series_elastic.q_x]");
    assert!(s.starts_with("sea.toml:") && s.contains("series_elastic") && !s.contains('\n'), "{s}");
}

