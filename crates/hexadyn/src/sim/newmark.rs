//! Implicit Newmark integration with Newton-Raphson on q''(t+h) (thesis Eq. 3.7-3.15).

use std::sync::Arc;

use nalgebra::{DMatrix, DVector};

use super::broyden::Broyden;
use super::error::largest_rows;
use super::factorization::Factorization;
use super::newton_test::{NewtonScales, NewtonTest};
use super::jacobian::mass_matrix;
use super::{Jacobian, Order, SimError, System};

/// A kept factorization of M is used as long as each Newton correction of the consistent
/// accelerations is at least this many times smaller than the one before.
const FAST_CONTRACTION: f64 = 0.1;

/// A Newton correction of a step that did not contract and whose cosine with the previous one
/// (metric of the Newton test) is below −REVERSAL reverses it: it is halved (see
/// [`Newmark::step`]). INTERPRETATION: the thesis (Section 3.3.2) does not say how Newton is
/// globalized; on the 75 s LuGre walk 647 of the 802 Newton failures ended in corrections that
/// alternate in sign at a constant or growing size (docs/performance-log.md, session 23).
const REVERSAL: f64 = 0.5;

/// A correction of the surrogate iterations (see [`Newmark::iterate_on_surrogate`]) larger than
/// this many times the last correction from the residual itself is not taken: the surrogate is
/// then no guide to f there (a Newton iterate far from its base). INTERPRETATION: not in the
/// thesis; 1, 3, 10 and 100 measured on the 75 s LuGre walk (25 865 evaluations at 10,
/// 26 200 at 3, 27 181 at 1, 26 190 at 100; docs/performance-log.md, session 29).
const SURROGATE_GROWTH: f64 = 10.0;

/// Integration parameters. Defaults: the trapezoidal rule β = 1/4, γ = 1/2 (unconditionally
/// stable for linear systems, second order, no numerical damping).
#[derive(Clone, Debug, PartialEq)]
pub struct NewmarkOptions {
    /// Newmark β (Eq. 3.7).
    pub beta: f64,
    /// Newmark γ (Eq. 3.8); γ > 1/2 adds numerical damping (then take β ≥ (γ + 1/2)²/4).
    pub gamma: f64,
    /// Tolerance on the error estimate of Eq. 3.15, in units of the layout scales.
    pub tolerance: f64,
    /// First step tried.
    pub h_initial: f64,
    pub h_min: f64,
    pub h_max: f64,
    /// Newton stops when the scaled correction of the integrated quantities is below
    /// `newton_tolerance` × `tolerance` and the correction of each q'' is below
    /// `newton_tolerance` × |q''| (plus the correction the first test allows at h_max).
    pub newton_tolerance: f64,
    /// Newton iterations allowed per step before the Jacobian is refreshed or the step reduced.
    pub max_iterations: usize,
    /// A contraction ratio of the Newton corrections above this makes the iteration "slow":
    /// the factorization is refreshed (modified Newton, Section 3.3.2).
    pub slow_contraction: f64,
    /// Adapt h from the error estimate (Eq. 3.15); with `false` the step is h_max, shortened
    /// only to land on requested instants or after a Newton failure.
    pub adaptive: bool,
    /// Newton iterations on the system's surrogate residual allowed after each evaluation of
    /// the residual ([`System::surrogate_residual`]); 0 (the default here): none, the thesis'
    /// iteration on f alone, the right choice for a system whose surrogate is the residual
    /// itself. The robot's plant takes 8 (`PlantOptions::new`): there the
    /// iteration seldom fails at the kinks of the force laws, so the step sequence differs from
    /// the one on f alone within the integration error of Eq. 3.15 (docs/performance-log.md,
    /// sessions 29-30).
    pub surrogate_iterations: usize,
    /// Steps accepted in a row on the Newton test of the surrogate, without evaluating f at their
    /// last iterate, while the surrogate is trusted (`SurrogateTrust`): the evaluation of f that
    /// last followed a converged surrogate iteration passed the Newton test itself, and no
    /// Newton iteration failed and no step was rejected since. 0 (the default): every step
    /// passes the Newton test on f, the thesis' iteration. The robot's plant takes 8
    /// (`PlantOptions::new`); docs/performance-log.md, session 33, measures what
    /// the verifications find.
    pub unverified_steps: usize,
}

impl Default for NewmarkOptions {
    fn default() -> Self {
        NewmarkOptions {
            beta: 0.25,
            gamma: 0.5,
            tolerance: 1e-6,
            h_initial: 1e-4,
            h_min: 1e-10,
            h_max: 1e-2,
            newton_tolerance: 1e-2,
            max_iterations: 8,
            slow_contraction: 0.5,
            adaptive: true,
            surrogate_iterations: 0,
            unverified_steps: 0,
        }
    }
}

