//! Static equilibrium with a chosen subset of coordinates locked (thesis Section 3.3.2).

use nalgebra::{DMatrix, DVector};

use super::error::largest_rows;
use super::{Jacobian, Order, SimError, System};

#[derive(Clone, Debug, PartialEq)]
pub struct StaticOptions {
    /// Converged when the largest |f_i| is below this (in residual units).
    pub residual_tolerance: f64,
    pub max_iterations: usize,
}

impl Default for StaticOptions {
    fn default() -> Self {
        StaticOptions { residual_tolerance: 1e-9, max_iterations: 100 }
    }
}

/// Finds the static equilibrium f(q, q', 0, t) = 0 starting from (q, q').
///
/// The unknowns are q for free second-order coordinates (their q' is held at zero) and q' for
/// first-order states (a motor current at rest is not zero). Coordinates listed in `locked`
/// keep their given value; a row whose coordinate is locked is not required to vanish (the
/// locked coordinate's generalized force is the reaction that holds it). Newton-Raphson on
/// KT / CT with backtracking on the residual norm.
pub fn static_equilibrium<S: System + ?Sized>(
    sys: &mut S,
    t: f64,
    q: &mut [f64],
    qd: &mut [f64],
    locked: &[usize],
    options: &StaticOptions,
) -> Result<(), SimError> {
    let n = q.len();
    let orders = sys.layout().orders.clone();
    let free: Vec<usize> = (0..n).filter(|i| !locked.contains(i)).collect();
    for i in 0..n {
        if orders[i] == Order::Second {
            qd[i] = 0.0;
        }
    }
    let qdd = vec![0.0; n];
    let mut f = vec![0.0; n];
    let norm = |sys: &mut S, q: &[f64], qd: &[f64], f: &mut [f64]| -> f64 {
        sys.residual(t, q, qd, &qdd, f);
        free.iter().map(|&i| f[i] * f[i]).sum::<f64>().sqrt()
    };
    let mut current = norm(sys, q, qd, &mut f);
    // `max_iterations` Newton updates, each followed by the convergence test (the last update is
    // tested too).
    for iteration in 0..=options.max_iterations {
        let worst = free.iter().map(|&i| f[i].abs()).fold(0.0, f64::max);
        if !worst.is_finite() {
            return Err(SimError::NonFinite { t, h: None, rows: largest_rows(sys.layout(), &f, 5) });
        }
        if worst <= options.residual_tolerance {
            return Ok(());
        }
        if iteration == options.max_iterations {
            break;
        }
        let jac = Jacobian::evaluate(sys, t, q, qd, &qdd);
        let k = free.len();
        let mut a = DMatrix::zeros(k, k);
        let mut rhs = DVector::zeros(k);
        for (r, &i) in free.iter().enumerate() {
            rhs[r] = f[i];
            for (c, &j) in free.iter().enumerate() {
                a[(r, c)] = match orders[j] {
                    Order::Second => jac.kt[(i, j)],
                    Order::First => jac.ct[(i, j)],
                };
            }
        }
        // A tangent stiffness that vanishes in some direction (a foot just touching the
        // ground, Eq. 3.72 with δ = 0) is regularized Levenberg-Marquardt style, and so is a
        // step along which the backtracking finds no decrease of the residual: the damping
        // grows a hundredfold until one does (the step turns towards the gradient and
        // shortens). Past the largest damping the backtracking's last step is taken.
        let scale = (0..k).map(|i| a[(i, i)].abs()).fold(0.0, f64::max).max(1e-300);
        let grow = |damping: f64| if damping == 0.0 { 1e-9 * scale } else { damping * 100.0 };
        let (q0, qd0) = (q.to_vec(), qd.to_vec());
        let mut damping = 0.0;
        loop {
            let mut damped = a.clone();
            for i in 0..k {
                damped[(i, i)] += damping;
            }
            let dx = match damped.lu().solve(&rhs) {
                Some(dx) if dx.iter().all(|x| x.is_finite()) => dx,
                _ if damping < scale => {
                    damping = grow(damping);
                    continue;
                }
                _ => return Err(SimError::Singular { what: "static tangent stiffness", t }),
            };
            // The backtracking's last trial (q, q' and f are at it) and whether it decreased.
            let mut lambda = 1.0;
            let (trial, decreased) = loop {
                for (c, &j) in free.iter().enumerate() {
                    match orders[j] {
                        Order::Second => q[j] = q0[j] - lambda * dx[c],
                        Order::First => qd[j] = qd0[j] - lambda * dx[c],
                    }
                }
                let trial = norm(sys, q, qd, &mut f);
                if trial.is_finite() && trial < current {
                    break (trial, true);
                }
                if lambda < 1e-4 {
                    break (trial, false);
                }
                lambda *= 0.5;
            };
            if decreased || damping >= 1e6 * scale {
                current = trial;
                break;
            }
            damping = grow(damping);
        }
    }
    sys.residual(t, q, qd, &qdd, &mut f);
    let free_f: Vec<f64> = (0..n).map(|i| if locked.contains(&i) { 0.0 } else { f[i] }).collect();
    Err(SimError::NoEquilibrium { iterations: options.max_iterations, rows: largest_rows(sys.layout(), &free_f, 5) })
}
