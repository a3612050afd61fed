//! A robot description with serial legs (`leg_mechanism = "serial"`): the mechanism the URDF
//! way (the base link and six chains of three joints with their links and feet, as
//! `hexadyn import-urdf` writes them), a drive per joint of a leg (a DC motor and gear under
//! the master's digital PI of Eq. 4.18-4.20, or a position servo, [`PositionServo`]) with its
//! joint friction (Eq. 6.1 or the LuGre law of Eq. 3.83-3.87), the control period and supply,
//! and the ground of Table 3.3. The format is `docs/robot-format.md`.
//!
//! Errors name the file, the line, the dotted field (`legs[2].joints[1].link.mass_kg`,
//! `drives.femur.servo.punch`), the value and what is allowed, like AMRU5's description.

use std::collections::BTreeMap;

use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use serde::Deserialize;

use super::tables::{ideal, GroundTable};
use super::PiGains;
use crate::control::{Encoder, FrictionFeedForward, PositionServo};
use crate::fields::{Bound, Ctx, Finite, NonNegative, Positive, Result};
use crate::hexapod::{JointKind, LegJoints, Link, Rotor, SerialHexapod, SerialJoint, SerialLeg, JOINTS, LEG_COUNT};
use crate::physics::{DcMotor, DryViscous, Efficiency, FrictionElement, GroundContact, JointFriction, LuGre, SteadyState};
use crate::robot::model::{FrictionModel, JointControl, ModelOptions, RobotParts};
use crate::spatial::{yaw_pitch_roll, Htm};

use super::values::{AtLeastOne, Fraction, Gaussian, Shapes};

/// A link: mass, centre of mass and inertia tensor about it, in the link frame.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LinkTable {
    #[serde(deserialize_with = "Positive::checked")]
    pub mass_kg: f64,
    pub com_m: [f64; 3],
    /// [I_xx, I_yy, I_zz, I_xy, I_xz, I_yz] (URDF's order of `<inertia>`, kg m²).
    pub inertia_kg_m2: [f64; 6],
}

/// One joint of a leg and the link it moves.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct JointTable {
    pub name: String,
    pub kind: JointKind,
    /// The joint frame in the parent link's frame at q = 0 (URDF `<origin xyz rpy>`).
    pub origin_xyz_m: [f64; 3],
    pub origin_rpy_rad: [f64; 3],
    pub axis: [f64; 3],
    /// Range (rad, or m for a prismatic joint).
    #[serde(deserialize_with = "Finite::checked")]
    pub lower: f64,
    #[serde(deserialize_with = "Finite::checked")]
    pub upper: f64,
    pub link: LinkTable,
}

/// A leg: three joints from the base, and the foot sphere on the last link.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LegTable {
    pub joints: Vec<JointTable>,
    /// The foot sphere's centre in the last link's frame.
    pub foot_m: [f64; 3],
    #[serde(deserialize_with = "Positive::checked")]
    pub foot_radius_m: f64,
}

/// The DC motor of a drive.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MotorSpec {
    #[serde(deserialize_with = "Positive::checked")]
    pub resistance_ohm: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub torque_constant_nm_per_a: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub inductance_mh: f64,
    /// Rotor inertia about its axis (kg m²), turning at n q on the link that carries the motor.
    #[serde(deserialize_with = "NonNegative::checked")]
    pub rotor_inertia_kg_m2: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub nominal_voltage_v: f64,
}

/// Joint friction of a drive, joint side, the same in both senses (Nm or N; Nm s/rad or N s/m).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FrictionSpec {
    /// Dry friction τ_f,d (Eq. 6.1).
    #[serde(deserialize_with = "NonNegative::checked")]
    pub tau_f_d: f64,
    /// Viscous coefficient f_v.
    #[serde(deserialize_with = "NonNegative::checked")]
    pub f_v: f64,
    /// Half width ε of the linear zone of Eq. 6.1 (rad/s or m/s).
    #[serde(deserialize_with = "Positive::checked")]
    pub linear_zone: f64,
    /// LuGre bristle stiffness σ0 and damping σ1 (Eq. 3.83), and v_d of Eq. 3.84.
    #[serde(deserialize_with = "Positive::checked")]
    pub sigma_0: f64,
    #[serde(deserialize_with = "NonNegative::checked")]
    pub sigma_1: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub v_d: f64,
    /// Forward and backward efficiencies of the transmission (the efficiency law,
    /// [`crate::physics::Efficiency`]), in (0, 1]; 1 (ideal) where left out.
    #[serde(default = "ideal", deserialize_with = "Fraction::checked")]
    pub eta_forward: f64,
    #[serde(default = "ideal", deserialize_with = "Fraction::checked")]
    pub eta_backward: f64,
}

/// A position servo's loop (the Dynamixel AX control table's compliance), and its position
/// sensor.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ServoSpec {
    #[serde(deserialize_with = "NonNegative::checked")]
    pub compliance_margin_deg: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub compliance_slope_deg: f64,
    /// Fraction of the supply, [0, torque_limit].
    #[serde(deserialize_with = "NonNegative::checked")]
    pub punch: f64,
    #[serde(deserialize_with = "Fraction::checked")]
    pub torque_limit: f64,
    /// The position sensor: `sensor_counts` over `sensor_range_deg` of the joint.
    #[serde(deserialize_with = "Positive::checked")]
    pub sensor_counts: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub sensor_range_deg: f64,
}

