//! The ground detection experiment of Section 5.6.3 on the full dynamic model.

use std::path::Path;

use hexadyn::scenario::{run_scenario, Scenario};

fn scenario(text_replacements: &[(&str, &str)]) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/hexadyn/scenarios/ground_detection.toml");
    let mut text = std::fs::read_to_string(&path).unwrap();
    for (from, to) in text_replacements {
        assert!(text.contains(from), "`{from}` not in the scenario");
        text = text.replacen(from, to, 1);
    }
    Scenario::from_str(&text, "ground_detection.toml", Path::new(".")).unwrap()
}

#[test]
#[ignore]
fn explore() {
    let s = scenario(&[("legs = [0, 1, 2, 3, 4, 5]", "legs = [0]"), ("thresholds_n = [40.0, 50.0, 60.0]", "thresholds_n = [40.0]"), ("trials = 4", "trials = 2"), ("duration_s = 606.0", "duration_s = 21.0")]);
    let t0 = std::time::Instant::now();
    let r = run_scenario(&s, |_| {}).unwrap();
    eprintln!("wall {:?}", t0.elapsed());
    let v = |n: &str| r.series.values(n).unwrap().to_vec();
    let (t, f, fn0, stop, q, qref, i, im) = (v("t"), v("F_gnd_est[0]"), v("Fn[0]"), v("gd_stop"), v("q_v[0]"), v("q_v_ref[0]"), v("i_q_v[0]"), v("i_meas_q_v[0]"));
    for k in (0..t.len()).step_by(5) {
        eprintln!("{:6.2} est {:8.2} Fn {:8.2} stop {} q {:.5} ref {:.5} i {:.4} im {:.4}", t[k], f[k], fn0[k], stop[k], q[k], qref[k], i[k], im[k]);
    }
}
