//! Unit tests of the description: the shipped file against the thesis tables, the SI views,
//! and the errors of bad files.

use std::f64::consts::PI;

use super::*;
use crate::hexapod::PantographJoint;
use approx::assert_relative_eq;

fn amru5() -> RobotDescription {
    RobotDescription::from_str(AMRU5_TOML, "amru5.toml").expect("shipped description loads")
}

#[test]
fn shipped_file_loads_and_is_sorted() {
    let r = amru5();
    assert_eq!(r.name, "AMRU5");
    assert_eq!(r.origin, "amru5.toml");
    let ids: Vec<usize> = r.legs.iter().map(|l| l.id).collect();
    assert_eq!(ids, vec![0, 1, 2, 3, 4, 5]);
    assert_eq!(RobotDescription::amru5().origin, "robots/amru5.toml");
}

#[test]
fn leg_angles_follow_notes() {
    let r = amru5();
    let deg = [30.0, -30.0, 90.0, -90.0, 150.0, -150.0];
    for (leg, d) in deg.iter().enumerate() {
        assert_relative_eq!(r.leg_angle_rad(leg), d * PI / 180.0, epsilon = 1e-12);
        // even legs on the left (y > 0), odd on the right
        let y = r.leg_origin_m(leg)[1];
        assert_eq!(y > 0.0, leg % 2 == 0, "leg {leg}");
    }
    assert_relative_eq!(r.leg_origin_m(2)[1], 0.175, epsilon = 1e-12);
}

#[test]
fn masses_of_table_b2() {
    let r = amru5();
    // m_leg = 2.895 + 0.157 + 0.055 + 0.143 + 0.564 + 3 x 0.186 = 4.372 (Table B.2)
    assert_relative_eq!(r.leg_mass_kg(), 4.372, epsilon = 1e-9);
    // m_0 + 6 m_leg = 8.215 + 26.232 = 34.447 kg, "about 34 kg" in the thesis
    assert_relative_eq!(r.total_mass_kg(), 34.447, epsilon = 1e-9);
    assert!((r.total_mass_kg() - 34.0).abs() / 34.0 < 0.015);
}

#[test]
fn motor_and_reductions_in_si() {
    let r = amru5();
    assert_relative_eq!(r.motor.inductance_h(), 0.09e-3, epsilon = 1e-15);
    assert_relative_eq!(r.motor.rotor_inertia_kg_m2(), 6.55e-6, epsilon = 1e-15);
    assert_relative_eq!(r.circuit_resistance_ohm(), 0.934, epsilon = 1e-12);
    assert_eq!(r.reduction(PantographJoint::Rotation), 1682.0);
    assert_eq!(r.reduction(PantographJoint::Vertical), 69115.0);
    assert_eq!(r.reduction(PantographJoint::Horizontal), 58643.0);
    // Eq. 4.13 with k_t = 0.02 gives C_emf = 3388 for q_r; with 19.4e-3 about 6 % less.
    let c_emf = r.joint_torque_per_ampere(PantographJoint::Rotation).powi(2) / r.motor.resistance_ohm;
    assert!((c_emf / 3388.0 - 0.94).abs() < 0.01, "C_emf = {c_emf}");
    // Section 5.6: 100 N vertically at the foot ~ 0.4 A (100 N x 6 / (k_t n_v))
    let amps = 100.0 * 6.0 / r.joint_torque_per_ampere(PantographJoint::Vertical);
    assert!((amps - 0.45).abs() < 0.05, "{amps}");
    let (lo, hi) = r.joint_range(PantographJoint::Rotation);
    assert_relative_eq!(hi, 25f64.to_radians(), epsilon = 1e-15);
    assert_relative_eq!(lo, -25f64.to_radians(), epsilon = 1e-15);
    assert_eq!(r.joint_range(PantographJoint::Horizontal), (0.005, 0.055));
    assert_eq!(r.pi_gains(PantographJoint::Vertical), PiGains { k: 19863.0, t_i: 0.5 });
    assert_relative_eq!(r.encoder_resolution(PantographJoint::Rotation), 2.0 * PI / (500.0 * 1682.0));
}

