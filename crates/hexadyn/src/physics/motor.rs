//! DC motors with gearing and H-bridge (thesis Section 3.4.4, 4.2 and 6.4), supply saturation
//! (Section 4.4.3) and limit switches (Section 2.3.1).
//!
//! Sign convention: a positive voltage u drives the joint towards positive q (k_t, n > 0); the
//! joint torque n k_t i is the generalized force the motor applies to its joint (Eq. 4.6).

use std::ops::RangeInclusive;

use serde::{Deserialize, Serialize};

/// Series resistance of the H-bridge, 2 × 0.3 Ω (two conducting MOSFETs of the LMD18200,
/// Section 6.4).
#[cfg(test)]
const H_BRIDGE_RESISTANCE: f64 = 0.6;

/// A permanent-magnet DC motor driving one joint through a reduction n (Eq. 3.88-3.92).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DcMotor {
    /// Coil resistance R (Ω).
    pub r: f64,
    /// Series resistance of the H-bridge (Ω), added to R.
    pub r_bridge: f64,
    /// Coil inductance L (H).
    pub l: f64,
    /// Torque constant k_t (Nm/A), equal to the voltage constant k_v (V s/rad).
    pub k_t: f64,
    /// Reduction n > 0 from the joint to the rotor, θ_m' = n q' (rad/rad or rad/m), Eq. 3.92.
    pub n: f64,
    /// Whether the current is a first-order state (i = q'_i, Eq. 3.91) or follows the voltage
    /// instantly (Eq. 4.4, inductance neglected as in Section 4.2 and 4.5).
    pub inductance: bool,
}

/// Electrical residual of Eq. 3.91 and its partials.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurrentResidual {
    pub f: f64,
    /// With respect to i = q'_i (a CT entry).
    pub df_di: f64,
    /// With respect to di/dt = q''_i (an M entry).
    pub df_ddi: f64,
    /// With respect to the joint velocity q' (a CT entry).
    pub df_dqd: f64,
    /// With respect to the voltage u.
    pub df_du: f64,
}

/// Current of Eq. 4.4 (inductance neglected) and its partials.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Current {
    pub i: f64,
    pub di_dqd: f64,
    pub di_du: f64,
}

impl DcMotor {
    /// The Maxon RE35 of Table 3.4 (R = 0.334 Ω, L = 0.09 mH, k_t = 19.4e-3 Nm/A) behind the
    /// H-bridge of Section 6.4, with the reduction `n` of its joint (Fig. 2.16, Table 3.1) and
    /// the inductance neglected (Section 4.5).
    #[cfg(test)]
    fn re35(n: f64) -> Self {
        DcMotor { r: 0.334, r_bridge: H_BRIDGE_RESISTANCE, l: 0.09e-3, k_t: 19.4e-3, n, inductance: false }
    }

    /// Total resistance of the armature circuit, R + R_bridge (Ω).
    pub fn resistance(&self) -> f64 {
        self.r + self.r_bridge
    }

    /// Back electromotive force k_v n q' (V), Eq. 3.89 and 3.92.
    pub fn back_emf(&self, qd: f64) -> f64 {
        self.k_t * self.n * qd
    }

    /// Residual of Eq. 3.91-3.92 with the H-bridge resistance, for i = q'_i and di/dt = q''_i:
    /// f_i = (R + R_bridge) i + L di/dt + k_t n q' - u.
    pub fn current_residual(&self, i: f64, di_dt: f64, qd: f64, u: f64) -> CurrentResidual {
        let k = self.k_t * self.n;
        CurrentResidual { f: self.resistance() * i + self.l * di_dt + k * qd - u, df_di: self.resistance(), df_ddi: self.l, df_dqd: k, df_du: -1.0 }
    }

    /// Current without inductance, i = (u - k_t n q') / (R + R_bridge), Eq. 4.4.
    pub fn current(&self, qd: f64, u: f64) -> Current {
        let g = 1.0 / self.resistance();
        Current { i: (u - self.back_emf(qd)) * g, di_dqd: -self.k_t * self.n * g, di_du: g }
    }

    /// Joint torque τ = n k_t i (Nm or N) and ∂τ/∂i, Eq. 4.5-4.6.
    pub fn joint_torque(&self, i: f64) -> (f64, f64) {
        let k = self.n * self.k_t;
        (k * i, k)
    }

    /// Electrical power drawn from the supply, P = u i (W), Eq. 6.7.
    pub fn electrical_power(&self, u: f64, i: f64) -> f64 {
        u * i
    }

    /// Joule losses in the coil and the H-bridge, (R + R_bridge) i² (W).
    pub fn joule_loss(&self, i: f64) -> f64 {
        self.resistance() * i * i
    }
}

/// The voltage command limited to ±`supply` (V), Section 4.3.4 and 4.4.3.
pub fn saturate(u: f64, supply: f64) -> f64 {
    u.clamp(-supply, supply)
}

