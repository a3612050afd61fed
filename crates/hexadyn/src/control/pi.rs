//! Joint position controllers (thesis Section 3.4.4 and 4.4) and the encoders they read
//! (Section 2.3.2).

use std::f64::consts::TAU;

use serde::{Deserialize, Serialize};

/// Digital PI position controller with antiwindup, Eq. 4.18-4.20 (Section 4.4.5).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DigitalPi {
    /// Gain K (V/rad or V/m), Table 4.1.
    pub k: f64,
    /// Integral time T_i (s), Table 4.1.
    pub t_i: f64,
    /// Sampling time Δt (s): 0.01 on AMRU5 (100 Hz master, Section 2.3.2).
    pub dt: f64,
    /// Integral term I_{k-1} (V).
    pub integral: f64,
}

impl DigitalPi {
    pub fn new(k: f64, t_i: f64, dt: f64) -> Self {
        DigitalPi { k, t_i, dt, integral: 0.0 }
    }

    /// One control step on the position error ε_k = q_d - q (rad or m): u_k = P_k + I_k with
    /// P_k = K ε_k and I_k = I_{k-1} + K/T_i ε_k Δt (Eq. 4.18-4.19), saturated to ±`u_sat` (V);
    /// when saturated the integral is recomputed as I_k = u_k - P_k (Eq. 4.20).
    pub fn update(&mut self, error: f64, u_sat: f64) -> f64 {
        let p = self.k * error;
        let integral = self.integral + self.k / self.t_i * error * self.dt;
        let u = p + integral;
        let saturated = u.clamp(-u_sat, u_sat);
        self.integral = if saturated == u { integral } else { saturated - p };
        saturated
    }
}

/// Incremental encoder on a motor shaft (Section 2.3.2): 500 impulses per rotor revolution.
///
/// The slave boards count one impulse per rising edge of the optical encoder signal, with no
/// quadrature ×4 decoding, so one count is 1/500 of a rotor revolution. The joint zero is taken
/// on a count edge; the count of a position is floored (towards -∞).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Encoder {
    pub counts_per_rev: u32,
    /// Reduction n from the joint to the rotor (rad/rad or rad/m).
    pub n: f64,
}

impl Encoder {
    /// The AMRU5 encoder (500 counts per revolution) on a motor of reduction `n`.
    #[cfg(test)]
    fn amru5(n: f64) -> Self {
        Encoder { counts_per_rev: 500, n }
    }

    /// Joint displacement of one count, 2π / (counts · n) (rad or m).
    pub fn resolution(&self) -> f64 {
        TAU / (f64::from(self.counts_per_rev) * self.n)
    }

    /// Count read at the joint position q: the rotor angle n q in whole counts.
    pub fn counts(&self, q: f64) -> i64 {
        (self.n * q / TAU * f64::from(self.counts_per_rev)).floor() as i64
    }

    /// Joint position the encoder reports at the joint position q (rad or m).
    pub fn measure(&self, q: f64) -> f64 {
        self.counts(q) as f64 * self.resolution()
    }
}

/// Continuous PID with filtered derivative (Eq. 3.93) in residual form (Eq. 3.94-3.97), for the
/// 96-DOF model of Table 3.5: the voltage is the first-order state u = q'_u (u' = q''_u) and q_I
/// is a second-order state with q'_I ≈ ε, q''_I ≈ ε', q_I ≈ ∫ε (Eq. 3.95).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContinuousPid {
    /// Gain K (V/rad or V/m).
    pub k: f64,
    /// Integral time T_I (s).
    pub t_i: f64,
    /// Derivative time T_D (s); zero for a PI.
    pub t_d: f64,
    /// High-frequency limit N of the derivative gain.
    pub n: f64,
    /// Bandwidth ω0 (rad/s) of the error filter of Eq. 3.95, well above the closed loop's.
    pub omega_0: f64,
}

/// Residual of Eq. 3.96 and its partials (all constant: the law is linear).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PidVoltageResidual {
    pub f: f64,
    /// With respect to q'_u = u (a CT entry).
    pub df_dqd_u: f64,
    /// With respect to q''_u = u' (an M entry).
    pub df_dqdd_u: f64,
    /// With respect to q_I (a KT entry).
    pub df_dq_i: f64,
    /// With respect to q'_I (a CT entry).
    pub df_dqd_i: f64,
    /// With respect to q''_I (an M entry).
    pub df_dqdd_i: f64,
}

