//! Dependent parameters (thesis Section 3.3.4, Eq. 3.42-3.50): intermediate variables p(q)
//! evaluated once per kinematic evaluation, with their exact first and second derivatives.

use num_dual::Dual2_64;

/// A group of dependent parameters p = p(x), x a few configuration parameters.
///
/// Implementations write p(x) once, on second-order dual numbers; the engine obtains the value,
/// the gradient ∂p/∂x, the rate ṗ = ∂p/∂x ẋ and the convective term ẋᵀ (∂²p/∂x²) ẋ of
/// p̈ = ∂p/∂x ẍ + ẋᵀ (∂²p/∂x²) ẋ exactly (no numerical differentiation).
pub trait DependentFunction: Send + Sync + std::fmt::Debug {
    fn input_count(&self) -> usize;
    fn output_count(&self) -> usize;
    fn eval(&self, x: &[Dual2_64], p: &mut [Dual2_64]);
}

/// Value and derivatives of one dependent parameter.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DependentValue {
    pub value: f64,
    /// ṗ.
    pub rate: f64,
    /// Convective part of p̈ (the part not proportional to q̈).
    pub bias: f64,
    /// ∂p/∂x for each input of the group.
    pub gradient: Vec<f64>,
}

/// Evaluates a group at (x, ẋ): one pass along ẋ for rate and bias, one pass per input for the
/// gradient.
pub(crate) fn evaluate(function: &dyn DependentFunction, x: &[f64], xd: &[f64], out: &mut [DependentValue], work: &mut Vec<Dual2_64>) {
    let (ni, no) = (function.input_count(), function.output_count());
    work.clear();
    work.resize(ni + no, Dual2_64::from_re(0.0));
    let (xs, ps) = work.split_at_mut(ni);
    for k in 0..ni {
        xs[k] = Dual2_64::new(x[k], xd[k], 0.0);
    }
    function.eval(xs, ps);
    for (o, p) in out.iter_mut().zip(ps.iter()) {
        o.value = p.re;
        o.rate = p.v1;
        o.bias = p.v2;
    }
    for j in 0..ni {
        for k in 0..ni {
            xs[k] = Dual2_64::new(x[k], if k == j { 1.0 } else { 0.0 }, 0.0);
        }
        function.eval(xs, ps);
        for (o, p) in out.iter_mut().zip(ps.iter()) {
            o.gradient[j] = p.v1;
        }
    }
}
