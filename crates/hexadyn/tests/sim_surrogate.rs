//! Newton iterations on a system's surrogate residual between two evaluations of f
//! (`System::surrogate_residual`, `NewmarkOptions::surrogate_iterations`): the surrogate changes
//! how many evaluations of f a step takes, never what the integrator accepts, since every
//! accepted iterate passes the Newton test on f itself; and the steps accepted on the surrogate's
//! own Newton test while a verification by f vouches for it (`NewmarkOptions::unverified_steps`);
//! and a step where f and the surrogate alternate without converging, taken again on f alone.

use hexadyn::sim::{Layout, Newmark, NewmarkOptions, Order, System};

/// What the block's surrogate is.
#[derive(Clone, Copy, PartialEq)]
enum Surrogate {
    /// None: the integrator iterates on f alone.
    None,
    /// The robot's kind: the force law exact, the smooth part (inertia, hardening spring)
    /// linearized about the base.
    Linearized,
    /// The residual off by a constant force: were its root accepted, the block would stand
    /// 5 mm away from where it is.
    Biased,
}

/// A block on a belt moving at v_b, held by a hardening spring, m x'' + k x + k₃ x³ +
/// F_c (2/π) atan((x' − v_b)/v_s) = 0: stick-slip through a steep regularised dry friction,
/// the kind of kink where Newton iterates most.
struct BeltBlock {
    layout: Layout,
    surrogate: Surrogate,
    /// (x, x', x'', f) of the base.
    base: Option<(f64, f64, f64, f64)>,
}

const M: f64 = 1.0;
const K: f64 = 100.0;
const K3: f64 = 2.0e4;
const F_C: f64 = 5.0;
const V_BELT: f64 = 0.1;
const V_S: f64 = 1e-3;
/// The biased surrogate's error: 5 mm of the spring.
const BIAS: f64 = K * 5e-3;

impl BeltBlock {
    fn new(surrogate: Surrogate) -> Self {
        let mut layout = Layout::default();
        layout.push("x", Order::Second, 1e-3, "block");
        BeltBlock { layout, surrogate, base: None }
    }
    fn friction(xd: f64) -> f64 {
        F_C * std::f64::consts::FRAC_2_PI * ((xd - V_BELT) / V_S).atan()
    }
}

impl System for BeltBlock {
    fn layout(&self) -> &Layout {
        &self.layout
    }
    fn residual(&mut self, _t: f64, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
        f[0] = M * qdd[0] + K * q[0] + K3 * q[0].powi(3) + Self::friction(qd[0]);
    }
    fn keep_surrogate_base(&mut self, q: &[f64], qd: &[f64], qdd: &[f64], f: &[f64]) -> bool {
        self.base = Some((q[0], qd[0], qdd[0], f[0]));
        self.surrogate != Surrogate::None
    }
    fn surrogate_residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
        let (x0, xd0, xdd0, f0) = self.base.expect("a base is kept before the surrogate is used");
        match self.surrogate {
            Surrogate::Linearized => {
                let stiffness = K + 3.0 * K3 * x0 * x0;
                f[0] = f0 + M * (qdd[0] - xdd0) + stiffness * (q[0] - x0) + Self::friction(qd[0]) - Self::friction(xd0);
            }
            _ => {
                self.residual(t, q, qd, qdd, f);
                f[0] += BIAS;
            }
        }
    }
}

/// x over 2 s of stick-slip at fixed 1 ms steps, and the integrator's counters.
fn run(surrogate: Surrogate) -> (Vec<f64>, hexadyn::sim::NewmarkStats) {
    run_with(surrogate, 0)
}

/// [`run`] with at most `unverified_steps` steps in a row accepted on the surrogate's Newton test.
fn run_with(surrogate: Surrogate, unverified_steps: usize) -> (Vec<f64>, hexadyn::sim::NewmarkStats) {
    let options = NewmarkOptions { adaptive: false, h_max: 1e-3, h_min: 1e-9, tolerance: 1e-6, surrogate_iterations: 8, unverified_steps, ..Default::default() };
    let mut block = BeltBlock::new(surrogate);
    let mut nm = Newmark::new(&mut block, 0.0, &[0.0], &[0.0], options).unwrap();
    let mut x = Vec::new();
    for i in 1..=2000 {
        nm.advance_to(&mut block, i as f64 * 1e-3).unwrap();
        x.push(nm.state().q[0]);
    }
    (x, nm.stats().clone())
}

