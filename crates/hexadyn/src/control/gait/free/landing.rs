//! Landing detection of the free gait (thesis Section 7.7): a landing leg descends until its
//! foot is detected on the ground. In simulation the thesis detects the ground when the normal
//! force exceeds 10 N ([`NormalForce`]); the real robot, which has no foot sensors, detects it
//! from its motor currents (Section 5.6.3): any [`LandingDetector`] plugs into the free gait
//! controller ([`super::FreeGaitController::new`]).

use crate::control::Measurements;

/// Decides, at each control instant, which feet are on the ground, from the measurements. The
/// free gait controller calls it once per update (so a detector may filter its signals over
/// time) and reads its answer for the legs that are landing.
pub trait LandingDetector: Send {
    fn ground_contact(&mut self, m: &Measurements) -> [bool; 6];
}

/// The simulation mode of Section 7.7: the ground is detected when the true normal force on the
/// foot ([`Measurements::foot_normal_forces`], filled by the simulated plant only) exceeds the
/// threshold. Without the forces (the real robot) no landing is ever detected.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalForce {
    /// N; 10 N in Section 7.7.
    pub threshold: f64,
}

/// Section 7.7: "ground is detected when the normal force is higher than a threshold of 10 N".
pub const THESIS_FORCE_THRESHOLD: f64 = 10.0;

impl LandingDetector for NormalForce {
    fn ground_contact(&mut self, m: &Measurements) -> [bool; 6] {
        m.foot_normal_forces.map_or([false; 6], |f| f.map(|f| f > self.threshold))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_force_detects_above_the_threshold_only_with_forces() {
        let mut d = NormalForce { threshold: THESIS_FORCE_THRESHOLD };
        let mut m = Measurements { foot_normal_forces: Some([0.0, 9.99, 10.0, 10.01, 50.0, -1.0]), ..Default::default() };
        assert_eq!(d.ground_contact(&m), [false, false, false, true, true, false]);
        m.foot_normal_forces = None;
        assert_eq!(d.ground_contact(&m), [false; 6]);
    }
}