/// The master's digital PI (Eq. 4.18-4.20) through an H-bridge, with a motor encoder.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PiSpec {
    /// K (V/rad or V/m).
    #[serde(deserialize_with = "Positive::checked")]
    pub k: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub t_i_s: f64,
    /// The H-bridge's series resistance (Ω).
    #[serde(deserialize_with = "NonNegative::checked")]
    pub bridge_resistance_ohm: f64,
    /// Encoder counts per rotor revolution.
    #[serde(deserialize_with = "Positive::checked")]
    pub encoder_counts_per_rev: f64,
}

/// The drive of one joint of every leg.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DriveTable {
    /// n: rotor turns per joint radian (or per metre).
    #[serde(deserialize_with = "Positive::checked")]
    pub gear_ratio: f64,
    pub motor: MotorSpec,
    pub friction: FrictionSpec,
    pub servo: Option<ServoSpec>,
    pub pi: Option<PiSpec>,
}

/// `[controller]`: the master.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SerialControllerTable {
    /// The master's period (s): goals or voltages are sent at this rate.
    #[serde(deserialize_with = "Positive::checked")]
    pub period_s: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub supply_voltage_v: f64,
}

/// `[joints]`: the names of a leg's joints.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SerialJointsTable {
    pub names: [String; 3],
}

/// `[monte_carlo]`: the Monte Carlo runs over the joint friction (Section 6.5, Eq. 6.12): the
/// campaign's defaults and, per joint, the Gaussians the drive friction is drawn from.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SerialMonteCarloTable {
    #[serde(deserialize_with = "AtLeastOne::checked")]
    pub runs_per_velocity: u32,
    /// Draws outside mu +- truncation_sigmas sigma are redrawn.
    #[serde(deserialize_with = "Positive::checked")]
    pub truncation_sigmas: f64,
    #[serde(deserialize_with = "super::tables::velocities")]
    pub velocities_m_per_s: Vec<f64>,
    /// `[monte_carlo.friction.<joint>]`, per joint name of `[joints] names`.
    pub friction: BTreeMap<String, FrictionDistributionTable>,
}

/// `[monte_carlo.friction.<joint>]`: the Gaussians N(mu, sigma^2) of the fields of
/// `[drives.<joint>.friction]` drawn per run (identical for every leg); a field left out is
/// not drawn and keeps the drive's value.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FrictionDistributionTable {
    #[serde(default, deserialize_with = "positive_gaussian")]
    pub tau_f_d: Option<Gaussian>,
    #[serde(default, deserialize_with = "non_negative_gaussian")]
    pub f_v: Option<Gaussian>,
}

fn positive_gaussian<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Option<Gaussian>, D::Error> {
    Positive::gaussian(d).map(Some)
}

fn non_negative_gaussian<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Option<Gaussian>, D::Error> {
    NonNegative::gaussian(d).map(Some)
}

impl FrictionDistributionTable {
    /// The drawn fields, as (key of `[model.joint_friction.<joint>]`, Gaussian), in the order
    /// of the drive's friction table.
    pub fn drawn(&self) -> impl Iterator<Item = (&'static str, Gaussian)> {
        [("tau_f_d", self.tau_f_d), ("f_v", self.f_v)].into_iter().filter_map(|(k, g)| g.map(|g| (k, g)))
    }
}

/// The file, as written.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SerialDescriptionFile {
    pub name: String,
    pub leg_mechanism: String,
    pub joints: SerialJointsTable,
    pub base: LinkTable,
    pub legs: Vec<LegTable>,
    pub drives: BTreeMap<String, DriveTable>,
    pub controller: SerialControllerTable,
    pub ground: GroundTable,
    pub monte_carlo: Option<SerialMonteCarloTable>,
}

/// The Monte Carlo set-up of a serial robot, validated: the friction Gaussians per joint of a
/// leg, in the order of the joints.
#[derive(Clone, Debug, PartialEq)]
pub struct SerialMonteCarlo {
    pub runs_per_velocity: u32,
    pub truncation_sigmas: f64,
    pub velocities_m_per_s: Vec<f64>,
    pub friction: [FrictionDistributionTable; 3],
}

/// A joint's drive, validated.
#[derive(Clone, Debug, PartialEq)]
pub struct Drive {
    pub gear_ratio: f64,
    pub motor: MotorSpec,
    pub friction: FrictionSpec,
    pub control: DriveControl,
}

/// What drives the motor.
#[derive(Clone, Debug, PartialEq)]
pub enum DriveControl {
    Servo(ServoSpec),
    Pi(PiSpec),
}

