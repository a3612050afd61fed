//! The friction laws against their equations, analytic cases and their exact partial derivatives
//! against finite differences.

use super::*;
use crate::test_util::{assert_partial, central, noise, rng};
use rand::Rng;

/// The shortcut past the underflow is exp(−r²) bit for bit, on both sides of r² = 746 and
/// through the subnormal range of the result.
#[test]
fn gaussian_is_exp_of_minus_r_squared() {
    for k in 0..200_000 {
        let r = 1e-3 * k as f64 * if k % 2 == 0 { 1.0 } else { -1.0 };
        assert_eq!(gaussian(r).to_bits(), (-r * r).exp().to_bits(), "r = {r}");
    }
}

/// Vertical joint of leg 0: Table 5.3 (dry, viscous) and Table 5.4 (stiction, 10 kg).
fn vertical_leg0() -> LuGre {
    let steady = SteadyState::Stribeck { tau_f_d_plus: 335.1, tau_f_d_minus: -423.6, tau_f_s_plus: 673.0, tau_f_s_minus: -679.5, qd_st: STRIBECK_VELOCITY };
    LuGre::new(steady, 3763.0, 8005.8).unwrap()
}

/// Horizontal joint of leg 0: Table 5.3 (viscous neglected, Section 6.1) and Table 5.5
/// (a_1^- is not legible in the table: a made-up value of the right sign).
fn horizontal_leg0_load() -> LoadDependence {
    LoadDependence { a_2_plus: 3.84, a_1_plus: 20.3, a_2_minus: -3.84, a_1_minus: -15.0 }
}

fn random_dry_viscous(r: &mut impl Rng) -> DryViscous {
    DryViscous::new(r.random_range(1.0..500.0), r.random_range(-500.0..-1.0), r.random_range(0.0..2e4), r.random_range(0.0..2e4)).unwrap()
}

fn random_lugre(r: &mut impl Rng, stribeck: bool) -> LuGre {
    let (tau_f_d_plus, tau_f_d_minus) = (r.random_range(1.0..500.0), r.random_range(-500.0..-1.0));
    let steady = if stribeck {
        SteadyState::Stribeck {
            tau_f_d_plus,
            tau_f_d_minus,
            tau_f_s_plus: r.random_range(1.0..1500.0),
            tau_f_s_minus: r.random_range(-1500.0..-1.0),
            qd_st: r.random_range(1e-5..1e-3),
        }
    } else {
        SteadyState::Dry { tau_f_d_plus, tau_f_d_minus }
    };
    let mut law = LuGre::new(steady, r.random_range(0.0..2e4), r.random_range(0.0..2e4)).unwrap();
    law.sigma_1 = r.random_range(0.0..1.0);
    law.v_d = r.random_range(1e-5..1e-2);
    law
}

/// A random velocity of random sign with |q'| log-uniform in [lo, hi].
fn velocity(r: &mut impl Rng, lo: f64, hi: f64) -> f64 {
    let magnitude = (r.random_range(lo.ln()..hi.ln())).exp();
    if r.random_bool(0.5) {
        magnitude
    } else {
        -magnitude
    }
}

#[test]
fn dry_viscous_partials_match_finite_differences() {
    let mut r = rng(1);
    for k in 0..400 {
        let law = random_dry_viscous(&mut r);
        let eps = law.epsilon;
        // Alternate inside and outside the linear zone; the step never crosses a kink.
        let qd = if k % 2 == 0 { velocity(&mut r, 0.05 * eps, 0.95 * eps) } else { velocity(&mut r, 1.05 * eps, 1e3 * eps) };
        let h = 1e-3 * qd.abs();
        let (tau, dtau_dqd) = law.torque(qd);
        assert_partial("dτ/dq'", dtau_dqd, central(|x| law.torque(x).0, qd, h), 1e-6, noise(tau, h));

        let element = FrictionElement::new(JointFriction::DryViscous(law)).with_load(horizontal_leg0_load());
        let load = r.random_range(1.0..200.0);
        let t = element.torque(qd, 0.0, 0.0, load, 0.0);
        assert_partial("dτ/dq' (loaded)", t.dtau_dqd, central(|x| element.torque(x, 0.0, 0.0, load, 0.0).tau, qd, h), 1e-6, noise(t.tau, h));
        assert_partial("dτ/dload", t.dtau_dload, central(|x| element.torque(qd, 0.0, 0.0, x, 0.0).tau, load, 1e-2), 1e-6, noise(t.tau, 1e-2));
    }
}

