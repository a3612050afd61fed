//! Fixed-step behaviour of the Newmark integrator (thesis Eq. 3.7-3.14): order of accuracy,
//! unconditional stability, energy conservation of the trapezoidal rule, numerical damping, and
//! validation of the options.

mod common;

use common::*;
use hexadyn::sim::{Newmark, NewmarkOptions, SimError};
use nalgebra::{Matrix3, Vector3};

fn fixed(h: f64) -> NewmarkOptions {
    NewmarkOptions { adaptive: false, h_max: h, h_min: 1e-12, tolerance: 1e-10, ..Default::default() }
}

/// Eq. 3.7-3.8 with β = 1/4, γ = 1/2 are second-order accurate: on the damped oscillator
/// m q'' + c q' + k q = 0 the global error at t = 2 s against the closed-form solution must fall as
/// h², i.e. the least-squares slope of log(error) against log(h) over five step sizes lies in
/// [1.9, 2.1].
#[test]
fn newmark_trapezoidal_rule_is_second_order() {
    let (m, k) = (1.3, 1.3 * (2.0 * std::f64::consts::PI).powi(2));
    let c = 2.0 * 0.05 * (k * m).sqrt();
    let (q0, v0, t_end) = (1.0, 0.5, 2.0);
    let mut log_h = Vec::new();
    let mut log_e = Vec::new();
    for n in [40usize, 80, 160, 320, 640] {
        let h = t_end / n as f64;
        let mut sys = Linear::oscillator(m, c, k);
        let mut nm = Newmark::new(&mut sys, 0.0, &[q0], &[v0], fixed(h)).unwrap();
        // Error sampled at 8 instants on the way (all multiples of h).
        let mut err: f64 = 0.0;
        for i in 1..=8 {
            let t = t_end * i as f64 / 8.0;
            nm.advance_to(&mut sys, t).unwrap();
            let (qe, ve) = damped_oscillator(m, c, k, q0, v0, t);
            let s = nm.state();
            assert_eq!(s.t, t);
            err = err.max((s.q[0] - qe).abs()).max((s.qd[0] - ve).abs() / (k / m).sqrt());
        }
        assert_eq!(nm.stats().steps, n, "fixed step h = {h} must take exactly {n} steps");
        assert_eq!(nm.stats().rejected_steps, 0);
        log_h.push(h.ln());
        log_e.push(err.ln());
    }
    let order = fit_slope(&log_h, &log_e);
    eprintln!("Newmark(1/4, 1/2) measured order = {order:.4}, errors = {:?}", log_e.iter().map(|e| e.exp()).collect::<Vec<_>>());
    assert!((1.9..=2.1).contains(&order), "measured order {order}");
}

/// Same order check with the finite-difference Jacobian fallback (the EasyDyn column-by-column
/// numerical derivation of Eq. 3.13): results must agree with the exact-Jacobian run to 1e-9.
#[test]
fn finite_difference_jacobian_gives_the_same_trajectory() {
    let (m, c, k) = (1.0, 0.3, 40.0);
    let run = |exact: bool| {
        let mut sys = Linear::oscillator(m, c, k);
        sys.exact_jacobian = exact;
        let mut nm = Newmark::new(&mut sys, 0.0, &[1.0], &[0.0], fixed(0.01)).unwrap();
        nm.advance_to(&mut sys, 1.0).unwrap();
        nm.state().clone()
    };
    let (a, b) = (run(true), run(false));
    assert!((a.q[0] - b.q[0]).abs() < 1e-9 && (a.qd[0] - b.qd[0]).abs() < 1e-9, "{a:?} vs {b:?}");
}

/// Energy of the undamped oscillator, ½ m q'² + ½ k q².
fn energy(m: f64, k: f64, q: f64, v: f64) -> f64 {
    0.5 * m * v * v + 0.5 * k * q * q
}

