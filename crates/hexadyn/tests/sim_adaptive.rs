//! Adaptive stepping from the error estimate of Eq. 3.15, ε = h²/12 · rms(q''(t+h) − q''(t)), and
//! `advance_to` landing on requested instants.

mod common;

use common::*;
use hexadyn::sim::{Newmark, NewmarkOptions};

fn adaptive(tolerance: f64) -> NewmarkOptions {
    NewmarkOptions { tolerance, h_initial: 1e-4, h_max: 0.05, ..Default::default() }
}

/// Damped oscillator (ω = 4π rad/s, ζ = 0.02) integrated with the adaptive step of Eq. 3.15 at
/// tolerances 1e-4, 1e-6, 1e-8, sampled every 0.1 s against the closed form: each 100× tighter
/// tolerance cuts the maximum error by more than 5× (h ∝ ε^⅓ so the global error ∝ ε^⅔, about 21×)
/// and costs more steps; every requested instant is hit exactly (t == requested, bit for bit).
#[test]
fn tighter_tolerance_gives_smaller_error() {
    let (m, k) = (1.0, (4.0 * std::f64::consts::PI).powi(2));
    let c = 2.0 * 0.02 * (k * m).sqrt();
    let mut errors = Vec::new();
    let mut steps = Vec::new();
    for tol in [1e-4, 1e-6, 1e-8] {
        let mut sys = Linear::oscillator(m, c, k);
        let mut nm = Newmark::new(&mut sys, 0.0, &[1.0], &[0.0], adaptive(tol)).unwrap();
        let mut err: f64 = 0.0;
        for i in 1..=20 {
            let t = 0.1 * i as f64; // not a binary fraction: landing must be exact anyway
            nm.advance_to(&mut sys, t).unwrap();
            assert_eq!(nm.state().t, t, "advance_to({t}) landed on {}", nm.state().t);
            let (qe, _) = damped_oscillator(m, c, k, 1.0, 0.0, t);
            err = err.max((nm.state().q[0] - qe).abs());
        }
        errors.push(err);
        steps.push(nm.stats().steps);
    }
    eprintln!("adaptive: tolerances 1e-4, 1e-6, 1e-8 -> max errors {errors:?}, steps {steps:?}");
    for i in 0..2 {
        assert!(errors[i + 1] < errors[i] / 5.0, "errors {errors:?}");
        assert!(steps[i + 1] > steps[i], "steps {steps:?}");
    }
    assert!(errors[2] < 1e-4, "errors {errors:?}");
}

/// Large-amplitude undamped pendulum θ'' + (g/l) sin θ = 0 from θ0 = 2 rad at rest: its period is
/// T = 4 √(l/g) K(sin(θ0/2)) (complete elliptic integral), so θ(T/2) = −θ0 and θ(T) = θ0,
/// θ'(T) = 0. A nonlinear problem where the tolerance of Eq. 3.15 matters: the error at T falls
/// below 1e-3 rad at ε = 1e-6 and 1e-5 rad at ε = 1e-9.
#[test]
fn large_amplitude_pendulum_period() {
    let (m, l, theta0) = (0.5, 0.8, 2.0_f64);
    let period = 4.0 * (l / G).sqrt() * elliptic_k((theta0 / 2.0).sin());
    let mut errors = Vec::new();
    for tol in [1e-6, 1e-9] {
        let mut sys = Pendulum::hanging(m, l, 0.0);
        let mut nm = Newmark::new(&mut sys, 0.0, &[theta0], &[0.0], adaptive(tol)).unwrap();
        nm.advance_to(&mut sys, 0.5 * period).unwrap();
        let half = (nm.state().q[0] + theta0).abs();
        nm.advance_to(&mut sys, period).unwrap();
        assert_eq!(nm.state().t, period);
        let full = (nm.state().q[0] - theta0).abs() + nm.state().qd[0].abs() * (l / G).sqrt();
        errors.push(half.max(full));
    }
    eprintln!("pendulum theta0 = 2 rad, period {period:.6} s: errors at tolerances 1e-6, 1e-9: {errors:?}");
    assert!(errors[0] < 1e-3 && errors[1] < 1e-5, "{errors:?}");
    assert!(errors[1] < errors[0] / 10.0, "{errors:?}");
}