/// A validated serial robot description.
#[derive(Clone, Debug, PartialEq)]
pub struct SerialRobot {
    pub name: String,
    /// The file (or origin name).
    pub origin: String,
    pub hexapod: SerialHexapod,
    pub joints: LegJoints,
    /// Per joint of a leg, in the order of `joints`.
    pub drives: [Drive; 3],
    pub period: f64,
    pub supply_voltage: f64,
    pub ground: GroundTable,
    /// `[monte_carlo]`, when the description has one.
    pub monte_carlo: Option<SerialMonteCarlo>,
}

fn pose(xyz: [f64; 3], rpy: [f64; 3]) -> Htm {
    Htm { rotation: yaw_pitch_roll(rpy[2], rpy[1], rpy[0]), translation: Vector3::from(xyz) }
}

fn link(c: &Ctx, field: &str, t: &LinkTable) -> Result<Link> {
    for (i, v) in t.com_m.iter().chain(&t.inertia_kg_m2).enumerate() {
        let name = if i < 3 { format!("{field}.com_m[{i}]") } else { format!("{field}.inertia_kg_m2[{}]", i - 3) };
        c.finite(&name, *v)?;
    }
    let [xx, yy, zz, xy, xz, yz] = t.inertia_kg_m2;
    let inertia = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
    // A physical tensor: positive principal moments satisfying the triangle inequality.
    let moments = SymmetricEigen::try_new(inertia, 1e-15, 200).map(|e| e.eigenvalues);
    let physical = moments.is_some_and(|m| {
        let tol = 1e-9 * m.amax();
        m.iter().all(|&v| v > 0.0) && m[0] + m[1] + tol >= m[2] && m[1] + m[2] + tol >= m[0] && m[0] + m[2] + tol >= m[1]
    });
    if !physical {
        return Err(c.err(&format!("{field}.inertia_kg_m2"), format!("{:?}", t.inertia_kg_m2), "not a physical inertia tensor", "[I_xx, I_yy, I_zz, I_xy, I_xz, I_yz] (kg m²) with positive principal moments that satisfy the triangle inequality"));
    }
    Ok(Link { mass: t.mass_kg, com: Vector3::from(t.com_m), inertia })
}

fn finite3(c: &Ctx, field: &str, v: &[f64; 3]) -> Result<()> {
    for (i, x) in v.iter().enumerate() {
        c.finite(&format!("{field}[{i}]"), *x)?;
    }
    Ok(())
}