impl NewmarkOptions {
    fn validate(&self) -> Result<(), SimError> {
        let check = |ok: bool, field, value, allowed| if ok { Ok(()) } else { Err(SimError::InvalidOption { field, value, allowed }) };
        check(self.gamma >= 0.5 && self.gamma.is_finite(), "gamma", self.gamma, "gamma >= 0.5 (stability)")?;
        check(self.beta >= self.gamma / 2.0 - 1e-15 && self.beta <= 1.0, "beta", self.beta, "gamma/2 <= beta <= 1 (unconditional stability)")?;
        check(self.tolerance > 0.0, "tolerance", self.tolerance, "> 0")?;
        check(self.h_min > 0.0 && self.h_min <= self.h_max, "h_min", self.h_min, "0 < h_min <= h_max")?;
        check(self.h_initial > 0.0, "h_initial", self.h_initial, "> 0")?;
        check(self.newton_tolerance > 0.0, "newton_tolerance", self.newton_tolerance, "> 0")?;
        check(self.max_iterations >= 1, "max_iterations", self.max_iterations as f64, ">= 1")?;
        check(self.slow_contraction > 0.0 && self.slow_contraction < 1.0, "slow_contraction", self.slow_contraction, "in (0, 1)")
    }
}

/// State (t, q, q', q'') of a residual system.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub t: f64,
    pub q: DVector<f64>,
    pub qd: DVector<f64>,
    pub qdd: DVector<f64>,
}

/// Work counters, for benchmarks and diagnostics.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct NewmarkStats {
    pub steps: usize,
    pub rejected_steps: usize,
    pub newton_iterations: usize,
    pub residual_evaluations: usize,
    pub jacobian_evaluations: usize,
    pub factorizations: usize,
    /// Evaluations of [`System::surrogate_residual`].
    pub surrogate_evaluations: usize,
    /// Steps accepted on the surrogate's Newton test ([`NewmarkOptions::unverified_steps`]).
    pub unverified_steps: usize,
}

/// Whether a step may be accepted on the Newton test of the surrogate residual
/// ([`NewmarkOptions::unverified_steps`]). INTERPRETATION: the thesis accepts a step on the
/// Newton test of f (Section 3.3.2). The surrogate's root differs from f's by the surrogate's
/// model error, which the evaluation of f after a converged surrogate iteration measures: on the
/// 75 s LuGre walk its Newton correction is a median 0.02 and at most 13 times the Newton
/// tolerance, itself 1 % of the error tolerance of Eq. 3.15 (docs/performance-log.md, session
/// 33). Trust is earned by such a verification that passes, and lost on a verification that fails,
/// on every Newton failure and on every rejected step (touchdowns, lift-offs and velocity
/// reversals, where the surrogate's base is furthest from the step's end).
#[derive(Clone, Copy, Debug, Default)]
struct SurrogateTrust {
    verified: bool,
    /// Steps accepted on the surrogate since the last verification.
    unverified: usize,
}

impl SurrogateTrust {
    /// Whether the step whose surrogate iteration converged is accepted on it: trusted, and
    /// fewer than `limit` steps accepted so since the last verification (counted when true).
    fn accept(&mut self, limit: usize) -> bool {
        let accepted = self.verified && self.unverified < limit;
        self.unverified += usize::from(accepted);
        accepted
    }
    /// The Newton test of f after a converged surrogate iteration: passed or not.
    fn verify(&mut self, passed: bool) {
        *self = SurrogateTrust { verified: passed, unverified: 0 };
    }
}

/// The Newmark integrator. It owns the state and the (reused) factorized iteration matrix.
pub struct Newmark {
    pub options: NewmarkOptions,
    state: State,
    /// Step proposed for the next interval.
    h: f64,
    jacobian: Option<Jacobian>,
    /// Factorization of J (Eq. 3.14) and the h it was built with.
    lu: Option<(Factorization, f64)>,
    /// True when `jacobian` was evaluated during the current step (refreshing it again is useless).
    jacobian_fresh: bool,
    /// Factorization of M = ∂f/∂q'' kept for [`Self::reset_accelerations`].
    mass_lu: Option<Factorization>,
    /// The Jacobian was refreshed since `mass_lu` was factorized: its mass block is the newer M.
    mass_outdated: bool,
    stats: NewmarkStats,
    /// The steps of the current Newton iteration, for Broyden's update of the kept matrix.
    broyden: Broyden,
    /// The system keeps its last evaluation of f as its surrogate's base
    /// ([`System::keep_surrogate_base`]): after an accepted step, the evaluation at its last
    /// Newton iterate on f, within the Newton test of the state, or (a step accepted on the
    /// surrogate) the one its surrogate iterations started from.
    surrogate_base: bool,
    trust: SurrogateTrust,
    /// The steps iterate on f alone, without the surrogate iterations, until the next reset of
    /// the accelerations (a control instant): set when a step fails down to `h_min` with them
    /// (see [`Newmark::step`]).
    plain_newton: bool,
    /// What the Newton tests of all step sizes share, built once.
    newton_scales: Option<Arc<NewtonScales>>,
    work: Work,
}

