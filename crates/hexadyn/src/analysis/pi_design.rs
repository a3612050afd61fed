//! PI position-controller synthesis for one joint (thesis Section 4.4, Eq. 4.14-4.17, Table 4.1).
//!
//! Each joint is a SISO plant from motor voltage to joint position,
//! G(s) = K / (s (1 + τ_m s)) with K = 1 / (n k_t) and τ_m = R J / (n k_t)² (Eq. 4.14), closed by
//! a PI controller C(s) = K_p (1 + 1 / (T_i s)) (Eq. 3.93 without derivative action).

use nalgebra::{Complex, Matrix3, Vector3};

/// Open-loop transfer function of Eq. 4.14-4.17: Q(s)/U(s) = (1/s) · gain / (1 + time_constant s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointPlant {
    /// K = 1 / (n k_t) in rad/(V s) or m/(V s).
    pub gain: f64,
    /// τ_m = R J / (n k_t)², s.
    pub time_constant: f64,
}

impl JointPlant {
    /// From the diagonal inertia J of the linearized mass matrix, the reduction n, the torque
    /// constant k_t and the armature resistance R (Eq. 4.14).
    pub fn from_motor(j: f64, n: f64, k_t: f64, r: f64) -> Self {
        JointPlant { gain: 1.0 / (n * k_t), time_constant: r * j / (n * k_t).powi(2) }
    }
    pub fn response(&self, s: Complex<f64>) -> Complex<f64> {
        Complex::new(self.gain, 0.0) / (s * (Complex::new(1.0, 0.0) + s * self.time_constant))
    }
}

/// A PI controller and the closed-loop performance it gives (the columns of Table 4.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PiDesign {
    /// K_p in V/rad or V/m.
    pub k: f64,
    /// T_i in s.
    pub t_i: f64,
    /// −3 dB bandwidth of the closed loop, Hz.
    pub bandwidth_hz: f64,
    /// Phase margin, degrees.
    pub phase_margin_deg: f64,
    /// Overshoot of the closed-loop step response, %.
    pub overshoot_percent: f64,
}

fn controller(k: f64, t_i: f64, s: Complex<f64>) -> Complex<f64> {
    Complex::new(k, 0.0) * (Complex::new(1.0, 0.0) + Complex::new(1.0, 0.0) / (s * t_i))
}

fn loop_gain(plant: &JointPlant, k: f64, t_i: f64, w: f64) -> Complex<f64> {
    let s = Complex::new(0.0, w);
    controller(k, t_i, s) * plant.response(s)
}

