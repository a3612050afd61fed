//! [`Robot`]: a robot description of either leg mechanism, told apart by its `leg_mechanism`
//! key (`"serial"`; none for the pantograph descriptions like `robots/amru5.toml`), with what
//! scenarios, the model and the controllers ask of any robot.

use std::path::Path;

use super::serial::{SerialDescriptionFile, SerialRobot};
use super::{PiGains, RobotDescription};
use crate::fields::{Ctx, DescriptionError, Result, SpanIndex};
use crate::control::FrictionFeedForward;
use crate::hexapod::{LegDynamics, LegJoints, PantographJoint, JOINTS};
use crate::robot::model::{FrictionModel, ModelOptions, RobotParts};

/// Where "missing field" errors of a serial description send the reader (a command every
/// installation has, and the format's documentation).
const SERIAL_REFERENCE: &str = "`hexadyn robot-file phantomx`, a complete description, and docs/robot-format.md";

/// A robot description: AMRU5's pantograph legs, or serial legs. (Read once per scenario and
/// never moved in a loop: the variants' sizes do not matter.)
#[derive(Clone, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)]
pub enum Robot {
    Pantograph(RobotDescription),
    Serial(SerialRobot),
}

impl Robot {
    /// Reads and validates a description file of either kind; errors name `path`.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Robot> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let text = crate::fields::read_input(path).map_err(|reason| DescriptionError::Io { file: file.clone(), reason })?;
        Self::from_str(&text, &file)
    }

    /// Parses and validates a description of either kind; `origin` names it in errors.
    #[allow(clippy::should_implement_trait)]
    pub fn from_str(text: &str, origin: &str) -> Result<Robot> {
        let serial = toml::from_str::<toml::Table>(text).ok().is_some_and(|t| t.contains_key("leg_mechanism"));
        if !serial {
            return RobotDescription::from_str(text, origin).map(Robot::Pantograph);
        }
        let index = SpanIndex::build_for(text, origin, SERIAL_REFERENCE)?;
        index.check_top_level(crate::fields::struct_fields::<SerialDescriptionFile>())?;
        let file: SerialDescriptionFile = toml::from_str(text).map_err(|e| index.serde_error(&e))?;
        let c = Ctx { file: origin, index: Some(&index) };
        SerialRobot::validate(&file, &c).map(Robot::Serial)
    }

    /// The pantograph description, for what only AMRU5's legs have (its friction tables, the
    /// free gait's leg model, ground detection).
    pub fn pantograph(&self) -> Option<&RobotDescription> {
        match self {
            Robot::Pantograph(d) => Some(d),
            Robot::Serial(_) => None,
        }
    }

    pub fn name(&self) -> &str {
        match self {
            Robot::Pantograph(d) => &d.name,
            Robot::Serial(s) => &s.name,
        }
    }

    /// The file (or origin name) it was read from.
    pub fn origin(&self) -> &str {
        match self {
            Robot::Pantograph(d) => &d.origin,
            Robot::Serial(s) => &s.origin,
        }
    }

    /// The leg mechanism's name, for messages: "pantograph" or "serial".
    pub fn leg_mechanism(&self) -> &'static str {
        match self {
            Robot::Pantograph(_) => "pantograph",
            Robot::Serial(_) => "serial",
        }
    }

    pub fn joints(&self) -> &LegJoints {
        match self {
            Robot::Pantograph(d) => &d.joints.names,
            Robot::Serial(s) => &s.joints,
        }
    }

    /// The control period (s).
    pub fn period(&self) -> f64 {
        match self {
            Robot::Pantograph(d) => d.controller.period_s,
            Robot::Serial(s) => s.period,
        }
    }

    /// The motors' nominal voltage (V).
    pub fn nominal_voltage(&self) -> f64 {
        match self {
            Robot::Pantograph(d) => d.motor.nominal_voltage_v,
            Robot::Serial(s) => s.nominal_voltage(),
        }
    }

    /// The range of joint k = 3 leg + j (rad or m).
    pub fn joint_range(&self, k: usize) -> (f64, f64) {
        match self {
            Robot::Pantograph(d) => d.joint_range(PantographJoint::ALL[k % 3]),
            Robot::Serial(s) => s.joint_range(k),
        }
    }

    /// The PI gains of each joint (Table 4.1 for AMRU5).
    pub fn pi_gains(&self) -> [PiGains; JOINTS] {
        match self {
            Robot::Pantograph(d) => d.joint_pi_gains(),
            Robot::Serial(s) => std::array::from_fn(|k| s.pi_gains(k)),
        }
    }

    /// The master's friction feed-forward for position servos at the control period `dt`
    /// (None without servos).
    pub fn friction_feedforward(&self, dt: f64) -> Option<FrictionFeedForward> {
        match self {
            Robot::Pantograph(_) => None,
            Robot::Serial(s) => s.friction_feedforward(dt),
        }
    }

    /// The description's ground and supply with the given friction model.
    pub fn model_options(&self, friction: FrictionModel) -> ModelOptions {
        match self {
            Robot::Pantograph(d) => ModelOptions::from_description(d, friction),
            Robot::Serial(s) => s.model_options(friction),
        }
    }

    /// The parts of the robot model under `options`.
    pub fn parts(&self, options: &ModelOptions) -> RobotParts {
        match self {
            Robot::Pantograph(d) => RobotParts::from_description(d, options),
            Robot::Serial(s) => s.parts(options),
        }
    }

    /// The multibody model with its rotors and feet, for the joint torques on a still body
    /// (the friction identification, the ground detection's torque estimate).
    pub fn leg_dynamics(&self) -> LegDynamics {
        self.parts(&self.model_options(FrictionModel::None)).into()
    }

    pub fn total_mass_kg(&self) -> f64 {
        match self {
            Robot::Pantograph(d) => d.total_mass_kg(),
            Robot::Serial(s) => s.total_mass_kg(),
        }
    }
}