struct Work {
    f: Vec<f64>,
    q: DVector<f64>,
    qd: DVector<f64>,
    qdd: DVector<f64>,
    weight_q: DVector<f64>,
    /// The Newton correction of the previous iteration (for the reversal test of a step).
    dx_previous: DVector<f64>,
}

enum StepOutcome {
    Accepted,
    Rejected { h_next: f64 },
}

impl Newmark {
    /// Starts at (t0, q0, q'0) with the consistent q''0 solved from f = 0 (see [`Self::reset_accelerations`]).
    pub fn new<S: System + ?Sized>(sys: &mut S, t0: f64, q0: &[f64], qd0: &[f64], options: NewmarkOptions) -> Result<Self, SimError> {
        options.validate()?;
        let n = sys.layout().len();
        assert_eq!(q0.len(), n, "q0 has {} entries, the system {}", q0.len(), n);
        assert_eq!(qd0.len(), n, "qd0 has {} entries, the system {}", qd0.len(), n);
        // Fixed-step mode uses h_max from the first step on (see `NewmarkOptions::adaptive`).
        let h = if options.adaptive { options.h_initial.clamp(options.h_min, options.h_max) } else { options.h_max };
        let mut nm = Newmark {
            options,
            state: State { t: t0, q: DVector::from_column_slice(q0), qd: DVector::from_column_slice(qd0), qdd: DVector::zeros(n) },
            h,
            jacobian: None,
            lu: None,
            jacobian_fresh: false,
            mass_lu: None,
            mass_outdated: false,
            broyden: Broyden::default(),
            surrogate_base: false,
            trust: SurrogateTrust::default(),
            plain_newton: false,
            newton_scales: None,
            stats: NewmarkStats::default(),
            work: Work { f: vec![0.0; n], q: DVector::zeros(n), qd: DVector::zeros(n), qdd: DVector::zeros(n), weight_q: DVector::zeros(n), dx_previous: DVector::zeros(n) },
        };
        nm.reset_accelerations(sys)?;
        Ok(nm)
    }

    pub fn state(&self) -> &State {
        &self.state
    }
    pub fn stats(&self) -> &NewmarkStats {
        &self.stats
    }
    /// The step the integrator will try next.
    pub fn step_size(&self) -> f64 {
        self.h
    }

    /// Replaces the state, e.g. after an impulsive change; accelerations are made consistent.
    pub fn set_state<S: System + ?Sized>(&mut self, sys: &mut S, q: &[f64], qd: &[f64]) -> Result<(), SimError> {
        self.state.q.copy_from_slice(q);
        self.state.qd.copy_from_slice(qd);
        self.surrogate_base = false;
        self.reset_accelerations(sys)
    }

    /// Solves f(q, q', q'', t) = 0 for q'' at the current (t, q, q'), e.g. after the inputs
    /// jumped (zero-order hold at a control instant), so that the error estimate of the next step
    /// does not see the discontinuity. Uses Newton on M = ∂f/∂q''; when M is singular (algebraic
    /// rows) q'' is left as it is and the next Newmark step restores consistency.
    ///
    /// The factorization of M is kept from one call to the next (the configuration moves little
    /// between control instants) and refreshed only when the iteration with it does not contract
    /// fast: modified Newton, as in the steps.
    pub fn reset_accelerations<S: System + ?Sized>(&mut self, sys: &mut S) -> Result<(), SimError> {
        self.plain_newton = false;
        if self.mass_lu.is_some() {
            let start = self.state.qdd.clone();
            if self.consistent_accelerations(sys, FAST_CONTRACTION)? {
                return Ok(());
            }
            self.state.qdd.copy_from(&start);
        }
        let t = self.state.t;
        let (m, direct) = mass_matrix(sys, t, self.state.q.as_slice(), self.state.qd.as_slice(), self.state.qdd.as_slice());
        if !direct {
            self.stats.jacobian_evaluations += 1;
        }
        self.mass_lu = Factorization::new(m, &self.first_order(sys), self.mass_lu.as_ref());
        self.mass_outdated = false;
        self.stats.factorizations += 1;
        if self.mass_lu.is_none() {
            return Ok(());
        }
        self.consistent_accelerations(sys, 1.0)?;
        Ok(())
    }

