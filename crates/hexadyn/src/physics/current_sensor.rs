//! The motor current sensors of the slave boards (thesis Section 5.6.2): the current is measured
//! through an analog first-order low-pass filter at 30 Hz, then sampled by the board at the
//! control instants, with optional Gaussian measurement noise.
//!
//! The analog filter is a continuous system, y' = ω_c (i − y) with ω_c = 2π f_c. The plant
//! integrates it exactly over each accepted integration step of the robot model (step ≤ the
//! control period) for a current varying linearly across the step ([`AnalogLowPass::advance`]);
//! a jump of the current at a control instant (the voltage held by the zero-order hold changes
//! there and, without inductance, the current follows at once, Eq. 4.4) is taken as a jump of
//! the filter input, which the filter output does not follow instantly.

use std::f64::consts::TAU;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

/// Cut-off of the analog current filter of the AMRU5 slave boards (Hz), Section 5.6.2.
pub const ANALOG_CURRENT_CUTOFF_HZ: f64 = 30.0;

/// Analog first-order low-pass y' = ω_c (x − y), integrated exactly for an input linear
/// between the instants it is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnalogLowPass {
    /// ω_c = 2π f_c (rad/s).
    pub omega_c: f64,
    /// Output y at `t`.
    pub y: f64,
    /// Input x at `t`.
    pub x: f64,
    pub t: f64,
}

impl AnalogLowPass {
    /// At rest at the input `x` at `t` (y = x).
    pub fn new(cutoff_hz: f64, t: f64, x: f64) -> Self {
        AnalogLowPass { omega_c: TAU * cutoff_hz, y: x, x, t }
    }

    /// Advances to `t` where the input is `x`, the input varying linearly from the last one:
    /// with h = t − t_0, s = (x − x_0)/h and a = exp(−ω_c h), the exact solution is
    /// y = x − s/ω_c + (y_0 − x_0 + s/ω_c) a. With h = 0 the input jumps to `x`.
    pub fn advance(&mut self, t: f64, x: f64) {
        self.advance_decaying(t, x, self.decay(t));
    }

    /// a = exp(−ω_c h) over h = t − t_0.
    fn decay(&self, t: f64) -> f64 {
        (-self.omega_c * (t - self.t)).exp()
    }

    /// [`Self::advance`] with a = [`Self::decay`] given (filters of the same ω_c and t_0 share it).
    fn advance_decaying(&mut self, t: f64, x: f64, a: f64) {
        let h = t - self.t;
        if h > 0.0 {
            let lag = (x - self.x) / (h * self.omega_c);
            self.y = x - lag + (self.y - self.x + lag) * a;
            self.t = t;
        }
        self.x = x;
    }

    /// Frequency response 1 / (1 + jω/ω_c) at ω (rad/s): (gain, phase in rad).
    pub fn response(&self, omega: f64) -> (f64, f64) {
        let r = omega / self.omega_c;
        (1.0 / (1.0 + r * r).sqrt(), -r.atan())
    }
}

/// The current sensing chain of the plant: the `[sensors]` options of a scenario.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurrentSensing {
    /// Cut-off of the analog filter (Hz), 30 Hz on AMRU5.
    pub cutoff_hz: f64,
    /// Standard deviation of the Gaussian noise added to each sample (A); 0: none.
    pub noise_a: f64,
    /// Seed of the noise.
    pub seed: u64,
}

impl Default for CurrentSensing {
    /// INTERPRETATION: the thesis gives no figure for the current noise of the boards (Section
    /// 5.6.2 only says it disturbs detection without the 3 Hz filter, and the meshing of the
    /// sprocket wheels, not modelled here, dominates Fig. 5.17): no noise by default, so that a
    /// run depends on its model alone; a scenario sets `[sensors] current_noise_a`.
    fn default() -> Self {
        CurrentSensing { cutoff_hz: ANALOG_CURRENT_CUTOFF_HZ, noise_a: 0.0, seed: 0 }
    }
}

/// The current sensors of `N` motors: an [`AnalogLowPass`] each, sampled with seeded noise.
#[derive(Clone, Debug)]
pub struct CurrentSensors<const N: usize> {
    filters: [AnalogLowPass; N],
    noise: Option<(Normal<f64>, ChaCha8Rng)>,
}

impl<const N: usize> CurrentSensors<N> {
    /// Filters at rest at the currents `i` at `t`. A non-finite or negative noise is a bug of
    /// the caller (scenario values are validated before).
    pub fn new(options: &CurrentSensing, t: f64, i: &[f64; N]) -> Self {
        let noise = (options.noise_a > 0.0).then(|| {
            (Normal::new(0.0, options.noise_a).expect("a validated finite noise level"), ChaCha8Rng::seed_from_u64(options.seed))
        });
        CurrentSensors { filters: std::array::from_fn(|k| AnalogLowPass::new(options.cutoff_hz, t, i[k])), noise }
    }

