//! First-order states written as y = q' (thesis Section 3.3.2, after Eq. 3.1: "first-order
//! differential equations f(y, y', t) = 0 can be solved by defining y = q' and y' = q''"), mixed
//! first/second-order systems, and inputs held constant between `advance_to` calls.

mod common;

use common::*;
use hexadyn::sim::{Newmark, NewmarkOptions, System};

/// RC circuit τ v' + v = v_in (τ = RC) as a single `Order::First` coordinate. With fixed steps the
/// Newmark formula for q' (Eq. 3.8, γ = 1/2) is the trapezoidal rule: the error against
/// v(t) = v_in + (v0 − v_in) e^(−t/τ) falls as h² (fitted order in [1.9, 2.1] over five steps).
#[test]
fn rc_circuit_fixed_step_is_second_order() {
    let (tau, v_in, v0, t_end) = (0.05, 5.0, 1.0, 0.2);
    let mut log_h = Vec::new();
    let mut log_e = Vec::new();
    for n in [20usize, 40, 80, 160, 320] {
        let h = t_end / n as f64;
        let mut sys = Linear::first_order_lag(tau, 1.0);
        sys.u[0] = v_in;
        let opts = NewmarkOptions { adaptive: false, h_max: h, h_min: 1e-12, tolerance: 1e-10, ..Default::default() };
        let mut nm = Newmark::new(&mut sys, 0.0, &[0.0], &[v0], opts).unwrap();
        let mut err: f64 = 0.0;
        for i in 1..=4 {
            let t = t_end * i as f64 / 4.0;
            nm.advance_to(&mut sys, t).unwrap();
            let exact = v_in + (v0 - v_in) * (-t / tau).exp();
            err = err.max((nm.state().qd[0] - exact).abs());
            // y' = q'' satisfies the equation at the step's end.
            assert!((tau * nm.state().qdd[0] + nm.state().qd[0] - v_in).abs() < 1e-9);
        }
        log_h.push(h.ln());
        log_e.push(err.ln());
    }
    let order = fit_slope(&log_h, &log_e);
    eprintln!("RC circuit (Order::First): measured order {order:.4}, errors {:?}", log_e.iter().map(|e| e.exp()).collect::<Vec<_>>());
    assert!((1.9..=2.1).contains(&order), "order {order}");
}

/// RC circuit with the adaptive step (Eq. 3.15): charging from 0 to 5 V with τ = 50 ms matches the
/// closed form within 1e-4 V at every 10 ms sample at tolerance 1e-8.
#[test]
fn rc_circuit_adaptive_matches_closed_form() {
    let (tau, v_in) = (0.05, 5.0);
    let mut sys = Linear::first_order_lag(tau, 1.0);
    sys.u[0] = v_in;
    let opts = NewmarkOptions { tolerance: 1e-8, h_max: 0.01, ..Default::default() };
    let mut nm = Newmark::new(&mut sys, 0.0, &[0.0], &[0.0], opts).unwrap();
    let mut err: f64 = 0.0;
    for i in 1..=30 {
        let t = 0.01 * i as f64;
        nm.advance_to(&mut sys, t).unwrap();
        err = err.max((nm.state().qd[0] - v_in * (1.0 - (-t / tau).exp())).abs());
    }
    eprintln!("RC circuit adaptive (tol 1e-8): max error {err:.3e} V, {:?}", nm.stats());
    assert!(err < 1e-4, "max error {err}");
}

