//! The "AMRU5 bis" drive variants of issue 40 (the thesis' conclusion): the low-ratio,
//! backdrivable drives (`robots/amru5_backdrivable.toml`). Their energy account closes on a
//! walk, and the unpowered robot of Section 6.2 sinks on them where AMRU5 stands.

use std::path::{Path, PathBuf};

use hexadyn::scenario::{run_scenario, Override, Scenario, Summary};

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
