//! The robot description file as a user meets it: loading `robots/amru5.toml` from disk and
//! the error messages for each kind of bad input (file, field path, value, allowed range).

mod robot {
    use hexadyn::description::{DescriptionError, RobotDescription, AMRU5_TOML};
    use hexadyn::hexapod::PantographJoint;
    use std::path::PathBuf;

    fn shipped_path() -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/amru5.toml")
    }

    /// Writes `text` to a fresh file in the temp dir and loads it.
    fn load_temp(name: &str, text: &str) -> (PathBuf, Result<RobotDescription, DescriptionError>) {
        let dir = std::env::temp_dir().join(format!("hexadyn-robotdesc-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        let r = RobotDescription::from_file(&path);
        let _ = std::fs::remove_file(&path);
        (path, r)
    }

    fn edited(from: &str, to: &str) -> String {
        assert!(AMRU5_TOML.contains(from), "pattern `{from}` not in the shipped file");
        AMRU5_TOML.replacen(from, to, 1)
    }

    /// Loads an edited copy and checks that the message names file, field, value, allowed.
    fn rejected(name: &str, from: &str, to: &str, field: &str, value: &str, allowed: &str) -> String {
        let (path, r) = load_temp(name, &edited(from, to));
        let e = r.expect_err("bad input must be rejected");
        let msg = e.to_string();
        eprintln!("{msg}");
        assert_eq!(e.file(), path.display().to_string());
        assert!(msg.contains(name), "file name missing: {msg}");
        assert_eq!(e.field(), Some(field), "{msg}");
        assert!(msg.contains(&format!("`{field}`")), "field missing: {msg}");
        assert!(msg.contains(value), "value `{value}` missing: {msg}");
        assert!(msg.contains(allowed), "allowed `{allowed}` missing: {msg}");
        msg
    }

    #[test]
    fn robot_shipped_file_loads_from_disk() {
        let r = RobotDescription::from_file(shipped_path()).expect("shipped file loads");
        assert_eq!(r.legs.len(), 6);
        // the embedded copy is the same file
        let mut embedded = RobotDescription::amru5();
        embedded.origin = r.origin.clone();
        assert_eq!(r, embedded);
    }

    #[test]
    fn robot_spot_checks_against_thesis_tables() {
        let r = RobotDescription::amru5();
        // Table 2.1 / B.1
        let p = &r.geometry.pantograph;
        assert_eq!((p.l_0_m, p.l_1_m, p.l_2_m, p.l_3_m, p.c_m), (0.28, 0.07, 0.24, 0.492, 0.04));
        assert_eq!(r.geometry.body.r_rot_m, 0.175);
        // Table B.2: m_0 + 6 (m_1 + m_2 + m_3 + m_4 + m_5 + 3 m_rot) = 8.215 + 6 x 4.372
        assert!((r.leg_mass_kg() - 4.372).abs() < 1e-9);
        assert!((r.total_mass_kg() - 34.447).abs() < 1e-9, "{}", r.total_mass_kg());
        // Table 3.1, 3.3, 3.4, 4.1
        assert_eq!(r.reductions.n_r, 1682.0);
        assert_eq!(
            (r.ground.p_k, r.ground.p_d, r.ground.k_gnd_n_per_m_pk, r.ground.mu),
            (1.5, 0.5, 1e6, 0.3)
        );
        assert_eq!(r.motor.torque_constant_nm_per_a, 19.4e-3);
        assert_eq!(r.controller.q_h.k_v_per_m, 16854.0);
        assert_eq!(r.controller.period_s, 0.01);
        // Table 5.3-5.5 through the SI accessor
        let f = r.friction(2, PantographJoint::Horizontal);
        assert_eq!((f.tau_f_d_plus, f.tau_f_d_minus, f.f_v_minus), (329.1, -481.0, 0.0));
        assert_eq!(f.f_v_minus_measured, -4556.3);
        assert_eq!(f.load_dependence.unwrap().a_2_plus, 6.84);
        let f = r.friction(4, PantographJoint::Vertical);
        assert_eq!((f.tau_f_s_plus, f.tau_f_s_minus), (457.2, -690.7));
        // Table 6.7 with the 3.56 fix
        let (_, _, minus, _) = r.monte_carlo_distribution(PantographJoint::Rotation);
        assert_eq!((minus.mu, minus.sigma), (-8.97, 3.56));
    }

    #[test]
    fn robot_rejects_negative_mass() {
        rejected(
            "neg_mass.toml",
            "mass_kg = 2.895",
            "mass_kg = -2.895",
            "inertia.chassis.mass_kg",
            "-2.895",
            "> 0",
        );
    }

    #[test]
    fn robot_rejects_nan() {
        rejected("nan.toml", "mu = 0.3 ", "mu = nan ", "ground.mu", "NaN", "finite number > 0");
    }

    #[test]
    fn robot_rejects_missing_field() {
        rejected(
            "missing.toml",
            "torque_constant_nm_per_a = 19.4e-3",
            "",
            "motor.torque_constant_nm_per_a",
            "<missing>",
            "required",
        );
    }

    #[test]
    fn robot_rejects_unknown_field() {
        rejected(
            "unknown.toml",
            "p_k = 1.5 ",
            "p_k = 1.5\np_q = 2.5 ",
            "ground.p_q",
            "2.5",
            "expected one of",
        );
    }

    #[test]
    fn robot_rejects_min_above_max() {
        rejected(
            "range.toml",
            "q_r_deg = { min = -25.0, max = 25.0 }",
            "q_r_deg = { min = 30.0, max = 25.0 }",
            "joint_ranges.q_r_deg.min",
            "30",
            "min < max (max = 25)",
        );
    }

    #[test]
    fn robot_rejects_wrong_type() {
        rejected(
            "type.toml",
            "encoder_impulses_per_rev = 500",
            "encoder_impulses_per_rev = 500.5",
            "controller.encoder_impulses_per_rev",
            "500.5",
            "expected",
        );
        rejected(
            "type2.toml",
            "t_i_s = 0.5",
            "t_i_s = [0.5]",
            "controller.q_r.t_i_s",
            "[0.5]",
            "expected f64",
        );
    }

    #[test]
    fn robot_rejects_bad_inertia_and_legs() {
        rejected(
            "triangle.toml",
            "i_zz_kg_m2 = 0.001147",
            "i_zz_kg_m2 = 0.000047",
            // the largest moment is the one that breaks the inequality
            "inertia.pantograph_upper.i_yy_kg_m2",
            "0.001142",
            "<= 0.000047 + 0.000019",
        );
        rejected("leg_id.toml", "id = 4", "id = 2", "legs[4].id", "2", "each id 0..5 exactly once");
        rejected("mu_zero.toml", "mu = 0.3 ", "mu = 0.0 ", "ground.mu", "= 0:", "> 0");
    }

    #[test]
    fn robot_missing_file_is_named() {
        let e = RobotDescription::from_file("/nonexistent/robot.toml").unwrap_err();
        assert!(matches!(e, DescriptionError::Io { .. }));
        assert!(e.to_string().contains("/nonexistent/robot.toml"), "{e}");
    }
}