/// Residual of Eq. 3.97 and its partials.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PidIntegralResidual {
    pub f: f64,
    /// With respect to q'_I (a CT entry).
    pub df_dqd_i: f64,
    /// With respect to q''_I (an M entry).
    pub df_dqdd_i: f64,
    /// With respect to the error ε = q_d - q (so ∂f/∂q = -∂f/∂ε).
    pub df_depsilon: f64,
}

impl ContinuousPid {
    /// Eq. 3.96: 0 = q'_u + T_D/N q''_u - K (1 + T_D/(N T_I)) q'_I - K T_D (1 + 1/N) q''_I - K/T_I q_I.
    pub fn voltage_residual(&self, qd_u: f64, qdd_u: f64, q_i: f64, qd_i: f64, qdd_i: f64) -> PidVoltageResidual {
        let df_dqdd_u = self.t_d / self.n;
        let df_dq_i = -self.k / self.t_i;
        let df_dqd_i = -self.k * (1.0 + self.t_d / (self.n * self.t_i));
        let df_dqdd_i = -self.k * self.t_d * (1.0 + 1.0 / self.n);
        PidVoltageResidual {
            f: qd_u + df_dqdd_u * qdd_u + df_dq_i * q_i + df_dqd_i * qd_i + df_dqdd_i * qdd_i,
            df_dqd_u: 1.0,
            df_dqdd_u,
            df_dq_i,
            df_dqd_i,
            df_dqdd_i,
        }
    }