/// Mass-spring x driven by a DC-motor-like current i (first-order state, i = q', Section 3.3.2
/// after Eq. 3.1; Eq. 3.7-3.8 integrate both):
///   m x'' + k x = kt i,   L i' + R i = V  (step V at t = 0, x = i = 0).
/// Closed form: i = V/R (1 − e^(−t/τ)), τ = L/R, and with ω² = k/m, a = kt V/(R m),
///   x = a/ω² + B e^(−t/τ) + C cos ωt + D sin ωt,  B = −a/(ω² + 1/τ²), C = −a/ω² − B, D = B/(τ ω).
/// The adaptive integration (tolerance 1e-10) matches both states within 1e-5 relative to their
/// final values, over 0.5 s sampled every 10 ms.
#[test]
fn motor_driven_mass_matches_closed_form() {
    let (m, k, kt, l, r, v) = (0.5, 200.0_f64, 0.8, 0.01, 2.0, 12.0);
    let tau = l / r;
    let w = (k / m).sqrt();
    let a = kt * v / (r * m);
    let b = -a / (w * w + 1.0 / (tau * tau));
    let c = -a / (w * w) - b;
    let d = b / (tau * w);
    let x_exact = |t: f64| a / (w * w) + b * (-t / tau).exp() + c * (w * t).cos() + d * (w * t).sin();
    let i_exact = |t: f64| v / r * (1.0 - (-t / tau).exp());
    let mut sys = Linear::motor_mass(m, 0.0, k, kt, l, r);
    sys.u[0] = v;
    let opts = NewmarkOptions { tolerance: 1e-10, h_max: 0.01, ..Default::default() };
    let mut nm = Newmark::new(&mut sys, 0.0, &[0.0, 0.0], &[0.0, 0.0], opts).unwrap();
    // Consistent start: x'' = 0, i' = V/L.
    assert!(nm.state().qdd[0].abs() < 1e-12 && rel(nm.state().qdd[1], v / l) < 1e-12, "{:?}", nm.state());
    let (x_ref, i_ref) = (2.0 * a / (w * w), v / r);
    let (mut ex, mut ei): (f64, f64) = (0.0, 0.0);
    for n in 1..=50 {
        let t = 0.01 * n as f64;
        nm.advance_to(&mut sys, t).unwrap();
        ex = ex.max((nm.state().q[0] - x_exact(t)).abs() / x_ref);
        ei = ei.max((nm.state().qd[1] - i_exact(t)).abs() / i_ref);
    }
    eprintln!("motor-driven mass: max relative errors x {ex:.3e}, i {ei:.3e}; {:?}", nm.stats());
    assert!(ex < 1e-5 && ei < 1e-5, "x error {ex}, i error {ei}");
}

/// The mixed system of the previous test with fixed steps (Eq. 3.7-3.8, β = 1/4, γ = 1/2): both the second-order coordinate x and
/// the first-order state i converge as h² (fitted order of the max error over 0.25 s in
/// [1.9, 2.1]), i.e. the coupling through q' of a first-order state keeps Newmark second order.
#[test]
fn motor_driven_mass_fixed_step_is_second_order() {
    let (m, k, kt, l, r, v) = (0.5, 200.0_f64, 0.8, 0.01, 2.0, 12.0);
    let tau = l / r;
    let w = (k / m).sqrt();
    let a = kt * v / (r * m);
    let b = -a / (w * w + 1.0 / (tau * tau));
    let (c, d) = (-a / (w * w) - b, b / (tau * w));
    let x_exact = |t: f64| a / (w * w) + b * (-t / tau).exp() + c * (w * t).cos() + d * (w * t).sin();
    let i_exact = |t: f64| v / r * (1.0 - (-t / tau).exp());
    let (mut log_h, mut log_ex, mut log_ei) = (Vec::new(), Vec::new(), Vec::new());
    for n in [250usize, 500, 1000, 2000, 4000] {
        let h = 0.25 / n as f64;
        let mut sys = Linear::motor_mass(m, 0.0, k, kt, l, r);
        sys.u[0] = v;
        let opts = NewmarkOptions { adaptive: false, h_max: h, h_min: 1e-12, tolerance: 1e-12, ..Default::default() };
        let mut nm = Newmark::new(&mut sys, 0.0, &[0.0, 0.0], &[0.0, 0.0], opts).unwrap();
        let (mut ex, mut ei): (f64, f64) = (0.0, 0.0);
        for j in 1..=10 {
            let t = 0.025 * j as f64;
            nm.advance_to(&mut sys, t).unwrap();
            ex = ex.max((nm.state().q[0] - x_exact(t)).abs());
            ei = ei.max((nm.state().qd[1] - i_exact(t)).abs());
        }
        log_h.push(h.ln());
        log_ex.push(ex.ln());
        log_ei.push(ei.ln());
    }
    let (px, pi) = (fit_slope(&log_h, &log_ex), fit_slope(&log_h, &log_ei));
    eprintln!("motor-driven mass, fixed step: measured order x {px:.4}, i {pi:.4}");
    assert!((1.9..=2.1).contains(&px) && (1.9..=2.1).contains(&pi), "orders x {px}, i {pi}");
}