/// Unconditional stability (γ ≥ 1/2, γ ≤ 2β, Section 3.3.2) on a stiff undamped oscillator
/// with h·ω = 100: the trapezoidal rule (β = 1/4, γ = 1/2) conserves the energy of a linear
/// undamped system exactly, so ½ m q'² + ½ k q² stays within 1e-9 of its initial value at every one
/// of 200 steps.
#[test]
fn trapezoidal_rule_conserves_energy_at_h_omega_100() {
    let (m, k) = (1.0, 1.0e4); // ω = 100 rad/s
    let h = 1.0; // h ω = 100
    let mut sys = Linear::oscillator(m, 0.0, k);
    let mut nm = Newmark::new(&mut sys, 0.0, &[1.0], &[3.0], fixed(h)).unwrap();
    let e0 = energy(m, k, 1.0, 3.0);
    let mut worst: f64 = 0.0;
    for i in 1..=200 {
        nm.advance_to(&mut sys, i as f64 * h).unwrap();
        let s = nm.state();
        let ratio = energy(m, k, s.q[0], s.qd[0]) / e0;
        worst = worst.max((ratio - 1.0).abs());
        assert!((ratio - 1.0).abs() < 1e-9, "step {i}: energy ratio {ratio}");
    }
    eprintln!("trapezoidal rule, h*omega = 100: worst |E/E0 - 1| = {worst:.3e}");
}

/// The Newmark recurrence of Eq. 3.7-3.8 applied to q'' = −ω² q as a 3×3 amplification matrix on
/// (q, q', q'') (q''(t+h) solved from the equation of motion, as the Newton iteration of Eq. 3.10
/// does exactly for a linear system).
fn amplification(w2: f64, h: f64, beta: f64, gamma: f64) -> Matrix3<f64> {
    let mut a = Matrix3::zeros();
    for j in 0..3 {
        let mut x = Vector3::zeros();
        x[j] = 1.0;
        let pred_q = x[0] + h * x[1] + (0.5 - beta) * h * h * x[2];
        let acc = -w2 * pred_q / (1.0 + beta * h * h * w2);
        let q = pred_q + beta * h * h * acc;
        let v = x[1] + (1.0 - gamma) * h * x[2] + gamma * h * acc;
        a.set_column(j, &Vector3::new(q, v, acc));
    }
    a
}

/// Numerical damping with γ = 0.6, β = 0.3025 = (γ + ½)²/4 at h·ω = 100: the integrator reproduces
/// the Newmark recurrence of Eq. 3.7-3.8 (amplification matrix, computed independently) to 1e-9
/// at each of 200 steps. Its spectral radius ρ is 0.818 < 1, the energy decays at the rate ρ² per
/// step (measured rate over steps 100-200 within 3 % of 2 ln ρ; the energy oscillates with the phase) and falls below 1e-20 of its
/// initial value after 200 steps. (The energy ½ m q'² + ½ k q² is not the norm the recurrence
/// contracts: it overshoots transiently during the first steps, by less than 4×.)
#[test]
fn gamma_above_one_half_damps_high_frequencies() {
    let (m, k, h) = (1.0, 1.0e4, 1.0);
    let (beta, gamma) = (0.3025, 0.6);
    let mut sys = Linear::oscillator(m, 0.0, k);
    let opts = NewmarkOptions { beta, gamma, ..fixed(h) };
    let mut nm = Newmark::new(&mut sys, 0.0, &[1.0], &[3.0], opts).unwrap();
    let amp = amplification(k / m, h, beta, gamma);
    let rho = amp.complex_eigenvalues().iter().map(|l| l.norm()).fold(0.0, f64::max);
    let mut x = Vector3::new(1.0, 3.0, -k / m * 1.0);
    let e0 = energy(m, k, 1.0, 3.0);
    let mut e_max: f64 = 0.0;
    let mut e = Vec::new();
    for i in 1..=200 {
        nm.advance_to(&mut sys, i as f64 * h).unwrap();
        x = amp * x;
        let s = nm.state();
        let scale = x.norm();
        assert!((s.q[0] - x[0]).abs() <= 1e-9 * scale, "step {i}: q {} vs recurrence {}", s.q[0], x[0]);
        assert!((s.qd[0] - x[1]).abs() <= 1e-9 * scale, "step {i}: q' {} vs recurrence {}", s.qd[0], x[1]);
        assert!((s.qdd[0] - x[2]).abs() <= 1e-9 * scale, "step {i}: q'' {} vs recurrence {}", s.qdd[0], x[2]);
        e.push(energy(m, k, s.q[0], s.qd[0]));
        e_max = e_max.max(e[i - 1]);
    }
    let ratio = e[199] / e0;
    let rate = (e[199] / e[99]).ln() / 100.0;
    eprintln!(
        "gamma = 0.6, beta = 0.3025, h*omega = 100: spectral radius {rho:.6}, E(200 h)/E0 = {ratio:.3e}, \
         energy decay rate {rate:.5}/step vs 2 ln(rho) = {:.5}, max E/E0 = {:.4}",
        2.0 * rho.ln(),
        e_max / e0
    );
    assert!((rho - 0.818).abs() < 1e-3, "spectral radius {rho}");
    assert!((rate / (2.0 * rho.ln()) - 1.0).abs() < 0.03, "decay rate {rate} vs {}", 2.0 * rho.ln());
    assert!(ratio < 1e-20, "energy ratio after 200 steps {ratio}");
    assert!(e_max < 4.0 * e0, "overshoot {}", e_max / e0);
}