impl SerialRobot {
    /// Validates the file's tables (`c` names the file).
    pub(crate) fn validate(f: &SerialDescriptionFile, c: &Ctx) -> Result<SerialRobot> {
        if f.leg_mechanism != "serial" {
            return Err(c.err("leg_mechanism", format!("{:?}", f.leg_mechanism), "not a serial description", "\"serial\" (or no leg_mechanism for a pantograph description like `hexadyn robot-file amru5`)"));
        }
        if f.legs.len() != LEG_COUNT {
            return Err(c.err("legs", format!("{} legs", f.legs.len()), "not six legs", "six [[legs]], numbered 0, 2, 4 on the left from front to rear and 1, 3, 5 on the right"));
        }
        let base = link(c, "base", &f.base)?;
        let mut legs = Vec::with_capacity(LEG_COUNT);
        for (l, leg) in f.legs.iter().enumerate() {
            let at = |rest: &str| format!("legs[{l}].{rest}");
            if leg.joints.len() != 3 {
                return Err(c.err(&at("joints"), format!("{} joints", leg.joints.len()), "not three joints", "three [[legs.joints]] from the base to the foot"));
            }
            let mut joints = Vec::new();
            let mut links = Vec::new();
            for (k, j) in leg.joints.iter().enumerate() {
                let jf = |rest: &str| at(&format!("joints[{k}].{rest}"));
                finite3(c, &jf("origin_xyz_m"), &j.origin_xyz_m)?;
                finite3(c, &jf("origin_rpy_rad"), &j.origin_rpy_rad)?;
                finite3(c, &jf("axis"), &j.axis)?;
                let axis = Vector3::from(j.axis);
                let norm = axis.norm();
                if !(norm > 1e-9 && norm.is_finite()) {
                    return Err(c.err(&jf("axis"), format!("{:?}", j.axis), "not a direction", "a non-zero axis of finite length (normalized when read)"));
                }
                c.check(j.upper > j.lower, &jf("upper"), j.upper, &format!("a value > lower = {}", j.lower))?;
                if f.legs[0].joints.len() == 3 && j.kind != f.legs[0].joints[k].kind {
                    return Err(c.err(&jf("kind"), format!("{:?}", j.kind), "differs from leg 0's", "the same joint kinds on every leg (the results' units are per joint name)"));
                }
                joints.push(SerialJoint { name: j.name.clone(), origin: pose(j.origin_xyz_m, j.origin_rpy_rad), axis: axis.normalize(), kind: j.kind, lower: j.lower, upper: j.upper });
                links.push(link(c, &jf("link"), &j.link)?);
            }
            finite3(c, &at("foot_m"), &leg.foot_m)?;
            if leg.foot_radius_m != f.legs[0].foot_radius_m {
                return Err(c.err(&at("foot_radius_m"), leg.foot_radius_m, "differs from leg 0's", format!("{} m, the foot radius of every leg (one contact law for the six feet)", f.legs[0].foot_radius_m)));
            }
            legs.push(SerialLeg {
                joints: joints.try_into().expect("three joints"),
                links: links.try_into().expect("three links"),
                foot: Vector3::from(leg.foot_m),
                foot_radius: leg.foot_radius_m,
            });
        }
        let kinds = std::array::from_fn(|k| f.legs[0].joints[k].kind);
        let joints = LegJoints::new(f.joints.names.clone(), kinds).map_err(|e| c.err("joints.names", format!("{:?}", f.joints.names), &e.to_string(), "three distinct identifiers that are not per-leg column names"))?;
        let mut drives = Vec::new();
        for name in &f.joints.names {
            let d = f.drives.get(name).ok_or_else(|| c.err(&format!("drives.{name}"), "<missing>", "missing table", format!("a [drives.<joint>] table for each of {}", f.joints.names.join(", "))))?;
            let field = |rest: &str| format!("drives.{name}.{rest}");
            let control = match (&d.servo, &d.pi) {
                (Some(s), None) => {
                    c.check(s.punch <= s.torque_limit, &field("servo.punch"), s.punch, &format!("a duty in [0, torque_limit = {}]", s.torque_limit))?;
                    DriveControl::Servo(s.clone())
                }
                (None, Some(p)) => DriveControl::Pi(p.clone()),
                _ => return Err(c.err(&format!("drives.{name}"), if d.servo.is_some() { "servo and pi" } else { "neither servo nor pi" }, "not one control", "exactly one of [drives.<joint>.servo] (a position servo) or [drives.<joint>.pi] (the master's PI through an H-bridge)")),
            };
            drives.push(Drive { gear_ratio: d.gear_ratio, motor: d.motor.clone(), friction: d.friction.clone(), control });
        }
        if let Some(extra) = f.drives.keys().find(|k| !f.joints.names.contains(k)) {
            return Err(c.err(&format!("drives.{extra}"), format!("[drives.{extra}]"), "no such joint", format!("one table per joint of joints.names: {}", f.joints.names.join(", "))));
        }
        let monte_carlo = f.monte_carlo.as_ref().map(|m| monte_carlo(c, m, &f.joints.names)).transpose()?;
        let mut legs: [SerialLeg; LEG_COUNT] = legs.try_into().expect("six legs");
        crate::description::urdf::number_serial_legs(&mut legs).map_err(|problem| c.err("legs", "the leg mounts", &problem, "three legs on each side (y > 0 left, y < 0 right) in the order 0, 2, 4 on the left from front to rear, 1, 3, 5 on the right"))?;
        let robot = SerialRobot {
            name: f.name.clone(),
            origin: c.file.to_string(),
            hexapod: SerialHexapod { name: f.name.clone(), base, legs },
            joints,
            drives: drives.try_into().expect("three drives"),
            period: f.controller.period_s,
            supply_voltage: f.controller.supply_voltage_v,
            ground: f.ground.clone(),
            monte_carlo,
        };
        check_one_drive_kind(&robot, c)?;
        Ok(robot)
    }

    /// The drive of joint k = 3 leg + j.
    pub fn drive(&self, k: usize) -> &Drive {
        &self.drives[k % 3]
    }

    /// The range of joint k = 3 leg + j (rad or m).
    pub fn joint_range(&self, k: usize) -> (f64, f64) {
        let j = &self.hexapod.legs[k / 3].joints[k % 3];
        (j.lower, j.upper)
    }

    /// The nominal voltage of the motors (the lowest).
    pub fn nominal_voltage(&self) -> f64 {
        self.drives.iter().map(|d| d.motor.nominal_voltage_v).fold(f64::INFINITY, f64::min)
    }

    /// The ground of `[ground]` with the feet's sphere radius, the supply, digital control.
    pub fn model_options(&self, friction: FrictionModel) -> ModelOptions {
        let g = &self.ground;
        ModelOptions {
            friction,
            load_dependence: false,
            inductance: false,
            ground: GroundContact { k_gnd: g.k_gnd_n_per_m_pk, d_gnd: g.d_gnd_ns_per_m_pd1, p_k: g.p_k, p_d: g.p_d, mu: g.mu, v_glim: g.v_glim_m_per_s, foot_radius: self.hexapod.legs[0].foot_radius },
            supply_voltage: self.supply_voltage,
            control: JointControl::Digital,
            stand: false,
            foot_load: [0.0; 6],
        }
    }

    /// The PI gains of joint k: the PI drive's, or for a servo the gain of its law's linear
    /// part with no integral action (what the master's PI stands for when it is not used).
    pub fn pi_gains(&self, k: usize) -> PiGains {
        let d = self.drive(k);
        match &d.control {
            DriveControl::Pi(p) => PiGains { k: p.k, t_i: p.t_i_s },
            DriveControl::Servo(_) => PiGains { k: self.servo(k).gain(self.supply_voltage), t_i: f64::INFINITY },
        }
    }

    /// Whether the motors are driven by position servos (the inputs are goal positions).
    pub fn has_servos(&self) -> bool {
        self.drives.iter().all(|d| matches!(d.control, DriveControl::Servo(_)))
    }