#[test]
fn dry_viscous_is_continuous_dissipative_and_matches_eq_6_1() {
    let law = DryViscous::new(335.1, -423.6, 3763.0, 8005.8).unwrap();
    let eps = law.epsilon;
    for border in [eps, -eps] {
        let inner = law.torque(border).0;
        let outer = law.torque(border * (1.0 + 1e-12)).0;
        assert!((inner - outer).abs() < 1e-6, "discontinuity at {border}: {inner} vs {outer}");
    }
    assert_eq!(law.torque(0.0).0, 0.0);
    assert!((law.torque(1e-3).0 - (335.1 + 3763.0e-3)).abs() < 1e-9);
    assert!((law.torque(-1e-3).0 - (-423.6 - 8005.8e-3)).abs() < 1e-9);
    let mut r = rng(2);
    for _ in 0..1000 {
        let qd = velocity(&mut r, 1e-8, 1.0);
        assert!(law.torque(qd).0 * qd > 0.0, "friction must oppose the motion at q' = {qd}");
    }
    // At q' = 0 the partial is the right derivative (q' ≥ 0 branch).
    let h = 1e-9;
    assert_partial("right derivative", law.torque(0.0).1, (law.torque(h).0 - law.torque(0.0).0) / h, 1e-6, 0.0);
}

#[test]
fn negative_viscous_coefficients_are_forced_to_zero_and_signs_checked() {
    let law = DryViscous::new(465.1, -563.1, -4112.7, 247.5).unwrap();
    assert_eq!(law.f_v_plus, 0.0);
    assert!(DryViscous::new(465.1, 563.1, 0.0, 0.0).is_err());
    assert!(SteadyState::Dry { tau_f_d_plus: 7.7, tau_f_d_minus: 8.8 }.validate().is_err());
    assert!(LoadDependence { a_2_plus: 3.84, a_1_plus: -1.0, a_2_minus: -3.84, a_1_minus: 0.0 }.validate().is_err());
}

#[test]
fn lugre_partials_match_finite_differences() {
    let mut r = rng(3);
    for k in 0..600 {
        let law = random_lugre(&mut r, k % 2 == 0);
        let qd = velocity(&mut r, 1e-6, 1e-1);
        let g = law.g(qd);
        let z = r.random_range(-2.0 * g..2.0 * g);
        let zdot = r.random_range(-1e-2..1e-2);
        let h = 1e-5 * qd.abs();
        let (hz, hzd) = (1e-3 * g, 1e-5);

        let (f0, df_dqd, df_dz, df_dzdot) = law.bristle_residual(qd, z, zdot);
        let f = |qd: f64, z: f64, zdot: f64| law.bristle_residual(qd, z, zdot).0;
        let nf = |h: f64| noise(f0.abs() + 3.0 * qd.abs() + zdot.abs(), h);
        assert_partial("∂f_z/∂q'", df_dqd, central(|x| f(x, z, zdot), qd, h), 1e-6, nf(h));
        assert_partial("∂f_z/∂z", df_dz, central(|x| f(qd, x, zdot), z, hz), 1e-6, nf(hz));
        assert_partial("∂f_z/∂z'", df_dzdot, central(|x| f(qd, z, x), zdot, hzd), 1e-6, nf(hzd));

        let (tau0, dtau_dqd, dtau_dz, dtau_dzdot) = law.torque(qd, z, zdot);
        let tau = |qd: f64, z: f64, zdot: f64| law.torque(qd, z, zdot).0;
        let nt = |h: f64| noise(law.sigma_0 * z.abs() + tau0.abs(), h);
        assert_partial("∂τ/∂q'", dtau_dqd, central(|x| tau(x, z, zdot), qd, h), 1e-6, nt(h));
        assert_partial("∂τ/∂z", dtau_dz, central(|x| tau(qd, x, zdot), z, hz), 1e-6, nt(hz));
        assert_partial("∂τ/∂z'", dtau_dzdot, central(|x| tau(qd, z, x), zdot, hzd), 1e-6, nt(hzd));

        let element = FrictionElement::new(JointFriction::LuGre(law)).with_load(horizontal_leg0_load());
        let load = r.random_range(1.0..200.0);
        let b = element.bristle_residual(qd, z, zdot, load).unwrap();
        let fe = |qd: f64, load: f64| element.bristle_residual(qd, z, zdot, load).unwrap().f;
        assert_partial("∂f_z/∂q' (loaded)", b.df_dqd, central(|x| fe(x, load), qd, h), 1e-6, nf(h));
        assert_partial("∂f_z/∂load", b.df_dload, central(|x| fe(qd, x), load, 1e-4), 1e-6, nf(1e-4));
        let t = element.torque(qd, z, zdot, load, 0.0);
        assert_eq!((t.tau, t.dtau_dqd, t.dtau_dz, t.dtau_dzdot, t.dtau_dload), (law.torque(qd, z, zdot).0, dtau_dqd, dtau_dz, dtau_dzdot, 0.0));
    }
}

