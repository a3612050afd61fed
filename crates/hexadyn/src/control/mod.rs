//! Joint control (thesis Section 3.4.4 and Chapter 4): the digital PI controllers of AMRU5 with
//! their encoders, and the continuous PID element of the 96-DOF model.

mod pi;

pub use pi::{ContinuousPid, DigitalPi, Encoder, PidIntegralResidual, PidVoltageResidual};