    /// The master's friction feed-forward for the servos ([`FrictionFeedForward`]; None
    /// without servos) at the control period `dt`: per joint the voltage whose stall torque is
    /// the drive's dry friction, τ_f,d R / (n k_t) (Eq. 4.4-4.6 at q' = 0), and the linear zone
    /// ε of its friction law.
    pub fn friction_feedforward(&self, dt: f64) -> Option<FrictionFeedForward> {
        let voltage = |k: usize| {
            let d = self.drive(k);
            d.friction.tau_f_d * d.motor.resistance_ohm / (d.gear_ratio * d.motor.torque_constant_nm_per_a)
        };
        self.has_servos().then(|| FrictionFeedForward::new(std::array::from_fn(|k| self.servo(k)), std::array::from_fn(voltage), std::array::from_fn(|k| self.drive(k).friction.linear_zone), dt))
    }

    fn servo(&self, k: usize) -> PositionServo {
        let DriveControl::Servo(s) = &self.drive(k).control else { unreachable!("a servo drive") };
        let (lower, upper) = self.joint_range(k);
        PositionServo {
            margin: s.compliance_margin_deg.to_radians(),
            slope: s.compliance_slope_deg.to_radians(),
            punch: s.punch,
            torque_limit: s.torque_limit,
            resolution: s.sensor_range_deg.to_radians() / s.sensor_counts,
            lower,
            upper,
        }
    }

    /// The rotor of each joint of a leg: its inertia turning at n q.
    pub fn rotors(&self) -> [Rotor; 3] {
        std::array::from_fn(|j| Rotor { inertia: self.drives[j].motor.rotor_inertia_kg_m2, ratio: self.drives[j].gear_ratio })
    }

    /// The parts of the robot model: the multibody of the legs with the motor rotors, the DC
    /// motors (Eq. 4.4), the joint friction of `options.friction`, the joint ranges as strokes,
    /// the position sensors and the servos.
    pub fn parts(&self, options: &ModelOptions) -> RobotParts {
        let mechanics = self.hexapod.mechanics_with(&self.rotors()).expect("a validated description builds a valid multibody model");
        let motor = |k: usize| {
            let d = self.drive(k);
            let r_bridge = match &d.control {
                DriveControl::Pi(p) => p.bridge_resistance_ohm,
                // INTERPRETATION: a servo's driver resistance is not published; it is in the
                // winding resistance identified at stall (the servo's figures are at its
                // connector).
                DriveControl::Servo(_) => 0.0,
            };
            DcMotor { r: d.motor.resistance_ohm, r_bridge, l: d.motor.inductance_mh * 1e-3, k_t: d.motor.torque_constant_nm_per_a, n: d.gear_ratio, inductance: options.inductance }
        };
        let encoder = |k: usize| {
            let d = self.drive(k);
            match &d.control {
                DriveControl::Pi(p) => Encoder { counts_per_rev: p.encoder_counts_per_rev as u32, n: d.gear_ratio },
                // sensor_counts over sensor_range_deg of the joint: counts per turn of a shaft
                // turning 360/range times the joint.
                DriveControl::Servo(s) => Encoder { counts_per_rev: s.sensor_counts as u32, n: 360.0 / s.sensor_range_deg },
            }
        };
        RobotParts {
            multibody: mechanics.model,
            feet: mechanics.feet,
            joints: self.joints.clone(),
            motors: std::array::from_fn(motor),
            friction: std::array::from_fn(|k| friction_element(&self.drive(k).friction, options.friction)),
            strokes: std::array::from_fn(|k| {
                let (lo, hi) = self.joint_range(k);
                lo..=hi
            }),
            pi_gains: std::array::from_fn(|k| self.pi_gains(k)),
            encoders: std::array::from_fn(encoder),
            servos: self.has_servos().then(|| std::array::from_fn(|k| self.servo(k))),
            series: None,
        }
    }

    /// The total mass (kg).
    pub fn total_mass_kg(&self) -> f64 {
        self.hexapod.base.mass + self.hexapod.legs.iter().flat_map(|l| l.links.iter()).map(|l| l.mass).sum::<f64>()
    }
}

/// The friction element of a drive under the model's friction choice (Eq. 6.1, Eq. 3.83-3.87
/// with a dry steady state, as the rotation joints of Section 6.1, or the efficiency law on the
/// no-load friction of Eq. 6.1).
fn friction_element(f: &FrictionSpec, model: FrictionModel) -> FrictionElement {
    let dry_viscous = DryViscous { tau_f_d_plus: f.tau_f_d, tau_f_d_minus: -f.tau_f_d, f_v_plus: f.f_v, f_v_minus: f.f_v, epsilon: f.linear_zone };
    let law = match model {
        FrictionModel::None => JointFriction::None,
        FrictionModel::DryViscous => JointFriction::DryViscous(dry_viscous),
        FrictionModel::Efficiency => JointFriction::Efficiency(Efficiency { eta_forward: f.eta_forward, eta_backward: f.eta_backward, no_load: dry_viscous }),
        FrictionModel::LuGre => JointFriction::LuGre(LuGre { sigma_0: f.sigma_0, sigma_1: f.sigma_1, v_d: f.v_d, f_v_plus: f.f_v, f_v_minus: f.f_v, steady: SteadyState::Dry { tau_f_d_plus: f.tau_f_d, tau_f_d_minus: -f.tau_f_d } }),
    };
    FrictionElement::new(law)
}

