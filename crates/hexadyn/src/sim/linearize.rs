//! Linearization around a state (thesis Eq. 3.16-3.17) and the poles of the linearized system.

use nalgebra::{Complex, DMatrix};

use super::{Jacobian, Order, SimError, System};

/// M Δq'' + CT Δq' + KT Δq = F u (Eq. 3.17).
#[derive(Clone, Debug)]
pub struct Linearization {
    pub m: DMatrix<f64>,
    pub ct: DMatrix<f64>,
    pub kt: DMatrix<f64>,
    /// Input influence matrix F = -∂f/∂u.
    pub f: DMatrix<f64>,
    orders: Vec<Order>,
}

/// A pole λ of the linearized system with its natural frequency and damping ratio.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pole {
    pub value: Complex<f64>,
    /// |λ| / 2π.
    pub frequency_hz: f64,
    /// -Re(λ) / |λ| (1 for a real negative pole).
    pub damping_ratio: f64,
}

/// Linearizes `sys` around (t, q, q', q''): exact or finite-difference M, CT, KT and a central
/// finite difference of the inputs for F.
pub fn linearize<S: System + ?Sized>(sys: &mut S, t: f64, q: &[f64], qd: &[f64], qdd: &[f64]) -> Linearization {
    let n = q.len();
    let jac = Jacobian::evaluate(sys, t, q, qd, qdd);
    let nu = sys.input_count();
    let mut f = DMatrix::zeros(n, nu);
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    for k in 0..nu {
        let u0 = sys.input(k);
        let du = 1e-6 * u0.abs().max(1.0);
        sys.set_input(k, u0 + du);
        sys.residual(t, q, qd, qdd, &mut fp);
        sys.set_input(k, u0 - du);
        sys.residual(t, q, qd, qdd, &mut fm);
        sys.set_input(k, u0);
        for i in 0..n {
            f[(i, k)] = -(fp[i] - fm[i]) / (2.0 * du);
        }
    }
    Linearization { m: jac.m, ct: jac.ct, kt: jac.kt, f, orders: sys.layout().orders.clone() }
}

impl Linearization {
    /// State-space matrix A of ẋ = A x with x = (q of second-order coordinates, q' of all
    /// coordinates); first-order states contribute only their q' (their q is meaningless).
    pub fn state_matrix(&self) -> Result<DMatrix<f64>, SimError> {
        let n = self.m.nrows();
        let second: Vec<usize> = (0..n).filter(|&i| self.orders[i] == Order::Second).collect();
        let ns = second.len();
        let minv = self.m.clone().try_inverse().ok_or(SimError::Singular { what: "mass (M = ∂f/∂q'')", t: f64::NAN })?;
        let mut a = DMatrix::zeros(ns + n, ns + n);
        for (r, &i) in second.iter().enumerate() {
            a[(r, ns + i)] = 1.0;
        }
        let mk = -&minv * &self.kt;
        let mc = -&minv * &self.ct;
        for i in 0..n {
            for (c, &j) in second.iter().enumerate() {
                a[(ns + i, c)] = mk[(i, j)];
            }
            for j in 0..n {
                a[(ns + i, ns + j)] = mc[(i, j)];
            }
        }
        Ok(a)
    }

    /// Eigenvalues of [`Self::state_matrix`], sorted by increasing frequency.
    pub fn poles(&self) -> Result<Vec<Pole>, SimError> {
        let a = self.state_matrix()?;
        let mut poles: Vec<Pole> = a
            .complex_eigenvalues()
            .iter()
            .map(|&value| {
                let modulus = value.norm();
                Pole {
                    value,
                    frequency_hz: modulus / (2.0 * std::f64::consts::PI),
                    damping_ratio: if modulus > 0.0 { -value.re / modulus } else { 0.0 },
                }
            })
            .collect();
        poles.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz).then(a.value.im.total_cmp(&b.value.im)));
        Ok(poles)
    }
}