    /// The accelerations after the inputs jumped from `previous` to the values the system holds
    /// now (zero-order hold at a control instant), with one evaluation of f.
    ///
    /// First the jump of q'' that compensates the exact change of the residual: with f affine in
    /// q'' at fixed (q, q'), M Δq'' = −Δf (Eq. 3.16 at fixed q, q', with M of Eq. 3.39 from the
    /// mass block of the newest Jacobian) and Δf from [`System::input_change`], without
    /// evaluating f. Then f is evaluated once (when the last step's last evaluation is the
    /// system's surrogate base, its surrogate instead: the state differs from that base by the
    /// last Newton correction alone, and the surrogate evaluates the laws the inputs enter
    /// exactly; on the 75 s LuGre walk 28 % fewer evaluations of f, the figures unchanged,
    /// docs/performance-log.md, session 30) and its Newton correction M⁻¹ f is taken when it
    /// passes the Newton test of the steps: q'' is then consistent, as after
    /// [`Self::reset_accelerations`]. When it does not, one correction cannot be trusted to make
    /// q'' consistent (what the test sees is the step's residual in stiff rows, small in the
    /// metric of the iteration matrix J = M + γh CT + βh² KT of Eq. 3.14 that accepted it and
    /// large in the metric of M, or M's error times a large jump), and iterating costs
    /// evaluations and leaves noise in q'' that the next steps' error estimate and Newton
    /// iteration pay for. Then only the rates of the first-order states are corrected: their
    /// rows (Eq. 3.85, 3.91) are affine in their own rate alone, so the correction of
    /// M [Δq''_a; Δy'] = −[0; f_y] zeroes them exactly, and the second-order coordinates keep the
    /// step's accelerations plus the jump.
    ///
    /// INTERPRETATION: the thesis (Section 3.3.2) restarts the integration at each control
    /// instant without saying how q'' is made consistent. On the 75 s LuGre walk this takes 9 %
    /// of the residual evaluations off iterating to consistency, with the walk's figures
    /// unchanged; the stand's identification campaigns, where the joint accelerations at the
    /// instants matter, keep their accuracy (correcting the first-order rates alone: noise-free
    /// identification errors 7.1e-4 -> 1.08e-3; docs/performance-log.md, sessions 27-28).
    ///
    /// Without Δf (the system returns false) or a factorization of M, this is
    /// [`Self::reset_accelerations`].
    pub fn reset_accelerations_after_input_jump<S: System + ?Sized>(&mut self, sys: &mut S, previous: &[f64]) -> Result<(), SimError> {
        self.plain_newton = false;
        if let (true, Some(jacobian)) = (self.mass_outdated, &self.jacobian) {
            if let Some(lu) = Factorization::new(jacobian.m.clone(), &self.first_order(sys), self.mass_lu.as_ref()) {
                self.mass_lu = Some(lu);
                self.stats.factorizations += 1;
            }
            self.mass_outdated = false;
        }
        let s = &self.state;
        let exact = self.mass_lu.is_some() && sys.input_change(s.t, s.q.as_slice(), s.qd.as_slice(), s.qdd.as_slice(), previous, &mut self.work.f) && self.work.f.iter().all(|x| x.is_finite());
        let Some(jump) = exact.then(|| self.mass_lu.as_ref().and_then(|lu| lu.solve(&self.work.f))).flatten() else {
            return self.reset_accelerations(sys);
        };
        self.state.qdd -= &jump;
        let t = self.state.t;
        let s = &self.state;
        if self.surrogate_base {
            sys.surrogate_residual(t, s.q.as_slice(), s.qd.as_slice(), s.qdd.as_slice(), &mut self.work.f);
            self.stats.surrogate_evaluations += 1;
        } else {
            sys.residual(t, s.q.as_slice(), s.qd.as_slice(), s.qdd.as_slice(), &mut self.work.f);
            self.stats.residual_evaluations += 1;
        }
        check_finite(sys, t, None, &self.work.f)?;
        self.weights(sys);
        let test = self.newton_test(sys, self.h);
        let lu = self.mass_lu.as_ref().expect("factorized");
        if let Some(dx) = lu.solve(&self.work.f) {
            let consistent = &self.state.qdd - &dx;
            if test.converged(test.norm(&dx), &dx, &consistent) {
                self.state.qdd = consistent;
                return Ok(());
            }
        }
        for (f, order) in self.work.f.iter_mut().zip(&sys.layout().orders) {
            if *order == Order::Second {
                *f = 0.0;
            }
        }
        if let Some(dx) = lu.solve(&self.work.f) {
            self.state.qdd -= &dx;
        }
        Ok(())
    }