/// Zero-order hold of the inputs between `advance_to` calls (Section 3.3.2, inputs u of Eq. 3.16):
/// a first-order lag τ y' + y = u with u = 0 on [0, 0.5), 1 on [0.5, 1.5), −0.5 on [1.5, 2.5]
/// follows the piecewise closed form y = u + (y(t_k) − u) e^(−(t − t_k)/τ) within 2e-5 at every
/// 50 ms sample. After each jump `reset_accelerations` makes q'' consistent again,
/// q'' = (u − y)/τ to 1e-12, where before it still held the old value.
#[test]
fn step_inputs_are_held_between_calls() {
    let tau = 0.2;
    let mut sys = Linear::first_order_lag(tau, 1.0);
    let opts = NewmarkOptions { tolerance: 1e-8, h_max: 0.02, ..Default::default() };
    let mut nm = Newmark::new(&mut sys, 0.0, &[0.0], &[0.0], opts).unwrap();
    let schedule = [(0.0, 0.0), (0.5, 1.0), (1.5, -0.5)];
    let mut y_k = 0.0;
    let mut err: f64 = 0.0;
    for (seg, &(t_k, u)) in schedule.iter().enumerate() {
        let t_next = schedule.get(seg + 1).map_or(2.5, |s| s.0);
        if t_k > 0.0 {
            nm.advance_to(&mut sys, t_k).unwrap();
            y_k = nm.state().qd[0];
            let stale = nm.state().qdd[0];
            sys.set_input(0, u);
            assert_eq!(sys.input(0), u);
            // The acceleration is stale until reset.
            assert!((stale - (u - y_k) / tau).abs() > 1.0, "stale q'' {stale}");
            nm.reset_accelerations(&mut sys).unwrap();
            let fresh = nm.state().qdd[0];
            assert!((fresh - (u - y_k) / tau).abs() < 1e-12, "reset q'' {fresh} vs {}", (u - y_k) / tau);
            assert_eq!(nm.state().t, t_k);
            assert_eq!(nm.state().qd[0], y_k, "reset_accelerations must not move the state");
        }
        let mut t = t_k;
        while t < t_next - 1e-12 {
            t = (t + 0.05).min(t_next);
            nm.advance_to(&mut sys, t).unwrap();
            let exact = u + (y_k - u) * (-(t - t_k) / tau).exp();
            err = err.max((nm.state().qd[0] - exact).abs());
        }
    }
    eprintln!("zero-order hold: max error {err:.3e}, {:?}", nm.stats());
    assert!(err < 2e-5, "max error {err}");
}

/// A system that does not write the change of its residual (`System::input_change` returns
/// false, the default) gets the plain Newton reset from `reset_accelerations_after_input_jump`:
/// the same q'' with the same residual evaluations, on the lag above after u jumps 0 → 1 at
/// t = 0.5, and q'' = (u − y)/τ to 1e-12.
#[test]
fn reset_after_an_input_jump_falls_back_to_the_newton_reset() {
    let tau = 0.2;
    let run = |after_jump: bool| {
        let mut sys = Linear::first_order_lag(tau, 1.0);
        let mut nm = Newmark::new(&mut sys, 0.0, &[0.0], &[0.0], NewmarkOptions { tolerance: 1e-8, h_max: 0.02, ..Default::default() }).unwrap();
        nm.advance_to(&mut sys, 0.5).unwrap();
        sys.set_input(0, 1.0);
        if after_jump {
            nm.reset_accelerations_after_input_jump(&mut sys, &[0.0]).unwrap();
        } else {
            nm.reset_accelerations(&mut sys).unwrap();
        }
        (nm.state().qdd[0], nm.state().qd[0], nm.stats().residual_evaluations)
    };
    let (qdd, y, evaluations) = run(true);
    assert_eq!((qdd, y, evaluations), run(false));
    assert!((qdd - (1.0 - y) / tau).abs() < 1e-12, "q'' {qdd} vs {}", (1.0 - y) / tau);
}

