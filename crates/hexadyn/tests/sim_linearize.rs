//! Linearization M Δq'' + CT Δq' + KT Δq = F u (thesis Eq. 3.16-3.17), poles of the linearized
//! system, and the Jacobian blocks of Eq. 3.12 (analytic against finite differences).

mod common;

use std::f64::consts::PI;

use common::*;
use hexadyn::sim::{finite_difference_jacobian, linearize, Jacobian, Newmark, NewmarkOptions, Pole, System};
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The two poles of an underdamped mode, from a sorted pole list.
fn pair(poles: &[Pole], mode: usize) -> (Pole, Pole) {
    (poles[2 * mode], poles[2 * mode + 1])
}

/// Pendulum m l² θ'' + c θ' + m g l sin θ = u linearized at the bottom (Eq. 3.17):
/// M = m l², CT = c, KT = m g l, F = 1 (−∂f/∂u). Exact with the analytic Jacobian (F, from the
/// central difference on u of a linear dependence, to 1e-9); within 1e-6 relative from finite
/// differences. The two poles have natural frequency |λ|/2π = √(g/l)/2π and damping ratio
/// ζ = c / (2 m l² ω), to 1e-12 (analytic) and 1e-6 (finite differences) relative; they are complex
/// conjugates with Im λ = ω √(1 − ζ²).
#[test]
fn pendulum_at_the_bottom() {
    let (m, l, c) = (0.8, 0.5, 0.12);
    let w = (G / l).sqrt();
    let zeta = c / (2.0 * m * l * l * w);
    for exact in [true, false] {
        let tol = if exact { 1e-12 } else { 1e-6 };
        let mut sys = Pendulum::hanging(m, l, c);
        sys.exact_jacobian = exact;
        sys.u = 0.3; // a non-zero operating input: F must not depend on it
        let lin = linearize(&mut sys, 0.0, &[0.0], &[0.0], &[0.0]);
        assert!(rel(lin.m[(0, 0)], m * l * l) <= tol, "M {}", lin.m);
        assert!(rel(lin.ct[(0, 0)], c) <= tol, "CT {}", lin.ct);
        assert!(rel(lin.kt[(0, 0)], m * G * l) <= tol, "KT {}", lin.kt);
        assert!(rel(lin.f[(0, 0)], 1.0) <= 1e-9, "F {}", lin.f);
        assert_eq!(sys.u, 0.3, "linearize must restore the input");
        let poles = lin.poles().unwrap();
        assert_eq!(poles.len(), 2);
        let (a, b) = pair(&poles, 0);
        for p in [a, b] {
            assert!(rel(p.frequency_hz, w / (2.0 * PI)) <= tol, "exact {exact}: f = {} Hz vs {}", p.frequency_hz, w / (2.0 * PI));
            assert!(rel(p.damping_ratio, zeta) <= tol, "exact {exact}: zeta = {} vs {zeta}", p.damping_ratio);
            assert!(rel(p.value.im.abs(), w * (1.0 - zeta * zeta).sqrt()) <= tol);
        }
        assert!(a.value.im * b.value.im < 0.0, "complex conjugate pair expected: {poles:?}");
    }
}

/// Linearized away from the bottom, at θ0 = 0.3 rad, the tangent stiffness (Eq. 3.12) is
/// KT = m g l cos θ0 (to 1e-6 relative from finite differences) and the frequency √(g cos θ0 / l)/2π.
#[test]
fn pendulum_off_the_bottom() {
    let (m, l) = (0.8, 0.5);
    let theta0 = 0.3_f64;
    let mut sys = Pendulum::hanging(m, l, 0.0);
    sys.exact_jacobian = false;
    let lin = linearize(&mut sys, 0.0, &[theta0], &[0.0], &[0.0]);
    assert!(rel(lin.kt[(0, 0)], m * G * l * theta0.cos()) < 1e-6, "KT {}", lin.kt);
    let f = lin.poles().unwrap()[0].frequency_hz;
    assert!(rel(f, (G * theta0.cos() / l).sqrt() / (2.0 * PI)) < 1e-6, "f = {f}");
}