#[test]
fn friction_rules_of_section_6_1() {
    let r = amru5();
    // Table 5.3 spot checks
    let f = r.friction(3, PantographJoint::Rotation);
    assert_eq!((f.tau_f_d_plus, f.tau_f_d_minus), (14.9, -15.6));
    assert_eq!((f.tau_f_s_plus, f.tau_f_s_minus), (14.9, -15.6));
    assert!(f.q_st.is_none() && f.load_dependence.is_none());
    // negative viscous forced to zero, measured kept
    let f = r.friction(5, PantographJoint::Rotation);
    assert_eq!((f.f_v_plus, f.f_v_plus_measured), (0.0, -0.3));
    let f = r.friction(0, PantographJoint::Horizontal);
    assert_eq!((f.f_v_plus, f.f_v_plus_measured, f.f_v_minus), (0.0, -4112.7, 247.5));
    // vertical stiction of the 10 kg case; legs 1 and 3 minus sense from Table 5.3
    let f = r.friction(0, PantographJoint::Vertical);
    assert_eq!((f.tau_f_s_plus, f.tau_f_s_minus), (673.0, -679.5));
    assert_eq!(f.q_st, Some(1e-4));
    let f = r.friction(1, PantographJoint::Vertical);
    assert_eq!((f.tau_f_s_plus, f.tau_f_s_minus), (482.6, -351.6));
    let f = r.friction(3, PantographJoint::Vertical);
    assert_eq!((f.tau_f_s_plus, f.tau_f_s_minus), (571.6, -381.8));
    assert_eq!(r.vertical_stiction_measured(3, 10.0), Some((Some(571.6), None)));
    assert_eq!(r.vertical_stiction_measured(5, 5.0), Some((Some(1010.4), Some(-435.8))));
    // LuGre (Table 6.1 with the NOTES exponent fix)
    assert_eq!((f.sigma_0, f.sigma_1), (1e9, 0.02));
}

#[test]
fn horizontal_load_dependence_eq_5_12() {
    let r = amru5();
    let f = r.friction(0, PantographJoint::Horizontal);
    let a = f.load_dependence.unwrap();
    assert_eq!((a.a_2_plus, a.a_2_minus, a.a_1_plus, a.a_1_minus), (3.84, -3.84, 20.3, 0.0));
    let (p, m) = f.dry_under_load(10.0);
    assert_relative_eq!(p, 3.84 * 100.0 + 20.3 * 10.0 + 465.1, epsilon = 1e-9);
    assert_relative_eq!(m, -3.84 * 100.0 - 563.1, epsilon = 1e-9);
    assert_eq!(f.dry_under_load(0.0), (465.1, -563.1));
    // the mirror rule
    let mut r2 = r.clone();
    r2.friction.missing_a1_minus = MissingA1MinusRule::MirrorA1Plus;
    assert_eq!(r2.friction(1, PantographJoint::Horizontal).load_dependence.unwrap().a_1_minus, -48.0);
}