/// Without `reset_accelerations` after an input jump, the first step's Newmark formula (Eq. 3.8)
/// mixes the stale q''(t) with the new q''(t+h): the error estimate of Eq. 3.15 sees the jump and
/// rejects steps, and the result is less accurate than with the reset. Same lag and input step as
/// above (u: 0 → 1 at t = 0.5, y(0.5) = 0), compared at t = 0.55.
#[test]
fn reset_accelerations_after_an_input_jump_pays_off() {
    let tau = 0.2;
    let run = |reset: bool| {
        let mut sys = Linear::first_order_lag(tau, 1.0);
        let opts = NewmarkOptions { tolerance: 1e-7, h_max: 0.02, h_initial: 0.02, ..Default::default() };
        let mut nm = Newmark::new(&mut sys, 0.0, &[0.0], &[0.0], opts).unwrap();
        nm.advance_to(&mut sys, 0.5).unwrap();
        let before = nm.stats().clone();
        sys.set_input(0, 1.0);
        if reset {
            nm.reset_accelerations(&mut sys).unwrap();
        }
        nm.advance_to(&mut sys, 0.55).unwrap();
        let err = (nm.state().qd[0] - (1.0 - (-0.05 / tau).exp())).abs();
        (err, nm.stats().rejected_steps - before.rejected_steps, nm.stats().steps - before.steps)
    };
    let (err_reset, rej_reset, steps_reset) = run(true);
    let (err_stale, rej_stale, steps_stale) = run(false);
    eprintln!(
        "input jump: with reset error {err_reset:.3e} ({rej_reset} rejected, {steps_reset} steps), \
         without {err_stale:.3e} ({rej_stale} rejected, {steps_stale} steps)"
    );
    assert!(rej_stale > rej_reset, "rejections with stale q'': {rej_stale}, after reset: {rej_reset}");
    assert!(err_reset < err_stale, "error with reset {err_reset}, without {err_stale}");
    assert!(err_reset < 1e-5, "error with reset {err_reset}");
}

/// Logistic growth y' = r y (1 − y/K) as a nonlinear first-order state (y = q', no analytic
/// Jacobian: finite differences and modified Newton, Eq. 3.10-3.13). Closed form
/// y = K / (1 + (K/y0 − 1) e^(−r t)). Fixed steps converge as h² (fitted order in [1.9, 2.1]) and
/// the adaptive run at tolerance 1e-8 stays within 1e-5 K of the closed form over 0-10 s.
#[test]
fn logistic_growth_nonlinear_first_order() {
    struct Logistic {
        layout: hexadyn::sim::Layout,
        r: f64,
        k: f64,
    }
    impl System for Logistic {
        fn layout(&self) -> &hexadyn::sim::Layout {
            &self.layout
        }
        fn residual(&mut self, _t: f64, _q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
            f[0] = qdd[0] - self.r * qd[0] * (1.0 - qd[0] / self.k);
        }
    }
    let (r, k, y0) = (1.5, 10.0, 0.2);
    let exact = |t: f64| k / (1.0 + (k / y0 - 1.0) * (-r * t).exp());
    let make = || {
        let mut layout = hexadyn::sim::Layout::default();
        layout.push("population", hexadyn::sim::Order::First, 10.0, "logistic");
        Logistic { layout, r, k }
    };
    let (mut log_h, mut log_e) = (Vec::new(), Vec::new());
    for n in [50usize, 100, 200, 400, 800] {
        let h = 10.0 / n as f64;
        let mut sys = make();
        let opts = NewmarkOptions { adaptive: false, h_max: h, h_min: 1e-12, tolerance: 1e-10, ..Default::default() };
        let mut nm = Newmark::new(&mut sys, 0.0, &[0.0], &[y0], opts).unwrap();
        let mut err: f64 = 0.0;
        for i in 1..=10 {
            nm.advance_to(&mut sys, i as f64).unwrap();
            err = err.max((nm.state().qd[0] - exact(i as f64)).abs());
        }
        log_h.push(h.ln());
        log_e.push(err.ln());
    }
    let order = fit_slope(&log_h, &log_e);
    let mut sys = make();
    let opts = NewmarkOptions { tolerance: 1e-8, h_max: 0.1, ..Default::default() };
    let mut nm = Newmark::new(&mut sys, 0.0, &[0.0], &[y0], opts).unwrap();
    let mut err: f64 = 0.0;
    for i in 1..=100 {
        let t = 0.1 * i as f64;
        nm.advance_to(&mut sys, t).unwrap();
        err = err.max((nm.state().qd[0] - exact(t)).abs());
    }
    eprintln!("logistic: fixed-step order {order:.4}; adaptive (tol 1e-8) max error {err:.3e}, {:?}", nm.stats());
    assert!((1.9..=2.1).contains(&order), "order {order}");
    assert!(err < 1e-5 * k, "max error {err}");
}

