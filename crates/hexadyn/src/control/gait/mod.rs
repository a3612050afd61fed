//! Gait control (thesis Chapter 7): desired body motion from the heading velocities, periodic
//! gait patterns, the plain and enhanced foot cycles, the periodic gait controller that turns
//! them into joint references through the legs' inverse kinematics, its schedule of gait changes
//! while walking (Sections 7.1-7.6, flat ground), and the free gait on uneven ground (Section
//! 7.7, [`free`]).

pub mod body_motion;
pub mod controller;
pub mod free;
pub mod heading;
pub mod pattern;
pub mod schedule;
pub mod walk;
