//! The Newton convergence test of a Newmark step (Section 3.3.2): the correction of the
//! integrated quantities against the Newton tolerance, and of q'' against q'' itself.

use std::sync::Arc;

use nalgebra::DVector;

use super::newmark::NewmarkOptions;
use super::Order;

/// What the Newton test of every step size shares: per coordinate, the factors of its powers of
/// h, second-order coordinates in the `second` entries and first-order ones in the `first`
/// entries (zero in the other), for the options and the weights (inverse error scales) they were
/// built for.
pub(super) struct NewtonScales {
    options: NewmarkOptions,
    weight: DVector<f64>,
    /// (β w_i)² / n and (γ w_i)² / n: the metric is h⁴ second_i + h² first_i.
    metric: (Vec<f64>, Vec<f64>),
    /// newton_tolerance · tolerance / (w_i β) and / (w_i γ): the floor at h_ref is
    /// second_i / h_ref² + first_i / h_ref.
    floor: (Vec<f64>, Vec<f64>),
}

impl NewtonScales {
    pub(super) fn new(options: &NewmarkOptions, orders: &[Order], weight: &DVector<f64>) -> Self {
        let n = orders.len() as f64;
        let converge_at = options.newton_tolerance * options.tolerance;
        // value(w_i, β or γ) in the entries of coordinates of `order`, zero in the others.
        let entries = |order: Order, value: &dyn Fn(f64, f64) -> f64| -> Vec<f64> {
            let factor = if order == Order::Second { options.beta } else { options.gamma };
            orders.iter().zip(weight.iter()).map(|(o, &w)| if *o == order { value(w, factor) } else { 0.0 }).collect()
        };
        let (metric, floor) = (|w: f64, c: f64| (c * w).powi(2) / n, |w: f64, c: f64| converge_at / w / c);
        NewtonScales {
            options: options.clone(),
            weight: weight.clone(),
            metric: (entries(Order::Second, &metric), entries(Order::First, &metric)),
            floor: (entries(Order::Second, &floor), entries(Order::First, &floor)),
        }
    }

    pub(super) fn is_for(&self, options: &NewmarkOptions, weight: &DVector<f64>) -> bool {
        // On the slices: nalgebra's `==` compares through its generic element iterator, about
        // five times the instructions.
        self.options == *options && self.weight.as_slice() == weight.as_slice()
    }
}

/// The Newton convergence test of a step of size h.
pub(super) struct NewtonTest {
    scales: Arc<NewtonScales>,
    /// Newton corrections are measured on the integrated quantity: q (βh² Δq'') for
    /// second-order coordinates and q' (γh Δq'') for first-order ones, in units of their scales:
    /// the mean square of the weighted correction is Σ (h⁴ second_i + h² first_i) Δq''_i².
    h4: f64,
    h2: f64,
    /// The last correction must also be small against q'' itself (`newton_tolerance` relative),
    /// with an absolute floor equal to what the test on the integrated quantities allows at
    /// h_ref = h_max: as h → 0 that test alone accepts any bounded q'' (βh² Δq'' vanishes), so
    /// an iteration that does not converge at all, e.g. on a residual without a root, would pass
    /// silently. 1 / h_ref² and 1 / h_ref.
    inverse_ref: (f64, f64),
    converge_at: f64,
    relative: f64,
}

impl NewtonTest {
    pub(super) fn new(scales: Arc<NewtonScales>, h: f64) -> Self {
        let options = &scales.options;
        let h_ref = if options.h_max.is_finite() { options.h_max.max(h) } else { h };
        let (converge_at, relative) = (options.newton_tolerance * options.tolerance, options.newton_tolerance);
        NewtonTest { h4: h.powi(4), h2: h * h, inverse_ref: (h_ref.powi(-2), 1.0 / h_ref), converge_at, relative, scales }
    }

    /// RMS of the correction of the integrated quantities, in units of their scales.
    pub(super) fn norm(&self, dx: &DVector<f64>) -> f64 {
        self.dot(dx, dx).sqrt()
    }

    /// Scalar product of two corrections in the metric of [`Self::norm`].
    pub(super) fn dot(&self, a: &DVector<f64>, b: &DVector<f64>) -> f64 {
        let (second, first) = &self.scales.metric;
        let products = a.as_slice().iter().zip(b.as_slice()).zip(second.iter().zip(first));
        products.map(|((x, y), (s, f))| x * y * (self.h4 * s + self.h2 * f)).sum()
    }

    pub(super) fn converged(&self, norm: f64, dx: &DVector<f64>, qdd: &DVector<f64>) -> bool {
        let (second, first) = &self.scales.floor;
        norm <= self.converge_at && (0..dx.len()).all(|i| dx[i].abs() <= self.relative * qdd[i].abs() + second[i] * self.inverse_ref.0 + first[i] * self.inverse_ref.1)
    }
}