/// The consistent accelerations after an input jump at every 10 ms control instant (the walk's
/// zero-order hold) on a cart-pole, whose mass matrix changes with the pole angle: the pole is
/// driven through ±0.8 rad, so the factorization of M kept from one reset to the next goes stale.
/// After every reset q'' solves M(q) q'' = rhs(q, q', u) (closed form, 2 × 2) within the Newton
/// test of the steps (1 % of q'' plus tolerance · newton_tolerance / (β h²)). (A reset stopped
/// after a single correction trusted for nine resets after each verified one was off by up to 194
/// times that; see docs/performance-log.md.)
#[test]
fn consistent_accelerations_at_every_control_instant() {
    let mut sys = CartPole::new();
    let opts = NewmarkOptions { tolerance: 1e-6, h_max: 0.01, ..Default::default() };
    let (beta, h, tol) = (opts.beta, opts.h_max, opts.newton_tolerance * opts.tolerance);
    let mut nm = Newmark::new(&mut sys, 0.0, &[0.0, 0.0], &[0.0, 0.0], opts).unwrap();
    let (mut resets, mut evaluations, mut largest) = (0usize, 0usize, 0.0_f64);
    let mut theta_range = (0.0_f64, 0.0_f64);
    for k in 1..=300 {
        let t = 0.01 * k as f64;
        nm.advance_to(&mut sys, t).unwrap();
        // A pumping force with a jump at every instant.
        let u = 12.0 * (2.0 * t).sin().signum() + 0.5 * (k % 7) as f64;
        sys.set_input(0, u);
        let before = nm.stats().residual_evaluations;
        nm.reset_accelerations(&mut sys).unwrap();
        evaluations += nm.stats().residual_evaluations - before;
        resets += 1;
        let s = nm.state();
        let (q, qd, qdd) = (&s.q, &s.qd, &s.qdd);
        let (m, l, mc) = (sys.m, sys.l, sys.mc);
        let (sn, cs) = q[1].sin_cos();
        let mass = nalgebra::Matrix2::new(mc + m, m * l * cs, m * l * cs, m * l * l);
        let rhs = nalgebra::Vector2::new(u + m * l * sn * qd[1] * qd[1] - sys.cx * qd[0], -m * G * l * sn - sys.ctheta * qd[1]);
        let exact = mass.lu().solve(&rhs).unwrap();
        for i in 0..2 {
            let allowed = 1e-2 * exact[i].abs() + tol / (beta * h * h);
            largest = largest.max((qdd[i] - exact[i]).abs() / allowed);
        }
        theta_range = (theta_range.0.min(q[1]), theta_range.1.max(q[1]));
    }
    eprintln!(
        "cart-pole resets: {resets}, {:.2} residual evaluations each, largest error {largest:.3} of the Newton test, theta in [{:.2}, {:.2}] rad",
        evaluations as f64 / resets as f64,
        theta_range.0,
        theta_range.1
    );
    assert!(theta_range.0 < -0.8 && theta_range.1 > 0.8, "the pole must swing: {theta_range:?}");
    assert!(largest <= 1.0, "reset q'' off by {largest} of the Newton test");
}
