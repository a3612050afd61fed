//! A position servo of the Dynamixel kind (beyond the thesis: the actuators of most small
//! hexapods): a DC motor and gear like AMRU5's (Eq. 4.4), driven by the servo's own
//! proportional position loop instead of the master's PI (Eq. 4.18-4.20). The master sends goal
//! positions; the servo's controller turns the error into a PWM duty of the supply.
//!
//! The loop is the "compliance" law of the Dynamixel AX control table (Robotis e-Manual, AX-12A,
//! "Compliance Margin / Slope" and "Punch"): no output while the error is within the margin,
//! the punch (the smallest output) just beyond it, then an output growing linearly with the
//! error up to the torque limit (the largest duty). Two choices are ours:
//! - INTERPRETATION: the servo's loop runs at its own rate (about 1 kHz, not in the e-Manual),
//!   far above a leg's bandwidth (~10 Hz): it is taken continuous, the voltage a function of the
//!   state inside the residual system like the continuous PID of Eq. 3.96-3.97;
//! - INTERPRETATION: the step to the punch at the margin is spread over one count of the
//!   position sensor (the servo sees whole counts), so that the voltage is continuous in q and
//!   the implicit integrator's Newton iteration keeps its derivative.
//!
//! The goal is held within the servo's angle limits (the CW/CCW limits of its control table),
//! so that a servo never drives beyond them: it has no limit switch.
//!
//! The master may add a friction feed-forward to its goals ([`FrictionFeedForward`]).

use crate::hexapod::JOINTS;

/// One position servo's controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionServo {
    /// Compliance margin (rad): no output while |goal − q| is within it.
    pub margin: f64,
    /// Compliance slope (rad): the error beyond the margin (and the punch's count) over which
    /// the duty grows from the punch to the torque limit.
    pub slope: f64,
    /// Punch: the duty just beyond the margin (fraction of the supply).
    pub punch: f64,
    /// Torque limit: the largest duty (fraction of the supply).
    pub torque_limit: f64,
    /// One count of the position sensor (rad), over which the punch comes in.
    pub resolution: f64,
    /// The servo's angle limits: the goal is held within them (rad).
    pub lower: f64,
    pub upper: f64,
}

/// The servo's voltage at a state and its derivative with respect to the joint position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ServoVoltage {
    /// u (V).
    pub u: f64,
    /// ∂u/∂q (V/rad).
    pub du_dq: f64,
}

impl PositionServo {
    /// The duty d(a) ∈ [0, torque_limit] at the error magnitude a and its derivative:
    /// 0 within the margin m, punch · (a − m)/δ over the next count δ, then
    /// punch + (limit − punch)(a − m − δ)/slope, at most the limit.
    fn duty(&self, a: f64) -> (f64, f64) {
        let beyond = a - self.margin;
        if beyond <= 0.0 {
            return (0.0, 0.0);
        }
        let (d, dd) = if beyond < self.resolution {
            (self.punch * beyond / self.resolution, self.punch / self.resolution)
        } else {
            let gain = (self.torque_limit - self.punch) / self.slope;
            (self.punch + gain * (beyond - self.resolution), gain)
        };
        if d >= self.torque_limit {
            (self.torque_limit, 0.0)
        } else {
            (d, dd)
        }
    }

    /// u = sign(e) d(|e|) V with e = clamp(goal) − q, and ∂u/∂q = −d'(|e|) V.
    pub fn voltage(&self, goal: f64, q: f64, supply: f64) -> ServoVoltage {
        let e = goal.clamp(self.lower, self.upper) - q;
        let (d, dd) = self.duty(e.abs());
        ServoVoltage { u: e.signum() * d * supply, du_dq: -dd * supply }
    }

    /// The error magnitude |goal − q| at which the law's duty reaches `d` (the inverse of the
    /// duty over its rising part): the margin for d ≤ 0, the end of the slope for d at or beyond
    /// the torque limit.
    pub fn error_for_duty(&self, d: f64) -> f64 {
        let d = d.clamp(0.0, self.torque_limit);
        if d < self.punch {
            self.margin + self.resolution * d / self.punch
        } else if self.torque_limit > self.punch {
            self.margin + self.resolution + (d - self.punch) * self.slope / (self.torque_limit - self.punch)
        } else {
            self.margin + self.resolution
        }
    }

