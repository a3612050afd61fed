//! Systems in residual form, Eq. 3.1.

/// The differential order of one coordinate of a residual system.
///
/// Mechanical coordinates are of second order. A first-order state y (a motor current, a LuGre
/// bristle deflection, ...) is written as y = q' so that y' = q'' (thesis Section 3.3.2, Eq. 3.85
/// and 3.91); its q is then meaningless and never read by the equations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Order {
    Second,
    First,
}

/// Names, orders and error scales of the coordinates of a system, and the element owning each
/// residual row (for diagnostics).
#[derive(Clone, Debug, Default)]
pub struct Layout {
    /// Name of each coordinate, e.g. `"q_v[2]"`.
    pub names: Vec<String>,
    pub orders: Vec<Order>,
    /// Scale of the integrated quantity of each coordinate (q for [`Order::Second`], q' for
    /// [`Order::First`]), in its own unit: the error estimate of Eq. 3.15 and the Newton
    /// convergence test are measured in these units.
    pub scales: Vec<f64>,
    /// Name of the element that writes each residual row, e.g. `"multibody"`, `"motor v[2]"`.
    pub elements: Vec<String>,
}

impl Layout {
    pub fn len(&self) -> usize {
        self.names.len()
    }
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }
    /// Appends one coordinate with its residual row.
    pub fn push(&mut self, name: impl Into<String>, order: Order, scale: f64, element: impl Into<String>) -> usize {
        self.names.push(name.into());
        self.orders.push(order);
        self.scales.push(scale);
        self.elements.push(element.into());
        self.names.len() - 1
    }
}

/// A system of differential equations f(q, q', q'', t) = 0 (Eq. 3.1), with optional inputs u.
///
/// The solver never knows what the rows mean: every physical element adds rows to f and, where it
/// can, its exact Jacobian blocks.
pub trait System {
    fn layout(&self) -> &Layout;

    /// Evaluates the residual f(q, q', q'', t) into `f` (Eq. 3.1).
    fn residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]);

    /// Writes the exact blocks M = ∂f/∂q'', CT = ∂f/∂q' and KT = ∂f/∂q (Eq. 3.12) into `jac`
    /// (zeroed by the caller) and returns true; returns false when the system has no analytic
    /// Jacobian, in which case the solver falls back to [`super::finite_difference_jacobian`].
    fn jacobian(&mut self, _t: f64, _q: &[f64], _qd: &[f64], _qdd: &[f64], _jac: &mut super::Jacobian) -> bool {
        false
    }

    /// Writes M = ∂f/∂q'' alone into `m` (zeroed by the caller) and returns true, when the
    /// system can do it more cheaply than the whole Jacobian; false falls back to finite
    /// differences on q''.
    fn mass_matrix(&mut self, _t: f64, _q: &[f64], _qd: &[f64], _qdd: &[f64], _m: &mut nalgebra::DMatrix<f64>) -> bool {
        false
    }

    /// Keeps the evaluation of [`Self::residual`] just made at (q, q', q'') with its result `f`
    /// as the base of [`Self::surrogate_residual`] and returns true; false (the default) when
    /// the system has no surrogate. The base stays until the next call: evaluations of the
    /// residual or the Jacobian in between do not change it.
    fn keep_surrogate_base(&mut self, _q: &[f64], _qd: &[f64], _qdd: &[f64], _f: &[f64]) -> bool {
        false
    }

    /// A cheaper approximation of [`Self::residual`] near the kept base, for the Newton
    /// iterations between two evaluations of f (`Newmark`): there its accuracy decides how many
    /// evaluations a step takes, never the accepted solution, which passes the Newton test on f
    /// itself. `Newmark::reset_accelerations_after_input_jump` also takes its correction at the
    /// state of the step that kept the base, where it must match f within the Newton test. The
    /// default is the residual.
    fn surrogate_residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
        self.residual(t, q, qd, qdd, f)
    }

    /// Number of inputs u (Eq. 3.16).
    fn input_count(&self) -> usize {
        0
    }
    /// Current value of input `k`.
    fn input(&self, _k: usize) -> f64 {
        0.0
    }
    /// Sets input `k` (held constant until changed: zero-order hold).
    fn set_input(&mut self, _k: usize, _value: f64) {}

    /// Writes into `df` the exact change of the residual when the inputs u (Eq. 3.16) jump from
    /// `previous` to their present values at fixed (t, q, q', q''):
    /// Δf = f(t, q, q', q''; u) − f(t, q, q', q''; u_previous), and returns true. Where the inputs
    /// enter f affinely through known functions (a motor voltage through Eq. 4.4, a reference
    /// through a controller's error) this costs no kinematics, unlike two evaluations of
    /// [`Self::residual`]. Returns false when the system cannot do it (the default), or when
    /// `previous` does not hold [`Self::input_count`] values or `df` one per coordinate.
    fn input_change(&mut self, _t: f64, _q: &[f64], _qd: &[f64], _qdd: &[f64], _previous: &[f64], _df: &mut [f64]) -> bool {
        false
    }
}
