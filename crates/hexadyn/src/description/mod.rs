//! [`RobotDescription`]: the robot parameter file (`robots/amru5.toml`) as Rust data.
//!
//! The structs mirror the TOML tables one to one, each named after its table (`[motor]` is
//! [`MotorTable`], `tables.rs`), with the thesis units in the field names (`resistance_ohm`,
//! `inductance_mh`, `angle_deg`, ...). Every struct denies unknown fields, and every field
//! declares its allowed values, checked while reading (`values.rs`: `Positive`,
//! `Negative::per_leg`, ...); the relations between fields (the pantograph closure, the
//! principal moments, the mass sums of Table B.2, the reduction products of Table 3.1, ...) are
//! checked after reading (`validate.rs`, [`RobotDescription::from_str`]). Errors name the file,
//! the dotted field path (`motor.resistance_ohm`, `legs[2].angle_deg`,
//! `friction.q_v.tau_f_d_plus_n.mu[3]`), the value and what is allowed, with the line when it
//! is known ([`crate::fields`]).
//!
//! SI accessors convert the thesis units (degrees, mH, g cm^2) and assemble per-leg friction
//! parameters in joint units (N or Nm, N s/m or Nm s/rad) with the rules of Section 6.1
//! ([`RobotDescription::friction`]). All friction values of Chapters 5-6 are joint-side
//! already; [`RobotDescription::joint_torque_per_ampere`] gives the k_t n factor of Eq. 5.17
//! for converting motor currents.
//!
//! ```
//! use hexadyn::description::RobotDescription;
//! use hexadyn::hexapod::PantographJoint;
//! let robot = RobotDescription::amru5();
//! assert_eq!(robot.legs.len(), 6);
//! let f = robot.friction(0, PantographJoint::Vertical);
//! assert!(f.tau_f_d_plus > 0.0 && f.tau_f_d_minus < 0.0);
//! ```

use std::path::Path;

mod tables;
mod extends;
pub mod mjcf;
pub mod urdf;
mod hexapod_parameters;
mod monte_carlo;
mod robot;
pub mod serial;
mod si;
mod validate;
mod values;

pub use crate::fields::{DescriptionError, FieldError};
pub use tables::*;
pub use monte_carlo::{across_legs, LoadDependenceDistribution};
pub use robot::Robot;
pub use serial::SerialRobot;
pub use si::{JointFrictionParameters, PiGains};
pub use values::{Gaussian, Interval, Measured, PerLeg, PerLegMaybe, Sweep};

use crate::fields::{Ctx, Result, SpanIndex};

/// The shipped AMRU5 description (`robots/amru5.toml`), embedded at compile time.
pub const AMRU5_TOML: &str = include_str!("../../../../robots/amru5.toml");

/// The shipped PhantomX Mark II description (`robots/phantomx/phantomx.toml`), embedded.
pub const PHANTOMX_TOML: &str = include_str!("../../../../robots/phantomx/phantomx.toml");

/// AMRU5 with low-ratio, backdrivable drives (`robots/amru5_backdrivable.toml`, issue 40's
/// "AMRU5 bis"), embedded: it extends `amru5`.
pub const AMRU5_BACKDRIVABLE_TOML: &str = include_str!("../../../../robots/amru5_backdrivable.toml");

/// AMRU5 with series-elastic transmissions (`robots/amru5_series_elastic.toml`, issue 40's
/// "AMRU5 bis"), embedded: it extends `amru5`.
pub const AMRU5_SERIES_ELASTIC_TOML: &str = include_str!("../../../../robots/amru5_series_elastic.toml");

/// The robots a scenario names by `scenario.robot = "<name>"`: name, embedded text, the file it
/// was embedded from (named in errors).
pub const SHIPPED_ROBOTS: [(&str, &str, &str); 4] = [
    ("amru5", AMRU5_TOML, AMRU5_ORIGIN),
    ("phantomx", PHANTOMX_TOML, "robots/phantomx/phantomx.toml"),
    ("amru5_backdrivable", AMRU5_BACKDRIVABLE_TOML, "robots/amru5_backdrivable.toml"),
    ("amru5_series_elastic", AMRU5_SERIES_ELASTIC_TOML, "robots/amru5_series_elastic.toml"),
];

/// Name used in error messages for the embedded file.
const AMRU5_ORIGIN: &str = "robots/amru5.toml";

/// Where "missing field" errors of a pantograph description send the reader: a command every
/// installation has (it prints the embedded file), not a path of the repository.
const PANTOGRAPH_REFERENCE: &str = "`hexadyn robot-file amru5`, a complete description";

impl RobotDescription {
    /// The shipped AMRU5 description (embedded `robots/amru5.toml`).
    ///
    /// # Panics
    /// Never in a tested build: the embedded file is validated by the unit tests.
    /// Parsed once per process (every scenario naming `"amru5"` starts from it).
    pub fn amru5() -> RobotDescription {
        static PARSED: std::sync::OnceLock<RobotDescription> = std::sync::OnceLock::new();
        PARSED.get_or_init(|| Self::from_str(AMRU5_TOML, AMRU5_ORIGIN).unwrap_or_else(|e| panic!("the embedded AMRU5 description is invalid: {e}"))).clone()
    }

    /// Reads and validates a description file; errors name `path`.
    pub fn from_file(path: impl AsRef<Path>) -> Result<RobotDescription> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let text = crate::fields::read_input(path).map_err(|reason| DescriptionError::Io { file: file.clone(), reason })?;
        Self::from_str(&text, &file)
    }

    /// Parses and validates a description; `origin_name` (a file name) is used in errors.
    #[allow(clippy::should_implement_trait)]
    ///
    /// A description with `extends = "<shipped robot>"` is that robot's with the text's tables
    /// merged over it (`extends.rs`, docs/robot-format.md).
    pub fn from_str(text: &str, origin_name: &str) -> Result<RobotDescription> {
        let index = SpanIndex::build_for(text, origin_name, PANTOGRAPH_REFERENCE)?;
        if let Some((merged, base)) = extends::merged(text, &index)? {
            return Self::from_str(&merged, origin_name).map_err(|e| extends::locate(e, &index, base));
        }
        index.check_top_level(crate::fields::struct_fields::<RobotDescription>())?;
        let mut robot: RobotDescription = toml::from_str(text).map_err(|e| index.serde_error(&e))?;
        robot.origin = origin_name.to_string();
        robot.validate(&Ctx { file: origin_name, index: Some(&index) })?;
        robot.legs.sort_by_key(|l| l.id);
        Ok(robot)
    }
}

#[cfg(test)]
mod tests;