#[test]
fn table_6_7_is_the_spread_of_the_leg_means() {
    // Table 6.7 was built as mean and (n-1) standard deviation of the six leg means of
    // Table 5.3: check the translational rows, which follow the text exactly.
    let r = amru5();
    let col = |p: &PerLeg| p.mu.iter().map(|&v| Some(v)).collect::<Vec<_>>();
    let f = &r.friction;
    let m = &r.monte_carlo;
    for (rows, table) in [
        (&f.q_v.tau_f_d_plus_n, m.q_v.tau_f_d_plus_n),
        (&f.q_v.f_v_plus_ns_per_m, m.q_v.f_v_plus_ns_per_m),
        (&f.q_v.tau_f_d_minus_n, m.q_v.tau_f_d_minus_n),
        (&f.q_v.f_v_minus_ns_per_m, m.q_v.f_v_minus_ns_per_m),
        (&f.q_h.tau_f_d_plus_n, m.q_h.tau_f_d_plus_n),
        (&f.q_h.tau_f_d_minus_n, m.q_h.tau_f_d_minus_n),
        (&f.q_r.tau_f_d_minus_nm, m.q_r.tau_f_d_minus_nm),
        (&f.q_r.f_v_minus_nms, m.q_r.f_v_minus_nms),
    ] {
        let g = across_legs(&col(rows), &[]).unwrap();
        assert!((g.mu - table.mu).abs() <= 0.01 * table.mu.abs() + 0.05, "{g:?} vs {table:?}");
        assert!((g.sigma - table.sigma).abs() <= 0.01 * table.sigma + 0.05, "{g:?} vs {table:?}");
    }
    // the 3.56 fix of NOTES.md
    assert_eq!(m.q_r.tau_f_d_minus_nm.sigma, 3.56);
    let d = m.load_dependence_distribution(&f.q_h.load_dependence);
    let a2p = d.a_2_plus.unwrap();
    assert_relative_eq!(a2p.mu, (3.84 + 4.09 + 6.84 + 5.07 + 7.66) / 5.0, epsilon = 1e-12);
    assert!(d.a_1_minus.is_none());
    assert_eq!(r.monte_carlo_distribution(PantographJoint::Horizontal).1, None);
}

#[test]
fn inertias_satisfy_the_triangle_inequality() {
    let r = amru5();
    let m = &r.inertia;
    for b in [
        &m.main_body,
        &m.chassis,
        &m.pantograph_upper,
        &m.pantograph_left,
        &m.pantograph_lower,
        &m.pantograph_leg,
    ] {
        let [a, b2, c] = b.principal_moments();
        assert!(a <= b2 + c && b2 <= a + c && c <= a + b2, "{b:?}");
    }
}

#[test]
fn geometry_reconstruction_of_notes() {
    let r = amru5();
    let c = &r.geometry.chassis;
    // C* at (0.112, 0, -0.052) from the q_r axis (NOTES.md)
    assert_relative_eq!(c.l_x1_m + c.l_xc_m, 0.112, epsilon = 1e-12);
    assert_relative_eq!(c.l_y1_m + c.l_yc_m, 0.0, epsilon = 1e-12);
    assert_relative_eq!(c.l_z1_m + c.l_zc_m, -0.052, epsilon = 1e-12);
}

fn with(replace: &str, by: &str) -> String {
    assert!(AMRU5_TOML.contains(replace), "test pattern `{replace}` not in the file");
    AMRU5_TOML.replacen(replace, by, 1)
}

fn field_error(text: &str) -> (DescriptionError, String) {
    let e = RobotDescription::from_str(text, "bad.toml").expect_err("must be rejected");
    let s = e.to_string();
    assert!(s.starts_with("bad.toml"), "{s}");
    (e, s)
}

#[test]
fn errors_name_file_field_value_and_allowed() {
    let (e, s) = field_error(&with("resistance_ohm = 0.334", "resistance_ohm = -0.334"));
    assert_eq!(e.field(), Some("motor.resistance_ohm"));
    assert!(s.contains("-0.334") && s.contains("> 0"), "{s}");
    // line number of the field
    let line = AMRU5_TOML.lines().position(|l| l.starts_with("resistance_ohm")).unwrap() + 1;
    assert!(s.starts_with(&format!("bad.toml:{line}:")), "{s}");

    let (e, s) = field_error(&with("resistance_ohm = 0.334", "resistance_ohm = nan"));
    assert_eq!(e.field(), Some("motor.resistance_ohm"));
    assert!(s.contains("NaN") && s.contains("finite"), "{s}");

    let (e, s) = field_error(&with("resistance_ohm = 0.334", ""));
    assert_eq!(e.field(), Some("motor.resistance_ohm"));
    assert!(s.contains("<missing>") && s.contains("required"), "{s}");

    let (e, s) =
        field_error(&with("resistance_ohm = 0.334", "resistance_ohm = 0.334\nresistanse_ohm = 1.0"));
    assert_eq!(e.field(), Some("motor.resistanse_ohm"));
    assert!(s.contains("unknown field") && s.contains("1.0") && s.contains("resistance_ohm"), "{s}");

    let (e, s) = field_error(&with("resistance_ohm = 0.334", "resistance_ohm = \"low\""));
    assert_eq!(e.field(), Some("motor.resistance_ohm"));
    assert!(s.contains("\"low\"") && s.contains("expected"), "{s}");

    let (e, s) =
        field_error(&with("q_v_m = { min = 0.04, max = 0.075 }", "q_v_m = { min = 0.075, max = 0.04 }"));
    assert_eq!(e.field(), Some("joint_ranges.q_v_m.min"));
    assert!(s.contains("0.075") && s.contains("min < max"), "{s}");
}