    /// Newton iterations q'' ← q'' − M⁻¹ f with the kept factorization of M, until the
    /// correction passes the Newton test of the next step (true) or is not at least
    /// `contraction` times smaller than the one before (false).
    fn consistent_accelerations<S: System + ?Sized>(&mut self, sys: &mut S, contraction: f64) -> Result<bool, SimError> {
        let t = self.state.t;
        self.weights(sys);
        let test = self.newton_test(sys, self.h);
        let mut previous = f64::INFINITY;
        for _ in 0..self.options.max_iterations {
            sys.residual(t, self.state.q.as_slice(), self.state.qd.as_slice(), self.state.qdd.as_slice(), &mut self.work.f);
            self.stats.residual_evaluations += 1;
            self.surrogate_base = false;
            check_finite(sys, t, None, &self.work.f)?;
            let lu = self.mass_lu.as_ref().expect("factorized");
            let Some(dx) = lu.solve(&self.work.f) else {
                return Ok(false);
            };
            self.state.qdd -= &dx;
            let norm = test.norm(&dx);
            if test.converged(norm, &dx, &self.state.qdd) {
                return Ok(true);
            }
            if !(norm <= contraction * previous) {
                return Ok(false);
            }
            previous = norm;
        }
        Ok(false)
    }

    /// Integrates up to exactly `t_end` with adaptive steps (Eq. 3.15): on return `state().t == t_end`.
    /// Inputs are held constant.
    pub fn advance_to<S: System + ?Sized>(&mut self, sys: &mut S, t_end: f64) -> Result<(), SimError> {
        self.advance_to_observed(sys, t_end, |_, _| {})
    }

    /// [`Self::advance_to`], calling `observe(sys, state)` after every accepted step (to integrate
    /// powers into energies, record fine-grained outputs, ...).
    pub fn advance_to_observed<S: System + ?Sized>(&mut self, sys: &mut S, t_end: f64, mut observe: impl FnMut(&mut S, &State)) -> Result<(), SimError> {
        if t_end < self.state.t {
            return Err(SimError::Backwards { requested: t_end, current: self.state.t });
        }
        let eps = 1e-12 * t_end.abs().max(1.0);
        while t_end - self.state.t > eps {
            let remaining = t_end - self.state.t;
            // Equal steps over the remaining interval rather than long ones and a sliver: with
            // requested instants on a regular grid (control periods), the step and its
            // factorization then carry over from one interval to the next.
            let steps = (remaining / self.h.min(self.options.h_max) * (1.0 - 1e-9)).ceil().max(1.0);
            let lands = steps == 1.0;
            let h = remaining / steps;
            match self.step(sys, h)? {
                StepOutcome::Accepted => {
                    if lands {
                        self.state.t = t_end;
                    }
                    observe(sys, &self.state);
                }
                StepOutcome::Rejected { h_next } => {
                    if h_next < self.options.h_min {
                        let rows = self.fastest_rows(sys);
                        return Err(SimError::StepTooSmall { t: self.state.t, h, error: f64::NAN, rows });
                    }
                    self.h = h_next;
                }
            }
        }
        // A remainder below `eps` is not worth a step: the state is taken as the one at t_end, so
        // that `state().t` is exactly the requested instant.
        self.state.t = t_end;
        Ok(())
    }

    /// The Newton test of a step of size h, with the weights of [`Self::weights`].
    fn newton_test<S: System + ?Sized>(&mut self, sys: &S, h: f64) -> NewtonTest {
        let scales = match &self.newton_scales {
            Some(scales) if scales.is_for(&self.options, &self.work.weight_q) => Arc::clone(scales),
            _ => Arc::clone(self.newton_scales.insert(Arc::new(NewtonScales::new(&self.options, &sys.layout().orders, &self.work.weight_q)))),
        };
        NewtonTest::new(scales, h)
    }

    fn weights<S: System + ?Sized>(&mut self, sys: &S) {
        let layout = sys.layout();
        for i in 0..self.work.weight_q.len() {
            self.work.weight_q[i] = 1.0 / layout.scales[i];
        }
    }

    fn refresh_jacobian<S: System + ?Sized>(&mut self, sys: &mut S, t: f64) {
        self.jacobian = Some(Jacobian::evaluate(sys, t, self.work.q.as_slice(), self.work.qd.as_slice(), self.work.qdd.as_slice()));
        self.stats.jacobian_evaluations += 1;
        self.jacobian_fresh = true;
        self.mass_outdated = true;
        self.lu = None;
    }

    fn factorize<S: System + ?Sized>(&mut self, sys: &mut S, h: f64) -> Result<(), SimError> {
        if self.jacobian.is_none() {
            self.refresh_jacobian(sys, self.state.t + h);
        }
        let jac = self.jacobian.as_ref().expect("jacobian present");
        let matrix: DMatrix<f64> = jac.iteration_matrix(self.options.beta, self.options.gamma, h);
        let first_order = self.first_order(sys);
        self.stats.factorizations += 1;
        let Some(lu) = Factorization::new(matrix, &first_order, self.lu.as_ref().map(|(lu, _)| lu)) else {
            return Err(SimError::Singular { what: "Newmark iteration", t: self.state.t });
        };
        self.lu = Some((lu, h));
        // Broyden's steps updated the previous matrix.
        self.broyden.clear();
        Ok(())
    }

