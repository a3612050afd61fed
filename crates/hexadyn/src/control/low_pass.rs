//! The digital first-order low-pass filter of the torque estimation (thesis Section 5.6.2): 3 Hz
//! on the encoder positions at the input of the leg model and on the measured currents.

use std::f64::consts::TAU;

use nalgebra::Complex;

/// Cut-off of the digital filters of the torque estimation (Hz), Section 5.6.2.
pub const DIGITAL_CUTOFF_HZ: f64 = 3.0;

/// Time constants 1/(2π f_c) of the 3 Hz filters a joint must have slid before a detection
/// counts (the free gait's landing, the stops of the Section 5.6.3 experiment past a reversal):
/// 3, after which a first-order filter has followed 95 % of a step (159 ms, 7 mm of AMRU5's foot
/// at the 4.5 cm/s of the landing).
pub const SETTLING_TIME_CONSTANTS: f64 = 3.0;

/// [`SETTLING_TIME_CONSTANTS`] time constants of the 3 Hz filters (s).
pub fn settling_time() -> f64 {
    SETTLING_TIME_CONSTANTS / (TAU * DIGITAL_CUTOFF_HZ)
}

/// y_k = a y_{k−1} + (1 − a) x_k with a = exp(−2π f_c Δt): the step-invariant discretization
/// of 1/(1 + s/ω_c) at the sampling time Δt, unit gain at rest, no delay on the current sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DigitalLowPass {
    /// Pole a = exp(−2π f_c Δt).
    pub a: f64,
    /// Last output; `None` before the first sample, which starts the filter at rest on it.
    pub y: Option<f64>,
}

impl DigitalLowPass {
    pub fn new(cutoff_hz: f64, dt: f64) -> Self {
        DigitalLowPass { a: (-TAU * cutoff_hz * dt).exp(), y: None }
    }

    /// Filters the next sample `x`.
    pub fn update(&mut self, x: f64) -> f64 {
        let y = match self.y {
            Some(y) => self.a * y + (1.0 - self.a) * x,
            None => x,
        };
        self.y = Some(y);
        y
    }

    /// H(e^{jωΔt}) = (1 − a) / (1 − a e^{−jωΔt}) at ω (rad/s).
    pub fn response(&self, omega: f64, dt: f64) -> Complex<f64> {
        Complex::new(1.0 - self.a, 0.0) / (Complex::new(1.0, 0.0) - Complex::from_polar(self.a, -omega * dt))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gain_and_phase_at_the_cutoff_and_below() {
        let dt = 0.01;
        for f in [1.0, 3.0, 10.0] {
            let omega = TAU * f;
            let mut lp = DigitalLowPass::new(DIGITAL_CUTOFF_HZ, dt);
            // Steady state of a sampled sine: least squares on sin and cos over whole periods.
            let (mut ys, mut yc, mut n) = (0.0, 0.0, 0.0);
            for k in 0..20_000 {
                let t = k as f64 * dt;
                let y = lp.update((omega * t).sin());
                if k >= 10_000 {
                    ys += y * (omega * t).sin();
                    yc += y * (omega * t).cos();
                    n += 1.0;
                }
            }
            let measured = Complex::new(2.0 * ys / n, 2.0 * yc / n);
            let h = lp.response(omega, dt);
            assert!((measured - h).norm() < 1e-3, "{f} Hz: {measured} vs {h}");
            // Against the continuous 1/(1 + jω/ω_c): the discretization costs a phase of about
            // ω Δt / 2 (half a sample) and a gain within 2 %.
            let c = 1.0 / Complex::new(1.0, f / DIGITAL_CUTOFF_HZ);
            assert!((h.norm() / c.norm() - 1.0).abs() < 0.02, "{f} Hz gain {} vs {}", h.norm(), c.norm());
            assert!((h.arg() - c.arg()).abs() < 0.6 * omega * dt, "{f} Hz phase {} vs {}", h.arg(), c.arg());
        }
        // At 3 Hz, 100 Hz sampling: a = exp(−0.06 π) = 0.8282, |H| = 0.708, arg H = −39.7°.
        let h = DigitalLowPass::new(3.0, dt).response(TAU * 3.0, dt);
        assert!((h.norm() - 0.708).abs() < 1e-3 && (h.arg().to_degrees() + 39.7).abs() < 0.1, "{h}");
    }

    #[test]
    fn step_response_and_start_at_rest() {
        let mut lp = DigitalLowPass::new(3.0, 0.01);
        assert_eq!(lp.update(2.0), 2.0);
        // A step of 1 from 2: 1 − a^k of it after k samples.
        for k in 1..=50 {
            let y = lp.update(3.0);
            assert!((y - (3.0 - lp.a.powi(k))).abs() < 1e-12);
        }
    }
}