#[test]
fn lugre_derivatives_at_zero_velocity_are_right_derivatives() {
    let law = vertical_leg0();
    let (z, zdot) = (2e-7, 1e-4);
    let h = 1e-10;
    let (f0, df_dqd, ..) = law.bristle_residual(0.0, z, zdot);
    assert_partial("right ∂f_z/∂q'", df_dqd, (law.bristle_residual(h, z, zdot).0 - f0) / h, 1e-6, 1e-9);
    let (t0, dtau_dqd, ..) = law.torque(0.0, z, zdot);
    assert_partial("right ∂τ/∂q'", dtau_dqd, (law.torque(h, z, zdot).0 - t0) / h, 1e-4, noise(t0, h));
}

#[test]
fn lugre_steady_state_reproduces_the_stribeck_curve() {
    let law = vertical_leg0();
    let SteadyState::Stribeck { tau_f_d_plus, tau_f_d_minus, tau_f_s_plus, tau_f_s_minus, qd_st } = law.steady else { unreachable!() };
    for v in [1e-5, 5e-5, 1e-4, 2e-4, 5e-4, 1e-3, 8e-3, -1e-5, -5e-5, -1e-4, -2e-4, -5e-4, -1e-3, -8e-3] {
        // Explicit Euler on z' = -f_z(q', z, 0) with a step half the bristle time constant.
        let dt = 0.5 * law.g(v) / v.abs();
        let mut z = 0.0;
        let mut zdot = 0.0;
        for _ in 0..200 {
            zdot = -law.bristle_residual(v, z, 0.0).0;
            z += dt * zdot;
        }
        let tau = law.torque(v, z, zdot).0;
        let (tau_d, tau_s, f_v) = if v >= 0.0 { (tau_f_d_plus, tau_f_s_plus, law.f_v_plus) } else { (tau_f_d_minus, tau_f_s_minus, law.f_v_minus) };
        let stribeck = tau_d + (tau_s - tau_d) * (-(v / qd_st).powi(2)).exp() + f_v * v; // Eq. 3.82
        assert!((tau - stribeck).abs() < 1e-9 * stribeck.abs(), "v = {v}: {tau} vs Eq. 3.82 {stribeck}");
        assert!((z - law.g(v) * v.signum()).abs() < 1e-12 * law.g(v), "Eq. 3.80 at v = {v}");
    }
}

/// Far from zero velocity g (Eq. 3.78) is τ_f,d / σ0 in each direction: the sliding
/// deflection is the smaller of the two, and below the stiction deflection.
#[test]
fn sliding_deflection_is_the_smaller_steady_deflection_in_motion() {
    let law = vertical_leg0();
    let (forward, backward) = (law.g(1.0), law.g(-1.0));
    assert!((forward - backward).abs() > 1e-3 * forward, "the test needs asymmetric dry friction");
    assert!((law.sliding_deflection() - forward.min(backward)).abs() < 1e-12 * forward);
    assert!(law.sliding_deflection() < law.g(0.0));
}

