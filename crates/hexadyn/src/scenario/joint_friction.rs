//! `[model.joint_friction]`: friction parameters identical for every leg, replacing the robot's
//! own in one scenario — the averaged friction of the Monte Carlo runs of Section 6.5
//! (Table 6.7), or a what-if study. One table per joint of a leg:
//!
//! - pantograph legs (AMRU5): `[model.joint_friction.q_r]`, `.q_v`, `.q_h`, the directional
//!   parameters of Eq. 6.1, the load coefficients of Eq. 5.12 and the transmission
//!   efficiencies of the efficiency law, replacing the per-leg identification (Tables 5.3 and
//!   5.5) and `[friction.efficiency]`;
//! - serial legs: `[model.joint_friction.<joint name>]` (the robot's `[joints] names`), the
//!   fields of its `[drives.<joint>.friction]` (the same in both senses), replacing them.
//!
//! The keys, units and signs are documented with the file format in `docs/scenario-format.md`.
//!
//! Keys left out keep the robot's values. The signs are those of a physical friction (a dry
//! friction opposes the motion and grows with the load; a viscous slope is not negative; an
//! efficiency is in (0, 1]), which is also the rejection rule of the Monte Carlo draws (Section
//! 6.5, [`physical_bounds`]).

use std::collections::BTreeMap;

use serde::Deserialize;

use crate::description::{Measured, PerLeg, Robot, RobotDescription, SerialRobot};
use crate::fields::{Ctx, DescriptionError};
use crate::hexapod::{JointKind, PantographJoint};

/// The scenario table's dotted name.
const TABLE: &str = "model.joint_friction";

/// The raw `[model.joint_friction]` table: joint name -> its fields as written, read once the
/// robot (and so its joints) is known.
#[derive(Deserialize, Default)]
#[serde(transparent)]
pub(super) struct RawJointFriction(BTreeMap<String, toml::Table>);

/// The sign (or range) a physical value has.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Sign {
    Positive,
    NonNegative,
    NonPositive,
    /// An efficiency, in (0, 1].
    Efficiency,
}

impl Sign {
    fn holds(self, v: f64) -> bool {
        match self {
            Sign::Positive => v > 0.0,
            Sign::NonNegative => v >= 0.0,
            Sign::NonPositive => v <= 0.0,
            Sign::Efficiency => v > 0.0 && v <= 1.0,
        }
    }

    fn allowed(self, what: &str) -> String {
        match self {
            Sign::Positive => format!("a finite number > 0 ({what})"),
            Sign::NonNegative => format!("a finite number >= 0 ({what})"),
            Sign::NonPositive => format!("a finite number <= 0 ({what}, minus sense)"),
            Sign::Efficiency => format!("a number in (0, 1] ({what})"),
        }
    }

    /// The interval of the physical values (closed: an efficiency of exactly 0 is never drawn).
    fn interval(self) -> (f64, f64) {
        match self {
            Sign::Positive | Sign::NonNegative => (0.0, f64::INFINITY),
            Sign::NonPositive => (f64::NEG_INFINITY, 0.0),
            Sign::Efficiency => (0.0, 1.0),
        }
    }
}

/// What a parameter is, for the messages: its name in the thesis and its unit on a revolute and
/// on a prismatic joint.
struct Parameter {
    key: &'static str,
    sign: Sign,
    what: &'static str,
    units: (&'static str, &'static str),
}

impl Parameter {
    const fn new(key: &'static str, sign: Sign, what: &'static str, units: (&'static str, &'static str)) -> Self {
        Parameter { key, sign, what, units }
    }

    fn allowed(&self, kind: JointKind) -> String {
        self.sign.allowed(&format!("{}, {}", self.what, kind.unit(self.units)))
    }
}

/// A dimensionless parameter's "units".
const RATIO: (&str, &str) = ("dimensionless", "dimensionless");

/// The efficiencies of the efficiency law, on every joint of either leg mechanism.
const EFFICIENCY: [Parameter; 2] = [
    Parameter::new("eta_forward", Sign::Efficiency, "forward transmission efficiency eta_f", RATIO),
    Parameter::new("eta_backward", Sign::Efficiency, "backward transmission efficiency eta_b", RATIO),
];

const DRY: (&str, &str) = ("Nm", "N");
const VISCOUS: (&str, &str) = ("Nm s/rad", "N s/m");

/// Pantograph legs: the directional dry/viscous parameters of Eq. 6.1 on every joint...
const PANTOGRAPH: [Parameter; 4] = [
    Parameter::new("tau_f_d_plus", Sign::NonNegative, "dry friction tau_f_d^+", DRY),
    Parameter::new("f_v_plus", Sign::NonNegative, "viscous slope f_v^+", VISCOUS),
    Parameter::new("tau_f_d_minus", Sign::NonPositive, "dry friction tau_f_d^-", DRY),
    Parameter::new("f_v_minus", Sign::NonNegative, "viscous slope f_v^-", VISCOUS),
];