/// Validates `[monte_carlo]`: a table per joint of `names` at most, and something drawn.
fn monte_carlo(c: &Ctx, m: &SerialMonteCarloTable, names: &[String; 3]) -> Result<SerialMonteCarlo> {
    if let Some(extra) = m.friction.keys().find(|k| !names.contains(k)) {
        return Err(c.err(&format!("monte_carlo.friction.{extra}"), format!("[monte_carlo.friction.{extra}]"), "no such joint", format!("a table per joint of joints.names: {}", names.join(", "))));
    }
    let friction: [FrictionDistributionTable; 3] = std::array::from_fn(|j| m.friction.get(&names[j]).cloned().unwrap_or_default());
    if friction.iter().all(|t| t.drawn().next().is_none()) {
        return Err(c.err("monte_carlo.friction", "no Gaussian", "nothing to draw", format!("a [monte_carlo.friction.<joint>] table with tau_f_d and/or f_v = {{ mu = ..., sigma = ... }} for a joint of {}", names.join(", "))));
    }
    Ok(SerialMonteCarlo { runs_per_velocity: m.runs_per_velocity, truncation_sigmas: m.truncation_sigmas, velocities_m_per_s: m.velocities_m_per_s.clone(), friction })
}

/// Checks that every drive is of one kind: position servos on some joints and the master's
/// voltages on others would need two kinds of inputs.
fn check_one_drive_kind(robot: &SerialRobot, c: &Ctx) -> Result<()> {
    let servos = robot.drives.iter().filter(|d| matches!(d.control, DriveControl::Servo(_))).count();
    if servos != 0 && servos != JOINTS / LEG_COUNT {
        return Err(c.err("drives", format!("{servos} servo drive(s) of 3"), "mixed drives", "servo drives on every joint or on none"));
    }
    Ok(())
}

/// The mechanism tables of a serial description (`name`, `leg_mechanism`, `[joints]`, `[base]`,
/// the six `[[legs]]` in the leg numbering) for `hexapod` with the joint names `names`: what
/// `hexadyn import-urdf` writes before the drives. Numbers are written in Rust's shortest
/// round-trip form, the joint origins' rotations as URDF roll, pitch, yaw.
pub fn mechanism_toml(hexapod: &SerialHexapod, names: &[String; 3]) -> String {
    let v = |a: &[f64]| format!("[{}]", a.iter().map(|x| format!("{x:?}")).collect::<Vec<_>>().join(", "));
    let link = |l: &Link| {
        let i = &l.inertia;
        format!("mass_kg = {:?}\ncom_m = {}\ninertia_kg_m2 = {}\n", l.mass, v(l.com.as_slice()), v(&[i[(0, 0)], i[(1, 1)], i[(2, 2)], i[(0, 1)], i[(0, 2)], i[(1, 2)]]))
    };
    let quoted = |s: &str| toml::Value::String(s.to_string()).to_string();
    let mut out = format!("name = {}\nleg_mechanism = \"serial\"\n\n[joints]\nnames = [{}]\n\n[base]\n{}", quoted(&hexapod.name), names.iter().map(|n| quoted(n)).collect::<Vec<_>>().join(", "), link(&hexapod.base));
    for (l, leg) in hexapod.legs.iter().enumerate() {
        out += &format!("\n# Leg {l}\n[[legs]]\nfoot_m = {}\nfoot_radius_m = {:?}\n", v(leg.foot.as_slice()), leg.foot_radius);
        for (joint, body) in leg.joints.iter().zip(&leg.links) {
            let (roll, pitch, yaw) = nalgebra::Rotation3::from_matrix_unchecked(joint.origin.rotation).euler_angles();
            let kind = match joint.kind {
                JointKind::Revolute => "revolute",
                JointKind::Prismatic => "prismatic",
            };
            out += &format!(
                "\n[[legs.joints]]\nname = {}\nkind = \"{kind}\"\norigin_xyz_m = {}\norigin_rpy_rad = {}\naxis = {}\nlower = {:?}\nupper = {:?}\n[legs.joints.link]\n{}",
                quoted(&joint.name),
                v(joint.origin.translation.as_slice()),
                v(&[roll, pitch, yaw]),
                v(joint.axis.as_slice()),
                joint.lower,
                joint.upper,
                link(body)
            );
        }
    }
    out
}