/// −3 dB bandwidth (rad/s) of T = L / (1 + L): the last frequency where |T| ≥ 1/√2, on a
/// logarithmic sweep refined by bisection.
fn bandwidth(plant: &JointPlant, k: f64, t_i: f64) -> f64 {
    let closed = |w: f64| {
        let l = loop_gain(plant, k, t_i, w);
        (l / (Complex::new(1.0, 0.0) + l)).norm()
    };
    let level = std::f64::consts::FRAC_1_SQRT_2;
    let (mut lo, mut hi) = (1e-3, 1e-3);
    while closed(hi) >= level || hi < 1.0 {
        lo = hi;
        hi *= 1.05;
        assert!(hi < 1e7, "closed loop never rolls off");
    }
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if closed(mid) >= level {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Phase margin (degrees) at the gain crossover |L(jω)| = 1.
fn phase_margin(plant: &JointPlant, k: f64, t_i: f64) -> f64 {
    let (mut lo, mut hi): (f64, f64) = (1e-4, 1e7);
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        if loop_gain(plant, k, t_i, mid).norm() > 1.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let l = loop_gain(plant, k, t_i, (lo * hi).sqrt());
    180.0 + l.arg().to_degrees()
}

/// Overshoot of the unit step response of the closed loop, integrating its state-space form
/// x = (∫e, q, q') with a fine fourth-order Runge-Kutta scheme over 20 closed-loop time
/// constants.
fn overshoot(plant: &JointPlant, k: f64, t_i: f64) -> f64 {
    // τ q''' + q'' = K u' with u = k (e + ∫e / T_i), e = 1 − q.
    let (g, tau) = (plant.gain, plant.time_constant);
    let a = Matrix3::new(0.0, -1.0, 0.0, 0.0, 0.0, 1.0, g * k / (t_i * tau), -g * k / tau, -1.0 / tau);
    let b = Vector3::new(1.0, 0.0, g * k / tau);
    let f = |x: &Vector3<f64>| a * x + b;
    let dt = tau / 50.0;
    let steps = ((20.0 * t_i.max(10.0 * tau)) / dt) as usize;
    let mut x = Vector3::zeros();
    let mut peak: f64 = 0.0;
    for _ in 0..steps {
        let k1 = f(&x);
        let k2 = f(&(x + k1 * (dt / 2.0)));
        let k3 = f(&(x + k2 * (dt / 2.0)));
        let k4 = f(&(x + k3 * dt));
        x += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (dt / 6.0);
        peak = peak.max(x[1]);
    }
    100.0 * (peak - 1.0).max(0.0)
}

impl PiDesign {
    /// Performance of a given PI on `plant`.
    pub fn evaluate(plant: &JointPlant, k: f64, t_i: f64) -> Self {
        PiDesign {
            k,
            t_i,
            bandwidth_hz: bandwidth(plant, k, t_i) / (2.0 * std::f64::consts::PI),
            phase_margin_deg: phase_margin(plant, k, t_i),
            overshoot_percent: overshoot(plant, k, t_i),
        }
    }

    /// The gain K_p whose closed loop has the requested −3 dB bandwidth, for a given T_i
    /// (Section 4.4.3-4.4.4: about 3 Hz keeps the motors out of saturation on the
    /// 0.8 × no-load-speed ramp). Bisection on K_p (the bandwidth grows with K_p).
    pub fn for_bandwidth(plant: &JointPlant, bandwidth_hz: f64, t_i: f64) -> Self {
        let target = bandwidth_hz * 2.0 * std::f64::consts::PI;
        let (mut lo, mut hi) = (1e-9 / plant.gain, 1.0 / plant.gain);
        while bandwidth(plant, hi, t_i) < target {
            hi *= 2.0;
        }
        for _ in 0..100 {
            let mid = (lo * hi).sqrt();
            if bandwidth(plant, mid, t_i) < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Self::evaluate(plant, (lo * hi).sqrt(), t_i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The thesis' own open-loop transfer functions (Eq. 4.15-4.17) and PI gains reproduce the
    /// closed-loop performance of Table 4.1.
    #[test]
    fn table_4_1_performance_from_eq_4_15_to_4_17() {
        let cases = [
            (JointPlant { gain: 0.031, time_constant: 0.0059 }, 483.0, 2.94, 77.3, 9.5),
            (JointPlant { gain: 0.00075, time_constant: 0.0058 }, 19863.0, 2.92, 77.4, 9.6),
            (JointPlant { gain: 0.00088, time_constant: 0.0058 }, 16854.0, 2.91, 77.4, 9.6),
        ];
        for (plant, k, bw, pm, os) in cases {
            let d = PiDesign::evaluate(&plant, k, 0.5);
            assert_relative_eq!(d.bandwidth_hz, bw, max_relative = 0.03);
            assert_relative_eq!(d.phase_margin_deg, pm, max_relative = 0.03);
            assert_relative_eq!(d.overshoot_percent, os, max_relative = 0.10);
            // And the synthesis recovers the gain from the bandwidth.
            let s = PiDesign::for_bandwidth(&plant, bw, 0.5);
            assert_relative_eq!(s.k, k, max_relative = 0.03);
        }
    }

    #[test]
    fn plant_from_motor_matches_eq_4_14() {
        let p = JointPlant::from_motor(31289.0, 69115.0, 0.02, 0.334);
        assert_relative_eq!(p.gain, 1.0 / (69115.0 * 0.02), max_relative = 1e-12);
        assert_relative_eq!(p.time_constant, 0.334 * 31289.0 / (69115.0f64 * 0.02).powi(2), max_relative = 1e-12);
    }
}