/// Three masses, four springs (both ends to the walls) and Rayleigh damping C = α M + β K: the
/// linearization (Eq. 3.17) reproduces M, C, K and F = I exactly, and each pair of poles has |λ| = ω_i and
/// ζ_i = α/(2 ω_i) + β ω_i/2, where ω_i² are the eigenvalues of the generalized symmetric problem
/// K φ = ω² M φ, solved independently as SymmetricEigen(M^-½ K M^-½): agreement to 1e-8 relative,
/// with the analytic and with the finite-difference Jacobian.
#[test]
fn spring_mass_chain_eigenfrequencies() {
    let masses = [1.0, 2.0, 1.5];
    let springs = [100.0, 200.0, 150.0, 80.0];
    let (alpha, beta) = (0.5, 1e-3);
    let reference = Linear::chain(masses, springs, alpha, beta);
    let m_inv_sqrt = DMatrix::from_diagonal(&DVector::from_iterator(3, masses.iter().map(|m| 1.0 / m.sqrt())));
    let sym = &m_inv_sqrt * &reference.k * &m_inv_sqrt;
    let mut w2: Vec<f64> = sym.symmetric_eigen().eigenvalues.iter().copied().collect();
    w2.sort_by(f64::total_cmp);
    let omegas: Vec<f64> = w2.iter().map(|x| x.sqrt()).collect();
    for exact in [true, false] {
        let mut sys = Linear::chain(masses, springs, alpha, beta);
        sys.exact_jacobian = exact;
        let q0 = [0.01, -0.02, 0.03];
        let lin = linearize(&mut sys, 0.0, &q0, &[0.0; 3], &[0.0; 3]);
        let close = |a: &DMatrix<f64>, b: &DMatrix<f64>| (a - b).amax() <= 1e-8 * b.amax();
        assert!(close(&lin.m, &reference.m) && close(&lin.ct, &reference.c) && close(&lin.kt, &reference.k), "exact {exact}: {lin:?}");
        assert!(close(&lin.f, &DMatrix::identity(3, 3)), "F = {}", lin.f);
        let poles = lin.poles().unwrap();
        assert_eq!(poles.len(), 6);
        for (i, &w) in omegas.iter().enumerate() {
            let zeta = alpha / (2.0 * w) + beta * w / 2.0;
            let (a, b) = pair(&poles, i);
            for p in [a, b] {
                assert!(rel(p.frequency_hz, w / (2.0 * PI)) < 1e-8, "exact {exact}, mode {i}: {} Hz vs {}", p.frequency_hz, w / (2.0 * PI));
                assert!(rel(p.damping_ratio, zeta) < 1e-8, "exact {exact}, mode {i}: zeta {} vs {zeta}", p.damping_ratio);
            }
        }
        if exact {
            eprintln!("chain natural frequencies (Hz): {:?}", omegas.iter().map(|w| w / (2.0 * PI)).collect::<Vec<_>>());
        }
    }
}

/// Poles with a first-order state (state vector x = (q of second-order coordinates, q' of all),
/// Eq. 3.17): the motor-driven mass m x'' + c x' + k x = kt i, L i' + R i = V has the motor pole
/// −R/L (real: damping ratio 1) and the mechanical pair, roots of m s² + c s + k; the state matrix is
/// 3×3 (q of the current is meaningless and excluded). Agreement to 1e-9 relative.
#[test]
fn poles_with_a_first_order_state() {
    let (m, c, k, kt, l, r) = (0.5, 0.4, 200.0_f64, 0.8, 0.01, 2.0);
    let mut sys = Linear::motor_mass(m, c, k, kt, l, r);
    let lin = linearize(&mut sys, 0.0, &[0.0, 0.0], &[0.0, 0.0], &[0.0, 0.0]);
    assert!(rel(lin.f[(1, 0)], 1.0) < 1e-9 && lin.f[(0, 0)].abs() < 1e-9, "F = {}", lin.f);
    assert_eq!(lin.state_matrix().unwrap().shape(), (3, 3));
    let poles = lin.poles().unwrap();
    assert_eq!(poles.len(), 3);
    let w = (k / m).sqrt();
    let zeta = c / (2.0 * (k * m).sqrt());
    // Sorted by frequency: the mechanical pair (~3.2 Hz) first, then the motor (R/L/2π ≈ 31.8 Hz).
    for p in &poles[..2] {
        assert!(rel(p.frequency_hz, w / (2.0 * PI)) < 1e-9 && rel(p.damping_ratio, zeta) < 1e-9, "{poles:?}");
    }
    assert!(rel(poles[2].value.re, -r / l) < 1e-9 && poles[2].value.im.abs() < 1e-9 * r / l, "{poles:?}");
    assert!(rel(poles[2].damping_ratio, 1.0) < 1e-12, "{poles:?}");
}

