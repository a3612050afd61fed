//! Analyses built on the model: controller design (thesis Chapter 4).

pub mod pi_design;
pub mod leg_design;
