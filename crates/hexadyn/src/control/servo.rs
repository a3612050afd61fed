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

    /// The proportional gain of the law's linear part (V/rad), for the master's own use of
    /// the servo (the equivalent of the PI gain K of Table 4.1).
    pub fn gain(&self, supply: f64) -> f64 {
        (self.torque_limit - self.punch) / self.slope * supply
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
}
