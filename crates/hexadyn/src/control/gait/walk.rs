//! The state both gait controllers (the periodic one of Sections 7.3-7.6 and the free gait of
//! Section 7.7) keep and show: the desired body motion (Eq. 7.12-7.23) and, per leg, its foot
//! phase and foot reference (leg frame).

use nalgebra::Vector3;

use super::body_motion::{BodyMotion, Pose};
use super::pattern::FootPhase;

/// What a gait controller's leg state shows.
pub trait LegState {
    fn phase(&self) -> FootPhase;
    /// The foot reference in the leg frame.
    fn foot(&self) -> Vector3<f64>;
}

/// The desired body motion (None before the first update) and the six legs of a gait
/// controller; the controllers dereference to it for its accessors.
#[derive(Clone, Debug)]
pub struct Walk<L> {
    pub(super) body: Option<BodyMotion>,
    pub(super) legs: [L; 6],
}

impl<L: LegState> Walk<L> {
    /// Phase of each foot at the last update (for gait diagrams and the ≥ 3 feet check).
    pub fn phases(&self) -> [FootPhase; 6] {
        std::array::from_fn(|l| self.legs[l].phase())
    }
    /// The desired body pose T*_{0,b} at the last update.
    pub fn desired_pose(&self) -> Option<Pose> {
        self.body.as_ref().map(|b| b.pose)
    }
    /// The desired body velocity v*_{b/0} and angular velocity ω*_{b/0} (global frame) at the
    /// last update.
    pub fn desired_velocity(&self) -> Option<(Vector3<f64>, Vector3<f64>)> {
        self.body.as_ref().map(|b| (b.velocity(), b.omega()))
    }
    /// Foot references in the leg frames at the last update.
    pub fn foot_references(&self) -> [Vector3<f64>; 6] {
        std::array::from_fn(|l| self.legs[l].foot())
    }
}
