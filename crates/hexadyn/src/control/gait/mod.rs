//! Gait control on flat ground (thesis Chapter 7.1-7.6): desired body motion from the heading
//! velocities, periodic gait patterns, the plain and enhanced foot cycles, and the gait
//! controller that turns them into joint references through the legs' inverse kinematics, and
//! its schedule of gait changes while walking.

pub mod body_motion;
pub mod controller;
pub mod heading;
pub mod pattern;
pub mod schedule;