impl SerialRobot {
    /// The whole description as TOML ([`mechanism_toml`], then the drives, the controller and
    /// the ground): read back, it is the same robot.
    pub fn to_toml(&self) -> String {
        let names: [String; 3] = std::array::from_fn(|j| self.joints.name(j).to_string());
        let mut out = mechanism_toml(&self.hexapod, &names);
        for (name, d) in names.iter().zip(&self.drives) {
            let m = &d.motor;
            let f = &d.friction;
            out += &format!(
                "\n[drives.{name}]\ngear_ratio = {:?}\n[drives.{name}.motor]\nresistance_ohm = {:?}\ntorque_constant_nm_per_a = {:?}\ninductance_mh = {:?}\nrotor_inertia_kg_m2 = {:?}\nnominal_voltage_v = {:?}\n[drives.{name}.friction]\ntau_f_d = {:?}\nf_v = {:?}\nlinear_zone = {:?}\nsigma_0 = {:?}\nsigma_1 = {:?}\nv_d = {:?}\n",
                d.gear_ratio, m.resistance_ohm, m.torque_constant_nm_per_a, m.inductance_mh, m.rotor_inertia_kg_m2, m.nominal_voltage_v, f.tau_f_d, f.f_v, f.linear_zone, f.sigma_0, f.sigma_1, f.v_d
            );
            out += &match &d.control {
                DriveControl::Servo(s) => format!(
                    "[drives.{name}.servo]\ncompliance_margin_deg = {:?}\ncompliance_slope_deg = {:?}\npunch = {:?}\ntorque_limit = {:?}\nsensor_counts = {:?}\nsensor_range_deg = {:?}\n",
                    s.compliance_margin_deg, s.compliance_slope_deg, s.punch, s.torque_limit, s.sensor_counts, s.sensor_range_deg
                ),
                DriveControl::Pi(p) => format!("[drives.{name}.pi]\nk = {:?}\nt_i_s = {:?}\nbridge_resistance_ohm = {:?}\nencoder_counts_per_rev = {:?}\n", p.k, p.t_i_s, p.bridge_resistance_ohm, p.encoder_counts_per_rev),
            };
        }
        let g = &self.ground;
        out += &format!("\n[controller]\nperiod_s = {:?}\nsupply_voltage_v = {:?}\n", self.period, self.supply_voltage);
        out += &format!(
            "\n[ground]\np_k = {:?}\np_d = {:?}\nk_gnd_n_per_m_pk = {:?}\nd_gnd_ns_per_m_pd1 = {:?}\nmu = {:?}\nv_glim_m_per_s = {:?}\n",
            g.p_k, g.p_d, g.k_gnd_n_per_m_pk, g.d_gnd_ns_per_m_pd1, g.mu, g.v_glim_m_per_s
        );
        if let Some(m) = &self.monte_carlo {
            let v = m.velocities_m_per_s.iter().map(|x| format!("{x:?}")).collect::<Vec<_>>().join(", ");
            out += &format!("\n[monte_carlo]\nruns_per_velocity = {}\ntruncation_sigmas = {:?}\nvelocities_m_per_s = [{v}]\n", m.runs_per_velocity, m.truncation_sigmas);
            for (name, t) in names.iter().zip(&m.friction) {
                if t.drawn().next().is_some() {
                    out += &format!("[monte_carlo.friction.{name}]\n");
                    for (key, g) in t.drawn() {
                        out += &format!("{key} = {{ mu = {:?}, sigma = {:?} }}\n", g.mu, g.sigma);
                    }
                }
            }
        }
        out
    }

    /// The robot `hexapod` (from a URDF) with the joint names `names` and this robot's drives,
    /// controller and ground, joint by joint in order: what `hexadyn import-urdf` writes.
    pub fn with_mechanism(&self, hexapod: SerialHexapod, names: [String; 3]) -> std::result::Result<SerialRobot, String> {
        let kinds = std::array::from_fn(|k| hexapod.legs[0].joints[k].kind);
        let joints = LegJoints::new(names, kinds).map_err(|e| e.to_string())?;
        Ok(SerialRobot { name: hexapod.name.clone(), hexapod, joints, ..self.clone() })
    }
}