/// With `adaptive: false` the Newmark step (Eq. 3.7-3.8) is h_max from the very first step (h_initial plays no role):
/// integrating 1 s with h_max = 0.01 takes exactly 100 steps.
#[test]
fn fixed_step_is_h_max_from_the_first_step() {
    let mut sys = Linear::oscillator(1.0, 0.1, 10.0);
    let opts = NewmarkOptions { adaptive: false, h_max: 0.01, ..Default::default() };
    let mut nm = Newmark::new(&mut sys, 0.0, &[1.0], &[0.0], opts).unwrap();
    assert_eq!(nm.step_size(), 0.01);
    nm.advance_to(&mut sys, 1.0).unwrap();
    assert_eq!(nm.stats().steps, 100);
    assert_eq!(nm.stats().rejected_steps, 0);
    assert_eq!(nm.state().t, 1.0);
}

/// Options outside the stability domain of Section 3.3.2 (γ ≥ 1/2, γ ≤ 2β) or otherwise
/// meaningless are refused with `SimError::InvalidOption` naming the field.
#[test]
fn invalid_options_are_refused() {
    let cases: Vec<(&str, NewmarkOptions)> = vec![
        ("gamma", NewmarkOptions { gamma: 0.45, ..Default::default() }),
        ("gamma", NewmarkOptions { gamma: f64::NAN, ..Default::default() }),
        ("beta", NewmarkOptions { gamma: 0.6, beta: 0.25, ..Default::default() }),
        ("beta", NewmarkOptions { beta: f64::NAN, ..Default::default() }),
        ("tolerance", NewmarkOptions { tolerance: 0.0, ..Default::default() }),
        ("tolerance", NewmarkOptions { tolerance: -1e-6, ..Default::default() }),
        ("h_min", NewmarkOptions { h_min: 0.0, ..Default::default() }),
        ("h_min", NewmarkOptions { h_min: 1.0, h_max: 0.1, ..Default::default() }),
        ("h_initial", NewmarkOptions { h_initial: -1.0, ..Default::default() }),
        ("newton_tolerance", NewmarkOptions { newton_tolerance: 0.0, ..Default::default() }),
        ("max_iterations", NewmarkOptions { max_iterations: 0, ..Default::default() }),
        ("slow_contraction", NewmarkOptions { slow_contraction: 1.0, ..Default::default() }),
    ];
    for (field, opts) in cases {
        let mut sys = Linear::oscillator(1.0, 0.0, 1.0);
        match Newmark::new(&mut sys, 0.0, &[0.0], &[0.0], opts.clone()) {
            Err(e @ SimError::InvalidOption { field: f, .. }) => {
                assert_eq!(f, field, "{opts:?}");
                assert!(e.to_string().contains(field), "{e}");
            }
            Err(e) => panic!("{opts:?}: expected InvalidOption {{ {field} }}, got {e}"),
            Ok(_) => panic!("{opts:?}: expected InvalidOption {{ {field} }}, got Ok"),
        }
    }
    // The boundary of the stability domain itself is valid: γ = 1/2, β = γ/2; γ = 0.6, β = 0.3.
    for (beta, gamma) in [(0.25, 0.5), (0.3, 0.6), (0.3025, 0.6)] {
        let mut sys = Linear::oscillator(1.0, 0.0, 1.0);
        assert!(Newmark::new(&mut sys, 0.0, &[0.0], &[0.0], NewmarkOptions { beta, gamma, ..Default::default() }).is_ok());
    }
}