#[test]
fn nested_and_array_paths() {
    let (e, s) = field_error(&with("mass_kg = 0.157", "mass_kg = -0.157"));
    assert_eq!(e.field(), Some("inertia.pantograph_upper.mass_kg"));
    assert!(s.contains("-0.157"), "{s}");

    let (e, s) = field_error(&with("angle_deg = 90.0", "angle_deg = 190.0"));
    assert_eq!(e.field(), Some("legs[2].angle_deg"));
    assert!(s.contains("190") && s.contains("(-180, 180]"), "{s}");

    let (e, _) =
        field_error(&with("[7.7, 6.3, 5.6, 14.9, 5.3, 8.3]", "[7.7, 6.3, -5.6, 14.9, 5.3, 8.3]"));
    assert_eq!(e.field(), Some("friction.q_r.tau_f_d_plus_nm.mu[2]"));

    let (e, s) =
        field_error(&with("[7.7, 6.3, 5.6, 14.9, 5.3, 8.3]", "[7.7, 6.3, \"x\", 14.9, 5.3, 8.3]"));
    assert_eq!(e.field(), Some("friction.q_r.tau_f_d_plus_nm.mu[2]"));
    assert!(s.contains("\"x\""), "{s}");

    let (e, s) = field_error(&with("[7.7, 6.3, 5.6, 14.9, 5.3, 8.3]", "[7.7, 6.3, 5.6, 14.9, 5.3]"));
    assert_eq!(e.field(), Some("friction.q_r.tau_f_d_plus_nm.mu"));
    assert!(s.contains("exactly 6"), "{s}");

    let (e, s) = field_error(&with("[-679.5, \"-\",", "[-679.5, \"?\","));
    assert_eq!(e.field(), Some("friction.q_v.stiction[2].tau_f_s_minus_n.mu[1]"));
    assert!(s.contains("\"-\""), "{s}");

    let (e, s) = field_error(&with("i_zz_kg_m2 = 0.0000047", "i_zz_kg_m2 = 0.00047"));
    assert_eq!(e.field(), Some("inertia.pantograph_left.i_zz_kg_m2"));
    assert!(s.contains("triangle"), "{s}");

    let (e, s) = field_error(&with("negative_viscous = \"zero\"", "negative_viscous = \"clamp\""));
    assert_eq!(e.field(), Some("friction.negative_viscous"));
    assert!(s.contains("clamp") && s.contains("keep"), "{s}");

    let (e, _) = field_error(&with("[[legs]]\nid = 5\nangle_deg = -150.0\n", ""));
    assert_eq!(e.field(), Some("legs"));
}

