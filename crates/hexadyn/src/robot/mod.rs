//! The simulated robot: the complete AMRU5 model as one residual system ([`model`]: the
//! hexapod mechanics with ground contact, joint friction, DC motors and their drivers), the
//! simulated robot as a [`crate::control::Plant`] with its energy account, driven by a
//! controller ([`simulation`]), the recorded time series with units ([`recorder`]) and the
//! columns a run records ([`columns`]).

pub mod columns;
pub mod model;
pub mod recorder;
pub mod simulation;
