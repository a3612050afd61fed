//! Static equilibrium f(q, 0, 0, t) = 0 with locked coordinates (thesis Section 3.3.2,
//! `StaticEquilibrium()`).

mod common;

use common::*;
use hexadyn::sim::{static_equilibrium, SimError, StaticOptions};

/// Static equilibrium f(q, 0, 0, t) = 0 (Eq. 3.1 at rest). Inverted pendulum held by a torsion
/// spring, m l² θ'' + k θ − m g l sin θ = 0 (θ from the
/// upright): the spring is chosen as k = m g l sin θ*/θ* with θ* = π/3, so the nonlinear
/// equilibrium k θ = m g l sin θ has the closed-form root θ*. Newton from θ = 1.3 rad (with a
/// non-zero initial velocity, which must be zeroed) finds it within 1e-12 rad (residual tolerance
/// 1e-12 N·m), with and without the analytic Jacobian.
#[test]
fn pendulum_with_torsion_spring() {
    let (m, l) = (1.2, 0.7);
    let theta_star = std::f64::consts::FRAC_PI_3;
    let k = m * G * l * theta_star.sin() / theta_star;
    for exact in [true, false] {
        let mut sys = Pendulum::inverted_with_spring(m, l, 0.4, k);
        sys.exact_jacobian = exact;
        let (mut q, mut qd) = ([1.3], [2.0]);
        let opts = StaticOptions { residual_tolerance: 1e-12, ..Default::default() };
        static_equilibrium(&mut sys, 0.0, &mut q, &mut qd, &[], &opts).unwrap();
        assert!((q[0] - theta_star).abs() < 1e-12, "exact jacobian {exact}: theta {} vs {theta_star}", q[0]);
        assert_eq!(qd[0], 0.0);
    }
}

/// Static equilibrium (Eq. 3.1 at rest) of a hanging pendulum under a constant torque u: m g l sin θ = u, θ = asin(u / (m g l)), within
/// 1e-12 rad (residual tolerance 1e-12 N·m).
#[test]
fn pendulum_under_constant_torque() {
    let (m, l) = (0.8, 0.5);
    let mut sys = Pendulum::hanging(m, l, 0.1);
    sys.u = 0.6 * m * G * l;
    let (mut q, mut qd) = ([0.0], [0.0]);
    let opts = StaticOptions { residual_tolerance: 1e-12, ..Default::default() };
    static_equilibrium(&mut sys, 0.0, &mut q, &mut qd, &[], &opts).unwrap();
    assert!((q[0] - 0.6_f64.asin()).abs() < 1e-12, "theta {}", q[0]);
}

/// Static equilibrium (Eq. 3.1 at rest) of three masses hanging in a vertical chain (x downward, from the unstretched springs; springs
/// ground–1, 1–2, 2–3, no bottom spring) under gravity m_i g:
/// - free: x1 = (m1+m2+m3) g/k1, x2 = x1 + (m2+m3) g/k2, x3 = x2 + m3 g/k3;
/// - with x1 locked at a: x1 stays exactly a, x2 = a + (m2+m3) g/k2, x3 = x2 + m3 g/k3, and the
///   residual of the locked row is the reaction (m1+m2+m3) g − k1 a, not zero.
///
/// All within 1e-12 m.
#[test]
fn hanging_chain_with_locked_coordinate() {
    let masses = [1.0, 2.0, 0.5];
    let springs = [300.0, 150.0, 80.0, 0.0];
    let make = || {
        let mut sys = Linear::chain(masses, springs, 0.0, 0.0);
        sys.load = masses.iter().map(|mi| mi * G).collect();
        sys
    };
    let (k1, k2, k3) = (springs[0], springs[1], springs[2]);
    let (m1, m2, m3) = (masses[0], masses[1], masses[2]);

    let mut sys = make();
    let (mut q, mut qd) = ([0.0; 3], [0.1, -0.2, 0.3]);
    static_equilibrium(&mut sys, 0.0, &mut q, &mut qd, &[], &StaticOptions::default()).unwrap();
    let x1 = (m1 + m2 + m3) * G / k1;
    let x2 = x1 + (m2 + m3) * G / k2;
    let x3 = x2 + m3 * G / k3;
    for (got, want) in q.iter().zip([x1, x2, x3]) {
        assert!((got - want).abs() < 1e-12, "free chain {q:?} vs {:?}", [x1, x2, x3]);
    }
    assert_eq!(qd, [0.0; 3]);

    let a = 0.01;
    let mut sys = make();
    let (mut q, mut qd) = ([a, 0.0, 0.0], [0.0; 3]);
    static_equilibrium(&mut sys, 0.0, &mut q, &mut qd, &[0], &StaticOptions::default()).unwrap();
    assert_eq!(q[0], a, "the locked coordinate moved");
    let x2 = a + (m2 + m3) * G / k2;
    let x3 = x2 + m3 * G / k3;
    assert!((q[1] - x2).abs() < 1e-12 && (q[2] - x3).abs() < 1e-12, "locked chain {q:?} vs [{a}, {x2}, {x3}]");
    let mut f = [0.0; 3];
    hexadyn::sim::System::residual(&mut sys, 0.0, &q, &qd, &[0.0; 3], &mut f);
    let reaction = k1 * a - (m1 + m2 + m3) * G;
    assert!((f[0] - reaction).abs() < 1e-9, "locked row residual {} vs reaction {reaction}", f[0]);
}