    /// Which coordinates are first-order states (candidates for the reduced factorization).
    fn first_order<S: System + ?Sized>(&self, sys: &S) -> Vec<bool> {
        sys.layout().orders.iter().map(|o| *o == Order::First).collect()
    }

    /// The Newton predictor of q''(t+h). Second-order coordinates: q''(t), the thesis' choice.
    /// First-order states y = q' (bristle deflections, currents, Section 3.3.2) are fast: a
    /// LuGre bristle relaxes to its steady deflection in well under a millisecond, against steps
    /// of up to 10 ms. Their predictor holds the state itself, y(t+h) = y(t), i.e.
    /// y'(t+h) = −(1 − γ)/γ · y'(t) by Eq. 3.8, instead of holding its rate: over a step much
    /// longer than its time constant a stiff state barely moves, while its rate at t is no guide
    /// to its rate at t+h (the rate a stiff state takes under the Newmark rule alternates in
    /// sign from step to step). INTERPRETATION: the thesis (Eq. 3.10) does not say how the
    /// Newton iteration is started; benches/walk: 20 % fewer residual evaluations on the 75 s
    /// LuGre walk, the physics figures unchanged.
    fn predict<S: System + ?Sized>(&mut self, sys: &S) {
        let hold = -(1.0 - self.options.gamma) / self.options.gamma;
        for (i, order) in sys.layout().orders.iter().enumerate() {
            self.work.qdd[i] = match order {
                Order::Second => self.state.qdd[i],
                Order::First => hold * self.state.qdd[i],
            };
        }
    }

    /// Newmark predictor-corrector for q(t+h), q'(t+h) from q''(t+h) (Eq. 3.7-3.8).
    fn update_kinematics(&mut self, h: f64) {
        let (b, g) = (self.options.beta, self.options.gamma);
        let s = &self.state;
        let w = &mut self.work;
        for i in 0..s.q.len() {
            w.q[i] = s.q[i] + h * s.qd[i] + (0.5 - b) * h * h * s.qdd[i] + b * h * h * w.qdd[i];
            w.qd[i] = s.qd[i] + (1.0 - g) * h * s.qdd[i] + g * h * w.qdd[i];
        }
    }

