//! The free gait for uneven ground (thesis Section 7.7): posture control (Rule 1, Section
//! 7.7.1), correction of the global velocities (Section 7.7.2), swing candidate selection by
//! Rules 2 and 3 with the deadlock condition (Sections 7.7.3-7.7.4), landing detection, and the
//! controller that puts them together (flowchart of Fig. 7.29), extended to a robot with a
//! failed leg.

mod controller;
pub mod elevator;
pub mod five_legs;
pub mod landing;
pub mod posture;
pub mod rules;
pub mod stability;
pub mod velocity;

pub use controller::{FreeGaitController, FreeGaitOptions, FreeGaitState};
pub use landing::{LandingDetector, MotorCurrent, NormalForce, THESIS_CURRENT_THRESHOLD, THESIS_FORCE_THRESHOLD};

#[cfg(test)]
mod tests;