/// A first step far too long for the tolerance (h_initial = h_max = 0.05 s on a 2 Hz oscillator,
/// ε = 1e-8) is rejected by the test of Eq. 3.15 and retried shorter. The statistics are checked
/// against an independent count from the residual evaluations the system saw: every evaluation
/// is counted, a rejection shows up as the next attempt being at an earlier time, and the exact
/// Jacobian is requested exactly `jacobian_evaluations` times.
#[test]
fn rejected_steps_are_counted() {
    let (m, c, k) = (1.0, 0.1, (4.0 * std::f64::consts::PI).powi(2));
    let mut sys = Linear::oscillator(m, c, k);
    sys.log = Some(Vec::new());
    let opts = NewmarkOptions { tolerance: 1e-8, h_initial: 0.05, h_max: 0.05, ..Default::default() };
    let mut nm = Newmark::new(&mut sys, 0.0, &[1.0], &[0.0], opts).unwrap();
    nm.advance_to(&mut sys, 1.0).unwrap();
    let log = sys.log.take().unwrap();
    // Attempts: runs of evaluations at the same time; the first run is the initial acceleration
    // solve at t = 0.
    let mut attempts: Vec<f64> = Vec::new();
    for &t in &log {
        if attempts.last() != Some(&t) {
            attempts.push(t);
        }
    }
    assert_eq!(attempts[0], 0.0);
    let attempts = &attempts[1..];
    let rejected = attempts.windows(2).filter(|w| w[1] < w[0]).count();
    let accepted = attempts.len() - rejected;
    let stats = nm.stats().clone();
    eprintln!("rejection test: {stats:?}");
    assert!(stats.rejected_steps >= 1, "{stats:?}");
    assert_eq!(stats.rejected_steps, rejected, "{stats:?}");
    assert_eq!(stats.steps, accepted, "{stats:?}");
    assert_eq!(stats.residual_evaluations, log.len(), "{stats:?}");
    assert_eq!(stats.jacobian_evaluations, sys.jacobian_calls, "{stats:?}");
    // The first attempt (t = 0.05) was rejected.
    assert_eq!(attempts[0], 0.05);
    assert!(attempts[1] < 0.05);
    // Accuracy is still within what the tolerance buys.
    let (qe, _) = damped_oscillator(m, c, k, 1.0, 0.0, 1.0);
    assert!((nm.state().q[0] - qe).abs() < 1e-4, "{} vs {qe}", nm.state().q[0]);
}

/// `advance_to` (the NewmarkInterval() of Section 3.3.2, steps from Eq. 3.15) lands exactly on
/// every requested instant, including awkward ones (1/3, 0.1 + 0.2,
/// an instant a few ulps after the current time, one closer than the minimum step), and the steps
/// taken on the way never exceed h_max.
#[test]
fn advance_to_lands_exactly() {
    let mut sys = Linear::oscillator(1.0, 0.2, 50.0);
    sys.log = Some(Vec::new());
    let opts = NewmarkOptions { h_max: 0.01, ..Default::default() };
    let mut nm = Newmark::new(&mut sys, 0.0, &[1.0], &[0.0], opts).unwrap();
    let targets = [1.0 / 3.0, 0.1 + 0.2 + 0.1, 0.4 + 1e-15, 0.4 + 1e-13, 0.4 + 1e-11, 0.7, 0.7 + 1e-9, 1.0, 3.0, 3.0 + 3.0 * f64::EPSILON];
    for &t in &targets {
        nm.advance_to(&mut sys, t).unwrap();
        assert_eq!(nm.state().t, t, "requested {t:e}, got {:e}", nm.state().t);
    }
    let log = sys.log.take().unwrap();
    let mut times: Vec<f64> = log.clone();
    times.dedup();
    assert!(times.windows(2).all(|w| w[1] - w[0] <= 0.01 * (1.0 + 1e-12)), "a step longer than h_max was attempted");
}