impl SerialRobot {
    /// The robot as URDF (the inverse of `hexadyn import-urdf`): `base_link` and per joint a
    /// link `<joint name>_link` with its inertial (centre of mass and tensor in the link axes),
    /// the joints with their origins, axes and ranges, the effort limit the drive's stall
    /// torque n k_t L V / R and the velocity limit its no-load speed V / (n k_t) at the supply,
    /// and the foot sphere as the last link's collision. Read back by the importer, it is the
    /// same mechanism.
    pub fn to_urdf(&self) -> String {
        let v = |a: &[f64]| a.iter().map(|x| format!("{x:?}")).collect::<Vec<_>>().join(" ");
        let escape = |s: &str| quick_xml::escape::escape(s).into_owned();
        let inertial = |l: &Link| {
            let i = &l.inertia;
            format!(
                "    <inertial>\n      <origin xyz=\"{}\" rpy=\"0 0 0\"/>\n      <mass value=\"{:?}\"/>\n      <inertia ixx=\"{:?}\" ixy=\"{:?}\" ixz=\"{:?}\" iyy=\"{:?}\" iyz=\"{:?}\" izz=\"{:?}\"/>\n    </inertial>\n",
                v(l.com.as_slice()),
                l.mass,
                i[(0, 0)],
                i[(0, 1)],
                i[(0, 2)],
                i[(1, 1)],
                i[(1, 2)],
                i[(2, 2)]
            )
        };
        let mut out = format!("<?xml version=\"1.0\"?>\n<!-- {} written by hexadyn from its robot description -->\n<robot name=\"{}\">\n  <link name=\"base_link\">\n{}  </link>\n", escape(&self.name), escape(&self.name), inertial(&self.hexapod.base));
        for leg in &self.hexapod.legs {
            let mut parent = "base_link".to_string();
            for (k, (joint, link)) in leg.joints.iter().zip(&leg.links).enumerate() {
                let d = &self.drives[k];
                let gain = d.gear_ratio * d.motor.torque_constant_nm_per_a;
                let limit = match &d.control {
                    DriveControl::Servo(s) => s.torque_limit,
                    DriveControl::Pi(_) => 1.0,
                };
                let (effort, velocity) = (gain * limit * self.supply_voltage / d.motor.resistance_ohm, self.supply_voltage / gain);
                let (roll, pitch, yaw) = nalgebra::Rotation3::from_matrix_unchecked(joint.origin.rotation).euler_angles();
                let kind = match joint.kind {
                    JointKind::Revolute => "revolute",
                    JointKind::Prismatic => "prismatic",
                };
                let child = format!("{}_link", joint.name);
                out += &format!(
                    "  <joint name=\"{}\" type=\"{kind}\">\n    <parent link=\"{}\"/>\n    <child link=\"{}\"/>\n    <origin xyz=\"{}\" rpy=\"{}\"/>\n    <axis xyz=\"{}\"/>\n    <limit lower=\"{:?}\" upper=\"{:?}\" effort=\"{effort:?}\" velocity=\"{velocity:?}\"/>\n  </joint>\n",
                    escape(&joint.name),
                    escape(&parent),
                    escape(&child),
                    v(joint.origin.translation.as_slice()),
                    v(&[roll, pitch, yaw]),
                    v(joint.axis.as_slice()),
                    joint.lower,
                    joint.upper
                );
                let foot = if k == 2 { format!("    <collision>\n      <origin xyz=\"{}\" rpy=\"0 0 0\"/>\n      <geometry><sphere radius=\"{:?}\"/></geometry>\n    </collision>\n", v(leg.foot.as_slice()), leg.foot_radius) } else { String::new() };
                out += &format!("  <link name=\"{}\">\n{}{foot}  </link>\n", escape(&child), inertial(link));
                parent = child;
            }
        }
        out + "</robot>\n"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fields::struct_fields;

    /// docs/robot-format.md documents every key of the loader's tables, and no other: each
    /// table's keys are the first column of the page's section for it.
    #[test]
    fn the_format_page_documents_every_key() {
        let page = include_str!("../../../../docs/robot-format.md");
        let tables: [(&str, &[&str]); 13] = [
            ("## Top level", struct_fields::<SerialDescriptionFile>()),
            ("## `[joints]`", struct_fields::<SerialJointsTable>()),
            ("## `[base]`", struct_fields::<LinkTable>()),
            ("## `[[legs]]`", struct_fields::<LegTable>()),
            ("### `[[legs.joints]]`", struct_fields::<JointTable>()),
            ("## `[drives.<joint name>]`", struct_fields::<DriveTable>()),
            ("### `[drives.<joint>.motor]`", struct_fields::<MotorSpec>()),
            ("### `[drives.<joint>.friction]`", struct_fields::<FrictionSpec>()),
            ("### `[drives.<joint>.servo]`", struct_fields::<ServoSpec>()),
            ("### `[drives.<joint>.pi]`", struct_fields::<PiSpec>()),
            ("## `[controller]`", struct_fields::<SerialControllerTable>()),
            ("## `[monte_carlo]`", struct_fields::<SerialMonteCarloTable>()),
            ("### `[monte_carlo.friction.<joint>]`", struct_fields::<FrictionDistributionTable>()),
        ];
        let ground = ("## `[ground]`", struct_fields::<GroundTable>());
        let section_keys = |heading: &str| -> Vec<String> {
            let start = page.find(heading).unwrap_or_else(|| panic!("no section {heading}"));
            let rest = &page[start + heading.len()..];
            let end = rest.find("\n#").unwrap_or(rest.len());
            rest[..end]
                .lines()
                .filter_map(|l| l.strip_prefix("| `"))
                .flat_map(|l| l.split(" |").next().unwrap_or("").split(", ").map(|k| k.trim_matches('`').to_string()).collect::<Vec<_>>())
                .collect()
        };
        for (heading, fields) in tables.iter().chain([&ground]) {
            let mut documented = section_keys(heading);
            documented.sort();
            // The tables of tables are documented in their own sections.
            let mut expected: Vec<String> = fields.iter().filter(|f| !["joints", "base", "legs", "drives", "controller", "ground", "monte_carlo", "motor", "friction", "servo", "pi"].contains(f) || (*heading == "## `[[legs]]`" && **f == "joints")).map(|f| f.to_string()).collect();
            expected.sort();
            assert_eq!(documented, expected, "{heading}");
        }
    }
}