#[test]
fn missing_fields_in_inline_tables_and_arrays_of_tables() {
    let (e, _) = field_error(&with("q_r_deg = { min = -25.0, max = 25.0 }", "q_r_deg = { min = -25.0 }"));
    assert_eq!(e.field(), Some("joint_ranges.q_r_deg.max"));
    let (e, _) = field_error(&with("id = 3\nangle_deg = -90.0", "id = 3"));
    assert_eq!(e.field(), Some("legs[3].angle_deg"));
    let (e, s) = field_error(&with("name = \"AMRU5\"", "name = \"AMRU5\"\nmass = 34"));
    assert_eq!(e.field(), Some("mass"));
    assert!(s.contains("34") && s.contains("`legs`"), "{s}");
    let (e, s) = field_error(&with("sprocket_r_teeth = [38, 12]", "sprocket_r_teeth = [38, 12, 5]"));
    assert_eq!(e.field(), Some("reductions.components.sprocket_r_teeth"), "{s}");
}

#[test]
fn syntax_errors_have_a_line() {
    let e = RobotDescription::from_str("name = \"x\"\nfoo = = 1\n", "syn.toml").unwrap_err();
    assert!(matches!(e, DescriptionError::Syntax { line: 2, .. }), "{e}");
    assert!(e.to_string().starts_with("syn.toml:2:"), "{e}");
}

#[test]
fn missing_top_level_table() {
    let start = AMRU5_TOML.find("[ground]").unwrap();
    let end = AMRU5_TOML.find("# Joint controllers").unwrap();
    let text = format!("{}{}", &AMRU5_TOML[..start], &AMRU5_TOML[end..]);
    let (e, s) = field_error(&text);
    assert_eq!(e.field(), Some("ground"), "{s}");
}

/// The backdrivable drives (`robots/amru5_backdrivable.toml`): AMRU5 with its drive tables
/// changed, every other table the base's; the same peak joint torque and torque-speed line; the
/// friction referred to a quarter of the ratio (dry x 1/4, viscous x 1/16).
#[test]
fn backdrivable_drives_extend_amru5() {
    let base = amru5();
    let bis = RobotDescription::from_str(AMRU5_BACKDRIVABLE_TOML, "robots/amru5_backdrivable.toml").expect("shipped description loads");
    assert_eq!(bis.name, "AMRU5 backdrivable");
    assert_eq!((&bis.geometry, &bis.ground, &bis.controller, &bis.joint_ranges, &bis.legs), (&base.geometry, &base.ground, &base.controller, &base.joint_ranges, &base.legs));
    assert_eq!(bis.motor.resistance_ohm, base.motor.resistance_ohm);
    for joint in PantographJoint::ALL {
        let ratio = bis.reduction(joint) / base.reduction(joint);
        assert_relative_eq!(ratio, 0.25, max_relative = 1e-3);
        assert_eq!(bis.friction_reduction_ratio(joint), ratio);
        assert_eq!(base.friction_reduction_ratio(joint), 1.0);
        // Stall force at the supply behind the H-bridge, and k_t n.
        let stall = |d: &RobotDescription| d.joint_torque_per_ampere(joint) * d.driver.supply_voltage_v / d.circuit_resistance_ohm();
        assert_relative_eq!(stall(&bis), stall(&base), max_relative = 1e-3);
        // The reflected rotor inertia J n^2.
        let reflected = |d: &RobotDescription| d.inertia.rotor.i_axial_kg_m2 * d.reduction(joint).powi(2);
        assert_relative_eq!(reflected(&bis), reflected(&base), max_relative = 2e-3);
        for leg in 0..6 {
            let (f, f0) = (bis.friction(leg, joint), base.friction(leg, joint));
            assert_eq!((f.tau_f_d_plus, f.tau_f_s_minus), (f0.tau_f_d_plus * ratio, f0.tau_f_s_minus * ratio));
            assert_eq!((f.f_v_plus, f.f_v_minus), (f0.f_v_plus * (ratio * ratio), f0.f_v_minus * (ratio * ratio)));
            assert_eq!((f.sigma_0, f.sigma_1), (f0.sigma_0, f0.sigma_1));
            if let (Some(a), Some(a0)) = (f.load_dependence, f0.load_dependence) {
                assert_eq!((a.a_2_plus, a.a_1_plus), (a0.a_2_plus * ratio, a0.a_1_plus * ratio));
            }
        }
    }
    // Section 6.2: the sinking sense of q_v (q_v' < 0) breaks away below the standing load of a
    // nut (m g, Eq. B.1's 6 x m g / 6) on the bis, above it on AMRU5.
    let nut = base.total_mass_kg() * crate::mbs::STANDARD_GRAVITY;
    for leg in 0..6 {
        assert!(-base.friction(leg, PantographJoint::Vertical).tau_f_s_minus > nut, "AMRU5 leg {leg} holds");
        assert!(-bis.friction(leg, PantographJoint::Vertical).tau_f_s_minus < nut / 1.9, "bis leg {leg} backdriven");
    }
}

