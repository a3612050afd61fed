//! Small hand-written residual systems (thesis Eq. 3.1) and closed-form helpers shared by the
//! `sim_*` integration tests.
#![allow(dead_code)]

use hexadyn::sim::{Jacobian, Layout, Order, System};
use nalgebra::DMatrix;

pub const G: f64 = 9.81;

// ---------------------------------------------------------------------------------------------
// Linear systems  M q'' + C q' + K q = B u
// ---------------------------------------------------------------------------------------------

/// A linear residual system f = M q'' + C q' + K q − B u (Eq. 3.1, 3.17), with any mix of
/// second- and first-order coordinates. With `exact_jacobian` it hands M, C, K to the solver
/// (Eq. 3.12); without, the solver falls back to finite differences.
pub struct Linear {
    pub layout: Layout,
    pub m: DMatrix<f64>,
    pub c: DMatrix<f64>,
    pub k: DMatrix<f64>,
    /// Input matrix (n × nu).
    pub b: DMatrix<f64>,
    pub u: Vec<f64>,
    /// Constant generalized force added to the right-hand side (gravity, ...).
    pub load: Vec<f64>,
    pub exact_jacobian: bool,
    /// Every time at which the residual was evaluated (for checking the solver's statistics).
    pub log: Option<Vec<f64>>,
    pub jacobian_calls: usize,
}

impl Linear {
    pub fn new(layout: Layout, m: DMatrix<f64>, c: DMatrix<f64>, k: DMatrix<f64>, b: DMatrix<f64>) -> Self {
        let n = layout.len();
        let nu = b.ncols();
        Linear { layout, m, c, k, b, u: vec![0.0; nu], load: vec![0.0; n], exact_jacobian: true, log: None, jacobian_calls: 0 }
    }

    /// m q'' + c q' + k q = u, one second-order coordinate "x" owned by element "oscillator".
    pub fn oscillator(m: f64, c: f64, k: f64) -> Self {
        let mut layout = Layout::default();
        layout.push("x", Order::Second, 1.0, "oscillator");
        let s = |v: f64| DMatrix::from_element(1, 1, v);
        Linear::new(layout, s(m), s(c), s(k), s(1.0))
    }

    /// First-order lag τ y' + y = g u written with y = q' (Order::First): the RC circuit
    /// R C v' + v = v_in, coordinate "v_c" of element "rc circuit".
    pub fn first_order_lag(tau: f64, gain: f64) -> Self {
        let mut layout = Layout::default();
        layout.push("v_c", Order::First, 1.0, "rc circuit");
        let s = |v: f64| DMatrix::from_element(1, 1, v);
        Linear::new(layout, s(tau), s(1.0), s(0.0), s(gain))
    }

    /// Mass-spring x driven by a DC-motor-like current i (first-order state, i = q'_1):
    ///   row 0 (x, "mass-spring"): m x'' + c x' + k x − kt i = 0
    ///   row 1 (i, "motor"):       L i' + R i − V = 0, V = input 0.
    pub fn motor_mass(m: f64, c: f64, k: f64, kt: f64, l: f64, r: f64) -> Self {
        let mut layout = Layout::default();
        layout.push("x", Order::Second, 1.0, "mass-spring");
        layout.push("i", Order::First, 1.0, "motor");
        let mm = DMatrix::from_row_slice(2, 2, &[m, 0.0, 0.0, l]);
        let cc = DMatrix::from_row_slice(2, 2, &[c, -kt, 0.0, r]);
        let kk = DMatrix::from_row_slice(2, 2, &[k, 0.0, 0.0, 0.0]);
        let bb = DMatrix::from_row_slice(2, 1, &[0.0, 1.0]);
        Linear::new(layout, mm, cc, kk, bb)
    }

    /// Three masses in a row between two walls: springs ground–1, 1–2, 2–3, 3–ground and
    /// Rayleigh damping C = α M + β K. Coordinates are displacements from the unstretched state.
    pub fn chain(masses: [f64; 3], springs: [f64; 4], alpha: f64, beta: f64) -> Self {
        let mut layout = Layout::default();
        for i in 0..3 {
            layout.push(format!("x{}", i + 1), Order::Second, 1.0, format!("mass {}", i + 1));
        }
        let m = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&masses));
        let [k0, k1, k2, k3] = springs;
        let k = DMatrix::from_row_slice(3, 3, &[k0 + k1, -k1, 0.0, -k1, k1 + k2, -k2, 0.0, -k2, k2 + k3]);
        let c = &m * alpha + &k * beta;
        Linear::new(layout, m, c, k, DMatrix::identity(3, 3))
    }

    pub fn n(&self) -> usize {
        self.layout.len()
    }
}