/// The voltage reaching the motor behind the limit switches of Section 2.3.1: the power is cut
/// (u = 0) when the joint is at or beyond an end of its stroke `range` and the command pushes it
/// further out; a command driving it back inside is passed. The cut voltage is 0 V across the
/// closed armature circuit (the back emf still brakes the joint), ∂u_eff/∂u is 1 or 0.
pub fn limit_switch(u: f64, q: f64, range: &RangeInclusive<f64>) -> f64 {
    if (q >= *range.end() && u > 0.0) || (q <= *range.start() && u < 0.0) {
        0.0
    } else {
        u
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::{assert_partial, central, noise, rng};
    use rand::Rng;

    /// Reduction of the vertical joints, Fig. 2.16 (rad/m).
    const N_V: f64 = 69115.0;

    #[test]
    fn partials_match_finite_differences() {
        let mut r = rng(11);
        for _ in 0..200 {
            let mut motor = DcMotor::re35(r.random_range(1e3..1e5));
            motor.inductance = true;
            let (i, di, qd, u) = (r.random_range(-3.0..3.0), r.random_range(-1e3..1e3), r.random_range(-1e-2..1e-2), r.random_range(-15.0..15.0));
            let res = motor.current_residual(i, di, qd, u);
            let f = |i: f64, di: f64, qd: f64, u: f64| motor.current_residual(i, di, qd, u).f;
            let n = |h: f64| noise(res.f.abs() + 30.0, h);
            assert_partial("∂f/∂i", res.df_di, central(|x| f(x, di, qd, u), i, 1e-3), 1e-8, n(1e-3));
            assert_partial("∂f/∂(di/dt)", res.df_ddi, central(|x| f(i, x, qd, u), di, 1e-1), 1e-8, n(1e-1));
            assert_partial("∂f/∂q'", res.df_dqd, central(|x| f(i, di, x, u), qd, 1e-6), 1e-8, n(1e-6));
            assert_partial("∂f/∂u", res.df_du, central(|x| f(i, di, qd, x), u, 1e-3), 1e-8, n(1e-3));

            let c = motor.current(qd, u);
            assert_partial("∂i/∂q'", c.di_dqd, central(|x| motor.current(x, u).i, qd, 1e-6), 1e-8, noise(30.0, 1e-6));
            assert_partial("∂i/∂u", c.di_du, central(|x| motor.current(qd, x).i, u, 1e-3), 1e-8, noise(30.0, 1e-3));
            let (tau, dtau_di) = motor.joint_torque(i);
            assert_partial("∂τ/∂i", dtau_di, central(|x| motor.joint_torque(x).0, i, 1e-3), 1e-8, noise(tau, 1e-3));
            // Without inductance the residual vanishes on the algebraic current (Eq. 4.4).
            assert!(motor.current_residual(c.i, 0.0, qd, u).f.abs() < 1e-12 * (1.0 + u.abs()));
        }
    }

    /// Rotor inertia of Table 3.4 brought to the joint, J_r n² (kg or kg m²).
    fn reflected_inertia(motor: &DcMotor) -> f64 {
        65.5e-7 * motor.n * motor.n
    }

    #[test]
    fn no_load_speed_and_stall_current() {
        let u = 12.0;
        for inductance in [false, true] {
            let mut motor = DcMotor::re35(N_V);
            motor.inductance = inductance;
            // Stall: q' = 0.
            let stall = u / (0.334 + 0.6);
            assert!((motor.current(0.0, u).i - stall).abs() < 1e-12);
            // Spin up the bare rotor (semi-implicit Euler) until the current vanishes.
            let j = reflected_inertia(&motor);
            let (dt, mut qd, mut i) = (1e-6, 0.0, 0.0);
            for _ in 0..300_000 {
                i = if motor.inductance {
                    let res = motor.current_residual(i, 0.0, qd, u);
                    i - dt * res.f / motor.l
                } else {
                    motor.current(qd, u).i
                };
                qd += dt * motor.joint_torque(i).0 / j;
            }
            let no_load = u / (motor.k_t * motor.n);
            assert!((qd - no_load).abs() < 1e-6 * no_load, "inductance {inductance}: {qd} vs {no_load}");
            assert!(i.abs() < 1e-5);
            assert!(motor.electrical_power(u, stall) > 0.0 && (motor.joule_loss(stall) - u * stall).abs() < 1e-9);
        }
    }

    #[test]
    fn saturation_and_limit_switches() {
        assert_eq!(saturate(20.0, 12.0), 12.0);
        assert_eq!(saturate(-20.0, 12.0), -12.0);
        assert_eq!(saturate(5.0, 12.0), 5.0);
        let stroke = 0.04..=0.075;
        assert_eq!(limit_switch(3.0, 0.06, &stroke), 3.0);
        assert_eq!(limit_switch(3.0, 0.076, &stroke), 0.0);
        assert_eq!(limit_switch(-3.0, 0.076, &stroke), -3.0);
        assert_eq!(limit_switch(-3.0, 0.039, &stroke), 0.0);
        assert_eq!(limit_switch(3.0, 0.039, &stroke), 3.0);
    }
}