    /// One attempted step of size h: Newton-Raphson on q''(t+h) (Eq. 3.10) with the iteration
    /// matrix of Eq. 3.14 kept from step to step and updated by Broyden within the step
    /// (`broyden.rs`), then the error estimate of Eq. 3.15.
    fn step<S: System + ?Sized>(&mut self, sys: &mut S, h: f64) -> Result<StepOutcome, SimError> {
        let t_new = self.state.t + h;
        self.weights(sys);
        self.jacobian_fresh = false;
        let test = self.newton_test(sys, h);
        'attempt: loop {
            // Predictor (a missing Jacobian is evaluated there).
            self.predict(sys);
            self.update_kinematics(h);
            // A step that lands on a requested instant differs from the nominal one by the
            // rounding of t_end − t (relative 1e-13 at t ~ 100 s): the factorization still fits.
            if self.lu.as_ref().is_none_or(|(_, hl)| (hl - h).abs() > 1e-9 * h) {
                self.factorize(sys, h)?;
            }
            let mut previous = f64::INFINITY;
            self.broyden.clear();
            // The next evaluation of f follows a converged surrogate iteration: it verifies it.
            let mut verifying = false;
            for iteration in 0..self.options.max_iterations {
                self.update_kinematics(h);
                sys.residual(t_new, self.work.q.as_slice(), self.work.qd.as_slice(), self.work.qdd.as_slice(), &mut self.work.f);
                self.stats.residual_evaluations += 1;
                self.stats.newton_iterations += 1;
                self.surrogate_base = false;
                if self.work.f.iter().any(|x| !x.is_finite()) {
                    break;
                }
                self.surrogate_base = self.options.surrogate_iterations > 0 && sys.keep_surrogate_base(self.work.q.as_slice(), self.work.qd.as_slice(), self.work.qdd.as_slice(), &self.work.f);
                let Some(dx) = self.correction(&test) else { break };
                self.work.qdd -= &dx;
                let norm = test.norm(&dx);
                if !norm.is_finite() {
                    break;
                }
                let converged = test.converged(norm, &dx, &self.work.qdd);
                if std::mem::take(&mut verifying) {
                    self.trust.verify(converged);
                }
                if converged {
                    self.update_kinematics(h);
                    return Ok(self.accept_or_reject(sys, h));
                }
                let contraction = norm / previous;
                if previous.is_finite() && contraction > self.options.slow_contraction && test.dot(&dx, &self.work.dx_previous) < -REVERSAL * norm * previous {
                    // The correction turns back on the previous one without contracting: Newton
                    // jumps across a kink (|q'| in a LuGre bristle rate, Eq. 3.85; the linear
                    // zone of the ground friction) and back, with a Jacobian from one side of
                    // it. Go to the middle of the last correction rather than to its end. Only
                    // the path of the iteration changes: the step is accepted by the same test.
                    self.work.qdd.axpy(0.5, &dx, 1.0);
                    self.broyden.clear();
                }
                self.work.dx_previous.copy_from(&dx);
                if iteration > 0 && contraction > self.options.slow_contraction && !self.jacobian_fresh {
                    // Modified Newton is slowing down: refresh the Jacobian at this iterate and
                    // go on from it.
                    self.refresh_jacobian(sys, t_new);
                    self.factorize(sys, h)?;
                    previous = f64::INFINITY;
                    continue;
                }
                if contraction > 1.0 && iteration > 1 {
                    break;
                }
                previous = norm;
                if self.surrogate_base && !self.plain_newton && self.iterate_on_surrogate(sys, h, t_new, &test, norm) {
                    if self.trust.accept(self.options.unverified_steps) {
                        self.stats.unverified_steps += 1;
                        self.update_kinematics(h);
                        return Ok(self.accept_or_reject(sys, h));
                    }
                    verifying = true;
                }
            }
            // Failure with the current Jacobian.
            self.trust = SurrogateTrust::default();
            if !self.jacobian_fresh {
                if self.work.qdd.iter().any(|x| !x.is_finite()) {
                    // The iteration blew up: evaluate the Jacobian at the predictor instead.
                    self.predict(sys);
                    self.update_kinematics(h);
                }
                self.refresh_jacobian(sys, t_new);
                continue 'attempt;
            }
            self.stats.rejected_steps += 1;
            // This Jacobian belongs to a failed step (possibly evaluated where the residual is not
            // finite): the next attempt evaluates its own rather than inherit a poisoned one.
            self.jacobian = None;
            self.lu = None;
            let h_next = h * 0.25;
            if h_next < self.options.h_min {
                if self.options.surrogate_iterations > 0 && !self.plain_newton {
                    // Each evaluation of f was followed by the surrogate's iterations, which
                    // took q'' back towards the surrogate's root: where the surrogate is a poor
                    // model of f (its base far from the step's end), the two alternate without
                    // converging at any h (a 25° slope with three loaded feet, t = 71.08 s of
                    // the terrain-class benchmark's seed 9). The step starts again from the
                    // first step size on f alone, the thesis' iteration, until the next control
                    // instant.
                    self.plain_newton = true;
                    return Ok(StepOutcome::Rejected { h_next: self.options.h_initial.clamp(self.options.h_min, self.options.h_max) });
                }
                return Err(self.newton_failure(sys, t_new, h));
            }
            return Ok(StepOutcome::Rejected { h_next });
        }
    }

    /// The Newton correction of q'' for the residual in `work.f` with the kept matrix updated by
    /// Broyden (`broyden.rs`; its product form is odd in the steps, so it takes the corrections
    /// dx = −s as they are); `None` when the factorization cannot solve.
    fn correction(&mut self, test: &NewtonTest) -> Option<DVector<f64>> {
        let (lu, _) = self.lu.as_ref().expect("factorized");
        let newton = lu.solve(&self.work.f)?;
        Some(self.broyden.step(newton, |a, b| test.dot(a, b)))
    }

    /// Newton iterations on the system's surrogate residual (`System::surrogate_residual`),
    /// about the evaluation of f just made, with the kept matrix updated by Broyden: they take
    /// q'' to the surrogate's root at the cost of its evaluations, and the next evaluation of f
    /// judges the iterate by the Newton test as any other, unless the step is accepted on the
    /// surrogate's test ([`NewmarkOptions::unverified_steps`]). A correction more than
    /// [`SURROGATE_GROWTH`] times `bound` (the last correction from f), or growing after the
    /// second, is not taken. Returns whether the surrogate's Newton test passed. INTERPRETATION:
    /// the thesis iterates on f alone (Section 3.3.2).
    fn iterate_on_surrogate<S: System + ?Sized>(&mut self, sys: &mut S, h: f64, t_new: f64, test: &NewtonTest, bound: f64) -> bool {
        self.broyden.clear();
        let mut converged = false;
        let mut previous = f64::INFINITY;
        for iteration in 0..self.options.surrogate_iterations {
            self.update_kinematics(h);
            sys.surrogate_residual(t_new, self.work.q.as_slice(), self.work.qd.as_slice(), self.work.qdd.as_slice(), &mut self.work.f);
            self.stats.surrogate_evaluations += 1;
            let Some(dx) = self.correction(test) else { break };
            let norm = test.norm(&dx);
            // A non-finite surrogate gives a NaN norm, which fails the first test too.
            if !(norm <= SURROGATE_GROWTH * bound) || (iteration > 1 && norm > previous) {
                break;
            }
            self.work.qdd -= &dx;
            if test.converged(norm, &dx, &self.work.qdd) {
                converged = true;
                break;
            }
            previous = norm;
        }
        // The next correction is f's: Broyden's steps were the surrogate's.
        self.broyden.clear();
        converged
    }

    /// Error estimate of Eq. 3.15, ε = h²/12 · rms(Δq''), with each coordinate weighted by its
    /// scale; accepts the step when ε ≤ tolerance and proposes the next h.
    fn accept_or_reject<S: System + ?Sized>(&mut self, _sys: &mut S, h: f64) -> StepOutcome {
        let n = self.state.q.len();
        let mut sum = 0.0;
        for i in 0..n {
            let d = (self.work.qdd[i] - self.state.qdd[i]) * self.work.weight_q[i];
            sum += d * d;
        }
        let error = h * h / 12.0 * (sum / n as f64).sqrt();
        let o = &self.options;
        let ratio = if error > 0.0 { (o.tolerance / error).cbrt() } else { f64::INFINITY };
        if o.adaptive && error > o.tolerance && h > o.h_min * (1.0 + 1e-9) {
            self.stats.rejected_steps += 1;
            self.trust = SurrogateTrust::default();
            let h_next = (h * (0.9 * ratio).clamp(0.1, 0.9)).max(o.h_min);
            return StepOutcome::Rejected { h_next };
        }
        self.state.t += h;
        self.state.q.copy_from(&self.work.q);
        self.state.qd.copy_from(&self.work.qd);
        self.state.qdd.copy_from(&self.work.qdd);
        self.stats.steps += 1;
        if o.adaptive {
            let grow = (0.9 * ratio).clamp(0.2, 2.0);
            // Keep h (and the factorization) unless the change is worth a new LU; h_max is
            // taken as soon as it is allowed (a step shortened to land on an instant would
            // otherwise hold the nominal step just below it).
            let proposed = (h * grow).clamp(o.h_min, o.h_max);
            let hold = proposed >= 0.9 * h && proposed <= 1.25 * self.h.max(h) && proposed < o.h_max;
            self.h = if hold { self.h.max(h) } else { proposed };
        } else {
            self.h = o.h_max;
        }
        StepOutcome::Accepted
    }

    /// The error for a step that Newton cannot solve even at the minimum step: the residual at
    /// the last iterate (NewtonDiverged), or its non-finite rows (NonFinite), taken at the
    /// predictor when the residual is not finite there already.
    fn newton_failure<S: System + ?Sized>(&mut self, sys: &mut S, t_new: f64, h: f64) -> SimError {
        self.update_kinematics(h);
        sys.residual(t_new, self.work.q.as_slice(), self.work.qd.as_slice(), self.work.qdd.as_slice(), &mut self.work.f);
        self.stats.residual_evaluations += 1;
        if self.work.f.iter().all(|x| x.is_finite()) {
            return SimError::NewtonDiverged { t: self.state.t, h, rows: largest_rows(sys.layout(), &self.work.f, 5) };
        }
        let iterate = self.work.f.clone();
        self.work.qdd.copy_from(&self.state.qdd);
        self.update_kinematics(h);
        sys.residual(t_new, self.work.q.as_slice(), self.work.qd.as_slice(), self.work.qdd.as_slice(), &mut self.work.f);
        self.stats.residual_evaluations += 1;
        let f = if self.work.f.iter().all(|x| x.is_finite()) { &iterate } else { &self.work.f };
        match check_finite(sys, t_new, Some(h), f) {
            Err(e) => e,
            Ok(()) => unreachable!("non-finite residual checked above"),
        }
    }

    fn fastest_rows<S: System + ?Sized>(&self, sys: &S) -> Vec<super::ResidualRow> {
        let d: Vec<f64> = (0..self.state.q.len()).map(|i| (self.work.qdd[i] - self.state.qdd[i]) / sys.layout().scales[i]).collect();
        largest_rows(sys.layout(), &d, 5)
    }
}

fn check_finite<S: System + ?Sized>(sys: &S, t: f64, h: Option<f64>, f: &[f64]) -> Result<(), SimError> {
    if f.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        let rows = largest_rows(sys.layout(), f, 5).into_iter().filter(|r| !r.value.is_finite()).collect();
        Err(SimError::NonFinite { t, h, rows })
    }
}