/// ... and the load coefficients of Eq. 5.12 on the horizontal joint only (both units are the
/// horizontal joint's).
const PANTOGRAPH_LOAD: [Parameter; 4] = [
    Parameter::new("a_2_plus", Sign::NonNegative, "a_2^+ of Eq. 5.12", ("N/kg^2", "N/kg^2")),
    Parameter::new("a_1_plus", Sign::NonNegative, "a_1^+ of Eq. 5.12", ("N/kg", "N/kg")),
    Parameter::new("a_2_minus", Sign::NonPositive, "a_2^- of Eq. 5.12", ("N/kg^2", "N/kg^2")),
    Parameter::new("a_1_minus", Sign::NonPositive, "a_1^- of Eq. 5.12", ("N/kg", "N/kg")),
];

/// Serial legs: the fields of `[drives.<joint>.friction]` that describe the friction (the width
/// of the linear zone of Eq. 6.1 is the regularisation of the sign of q', not a friction
/// parameter, and stays the description's). Bounds as in the description.
const SERIAL: [Parameter; 5] = [
    Parameter::new("tau_f_d", Sign::NonNegative, "dry friction tau_f_d of Eq. 6.1", DRY),
    Parameter::new("f_v", Sign::NonNegative, "viscous slope f_v", VISCOUS),
    Parameter::new("sigma_0", Sign::Positive, "LuGre bristle stiffness sigma_0 of Eq. 3.83", ("Nm/rad", "N/m")),
    Parameter::new("sigma_1", Sign::NonNegative, "LuGre bristle damping sigma_1 of Eq. 3.83", VISCOUS),
    Parameter::new("v_d", Sign::Positive, "LuGre Stribeck velocity v_d of Eq. 3.84", ("rad/s", "m/s")),
];

/// The physical values of a parameter of a `[model.joint_friction.<joint>]` table (`"tau_f_d"`,
/// `"tau_f_d_minus"`, `"a_2_plus"`...), of either leg mechanism: the scenario's check and the
/// rejection rule of the Monte Carlo draws (Section 6.5: "omitted if they are non-physical").
/// None for a key no table has.
pub fn physical_bounds(parameter: &str) -> Option<(f64, f64)> {
    PANTOGRAPH.iter().chain(&PANTOGRAPH_LOAD).chain(&SERIAL).chain(&EFFICIENCY).find(|p| p.key == parameter).map(|p| p.sign.interval())
}

/// The keys of a serial joint's `[model.joint_friction.<joint>]` table, in the documented order.
pub fn serial_parameters() -> impl Iterator<Item = &'static str> {
    SERIAL.iter().chain(&EFFICIENCY).map(|p| p.key)
}

/// Reads a joint's table: every key one of `parameters` (else `unknown` gives the error of a
/// key), a number of the parameter's sign. Returns the values in the order of `parameters`.
fn read(c: &Ctx, path: &str, kind: JointKind, table: &toml::Table, parameters: &[&Parameter], unknown: impl Fn(&str, &toml::Value) -> DescriptionError) -> Result<Vec<Option<f64>>, DescriptionError> {
    if let Some((key, value)) = table.iter().find(|(k, _)| !parameters.iter().any(|p| p.key == k.as_str())) {
        return Err(unknown(key, value));
    }
    parameters
        .iter()
        .map(|p| {
            let field = format!("{path}.{}", p.key);
            let Some(value) = table.get(p.key) else { return Ok(None) };
            let v = match value {
                toml::Value::Float(v) => *v,
                toml::Value::Integer(i) => *i as f64,
                other => return Err(c.err(&field, other, "not a number", p.allowed(kind))),
            };
            c.check(p.sign.holds(v), &field, v, &p.allowed(kind)).map(|()| Some(v))
        })
        .collect()
}

