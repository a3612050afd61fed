//! Analyses built on the model: controller design (thesis Chapter 4) and the judgement of a
//! walk over uneven ground (no fall, no permanent deadlock).

pub mod pi_design;
pub mod leg_design;
pub mod outcome;