impl System for Linear {
    fn layout(&self) -> &Layout {
        &self.layout
    }
    fn residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
        if let Some(log) = self.log.as_mut() {
            log.push(t);
        }
        let n = self.n();
        for (i, fi) in f.iter_mut().enumerate().take(n) {
            let mut r = -self.load[i];
            for j in 0..n {
                r += self.m[(i, j)] * qdd[j] + self.c[(i, j)] * qd[j] + self.k[(i, j)] * q[j];
            }
            for (k, u) in self.u.iter().enumerate() {
                r -= self.b[(i, k)] * u;
            }
            *fi = r;
        }
    }
    fn jacobian(&mut self, _t: f64, _q: &[f64], _qd: &[f64], _qdd: &[f64], jac: &mut Jacobian) -> bool {
        if !self.exact_jacobian {
            return false;
        }
        self.jacobian_calls += 1;
        jac.m.copy_from(&self.m);
        jac.ct.copy_from(&self.c);
        jac.kt.copy_from(&self.k);
        true
    }
    fn input_count(&self) -> usize {
        self.u.len()
    }
    fn input(&self, k: usize) -> f64 {
        self.u[k]
    }
    fn set_input(&mut self, k: usize, value: f64) {
        self.u[k] = value;
    }
}

// ---------------------------------------------------------------------------------------------
// Nonlinear systems
// ---------------------------------------------------------------------------------------------

/// Pendulum with a torsion spring and a torque input:
///   m l² θ'' + c θ' + s·m g l sin θ + k_s θ − u = 0,
/// with s = +1 for θ measured from the hanging position and s = −1 for θ measured from the
/// upright position (inverted pendulum). Exact Jacobian blocks on request.
pub struct Pendulum {
    pub layout: Layout,
    pub m: f64,
    pub l: f64,
    pub c: f64,
    pub g: f64,
    pub spring: f64,
    pub sign: f64,
    pub u: f64,
    pub exact_jacobian: bool,
}

impl Pendulum {
    pub fn hanging(m: f64, l: f64, c: f64) -> Self {
        let mut layout = Layout::default();
        layout.push("theta", Order::Second, 1.0, "pendulum");
        Pendulum { layout, m, l, c, g: G, spring: 0.0, sign: 1.0, u: 0.0, exact_jacobian: true }
    }
    pub fn inverted_with_spring(m: f64, l: f64, c: f64, spring: f64) -> Self {
        Pendulum { spring, sign: -1.0, ..Pendulum::hanging(m, l, c) }
    }
}

impl System for Pendulum {
    fn layout(&self) -> &Layout {
        &self.layout
    }
    fn residual(&mut self, _t: f64, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
        let (m, l) = (self.m, self.l);
        f[0] = m * l * l * qdd[0] + self.c * qd[0] + self.sign * m * self.g * l * q[0].sin() + self.spring * q[0] - self.u;
    }
    fn jacobian(&mut self, _t: f64, q: &[f64], _qd: &[f64], _qdd: &[f64], jac: &mut Jacobian) -> bool {
        if !self.exact_jacobian {
            return false;
        }
        let (m, l) = (self.m, self.l);
        jac.m[(0, 0)] = m * l * l;
        jac.ct[(0, 0)] = self.c;
        jac.kt[(0, 0)] = self.sign * m * self.g * l * q[0].cos() + self.spring;
        true
    }
    fn input_count(&self) -> usize {
        1
    }
    fn input(&self, _k: usize) -> f64 {
        self.u
    }
    fn set_input(&mut self, _k: usize, value: f64) {
        self.u = value;
    }
}

/// Cart-pole (point mass m at distance l on a cart of mass mc), θ from the hanging position:
///   (mc + m) x'' + m l cos θ θ'' − m l sin θ θ'² + cx x' − u = 0
///   m l cos θ x'' + m l² θ'' + m g l sin θ + cθ θ' = 0
/// A configuration-dependent mass matrix and velocity-quadratic terms, with exact Jacobian blocks.
pub struct CartPole {
    pub layout: Layout,
    pub mc: f64,
    pub m: f64,
    pub l: f64,
    pub cx: f64,
    pub ctheta: f64,
    pub u: f64,
}

impl CartPole {
    pub fn new() -> Self {
        let mut layout = Layout::default();
        layout.push("x", Order::Second, 1.0, "cart");
        layout.push("theta", Order::Second, 1.0, "pole");
        CartPole { layout, mc: 2.0, m: 0.7, l: 0.6, cx: 0.3, ctheta: 0.05, u: 0.0 }
    }
}

