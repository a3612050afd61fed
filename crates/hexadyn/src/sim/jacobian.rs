//! Jacobian blocks of a residual system and their finite-difference estimate.

use nalgebra::DMatrix;

use super::System;

/// The blocks M = ∂f/∂q'', CT = ∂f/∂q' and KT = ∂f/∂q (Eq. 3.12, 3.17).
#[derive(Clone, Debug, PartialEq)]
pub struct Jacobian {
    pub m: DMatrix<f64>,
    pub ct: DMatrix<f64>,
    pub kt: DMatrix<f64>,
}

/// A rows × cols matrix of zeros from a zeroed allocation: nalgebra's `DMatrix::zeros` writes
/// the entries one by one (about 8 instructions each, 14 k for the three 42 × 42 blocks of a
/// Jacobian).
pub(crate) fn zero_matrix(rows: usize, cols: usize) -> DMatrix<f64> {
    DMatrix::from_vec(rows, cols, vec![0.0; rows * cols])
}

impl Jacobian {
    pub fn zeros(n: usize) -> Self {
        Jacobian { m: zero_matrix(n, n), ct: zero_matrix(n, n), kt: zero_matrix(n, n) }
    }
    pub fn fill_zero(&mut self) {
        self.m.fill(0.0);
        self.ct.fill(0.0);
        self.kt.fill(0.0);
    }
    /// The Newmark iteration matrix J = M + γh CT + βh² KT (Eq. 3.14).
    pub fn iteration_matrix(&self, beta: f64, gamma: f64, h: f64) -> DMatrix<f64> {
        let (g, b) = (gamma * h, beta * h * h);
        let mut j = self.m.clone();
        for ((x, c), k) in j.as_mut_slice().iter_mut().zip(self.ct.as_slice()).zip(self.kt.as_slice()) {
            *x += c * g + k * b;
        }
        j
    }
    /// Exact blocks when the system provides them, finite differences otherwise.
    pub fn evaluate<S: System + ?Sized>(sys: &mut S, t: f64, q: &[f64], qd: &[f64], qdd: &[f64]) -> Self {
        let mut jac = Jacobian::zeros(q.len());
        if !sys.jacobian(t, q, qd, qdd, &mut jac) {
            jac = finite_difference_jacobian(sys, t, q, qd, qdd);
        }
        jac
    }
}

/// Column-by-column central finite-difference estimate of M, CT and KT (the EasyDyn method of
/// Section 3.3.2). It is the fallback for systems without analytic blocks and the oracle the
/// analytic blocks are tested against. The steps are 1e-6 times the coordinate or its scale
/// ([`finite_difference_jacobian_with_steps`]).
pub fn finite_difference_jacobian<S: System + ?Sized>(sys: &mut S, t: f64, q: &[f64], qd: &[f64], qdd: &[f64]) -> Jacobian {
    finite_difference_jacobian_with_steps(sys, t, q, qd, qdd, 1e-6)
}

/// [`finite_difference_jacobian`] with the steps `relative` times the coordinate or its scale:
/// a test compares two step sizes to see the estimate's own error (rounding grows as the step
/// shrinks, truncation as it grows).
pub fn finite_difference_jacobian_with_steps<S: System + ?Sized>(sys: &mut S, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], relative: f64) -> Jacobian {
    let n = q.len();
    let scales = sys.layout().scales.clone();
    let mut jac = Jacobian::zeros(n);
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    let mut x = [q.to_vec(), qd.to_vec(), qdd.to_vec()];
    for block in 0..3 {
        for j in 0..n {
            let x0 = x[block][j];
            // Residuals are usually linear in q'' (rounding is the only error there: take a
            // unit floor); q and q' steps follow the coordinate's scale.
            let floor = if block == 2 { 1.0 } else { scales.get(j).copied().unwrap_or(1.0) };
            let step = relative * x0.abs().max(floor).max(1e-12);
            x[block][j] = x0 + step;
            sys.residual(t, &x[0], &x[1], &x[2], &mut fp);
            x[block][j] = x0 - step;
            sys.residual(t, &x[0], &x[1], &x[2], &mut fm);
            x[block][j] = x0;
            let target = match block {
                0 => &mut jac.kt,
                1 => &mut jac.ct,
                _ => &mut jac.m,
            };
            for i in 0..n {
                target[(i, j)] = (fp[i] - fm[i]) / (2.0 * step);
            }
        }
    }
    jac
}

/// M = ∂f/∂q'': from the system when it provides it (`true` in the result), else the M block of
/// [`Jacobian::evaluate`] (`false`).
pub fn mass_matrix<S: System + ?Sized>(sys: &mut S, t: f64, q: &[f64], qd: &[f64], qdd: &[f64]) -> (DMatrix<f64>, bool) {
    let n = q.len();
    let mut m = DMatrix::zeros(n, n);
    if sys.mass_matrix(t, q, qd, qdd, &mut m) {
        return (m, true);
    }
    (Jacobian::evaluate(sys, t, q, qd, qdd).m, false)
}