    /// The proportional gain of the law's linear part (V/rad), for the master's own use of
    /// the servo (the equivalent of the PI gain K of Table 4.1).
    pub fn gain(&self, supply: f64) -> f64 {
        (self.torque_limit - self.punch) / self.slope * supply
    }
}

/// The master's friction feed-forward for position servos (beyond the thesis, whose PI loops
/// integrate the friction away; model-based friction compensation, B. Armstrong-Hélouvry,
/// P. Dupont, C. Canudas de Wit, "A survey of models, analysis tools and compensation methods
/// for the control of machines with friction", Automatica 30(7), 1994). A servo's proportional
/// law builds an error before its torque overcomes the gear's dry friction τ_f,d: a moving
/// joint lags its goal by that error e_f, and a joint starting to move waits for it, sticking
/// and slipping at each change of direction. The master adds e_f to each goal in the direction
/// the reference moves:
///
///   goal = q_d + e_f tanh(q'_d / ε),
///
/// with e_f the error at which the stalled motor's torque n k_t u / R (Eq. 4.4-4.6 at q' = 0)
/// equals τ_f,d ([`PositionServo::error_for_duty`] of u = τ_f,d R / (n k_t) over the supply),
/// q'_d the reference's rate over the last control period and ε the linear zone of the joint's
/// dry friction (Eq. 6.1), over which the friction itself changes sides. The first update has
/// no rate: its goals are the references.
#[derive(Clone, Debug, PartialEq)]
pub struct FrictionFeedForward {
    servos: [PositionServo; JOINTS],
    /// τ_f,d R / (n k_t) of each joint: the voltage whose stall torque is the dry friction (V).
    friction_voltage: [f64; JOINTS],
    /// ε of each joint (rad/s or m/s).
    zone: [f64; JOINTS],
    /// Control period (s).
    dt: f64,
    previous: Option<[f64; JOINTS]>,
}

impl FrictionFeedForward {
    /// The feed-forward of the servos `servos` with, per joint, the voltage whose stall torque
    /// is its dry friction and its linear zone ε, at the control period `dt`.
    pub fn new(servos: [PositionServo; JOINTS], friction_voltage: [f64; JOINTS], zone: [f64; JOINTS], dt: f64) -> Self {
        FrictionFeedForward { servos, friction_voltage, zone, dt, previous: None }
    }