/// Column-by-column finite differences (the EasyDyn numerical derivation, Section 3.3.2) agree with
/// the analytic blocks M = ∂f/∂q'', CT = ∂f/∂q', KT = ∂f/∂q (Eq. 3.12) within 1e-6 relative (to the
/// largest entry of the row) at 50 random states of each test system: the nonlinear pendulum with
/// torsion spring, the cart-pole (configuration-dependent mass matrix, velocity-quadratic terms) and
/// the spring-mass chain.
#[test]
fn finite_difference_jacobian_matches_analytic_blocks() {
    let mut rng = ChaCha8Rng::seed_from_u64(35);
    let mut systems: Vec<Box<dyn System>> = vec![
        Box::new(Pendulum::inverted_with_spring(1.2, 0.7, 0.3, 4.0)),
        Box::new(CartPole::new()),
        Box::new(Linear::chain([1.0, 2.0, 1.5], [100.0, 200.0, 150.0, 80.0], 0.5, 1e-3)),
    ];
    let mut worst: f64 = 0.0;
    for sys in systems.iter_mut() {
        let n = sys.layout().len();
        for _ in 0..50 {
            let mut draw = |s: f64| (0..n).map(|_| rng.random_range(-s..s)).collect::<Vec<f64>>();
            let (q, qd, qdd) = (draw(3.0), draw(5.0), draw(20.0));
            let t = 0.37;
            let mut exact = Jacobian::zeros(n);
            assert!(sys.jacobian(t, &q, &qd, &qdd, &mut exact));
            let fd = finite_difference_jacobian(sys.as_mut(), t, &q, &qd, &qdd);
            for i in 0..n {
                let scale = (0..n).map(|j| exact.m[(i, j)].abs().max(exact.ct[(i, j)].abs()).max(exact.kt[(i, j)].abs())).fold(0.0, f64::max);
                for (name, a, b) in [("M", &fd.m, &exact.m), ("CT", &fd.ct, &exact.ct), ("KT", &fd.kt, &exact.kt)] {
                    for j in 0..n {
                        let err = (a[(i, j)] - b[(i, j)]).abs() / scale;
                        worst = worst.max(err);
                        assert!(err < 1e-6, "{name}[{i},{j}] fd {} vs exact {} at q {q:?} qd {qd:?} qdd {qdd:?}", a[(i, j)], b[(i, j)]);
                    }
                }
            }
        }
    }
    eprintln!("finite-difference vs analytic Jacobian: worst relative difference {worst:.3e}");
}

/// The Newmark iteration matrix is J = M + γh CT + βh² KT (Eq. 3.14).
#[test]
fn iteration_matrix_is_eq_3_14() {
    let mut sys = CartPole::new();
    let (q, qd, qdd) = ([0.2, 0.7], [-0.3, 1.1], [0.5, -2.0]);
    let mut jac = Jacobian::zeros(2);
    sys.jacobian(0.0, &q, &qd, &qdd, &mut jac);
    let (beta, gamma, h) = (0.3025, 0.6, 0.01);
    let j = jac.iteration_matrix(beta, gamma, h);
    let expected = &jac.m + &jac.ct * (gamma * h) + &jac.kt * (beta * h * h);
    assert!((j - expected).amax() < 1e-15);
    // Jacobian::evaluate uses the analytic blocks when the system has them.
    assert_eq!(Jacobian::evaluate(&mut sys, 0.0, &q, &qd, &qdd), jac);
}

/// Modified Newton (Eq. 3.10, iteration matrix Eq. 3.13-3.14): on a nonlinear system (cart-pole swinging from 1.2 rad under a constant force) the modified
/// Newton iteration converges to the same trajectory with the analytic Jacobian and with the
/// finite-difference fallback: states at t = 2 s agree within 1e-7.
#[test]
fn analytic_and_numerical_jacobians_integrate_alike() {
    struct NoJacobian(CartPole);
    impl System for NoJacobian {
        fn layout(&self) -> &hexadyn::sim::Layout {
            self.0.layout()
        }
        fn residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
            self.0.residual(t, q, qd, qdd, f)
        }
    }
    let opts = NewmarkOptions { tolerance: 1e-8, ..Default::default() };
    let mut a = CartPole::new();
    a.u = 0.5;
    let mut b = NoJacobian(CartPole::new());
    b.0.u = 0.5;
    let mut na = Newmark::new(&mut a, 0.0, &[0.0, 1.2], &[0.0, 0.0], opts.clone()).unwrap();
    let mut nb = Newmark::new(&mut b, 0.0, &[0.0, 1.2], &[0.0, 0.0], opts).unwrap();
    na.advance_to(&mut a, 2.0).unwrap();
    nb.advance_to(&mut b, 2.0).unwrap();
    let (sa, sb) = (na.state(), nb.state());
    let diff = (&sa.q - &sb.q).amax().max((&sa.qd - &sb.qd).amax());
    eprintln!("cart-pole analytic vs finite-difference Jacobian: max state difference {diff:.3e}; {:?} / {:?}", na.stats(), nb.stats());
    assert!(diff < 1e-7, "{sa:?} vs {sb:?}");
}