#[test]
fn lugre_is_dissipative_with_the_thesis_parameters() {
    let vertical = vertical_leg0();
    let rotational = LuGre::new(SteadyState::Dry { tau_f_d_plus: 7.7, tau_f_d_minus: -8.8 }, 3.4, 22.3).unwrap();
    let horizontal = LuGre::new(SteadyState::Dry { tau_f_d_plus: 465.1, tau_f_d_minus: -563.1 }, 0.0, 0.0).unwrap();
    let mut constant_damping = vertical;
    constant_damping.v_d = f64::INFINITY;
    for law in [vertical, rotational, horizontal, constant_damping] {
        for k in 0..=90 {
            let v = 10f64.powf(-9.0 + 0.1 * k as f64); // up to 1 m/s (rad/s)
            assert!(law.dissipative(v) && law.dissipative(-v), "Eq. 3.83 violated at |q'| = {v} for {law:?}");
        }
        assert!(law.dissipative(0.0));
    }
    let mut stiff_damping = vertical;
    stiff_damping.sigma_1 = 1e9;
    assert!(!stiff_damping.dissipative(1e-5));
}

#[test]
fn load_dependence_follows_eq_5_12() {
    let load = horizontal_leg0_load();
    let a0 = 465.1;
    assert_eq!(load.dry_friction(a0, 1e-3, 0.0).0, a0);
    let ten_kg = 10.0 * LOAD_GRAVITY;
    assert!((load.dry_friction(a0, 1e-3, ten_kg).0 - (3.84 * 100.0 + 20.3 * 10.0 + a0)).abs() < 1e-9);
    assert!((load.dry_friction(-563.1, -1e-3, ten_kg).0 - (-3.84 * 100.0 - 15.0 * 10.0 - 563.1)).abs() < 1e-9);
    let mut r = rng(4);
    for _ in 0..100 {
        let (x, qd) = (r.random_range(0.0..300.0), velocity(&mut r, 1e-6, 1e-2));
        let a0 = if qd >= 0.0 { 465.1 } else { -563.1 };
        let (value, d) = load.dry_friction(a0, qd, x);
        assert!(value.abs() >= a0.abs());
        let x = x.max(1e-2);
        assert_partial("dτ̃_d/dload", d, central(|l| load.dry_friction(a0, qd, l).0, x, 1e-2), 1e-6, noise(value, 1e-2));
    }
    let element = FrictionElement::new(JointFriction::DryViscous(DryViscous::new(465.1, -563.1, 0.0, 0.0).unwrap())).with_load(load);
    assert!((element.torque(1e-3, 0.0, 0.0, ten_kg, 0.0).tau - element.dry_friction(1e-3, ten_kg).0).abs() < 1e-9);
}

fn random_efficiency(r: &mut impl Rng) -> Efficiency {
    Efficiency { eta_forward: r.random_range(0.3..1.0), eta_backward: r.random_range(0.3..1.0), no_load: random_dry_viscous(r) }
}

#[test]
fn efficiency_partials_match_finite_differences() {
    let mut r = rng(5);
    for k in 0..800 {
        let law = random_efficiency(&mut r);
        let eps = law.no_load.epsilon;
        let qd = if k % 2 == 0 { velocity(&mut r, 0.05 * eps, 0.95 * eps) } else { velocity(&mut r, 1.05 * eps, 1e3 * eps) };
        // A transmitted torque e = τ_m − N of either sign, away from the kink at e = 0.
        let e = velocity(&mut r, 10.0, 2000.0);
        let tau_m = law.no_load.torque(qd).0 + e;
        let (h, h_m) = (1e-4 * qd.abs(), 1e-4 * e.abs());
        let (tau, dtau_dqd, dtau_dtau_m) = law.torque(qd, tau_m);
        assert_partial("∂τ/∂q'", dtau_dqd, central(|x| law.torque(x, tau_m).0, qd, h), 1e-6, noise(tau.abs() + tau_m.abs(), h));
        assert_partial("∂τ/∂τ_m", dtau_dtau_m, central(|x| law.torque(qd, x).0, tau_m, h_m), 1e-6, noise(tau.abs() + tau_m.abs(), h_m));
        let element = FrictionElement::new(JointFriction::Efficiency(law));
        let t = element.torque(qd, 0.0, 0.0, 100.0, tau_m);
        assert_eq!((t.tau, t.dtau_dqd, t.dtau_dtau_m, t.dtau_dload, t.dtau_dz), (tau, dtau_dqd, dtau_dtau_m, 0.0, 0.0));
    }
}

