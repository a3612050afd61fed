//! Robot models: leg mechanisms and the hexapod mechanics built from a robot description.

pub mod mechanics;
pub mod pantograph;
