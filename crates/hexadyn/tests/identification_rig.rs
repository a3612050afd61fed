//! The friction identification rig of Chapter 5 as scenario fields: the robot on a stand
//! (`model.stand`, every leg in the air, Section 5.2; either leg mechanism) and the load at the foot
//! (`model.foot_load_kg`, Fig. 5.6), the Table 5.2 velocity staircase and the voltage ramp of
//! Section 5.3.

use std::path::{Path, PathBuf};

use hexadyn::scenario::{run_scenario, Scenario};

fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/hexadyn/scenarios")
}

fn shipped(name: &str, duration: f64) -> Scenario {
    let text = std::fs::read_to_string(scenarios_dir().join(format!("{name}.toml"))).unwrap();
    let text = text.lines().map(|l| if l.starts_with("duration_s =") { format!("duration_s = {duration}") } else { l.to_string() }).collect::<Vec<_>>().join("\n");
    Scenario::from_str(&text, &format!("{name}.toml"), &scenarios_dir()).unwrap()
}

/// On the stand the body does not move while six legs sweep, no foot touches the ground, and
/// the energy balance still closes (the stand does no work on a still body): AMRU5's q_v
/// campaign, and the PhantomX's femur campaign, whose servos take the sawtooth as goals.
#[test]
fn stand_holds_the_body_and_keeps_the_energy_balance() {
    for (name, joint, swept) in [("identification_q_v", "q_v", 0.002), ("phantomx_identification_femur", "femur", 0.05)] {
        let s = shipped(name, 6.0);
        let r = run_scenario(&s, |_| {}).unwrap();
        let ts = &r.series;
        for coordinate in ["X", "Y", "Z", "yaw", "pitch", "roll"] {
            // Up to the Newton tolerance of q'' = 0 on the body rows.
            let v = ts.values(coordinate).unwrap();
            let moved = v.iter().map(|x| (x - v[0]).abs()).fold(0.0, f64::max);
            assert!(moved < 1e-9, "{name}: {coordinate} moved {moved} on the stand");
        }
        for leg in 0..6 {
            let q = ts.values(&format!("{joint}[{leg}]")).unwrap();
            assert!(q.last().unwrap() - q[0] > swept, "{name}: leg {leg} {joint} did not sweep");
            assert!(ts.values(&format!("Fn[{leg}]")).unwrap().iter().all(|f| *f == 0.0), "{name}: foot {leg} touched the ground");
        }
        let balance = ts.values("E_balance").unwrap().last().copied().unwrap().abs();
        let electrical: f64 = (0..6).map(|l| ts.values(&format!("E_el_{joint}[{l}]")).unwrap().last().copied().unwrap().abs()).sum();
        assert!(balance < 1e-3 * electrical, "{name}: energy balance error {balance} J of {electrical} J");
    }
}

/// A 10 kg load at the foot is an upward 98.1 N force on it (Fz, the leg load of Eq. 5.12);
/// a q_v joint held still then needs about 6 x 98.1 N more (z_foot ~ -6 q_v, Section 5.3:
/// "10 kg x 9.81 m/s^2 x 6 (pantograph amplification) = 588.6 N").
#[test]
fn foot_load_pushes_up_through_the_pantograph() {
    let text = |load: f64| {
        format!(
            "[scenario]\nname = \"rig\"\nduration_s = 3.0\n[model]\nfriction = \"none\"\nstand = true\nfoot_load_kg = [{load}, {load}, {load}, {load}, {load}, {load}]\n[initial]\nq_v_m = 0.055\nsettle = false\nbody_height_offset_m = 0.3\n"
        )
    };
    let held = |load: f64| {
        let s = Scenario::from_str(&text(load), "rig.toml", Path::new(".")).unwrap();
        let r = run_scenario(&s, |_| {}).unwrap();
        let fz = *r.series.values("Fz[2]").unwrap().last().unwrap();
        let tau = *r.series.values("tau_m_q_v[2]").unwrap().last().unwrap();
        (fz, tau)
    };
    let (fz0, tau0) = held(0.0);
    let (fz10, tau10) = held(10.0);
    assert_eq!(fz0, 0.0);
    assert!((fz10 - 98.1).abs() < 1e-9, "Fz = {fz10}");
    // The load pushes the foot up, i.e. q_v down: the motor must push q_v up by ~6 F.
    let ratio = (tau10 - tau0) / 98.1;
    assert!((ratio - 6.0).abs() < 0.1, "motor torque change {} N = {ratio} x the load", tau10 - tau0);
}

#[test]
fn rig_fields_are_checked() {
    let bad = |text: &str| Scenario::from_str(text, "bad.toml", Path::new(".")).expect_err("must be rejected").to_string();
    let base = "[scenario]\nname = \"rig\"\nduration_s = 1.0\n[model]\n";
    let e = bad(&format!("{base}foot_load_kg = [10.0, 10.0]\n"));
    assert!(e.starts_with("bad.toml:") && e.contains("model.foot_load_kg") && e.contains("six masses"), "{e}");
    let e = bad(&format!("{base}foot_load_kg = [10.0, 10.0, -1.0, 0.0, 0.0, 0.0]\n"));
    assert!(e.contains("model.foot_load_kg[2]"), "{e}");
    let motion = "[control]\nmode = \"pi\"\n[[control.motion]]\nleg = 0\njoint = \"q_v\"\n";
    let e = bad(&format!("{base}[initial]\nq_v_m = 0.04\n{motion}kind = \"sawtooth\"\nmin = 0.04\nmax = 0.05\nspeed = 0.001\nspeed_step = 0.001\n"));
    assert!(e.contains("control.motion[0].speed_max") && e.contains("missing"), "{e}");
    let e = bad(&format!("{base}{motion}kind = \"voltage_ramp\"\nrate_v_per_s = 0.0\n"));
    assert!(e.contains("control.motion[0].rate_v_per_s"), "{e}");
}

/// The feet work against the stand's loads as against the ground: with 10 kg at each foot
/// (Sections 5.3-5.4) the energy balance closes, whichever way the loaded joints move. Before
/// the loads' work was in the contact work, the breakaway campaigns' balance was off by 100 %
/// and 17 % of the energy flows (the loads' −63 J and 13 J missing).
#[test]
fn the_energy_balance_counts_the_work_of_the_foot_loads() {
    for name in ["identification_breakaway_minus", "identification_breakaway_plus", "identification_loaded_q_h"] {
        let s = shipped(name, 20.0);
        let r = run_scenario(&s, |_| {}).unwrap();
        let relative = r.summary.energy_balance_error_relative;
        let contact = *r.series.values("E_contact").unwrap().last().unwrap();
        println!("{name}: balance {relative:.2e} of the flows, work against the loads {contact:.2} J");
        // The vertical joints' campaigns move the loaded feet up and down; q_h's, sideways.
        let moved_up_or_down = name.contains("breakaway");
        assert!(relative.abs() < 1e-3 && (!moved_up_or_down || contact.abs() > 1.0), "{name}: balance {relative}, contact work {contact} J");
    }
}