/// On the kink e = 0 the partial with respect to τ_m is the forward branch's, in both
/// directions of motion.
#[test]
fn efficiency_kink_belongs_to_the_forward_branch() {
    let law = Efficiency { eta_forward: 0.65, eta_backward: 0.5, no_load: DryViscous::new(335.1, -423.6, 3763.0, 8005.8).unwrap() };
    for qd in [1e-3, -1e-3] {
        let tau_m = law.no_load.torque(qd).0;
        let (tau, _, dtau_dtau_m) = law.torque(qd, tau_m);
        let h = 1e-3 * qd.signum();
        assert_partial("forward one-sided ∂τ/∂τ_m", dtau_dtau_m, (law.torque(qd, tau_m + h).0 - tau) / h, 1e-9, noise(tau, h.abs()));
        assert!((dtau_dtau_m - 0.35).abs() < 1e-12);
    }
}

/// Steady motion: the joint passes on η_f e forward and e / η_b backward; the friction
/// opposes the motion, vanishes at rest and is Eq. 6.1 without transmitted load or with
/// ideal efficiencies (bit for bit).
#[test]
fn efficiency_law_transmits_eta_times_the_power() {
    let no_load = DryViscous::new(335.1, -423.6, 3763.0, 8005.8).unwrap();
    let law = Efficiency { eta_forward: 0.65, eta_backward: 0.5, no_load };
    let ideal = Efficiency { eta_forward: 1.0, eta_backward: 1.0, no_load };
    let mut r = rng(6);
    for _ in 0..2000 {
        let qd = velocity(&mut r, 1e-8, 1.0);
        let tau_m = r.random_range(-3000.0..3000.0);
        assert_eq!(ideal.torque(qd, tau_m).0.to_bits(), no_load.torque(qd).0.to_bits());
        let n = no_load.torque(qd).0;
        assert_eq!(law.torque(qd, n).0, n, "no transmitted load at q' = {qd}");
        let tau = law.torque(qd, tau_m).0;
        assert!(tau * qd > 0.0, "friction must oppose the motion at q' = {qd}, τ_m = {tau_m}");
        if qd.abs() > no_load.epsilon {
            let (e, load) = (tau_m - n, tau_m - tau);
            let expected = if e * qd >= 0.0 { 0.65 * e } else { e / 0.5 };
            assert!((load - expected).abs() < 1e-9 * (1.0 + e.abs()), "q' = {qd}, e = {e}: τ_L = {load}, expected {expected}");
        }
    }
    assert_eq!(law.torque(0.0, 500.0).0, 0.0);
    for (eta_forward, eta_backward) in [(0.0, 0.5), (1.2, 0.5), (0.6, -0.1), (0.6, f64::NAN)] {
        assert!(Efficiency { eta_forward, eta_backward, no_load }.validate().is_err(), "{eta_forward}, {eta_backward}");
    }
}

#[test]
fn bristle_state_only_for_lugre() {
    let dry = FrictionElement::new(JointFriction::DryViscous(DryViscous::new(7.7, -8.8, 3.4, 22.3).unwrap()));
    let lugre = FrictionElement::new(JointFriction::LuGre(vertical_leg0()));
    let none = FrictionElement::new(JointFriction::None);
    assert!(!dry.has_bristle_state() && !none.has_bristle_state() && lugre.has_bristle_state());
    assert!(dry.bristle_residual(1e-3, 0.0, 0.0, 0.0).is_none());
    assert_eq!(none.torque(1.0, 1.0, 1.0, 1.0, 1.0), FrictionTorque::default());
}