impl RawJointFriction {
    /// Validates the table against the robot's joints and writes its values into every leg of
    /// `robot`. A joint the robot does not have is refused with the list of its joints.
    pub(super) fn apply(&self, c: &Ctx, robot: &mut Robot) -> Result<(), DescriptionError> {
        // Pantograph tables are named by the thesis symbols (whatever the description calls
        // the joints), serial ones by the robot's joint names.
        let names: Vec<String> = match robot {
            Robot::Pantograph(_) => PantographJoint::ALL.iter().map(|j| j.symbol().to_string()).collect(),
            Robot::Serial(s) => s.joints.names().map(str::to_string).collect(),
        };
        for (name, table) in &self.0 {
            let path = format!("{TABLE}.{name}");
            let Some(j) = names.iter().position(|n| n == name) else {
                let tables = names.iter().map(|n| format!("[{TABLE}.{n}]")).collect::<Vec<_>>().join(", ");
                return Err(c.err(&path, format!("[{path}]"), &format!("no joint {name:?} on the {} legs of {}", robot.leg_mechanism(), robot.name()), format!("a table per joint of the robot: {tables}")));
            };
            let unknown = |allowed: &[&Parameter]| {
                let list = allowed.iter().map(|p| p.key).collect::<Vec<_>>().join(", ");
                let path = path.clone();
                move |key: &str, value: &toml::Value| c.err(&format!("{path}.{key}"), value, "unknown field", format!("one of {list} (docs/scenario-format.md)"))
            };
            match robot {
                Robot::Pantograph(d) => {
                    let joint = PantographJoint::ALL[j];
                    let horizontal = joint == PantographJoint::Horizontal;
                    if !horizontal {
                        if let Some((key, value)) = table.iter().find(|(k, _)| PANTOGRAPH_LOAD.iter().any(|p| p.key == k.as_str())) {
                            return Err(c.err(&format!("{path}.{key}"), value, "no load dependence on this joint", "the load coefficients a_* only in [model.joint_friction.q_h] (Eq. 5.12 holds for the horizontal joints)"));
                        }
                    }
                    let parameters: Vec<&Parameter> = PANTOGRAPH.iter().chain(PANTOGRAPH_LOAD.iter().filter(|_| horizontal)).chain(&EFFICIENCY).collect();
                    let values = read(c, &path, joint.kind(), table, &parameters, unknown(&parameters))?;
                    set_pantograph(d, joint, &values);
                }
                Robot::Serial(s) => {
                    let parameters: Vec<&Parameter> = SERIAL.iter().chain(&EFFICIENCY).collect();
                    let values = read(c, &path, s.joints.kind(j), table, &parameters, unknown(&parameters))?;
                    set_serial(s, j, &values);
                }
            }
        }
        Ok(())
    }
}

/// Writes the values of [`PANTOGRAPH`], then [`PANTOGRAPH_LOAD`] (horizontal joint), then
/// [`EFFICIENCY`] into every leg.
fn set_pantograph(robot: &mut RobotDescription, joint: PantographJoint, values: &[Option<f64>]) {
    let f = &mut robot.friction;
    let efficiency = match joint {
        PantographJoint::Rotation => &mut f.efficiency.q_r,
        PantographJoint::Vertical => &mut f.efficiency.q_v,
        PantographJoint::Horizontal => &mut f.efficiency.q_h,
    };
    let [eta_forward, eta_backward] = [values[values.len() - 2], values[values.len() - 1]];
    efficiency.eta_forward = eta_forward.unwrap_or(efficiency.eta_forward);
    efficiency.eta_backward = eta_backward.unwrap_or(efficiency.eta_backward);
    let tables: [&mut PerLeg; 4] = match joint {
        PantographJoint::Rotation => [&mut f.q_r.tau_f_d_plus_nm, &mut f.q_r.f_v_plus_nms, &mut f.q_r.tau_f_d_minus_nm, &mut f.q_r.f_v_minus_nms],
        PantographJoint::Vertical => [&mut f.q_v.tau_f_d_plus_n, &mut f.q_v.f_v_plus_ns_per_m, &mut f.q_v.tau_f_d_minus_n, &mut f.q_v.f_v_minus_ns_per_m],
        PantographJoint::Horizontal => [&mut f.q_h.tau_f_d_plus_n, &mut f.q_h.f_v_plus_ns_per_m, &mut f.q_h.tau_f_d_minus_n, &mut f.q_h.f_v_minus_ns_per_m],
    };
    for (table, value) in tables.into_iter().zip(values) {
        if let Some(v) = value {
            table.mu.fill(*v);
        }
    }
    if joint != PantographJoint::Horizontal {
        return;
    }
    let ld = &mut f.q_h.load_dependence;
    let [a_2_plus, a_1_plus, a_2_minus, a_1_minus] = [values[4], values[5], values[6], values[7]];
    for (table, value) in [(&mut ld.a_2_plus_n_per_kg2, a_2_plus), (&mut ld.a_2_minus_n_per_kg2, a_2_minus)] {
        if let Some(v) = value {
            table.mu.fill(v);
        }
    }
    for (table, value) in [(&mut ld.a_1_plus_n_per_kg, a_1_plus), (&mut ld.a_1_minus_n_per_kg, a_1_minus)] {
        if let Some(v) = value {
            table.mu.fill(Measured::Value(v));
        }
    }
}

/// Writes the values of [`SERIAL`] then [`EFFICIENCY`] into the friction of joint `j`'s drive
/// (every leg's).
fn set_serial(robot: &mut SerialRobot, j: usize, values: &[Option<f64>]) {
    let f = &mut robot.drives[j].friction;
    for (slot, value) in [&mut f.tau_f_d, &mut f.f_v, &mut f.sigma_0, &mut f.sigma_1, &mut f.v_d, &mut f.eta_forward, &mut f.eta_backward].into_iter().zip(values) {
        if let Some(v) = value {
            *slot = *v;
        }
    }
}