impl System for CartPole {
    fn layout(&self) -> &Layout {
        &self.layout
    }
    fn residual(&mut self, _t: f64, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
        let (m, l) = (self.m, self.l);
        let (s, c) = q[1].sin_cos();
        f[0] = (self.mc + m) * qdd[0] + m * l * c * qdd[1] - m * l * s * qd[1] * qd[1] + self.cx * qd[0] - self.u;
        f[1] = m * l * c * qdd[0] + m * l * l * qdd[1] + m * G * l * s + self.ctheta * qd[1];
    }
    fn jacobian(&mut self, _t: f64, q: &[f64], qd: &[f64], qdd: &[f64], jac: &mut Jacobian) -> bool {
        let (m, l) = (self.m, self.l);
        let (s, c) = q[1].sin_cos();
        jac.m[(0, 0)] = self.mc + m;
        jac.m[(0, 1)] = m * l * c;
        jac.m[(1, 0)] = m * l * c;
        jac.m[(1, 1)] = m * l * l;
        jac.ct[(0, 0)] = self.cx;
        jac.ct[(0, 1)] = -2.0 * m * l * s * qd[1];
        jac.ct[(1, 1)] = self.ctheta;
        jac.kt[(0, 1)] = -m * l * s * qdd[1] - m * l * c * qd[1] * qd[1];
        jac.kt[(1, 1)] = -m * l * s * qdd[0] + m * G * l * c;
        true
    }
    fn input_count(&self) -> usize {
        1
    }
    fn input(&self, _k: usize) -> f64 {
        self.u
    }
    fn set_input(&mut self, _k: usize, value: f64) {
        self.u = value;
    }
}

/// A linear oscillator ("x", element "spring") plus a row that goes wrong:
/// - [`Faulty::NanAfter`]: row 1 ("y", element "leaky valve") is y'' + y = 0 until `t_bad`, then NaN;
/// - [`Faulty::NoSolution`]: row 1 ("y", element "magic brake") is y''² + y'' + 1 = 0, which has no
///   real root at all.
pub enum Fault {
    NanAfter(f64),
    NoSolution,
}

pub struct Faulty {
    pub layout: Layout,
    pub fault: Fault,
}

impl Faulty {
    pub fn new(fault: Fault) -> Self {
        let mut layout = Layout::default();
        layout.push("x", Order::Second, 1.0, "spring");
        let element = match fault {
            Fault::NanAfter(_) => "leaky valve",
            Fault::NoSolution => "magic brake",
        };
        layout.push("y", Order::Second, 1.0, element);
        Faulty { layout, fault }
    }
}

impl System for Faulty {
    fn layout(&self) -> &Layout {
        &self.layout
    }
    fn residual(&mut self, t: f64, q: &[f64], _qd: &[f64], qdd: &[f64], f: &mut [f64]) {
        f[0] = qdd[0] + 4.0 * q[0];
        f[1] = match self.fault {
            Fault::NanAfter(t_bad) => {
                if t > t_bad {
                    f64::NAN
                } else {
                    qdd[1] + q[1]
                }
            }
            Fault::NoSolution => qdd[1] * qdd[1] + qdd[1] + 1.0,
        };
    }
}

// ---------------------------------------------------------------------------------------------
// Closed forms and helpers
// ---------------------------------------------------------------------------------------------

/// Free response of m q'' + c q' + k q = 0 (underdamped): (q(t), q'(t)).
pub fn damped_oscillator(m: f64, c: f64, k: f64, q0: f64, v0: f64, t: f64) -> (f64, f64) {
    let w0 = (k / m).sqrt();
    let sigma = c / (2.0 * m);
    assert!(sigma < w0, "underdamped only");
    let wd = (w0 * w0 - sigma * sigma).sqrt();
    let (s, co) = (wd * t).sin_cos();
    let e = (-sigma * t).exp();
    let q = e * (q0 * co + (v0 + sigma * q0) / wd * s);
    let v = e * (v0 * co - (sigma * v0 + w0 * w0 * q0) / wd * s);
    (q, v)
}

/// Complete elliptic integral of the first kind K(k) by the arithmetic-geometric mean.
pub fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0_f64, (1.0 - k * k).sqrt());
    for _ in 0..40 {
        let (an, bn) = (0.5 * (a + b), (a * b).sqrt());
        a = an;
        b = bn;
    }
    std::f64::consts::PI / (2.0 * a)
}

/// Least-squares slope of y against x.
pub fn fit_slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// |a − b| / max(|b|, floor).
pub fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// A particle of mass m in polar coordinates (r, θ) held by a radial spring of stiffness k and
/// free length r0 (no analytic Jacobian):
///   row 0 (r, "radial spring"): m r'' − m r θ'² + k (r − r0) = 0
///   row 1 (theta, "particle"):  m r² θ'' + 2 m r r' θ' = 0
/// The θ row vanishes identically at r = 0, a point the motion never visits.
pub struct Polar {
    pub layout: Layout,
    pub m: f64,
    pub k: f64,
    pub r0: f64,
}

impl Polar {
    pub fn new(m: f64, k: f64, r0: f64) -> Self {
        let mut layout = Layout::default();
        layout.push("r", Order::Second, 1.0, "radial spring");
        layout.push("theta", Order::Second, 1.0, "particle");
        Polar { layout, m, k, r0 }
    }
}

impl System for Polar {
    fn layout(&self) -> &Layout {
        &self.layout
    }
    fn residual(&mut self, _t: f64, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
        let (m, r) = (self.m, q[0]);
        f[0] = m * qdd[0] - m * r * qd[1] * qd[1] + self.k * (r - self.r0);
        f[1] = m * r * r * qdd[1] + 2.0 * m * r * qd[0] * qd[1];
    }
}