/// `advance_to` (step-by-step integration of Eq. 3.7-3.10) refuses to integrate backwards (SimError::Backwards) and leaves the state alone.
#[test]
fn advance_to_refuses_to_go_backwards() {
    let mut sys = Linear::oscillator(1.0, 0.0, 1.0);
    let mut nm = Newmark::new(&mut sys, 0.0, &[1.0], &[0.0], NewmarkOptions::default()).unwrap();
    nm.advance_to(&mut sys, 0.5).unwrap();
    let before = nm.state().clone();
    let err = nm.advance_to(&mut sys, 0.25).unwrap_err();
    assert!(matches!(err, SimError::Backwards { requested, current } if requested == 0.25 && current == 0.5), "{err}");
    assert_eq!(nm.state(), &before);
    // Advancing to the current instant is a no-op.
    nm.advance_to(&mut sys, 0.5).unwrap();
    assert_eq!(nm.state(), &before);
}

/// `Newmark::new` starts from the consistent acceleration q''0 solved from f = 0 (Eq. 3.1):
/// for m q'' + c q' + k q = u, q''0 = (u − c q'0 − k q0)/m.
#[test]
fn initial_accelerations_are_consistent() {
    for exact in [true, false] {
        let (m, c, k) = (2.0, 0.7, 30.0);
        let mut sys = Linear::oscillator(m, c, k);
        sys.exact_jacobian = exact;
        sys.u[0] = 5.0;
        let nm = Newmark::new(&mut sys, 0.0, &[0.2], &[-1.5], NewmarkOptions::default()).unwrap();
        let expected = (5.0 - c * -1.5 - k * 0.2) / m;
        assert!(rel(nm.state().qdd[0], expected) < 1e-12, "{} vs {expected}", nm.state().qdd[0]);
    }
}

/// The iteration matrix of Eq. 3.14 is built from the Jacobian at the current state (the Newmark
/// predictor), not at some unrelated point: a particle on a circular orbit in polar coordinates,
/// whose θ row m r² θ'' + 2 m r r' θ' vanishes identically at r = 0, integrates without a singular
/// matrix. The orbit r = R, θ = Ω t (spring free length r0 = R − m R Ω²/k) has constant q'', which
/// Newmark reproduces exactly: r stays R within 1e-9 and θ(t) = Ω t within 1e-9 rad over 2 s.
#[test]
fn circular_orbit_in_polar_coordinates() {
    let (m, k, big_r, omega) = (0.5, 80.0, 1.5, 3.0);
    let r0 = big_r - m * big_r * omega * omega / k;
    let mut sys = Polar::new(m, k, r0);
    let mut nm = Newmark::new(&mut sys, 0.0, &[big_r, 0.0], &[0.0, omega], NewmarkOptions::default()).unwrap();
    for i in 1..=20 {
        let t = 0.1 * i as f64;
        nm.advance_to(&mut sys, t).unwrap();
        let s = nm.state();
        assert!((s.q[0] - big_r).abs() < 1e-9 && (s.q[1] - omega * t).abs() < 1e-9, "t = {t}: r {} theta {} vs {}", s.q[0], s.q[1], omega * t);
    }
}