/// Equilibrium (Eq. 3.1 with q' = 0 for second-order and y' = q'' = 0 for first-order states): for the motor-driven mass at constant voltage the unknown
/// of the motor row is the current i = q' (not q): i = V/R and x = kt i / k, within 1e-12.
#[test]
fn motor_driven_mass_at_rest() {
    let (k, kt, r, v) = (200.0, 0.8, 2.0, 12.0);
    let mut sys = Linear::motor_mass(0.5, 0.3, k, kt, 0.01, r);
    sys.u[0] = v;
    sys.exact_jacobian = false;
    let (mut q, mut qd) = ([0.0, 123.0], [0.0, 0.0]);
    static_equilibrium(&mut sys, 0.0, &mut q, &mut qd, &[], &StaticOptions::default()).unwrap();
    assert!(rel(qd[1], v / r) < 1e-12, "current {} vs {}", qd[1], v / r);
    assert!(rel(q[0], kt * v / (r * k)) < 1e-12, "x {} vs {}", q[0], kt * v / (r * k));
    assert_eq!(q[1], 123.0, "q of a first-order state is meaningless and must be left alone");
}

/// No root of Eq. 3.1 at rest: a torque larger than m g l cannot be held by a pendulum: static_equilibrium fails with
/// NoEquilibrium, naming the coordinate "theta" and the element "pendulum".
#[test]
fn impossible_equilibrium_is_reported() {
    let (m, l) = (0.8, 0.5);
    let mut sys = Pendulum::hanging(m, l, 0.0);
    sys.u = 1.5 * m * G * l;
    let (mut q, mut qd) = ([0.0], [0.0]);
    let err = static_equilibrium(&mut sys, 0.0, &mut q, &mut qd, &[], &StaticOptions { max_iterations: 30, ..Default::default() }).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, SimError::NoEquilibrium { iterations: 30, .. }), "{msg}");
    assert!(msg.contains("theta") && msg.contains("pendulum"), "{msg}");
}

/// Converging (Eq. 3.1 at rest) on the very last allowed Newton iteration is success: the hanging chain (linear, so Newton
/// converges in one iteration) with max_iterations = 1 succeeds.
#[test]
fn convergence_on_the_last_iteration_counts() {
    let mut sys = Linear::chain([1.0, 2.0, 0.5], [300.0, 150.0, 80.0, 50.0], 0.0, 0.0);
    sys.load = vec![1.0, 2.0, 3.0];
    let (mut q, mut qd) = ([0.0; 3], [0.0; 3]);
    static_equilibrium(&mut sys, 0.0, &mut q, &mut qd, &[], &StaticOptions { max_iterations: 1, ..Default::default() }).unwrap();
    let mut f = [0.0; 3];
    hexadyn::sim::System::residual(&mut sys, 0.0, &q, &qd, &[0.0; 3], &mut f);
    assert!(f.iter().all(|x| x.abs() < 1e-9), "{f:?}");
}
