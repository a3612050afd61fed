//! Dependent parameters (thesis Section 3.3.4, Eq. 3.42-3.50): intermediate variables p(q)
//! evaluated once per kinematic evaluation, with their exact first and second derivatives.

use nalgebra::{Const, SMatrix, SVector, U1};
use num_dual::{Derivative, HyperDualSVec64};

/// Most inputs a group of dependent parameters can have (a slider-crank has 1, a pantograph 2).
pub const MAX_INPUTS: usize = 3;

/// The numbers [`DependentFunction`]s are written on: hyper-dual numbers whose first
/// infinitesimal part carries the gradient over the group's inputs and whose second part the
/// derivative along the velocity ẋ, so that their product is the Hessian times ẋ. One
/// evaluation gives p, ∂p/∂x, ṗ = ∂p/∂x ẋ and ẋᵀ (∂²p/∂x²) ẋ.
pub type Jet = HyperDualSVec64<MAX_INPUTS, 1>;

/// A group of dependent parameters p = p(x), x a few configuration parameters (at most
/// [`MAX_INPUTS`]).
///
/// Implementations write p(x) once, on [`Jet`]s (best generically over
/// [`num_dual::DualNum`]); the engine obtains the value, the gradient ∂p/∂x, the rate
/// ṗ = ∂p/∂x ẋ and the convective term ẋᵀ (∂²p/∂x²) ẋ of p̈ = ∂p/∂x ẍ + ẋᵀ (∂²p/∂x²) ẋ
/// exactly (no numerical differentiation).
pub trait DependentFunction: Send + Sync + std::fmt::Debug {
    fn input_count(&self) -> usize;
    fn output_count(&self) -> usize;
    fn eval(&self, x: &[Jet], p: &mut [Jet]);

    /// The same derivatives in closed form, for functions that have it cheaper than the jets:
    /// fills `out` (value, rate, bias, gradient of each output, and its sine and cosine when it
    /// is an angle that has them cheaper than `sin_cos`) at (x, ẋ) and returns true.
    /// [`Self::eval`] stays the definition, and tests hold the two together
    /// ([`evaluate_jets`]). The default has no closed form.
    fn eval_closed_form(&self, _x: &[f64], _xd: &[f64], _out: &mut [DependentValue]) -> bool {
        false
    }
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
    /// (sin p, cos p) when the closed form gives them (an angle it has as an arc cosine, whose
    /// sine and cosine are algebraic in its argument); the kinematics takes those of the joint
    /// angles from here instead of evaluating them ([`DependentFunction::eval_closed_form`]).
    pub sin_cos: Option<(f64, f64)>,
}

/// Evaluates a group at (x, ẋ): in closed form when the function has it, else on jets.
pub(crate) fn evaluate(function: &dyn DependentFunction, x: &[f64], xd: &[f64], out: &mut [DependentValue], work: &mut Vec<Jet>) {
    if !function.eval_closed_form(x, xd, out) {
        evaluate_jets(function, x, xd, out, work);
    }
}

/// Evaluates a group at (x, ẋ) in one pass of [`DependentFunction::eval`]: input k seeded with
/// the unit gradient e_k and the rate ẋ_k.
pub fn evaluate_jets(function: &dyn DependentFunction, x: &[f64], xd: &[f64], out: &mut [DependentValue], work: &mut Vec<Jet>) {
    let (ni, no) = (function.input_count(), function.output_count());
    work.clear();
    work.resize(ni + no, Jet::from_re(0.0));
    let (xs, ps) = work.split_at_mut(ni);
    for (k, input) in xs.iter_mut().enumerate() {
        let unit = SVector::<f64, MAX_INPUTS>::from_fn(|r, _| if r == k { 1.0 } else { 0.0 });
        *input = Jet::new(x[k], Derivative::some(unit), Derivative::some(SMatrix::<f64, 1, 1>::new(xd[k])), Derivative::none());
    }
    function.eval(xs, ps);
    for (o, p) in out.iter_mut().zip(ps.iter()) {
        let gradient = p.eps1.unwrap_generic(Const::<MAX_INPUTS>, U1);
        let hessian_xd = p.eps1eps2.unwrap_generic(Const::<MAX_INPUTS>, U1);
        o.value = p.re;
        o.rate = p.eps2.unwrap_generic(U1, U1)[0];
        o.bias = (0..ni).map(|j| hessian_xd[j] * xd[j]).sum();
        o.gradient.copy_from_slice(&gradient.as_slice()[..ni]);
        o.sin_cos = None;
    }
}