#[test]
fn extends_errors_name_the_file_and_the_field() {
    let bad = |text: &str| RobotDescription::from_str(text, "bis.toml").unwrap_err().to_string();
    let s = bad("extends = \"phantomx\"\nname = \"x\"\n");
    assert!(s.starts_with("bis.toml:1: field `extends` = \"phantomx\"") && s.contains("\"amru5\"") && !s.contains("\"phantomx\","), "{s}");
    let s = bad("extends = 5\n");
    assert!(s.starts_with("bis.toml:1: field `extends` = 5"), "{s}");
    // A field of the file: its line.
    let s = bad("extends = \"amru5\"\n\n[motor]\ntorque_constant_nm_per_a = -1.0\n");
    assert!(s.starts_with("bis.toml:4: field `motor.torque_constant_nm_per_a` = -1") && s.contains("> 0"), "{s}");
    let s = bad("extends = \"amru5\"\n[friction.identified_with_reductions]\nn_r = 0.0\nn_v_rad_per_m = 1.0\nn_h_rad_per_m = 1.0\n");
    assert!(s.starts_with("bis.toml:3: field `friction.identified_with_reductions.n_r` = 0"), "{s}");
    let s = bad("extends = \"amru5\"\nmass = 3\n");
    assert!(s.starts_with("bis.toml:2: field `mass`") && s.contains("unknown"), "{s}");
    // A check failing on a field of the base: no line, and said to be the base's.
    let s = bad("extends = \"amru5\"\n[reductions]\nn_v_rad_per_m = 1000.0\n");
    assert!(s.starts_with("bis.toml:3: field `reductions.n_v_rad_per_m` = 1000"), "{s}");
    let s = bad("extends = \"amru5\"\n[reductions.components]\ngearbox_h = 1.0\n");
    assert!(s.starts_with("bis.toml: field `reductions.n_h_rad_per_m`") && s.contains("base robot \"amru5\""), "{s}");
}

/// The series-elastic transmissions (`robots/amru5_series_elastic.toml`): AMRU5 with a
/// `[series_elastic]` table, every other table the base's; each joint kind's spring in SI, the
/// same foot stiffness through the pantograph's ratios (k_v / 36 = k_h / 49, Eq. B.1-B.2).
#[test]
fn series_elastic_transmissions_extend_amru5() {
    let mut base = amru5();
    let sea = RobotDescription::from_str(AMRU5_SERIES_ELASTIC_TOML, "robots/amru5_series_elastic.toml").expect("shipped description loads");
    assert_eq!(sea.name, "AMRU5 series-elastic");
    assert!(base.series_spring(PantographJoint::Vertical).is_none());
    let spring = |joint| sea.series_spring(joint).expect("every joint has its spring");
    assert_eq!((spring(PantographJoint::Rotation).stiffness, spring(PantographJoint::Rotation).damping), (1.37e3, 8.95));
    assert_eq!((spring(PantographJoint::Vertical).stiffness, spring(PantographJoint::Vertical).damping), (3.86e5, 2530.0));
    assert_relative_eq!(spring(PantographJoint::Vertical).stiffness / 36.0, spring(PantographJoint::Horizontal).stiffness / 49.0, max_relative = 2e-3); // three digits
    (base.name, base.origin, base.series_elastic) = (sea.name.clone(), sea.origin.clone(), sea.series_elastic);
    assert_eq!(base, sea);
}