    /// The motor currents `i` at `t` (an accepted integration step, or the start of a control
    /// period after the voltages jumped).
    pub fn advance(&mut self, t: f64, i: &[f64; N]) {
        // The filters share ω_c and their last instant (they are built and advanced together):
        // one exponential for all.
        let Some(&first) = self.filters.first() else { return };
        let a = first.decay(t);
        for (f, &x) in self.filters.iter_mut().zip(i) {
            debug_assert!(f.omega_c == first.omega_c && f.t == first.t);
            f.advance_decaying(t, x, a);
        }
    }

    /// The filtered currents plus one draw of noise each: what the board samples.
    pub fn sample(&mut self) -> [f64; N] {
        let mut out = self.filters.map(|f| f.y);
        if let Some((normal, rng)) = &mut self.noise {
            for x in &mut out {
                *x += normal.sample(rng);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steady-state amplitude and phase of `y` against sin(ω t): least squares on sin and cos.
    fn fit(t: &[f64], y: &[f64], omega: f64) -> (f64, f64) {
        let (mut ss, mut sc, mut cc, mut ys, mut yc) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (&t, &y) in t.iter().zip(y) {
            let (s, c) = (omega * t).sin_cos();
            ss += s * s;
            sc += s * c;
            cc += c * c;
            ys += y * s;
            yc += y * c;
        }
        let det = ss * cc - sc * sc;
        let (a, b) = ((ys * cc - yc * sc) / det, (yc * ss - ys * sc) / det);
        (a.hypot(b), b.atan2(a))
    }

    #[test]
    fn analog_filter_gain_and_phase_at_30_and_10_hz() {
        for f in [10.0, 30.0, 60.0] {
            let omega = TAU * f;
            let mut lp = AnalogLowPass::new(ANALOG_CURRENT_CUTOFF_HZ, 0.0, 0.0);
            let h = 1e-4;
            let (mut t, mut y) = (Vec::new(), Vec::new());
            for k in 1..=20_000 {
                let tk = k as f64 * h;
                lp.advance(tk, (omega * tk).sin());
                if tk > 0.5 {
                    t.push(tk);
                    y.push(lp.y);
                }
            }
            let (gain, phase) = fit(&t, &y, omega);
            let (g, p) = lp.response(omega);
            // 1/(1 + jω/ω_c): at the cut-off 1/√2 and −45°.
            if f == 30.0 {
                assert!((g - 0.5f64.sqrt()).abs() < 1e-12 && (p + std::f64::consts::FRAC_PI_4).abs() < 1e-12);
            }
            // The input is linear between samples: O((ω h)²) from the true sine.
            assert!((gain - g).abs() < 1e-4 && (phase - p).abs() < 1e-4, "{f} Hz: ({gain}, {phase}) vs ({g}, {p})");
        }
    }

    #[test]
    fn analog_filter_is_exact_for_a_ramp_whatever_the_steps() {
        // y' = ω (s t − y), y(0) = 0: y = s (t − (1 − e^{−ω t})/ω).
        let mut lp = AnalogLowPass::new(30.0, 0.0, 0.0);
        let s = 2.0;
        let mut t = 0.0;
        for h in [1e-3, 7e-3, 2e-4, 1e-2, 3.3e-3] {
            t += h;
            lp.advance(t, s * t);
            let w = lp.omega_c;
            let exact = s * (t - (1.0 - (-w * t).exp()) / w);
            assert!((lp.y - exact).abs() < 1e-14, "t = {t}: {} vs {exact}", lp.y);
        }
        // A jump of the input at an instant: the output follows exponentially.
        lp.advance(t, 0.0);
        let y0 = lp.y;
        lp.advance(t + 0.01, 0.0);
        assert!((lp.y - y0 * (-lp.omega_c * 0.01).exp()).abs() < 1e-14);
    }

    #[test]
    fn noise_is_seeded_and_has_its_standard_deviation() {
        let options = CurrentSensing { noise_a: 0.05, seed: 7, ..Default::default() };
        let draw = |o: &CurrentSensing| {
            let mut s = CurrentSensors::<3>::new(o, 0.0, &[1.0, 2.0, 3.0]);
            (0..4000).flat_map(|_| s.sample()).collect::<Vec<_>>()
        };
        let (a, b) = (draw(&options), draw(&options));
        assert_eq!(a, b);
        let c = draw(&CurrentSensing { seed: 8, ..options });
        assert_ne!(a, c);
        let e: Vec<f64> = a.iter().enumerate().map(|(k, x)| x - (k % 3 + 1) as f64).collect();
        let n = e.len() as f64;
        let mean = e.iter().sum::<f64>() / n;
        let sd = (e.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        // 12000 samples: the standard errors are 0.05/√n ≈ 4.6e-4 (mean) and ≈ 3.2e-4 (sd).
        assert!(mean.abs() < 2e-3 && (sd - 0.05).abs() < 2e-3, "mean {mean}, sd {sd}");
        // Without noise the samples are the filter outputs.
        let mut quiet = CurrentSensors::<3>::new(&CurrentSensing::default(), 0.0, &[1.0, 2.0, 3.0]);
        assert_eq!(quiet.sample(), [1.0, 2.0, 3.0]);
    }
}