    /// Eq. 3.97: 0 = q''_I + ω0 (q'_I - ε).
    pub fn integral_residual(&self, qd_i: f64, qdd_i: f64, epsilon: f64) -> PidIntegralResidual {
        PidIntegralResidual { f: qdd_i + self.omega_0 * (qd_i - epsilon), df_dqd_i: self.omega_0, df_dqdd_i: 1.0, df_depsilon: -self.omega_0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::{assert_partial, central, noise, rng};
    use nalgebra::Complex;
    use rand::Rng;

    /// Table 4.1, vertical joint.
    fn vertical_pi() -> DigitalPi {
        DigitalPi::new(19863.0, 0.5, 0.01)
    }

    #[test]
    fn step_response_of_the_discrete_law() {
        let mut pi = vertical_pi();
        let e = 1e-4;
        for k in 0..50 {
            let u = pi.update(e, 15.0);
            let expected = pi.k * e + pi.k / pi.t_i * e * pi.dt * (k + 1) as f64;
            assert!((u - expected).abs() < 1e-12 * expected, "sample {k}: {u} vs {expected}");
        }
    }

    #[test]
    fn antiwindup_bounds_the_integral() {
        let mut pi = vertical_pi();
        // P = K ε = 9.93 V below the 12 V supply: only the integral drives the output up.
        let (e, u_sat) = (5e-4, 12.0);
        let mut saturated = 0;
        for _ in 0..10_000 {
            if pi.update(e, u_sat) == u_sat {
                saturated += 1;
                assert!((pi.integral - (u_sat - pi.k * e)).abs() < 1e-9);
            }
        }
        assert!(saturated > 9_900);
        // Without antiwindup the integral would be K/T_i ε Δt × 10000 ≈ 1986 V; here the output
        // leaves saturation as soon as the error vanishes.
        let u = pi.update(0.0, u_sat);
        assert!((u - (u_sat - pi.k * e)).abs() < 1e-9);
    }

    #[test]
    fn pure_integrator_plant_first_samples() {
        // q_{k+1} = q_k + Δt u_k (plant 1/s with zero-order hold), K = 2, T_i = 0.5, Δt = 0.01.
        let mut pi = DigitalPi::new(2.0, 0.5, 0.01);
        let mut q = 0.0;
        let mut samples = Vec::new();
        for _ in 0..3 {
            let u = pi.update(1.0 - q, 100.0);
            samples.push((u, pi.integral));
            q += pi.dt * u;
        }
        // By hand: ε0 = 1: P = 2, I = 0.04, u = 2.04, q1 = 0.0204; ε1 = 0.9796: P = 1.9592,
        // I = 0.079184, u = 2.038384, q2 = 0.04078384; ε2 = 0.95921616: P = 1.91843232,
        // I = 0.11755264640, u = 2.0359849664.
        let expected = [(2.04, 0.04), (2.038384, 0.079184), (2.0359849664, 0.1175526464)];
        for (k, ((u, i), (ue, ie))) in samples.iter().zip(expected).enumerate() {
            assert!((u - ue).abs() < 1e-12 && (i - ie).abs() < 1e-12, "sample {k}: ({u}, {i}) vs ({ue}, {ie})");
        }
    }

    #[test]
    fn encoder_quantization() {
        let n_v = 69115.0;
        let enc = Encoder::amru5(n_v);
        let step = TAU / (500.0 * n_v);
        assert!((enc.resolution() - step).abs() < 1e-20);
        let mut r = rng(31);
        for _ in 0..1000 {
            let q = r.random_range(-0.1..0.1);
            let m = enc.measure(q);
            assert!(m <= q && q - m < step * (1.0 + 1e-9), "q = {q}, measured {m}");
            let k = (m / step).round();
            assert!((m - k * step).abs() < 1e-9 * step);
        }
        assert_eq!(enc.counts(2.5 * step), 2);
        assert_eq!(enc.counts(-0.5 * step), -1);
        assert_eq!(Encoder::amru5(1682.0).counts(TAU / 1682.0 * 1.0001), 500);
    }

    #[test]
    fn continuous_pid_partials_match_finite_differences() {
        let mut r = rng(32);
        for _ in 0..100 {
            let pid = ContinuousPid {
                k: r.random_range(1.0..2e4),
                t_i: r.random_range(0.1..2.0),
                t_d: r.random_range(0.0..0.1),
                n: r.random_range(2.0..20.0),
                omega_0: r.random_range(100.0..1e4),
            };
            let x: [f64; 6] = std::array::from_fn(|_| r.random_range(-1.0..1.0));
            let v = pid.voltage_residual(x[0], x[1], x[2], x[3], x[4]);
            let analytic = [v.df_dqd_u, v.df_dqdd_u, v.df_dq_i, v.df_dqd_i, v.df_dqdd_i];
            for (j, a) in analytic.into_iter().enumerate() {
                let f = |t: f64| {
                    let mut y = x;
                    y[j] = t;
                    pid.voltage_residual(y[0], y[1], y[2], y[3], y[4]).f
                };
                assert_partial(&format!("Eq. 3.96 argument {j}"), a, central(f, x[j], 1e-3), 1e-9, noise(v.f.abs() + 1e5, 1e-3));
            }
            let w = pid.integral_residual(x[3], x[4], x[5]);
            let g = |a: f64, b: f64, c: f64| pid.integral_residual(a, b, c).f;
            let nw = noise(w.f.abs() + 1e4, 1e-3);
            assert_partial("∂/∂q'_I", w.df_dqd_i, central(|t| g(t, x[4], x[5]), x[3], 1e-3), 1e-9, nw);
            assert_partial("∂/∂q''_I", w.df_dqdd_i, central(|t| g(x[3], t, x[5]), x[4], 1e-3), 1e-9, nw);
            assert_partial("∂/∂ε", w.df_depsilon, central(|t| g(x[3], x[4], t), x[5], 1e-3), 1e-9, nw);
        }
    }

    #[test]
    fn continuous_pid_transfer_function_tends_to_eq_3_93() {
        // Linear residuals: at s = jω, q_I = -(∂f_I/∂ε) ε / (∂f_I/∂q''_I s² + ∂f_I/∂q'_I s) and
        // u = -(∂f_u/∂q_I + ∂f_u/∂q'_I s + ∂f_u/∂q''_I s²) q_I / (∂f_u/∂q'_u + ∂f_u/∂q''_u s).
        let pid = ContinuousPid { k: 19863.0, t_i: 0.5, t_d: 0.05, n: 10.0, omega_0: 1e4 };
        let v = pid.voltage_residual(0.0, 0.0, 0.0, 0.0, 0.0);
        let w = pid.integral_residual(0.0, 0.0, 0.0);
        for omega in [0.1, 1.0, 10.0, 100.0] {
            let s = Complex::new(0.0, omega);
            let q_i = -w.df_depsilon / (w.df_dqdd_i * s * s + w.df_dqd_i * s);
            let u = -(v.df_dq_i + v.df_dqd_i * s + v.df_dqdd_i * s * s) * q_i / (v.df_dqd_u + v.df_dqdd_u * s);
            let c = pid.k * (1.0 + 1.0 / (s * pid.t_i) + s * pid.t_d / (1.0 + s * pid.t_d / pid.n));
            let filter = pid.omega_0 / (s + pid.omega_0);
            assert!((u - c * filter).norm() < 1e-9 * c.norm(), "ω = {omega}: {u} vs {}", c * filter);
            assert!((u - c).norm() < 2.0 * omega / pid.omega_0 * c.norm());
        }
    }
}