/// The block sticks and slips (x' reaches the belt's speed and leaves it: the kinks). With the
/// linearized surrogate the steps are the same and the trajectory is that of Newton on f alone to
/// 1e-9 m (the Newton test leaves about 1e-11 m per step), for fewer evaluations of f. The biased
/// surrogate's root is 5e-3 m off, yet the trajectory stays within 1e-5 m: only its Newton
/// failures (some steps taken at h/4) move it, by their integration error.
#[test]
fn a_surrogate_changes_the_evaluations_not_the_solution() {
    let (reference, plain) = run(Surrogate::None);
    let (linearized, with_linearized) = run(Surrogate::Linearized);
    let (biased, with_biased) = run(Surrogate::Biased);
    eprintln!("f alone: {plain:?}\nlinearized: {with_linearized:?}\nbiased: {with_biased:?}");
    let amplitude = reference.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    assert!(amplitude > 0.03, "the block must be carried off and slip back: amplitude {amplitude} m");
    let gap = |x: &[f64]| x.iter().zip(&reference).fold(0.0_f64, |a, (x, r)| a.max((x - r).abs()));
    let (linearized_gap, biased_gap) = (gap(&linearized), gap(&biased));
    eprintln!("largest gaps to Newton on f alone: linearized {linearized_gap:.2e} m, biased {biased_gap:.2e} m");
    assert_eq!((with_linearized.steps, with_linearized.rejected_steps), (plain.steps, 0));
    assert!(linearized_gap < 1e-9, "linearized surrogate: trajectory {linearized_gap} m from Newton on f alone");
    assert!(biased_gap < 1e-5, "biased surrogate: trajectory {biased_gap} m from Newton on f alone");
    assert_eq!(plain.surrogate_evaluations, 0);
    assert!(with_linearized.surrogate_evaluations > 0 && with_biased.surrogate_evaluations > 0);
    assert!(with_linearized.residual_evaluations < plain.residual_evaluations, "{} vs {}", with_linearized.residual_evaluations, plain.residual_evaluations);
}

/// Steps accepted on the surrogate's own Newton test (`unverified_steps` 8): the linearized
/// surrogate earns the trust at its first verification and keeps it, so most steps take one
/// evaluation of f, and the trajectory stays that of Newton on f alone within what the Newton
/// test leaves over the run (1e-11 m a step, 2000 steps: 2e-8 m). The biased surrogate fails
/// every verification: no step is accepted on it, and the trajectory is the one above.
#[test]
fn steps_are_accepted_on_the_surrogate_only_while_a_verification_vouches_for_it() {
    let (reference, plain) = run(Surrogate::None);
    let (verified, with_verification) = run(Surrogate::Linearized);
    let (linearized, unverified) = run_with(Surrogate::Linearized, 8);
    let (biased, with_biased) = run_with(Surrogate::Biased, 8);
    eprintln!("f alone: {plain:?}\nlinearized, every step verified: {with_verification:?}\nlinearized, 8 unverified: {unverified:?}\nbiased, 8 unverified: {with_biased:?}");
    let gap = |x: &[f64]| x.iter().zip(&reference).fold(0.0_f64, |a, (x, r)| a.max((x - r).abs()));
    let (linearized_gap, biased_gap) = (gap(&linearized), gap(&biased));
    eprintln!("largest gaps to Newton on f alone: linearized {linearized_gap:.2e} m (every step verified {:.2e} m), biased {biased_gap:.2e} m", gap(&verified));
    assert!(unverified.unverified_steps > plain.steps / 2, "{} of {} steps accepted on the surrogate", unverified.unverified_steps, unverified.steps);
    assert!(unverified.residual_evaluations < with_verification.residual_evaluations, "{} vs {} evaluations of f", unverified.residual_evaluations, with_verification.residual_evaluations);
    assert!(linearized_gap < 2e-8, "linearized surrogate: trajectory {linearized_gap} m from Newton on f alone");
    assert_eq!(with_biased.unverified_steps, 0, "a surrogate whose verifications fail is never trusted");
    assert!(biased_gap < 1e-5, "biased surrogate: trajectory {biased_gap} m from Newton on f alone");
    assert_eq!(with_verification.unverified_steps, 0);
}

/// A step where the surrogate and f alternate at every step size (the terrain-class benchmark's
/// 25° slope, seed 9, uphill 41° from the heading: at t = 71.08 s the body leans on three feet,
/// the kept J_foot no guide to the contact forces; each evaluation of f brings q'' closer to its
/// root, the surrogate's iterations take it back, and the step was rejected down to h_min, the
/// run ending on "Newton-Raphson did not converge"): the step is taken again on f alone
/// (`Newmark`'s fallback until the next control instant) and the walk goes on.
#[test]
fn a_step_the_surrogate_cannot_solve_is_taken_on_f_alone() {
    use hexadyn::physics::terrain::classes::TerrainClass;
    use hexadyn::scenario::{run_scenario, Override, Scenario};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/hexadyn/scenarios/free_gait_straight.toml");
    let seeded = TerrainClass::Slope { angle: 25f64.to_radians() }.generate(9).unwrap();
    assert!(seeded.drawn.contains("uphill at 41 deg"), "{}", seeded.drawn);
    let overrides = [Override::new("scenario.duration_s", 72.0), Override::new("gait.navigation", true), Override::new("gait.heading.vx_m_s", 0.01)];
    let mut s = Scenario::from_file_with(&path, &overrides).unwrap_or_else(|e| panic!("{e}"));
    s.terrain = seeded.terrain;
    let r = run_scenario(&s, |_| {}).unwrap_or_else(|e| panic!("{e}"));
    assert!(r.summary.duration_s >= 72.0 - 1e-9, "{}", r.summary.duration_s);
}