    /// The goals for the joint references `references` with the supply voltage `supply`.
    pub fn goals(&mut self, references: &[f64; JOINTS], supply: f64) -> [f64; JOINTS] {
        let previous = self.previous.replace(*references).unwrap_or(*references);
        std::array::from_fn(|k| {
            let rate = (references[k] - previous[k]) / self.dt;
            let e_f = self.servos[k].error_for_duty(self.friction_voltage[k] / supply);
            references[k] + e_f * (rate / self.zone[k]).tanh()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The AX-12A defaults (margin 1, slope 32, punch 32 of 1023, torque limit 1023 of 1023;
    /// 300° over 1024 counts).
    fn ax12() -> PositionServo {
        let count = 300f64.to_radians() / 1024.0;
        PositionServo { margin: count, slope: 32.0 * count, punch: 32.0 / 1023.0, torque_limit: 1.0, resolution: count, lower: -2.0, upper: 2.0 }
    }

    #[test]
    fn the_compliance_law_has_its_margin_punch_slope_and_limit() {
        let s = ax12();
        let c = s.resolution;
        // Within the margin: nothing, whatever the sense.
        assert_eq!(s.voltage(0.5 * c, 0.0, 12.0).u, 0.0);
        assert_eq!(s.voltage(-0.9 * c, 0.0, 12.0).u, 0.0);
        // The punch one count beyond the margin, with the error's sign.
        assert_relative_eq!(s.voltage(2.0 * c, 0.0, 12.0).u, 12.0 * s.punch, epsilon = 1e-12);
        assert_relative_eq!(s.voltage(-2.0 * c, 0.0, 12.0).u, -12.0 * s.punch, epsilon = 1e-12);
        // The limit after the slope, and beyond.
        assert_relative_eq!(s.voltage(34.0 * c, 0.0, 12.0).u, 12.0, epsilon = 1e-12);
        assert_eq!(s.voltage(1.0, 0.0, 12.0).u, 12.0);
        // Linear in between, with the gain of the linear part.
        let (a, b) = (s.voltage(10.0 * c, 0.0, 12.0).u, s.voltage(20.0 * c, 0.0, 12.0).u);
        assert_relative_eq!((b - a) / (10.0 * c), s.gain(12.0), epsilon = 1e-9);
    }

    #[test]
    fn the_voltage_is_continuous_and_its_derivative_is_the_difference_quotient() {
        let s = ax12();
        let h = 1e-9;
        for k in 0..2000 {
            let q = -0.3 + 0.6 * k as f64 / 2000.0 + 1e-5;
            let v = s.voltage(0.0, q, 12.0);
            let numeric = (s.voltage(0.0, q + h, 12.0).u - s.voltage(0.0, q - h, 12.0).u) / (2.0 * h);
            assert!((v.du_dq - numeric).abs() <= 1e-4 * (1.0 + numeric.abs()), "q = {q}: {} against {numeric}", v.du_dq);
            let next = s.voltage(0.0, q + 3e-4, 12.0).u;
            assert!((next - v.u).abs() <= 3e-4 * s.punch / s.resolution * 12.0 + 1e-12, "a jump at q = {q}");
        }
    }

    #[test]
    fn the_goal_is_held_within_the_angle_limits() {
        let s = ax12();
        // A goal beyond the upper limit drives to the limit, not beyond it.
        assert_eq!(s.voltage(5.0, 2.0, 12.0).u, 0.0);
        assert!(s.voltage(5.0, 1.9, 12.0).u > 0.0);
        assert!(s.voltage(5.0, 2.1, 12.0).u < 0.0);
    }

    #[test]
    fn the_error_for_a_duty_inverts_the_law() {
        let s = ax12();
        for k in 1..1000 {
            let d = k as f64 / 1000.0 * s.torque_limit;
            let e = s.error_for_duty(d);
            assert_relative_eq!(s.voltage(e, 0.0, 1.0).u, d, epsilon = 1e-12);
        }
        assert_eq!(s.error_for_duty(-0.5), s.margin);
        assert_eq!(s.error_for_duty(2.0), s.error_for_duty(s.torque_limit));
    }

    /// Goals moving at a steady rate get the error whose stalled torque is the dry friction,
    /// ahead in the direction of the motion; still goals get nothing.
    #[test]
    fn the_feed_forward_leads_a_moving_goal_by_the_friction_error() {
        let s = ax12();
        // AX-12A-like: τ_f,d = 0.59 N m with n k_t / R = 0.174 N m/V: 3.39 V; ε = 1e-3 rad/s.
        let (u_f, supply, dt) = (0.59 / 0.174, 11.1, 0.01);
        let mut ff = FrictionFeedForward::new([s; JOINTS], [u_f; JOINTS], [1e-3; JOINTS], dt);
        let rates: [f64; JOINTS] = std::array::from_fn(|k| 0.1 * (k as f64 - 8.0));
        let at = |t: f64| -> [f64; JOINTS] { std::array::from_fn(|k| 0.2 + rates[k] * t) };
        assert_eq!(ff.goals(&at(0.0), supply), at(0.0));
        let goals = ff.goals(&at(dt), supply);
        for k in 0..JOINTS {
            let offset = goals[k] - at(dt)[k];
            if rates[k] == 0.0 {
                assert_eq!(offset, 0.0);
                continue;
            }
            // The servo's voltage at that error is the friction's, with the rate's sign.
            assert_relative_eq!(s.voltage(goals[k], at(dt)[k], supply).u, u_f * rates[k].signum(), epsilon = 1e-9);
        }
    }
}
