//! Robot models: the robot as data (the AMRU5 parameters of the thesis, read from
//! `robots/amru5.toml`), the pantograph leg mechanism and the hexapod mechanics built from it.
//!
//! [`RobotDescription`] mirrors the TOML file table by table (thesis units in the key names,
//! numbers 1:1 with the thesis tables). Loading validates every field and reports errors that
//! name the file, the dotted field path, the offending value and what is allowed
//! ([`DescriptionError`]). SI accessors (radians, kg m^2, H, per-leg friction in joint units
//! after the rules of Section 6.1) sit on top of the raw mirror.
//!
//! [`model`] is the complete robot as one residual system and [`simulation`] the simulated
//! robot driven by a controller. [`scenario`] reads ready-to-run simulations from TOML files
//! (reporting errors the same way as the description) and runs them into time series with
//! units ([`recorder`]).
//!
//! ```
//! use hexadyn::robot::{Joint, RobotDescription};
//! let robot = RobotDescription::amru5();
//! assert_eq!(robot.legs.len(), 6);
//! let f = robot.friction(0, Joint::Vertical);
//! assert!(f.tau_f_d_plus > 0.0 && f.tau_f_d_minus < 0.0);
//! ```

pub mod description;
pub mod mechanics;
pub mod model;
pub mod pantograph;
pub mod recorder;
pub mod scenario;
pub mod simulation;

pub use description::{
    DescriptionError, FieldError, Gaussian, JointFriction, LoadCoefficients, LoadDependenceDistribution,
    PiGains, RobotDescription, AMRU5_TOML,
};

/// The three actuated joints of a leg (Eq. 3.51): q_r the rotation of the leg chassis about
/// the vertical axis, q_v the vertical and q_h the horizontal ball-screw nut positions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Joint {
    /// q_r, rad (joint torques in Nm).
    Rotation,
    /// q_v, m (joint "torques" are forces in N).
    Vertical,
    /// q_h, m (joint "torques" are forces in N).
    Horizontal,
}

impl Joint {
    /// The three joints in the thesis order (q_r, q_v, q_h).
    pub const ALL: [Joint; 3] = [Joint::Rotation, Joint::Vertical, Joint::Horizontal];

    /// Thesis symbol: `q_r`, `q_v` or `q_h` (also the TOML table names).
    pub fn symbol(self) -> &'static str {
        match self {
            Joint::Rotation => "q_r",
            Joint::Vertical => "q_v",
            Joint::Horizontal => "q_h",
        }
    }

    /// True for q_r (radians and Nm), false for the translational joints (metres and N).
    pub fn is_rotational(self) -> bool {
        matches!(self, Joint::Rotation)
    }
}

impl std::fmt::Display for Joint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.symbol())
    }
}
