//! The spring of a series-elastic transmission (issue 40's "AMRU5 bis", after the thesis'
//! conclusion: "naturally compliant" actuators): a linear spring with viscous damping between
//! the gear output, at the drive coordinate θ (joint units: θ = θ_motor / n), and the joint q.
//! It pushes the joint with τ_s = k (θ − q) + c (θ' − q') and the gear back with −τ_s; it stores
//! ½ k (θ − q)² and its damper dissipates c (θ' − q')².

use serde::{Deserialize, Serialize};

/// Stiffness k (N/m or Nm/rad) and damping c (N s/m or Nm s/rad) of a series spring.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SeriesSpring {
    pub stiffness: f64,
    pub damping: f64,
}

impl SeriesSpring {
    /// τ_s = k δ + c δ' on the joint, for the deflection δ = θ − q and its rate δ' = θ' − q'
    /// (∂τ_s/∂θ = k = −∂τ_s/∂q, ∂τ_s/∂θ' = c = −∂τ_s/∂q').
    pub fn force(&self, deflection: f64, rate: f64) -> f64 {
        self.stiffness * deflection + self.damping * rate
    }

    /// The stored energy ½ k δ² (J).
    pub fn energy(&self, deflection: f64) -> f64 {
        0.5 * self.stiffness * deflection * deflection
    }

    /// The power dissipated by the damper, c δ'² (W).
    pub fn dissipation(&self, rate: f64) -> f64 {
        self.damping * rate * rate
    }

    /// The deflection that carries `load` at rest, load / k (static: no damping force).
    pub fn static_deflection(&self, load: f64) -> f64 {
        load / self.stiffness
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The power the spring takes from the gear and gives the joint, τ_s (θ' − q'), is the rate
    /// of its stored energy plus the damper's dissipation.
    #[test]
    fn power_is_stored_or_dissipated() {
        let s = SeriesSpring { stiffness: 2.0e5, damping: 300.0 };
        let (delta, rate) = (1.5e-3, -2.0e-4);
        // The central difference of the quadratic energy is exact at any time step h.
        let h = 1.0;
        let stored_rate = (s.energy(delta + h * rate) - s.energy(delta - h * rate)) / (2.0 * h);
        let power = s.force(delta, rate) * rate;
        assert!((power - stored_rate - s.dissipation(rate)).abs() < 1e-9 * power.abs().max(1e-9), "{power} vs {stored_rate} + {}", s.dissipation(rate));
        assert!((s.force(s.static_deflection(338.0), 0.0) - 338.0).abs() < 1e-12);
    }
}
