//! [`RobotDescription`]: the robot parameter file (`robots/amru5.toml`) as Rust data.
//!
//! The structs mirror the TOML tables one to one, with the thesis units in the field names
//! (`resistance_ohm`, `inductance_mh`, `angle_deg`, ...). Every struct denies unknown fields.
//! After deserialization every field is validated ([`RobotDescription::from_str`]); errors
//! name the file, the dotted field path (`motor.resistance_ohm`, `legs[2].angle_deg`,
//! `friction.q_v.tau_f_d_plus_n.mu[3]`), the value and what is allowed, with the line when
//! it is known.
//!
//! SI accessors convert the thesis units (degrees, mH, g cm^2) and assemble per-leg friction
//! parameters in joint units (N or Nm, N s/m or Nm s/rad) with the rules of Section 6.1
//! ([`RobotDescription::friction`]). All friction values of Chapters 5-6 are joint-side
//! already; [`RobotDescription::joint_torque_per_ampere`] gives the k_t n factor of Eq. 5.17
//! for converting motor currents.
//!
//! ```
//! use hexadyn::description::RobotDescription;
//! use hexadyn::hexapod::Joint;
//! let robot = RobotDescription::amru5();
//! assert_eq!(robot.legs.len(), 6);
//! let f = robot.friction(0, Joint::Vertical);
//! assert!(f.tau_f_d_plus > 0.0 && f.tau_f_d_minus < 0.0);
//! ```

use std::collections::BTreeSet;
use std::f64::consts::PI;
use std::fmt;
use std::ops::Range;
use std::path::Path;

use serde::de::{self, Deserializer, Visitor};
use serde::Deserialize;

use crate::hexapod::{Joint, LEG_COUNT};

mod hexapod_parameters;

/// The shipped AMRU5 description (`robots/amru5.toml`), embedded at compile time.
pub const AMRU5_TOML: &str = include_str!("../../../../robots/amru5.toml");

/// Name used in error messages for the embedded file.
const AMRU5_ORIGIN: &str = "robots/amru5.toml";

// =============================================================================================
// Errors
// =============================================================================================

/// A robot description that could not be read, parsed or validated.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DescriptionError {
    /// The file could not be read.
    #[error("{file}: cannot read the robot description: {reason}")]
    Io { file: String, reason: String },
    /// The text is not valid TOML.
    #[error("{file}:{line}:{column}: TOML syntax error: {message}")]
    Syntax { file: String, line: usize, column: usize, message: String },
    /// A field is missing, unknown, of the wrong type or out of its allowed range.
    #[error("{0}")]
    Field(Box<FieldError>),
}

/// The details of a [`DescriptionError::Field`].
#[derive(Clone, Debug, PartialEq)]
pub struct FieldError {
    pub file: String,
    /// 1-based line of the field in the file, when known.
    pub line: Option<usize>,
    /// Dotted path, e.g. `motor.resistance_ohm` or `legs[2].angle_deg`.
    pub field: String,
    /// The offending value as written (or `<missing>`).
    pub value: String,
    /// What is wrong (`out of range`, `unknown field`, `missing field`, `invalid type`...).
    pub problem: String,
    /// What would be accepted.
    pub allowed: String,
}

impl fmt::Display for FieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
        }
        write!(f, ": field `{}` = {}: {}; allowed: {}", self.field, self.value, self.problem, self.allowed)
    }
}

impl DescriptionError {
    fn field_error(
        file: &str,
        line: Option<usize>,
        field: String,
        value: String,
        problem: String,
        allowed: String,
    ) -> Self {
        DescriptionError::Field(Box::new(FieldError {
            file: file.to_string(),
            line,
            field,
            value,
            problem,
            allowed,
        }))
    }

    /// The file (or origin name) the error refers to.
    pub fn file(&self) -> &str {
        match self {
            DescriptionError::Io { file, .. } | DescriptionError::Syntax { file, .. } => file,
            DescriptionError::Field(e) => &e.file,
        }
    }

    /// The dotted field path, for field errors.
    pub fn field(&self) -> Option<&str> {
        match self {
            DescriptionError::Field(e) => Some(&e.field),
            _ => None,
        }
    }
}

type Result<T> = std::result::Result<T, DescriptionError>;

// =============================================================================================
// Raw mirror of the TOML file
// =============================================================================================

/// The whole robot description, mirroring `robots/amru5.toml`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RobotDescription {
    /// Robot name (`"AMRU5"`).
    pub name: String,
    /// The six legs, sorted by id after loading (NOTES.md, Fig. 2.14).
    pub legs: Vec<Leg>,
    /// Table 2.1, Table B.1.
    pub geometry: Geometry,
    /// Table B.2.
    pub inertia: Inertia,
    /// Table 3.1.
    pub reductions: Reductions,
    /// Table 3.4.
    pub motor: Motor,
    /// Sections 2.3.2, 4.4.3, 5.3, 6.4.
    pub driver: Driver,
    /// Table 3.3.
    pub ground: Ground,
    /// Table 4.1, Section 4.4.5.
    pub controller: Controller,
    /// Table 5.2.
    pub joint_ranges: JointRanges,
    /// Tables 5.3, 5.4, 5.5, 6.1 and the rules of Section 6.1.
    pub friction: Friction,
    /// Section 6.5, Table 6.7.
    pub monte_carlo: MonteCarlo,
    /// Where the description was read from (file path or origin name); not in the file.
    #[serde(skip)]
    pub origin: String,
}

/// One leg: its number and the direction of its q_r axis from the body centre.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Leg {
    /// Leg number 0..5 (0-2-4 on the left front to rear, 1-3-5 on the right).
    pub id: usize,
    /// Angle of the leg from x_b about z_b, degrees (NOTES.md: 0 at +30, 2 at +90, ...).
    pub angle_deg: f64,
}

/// Geometry, Table 2.1 and Table B.1 (metres).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Geometry {
    pub body: BodyGeometry,
    pub pantograph: Pantograph,
    pub chassis: ChassisOffsets,
    pub actuators: ActuatorOffsets,
}

/// Main body dimensions (Table B.1).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BodyGeometry {
    /// R_rot: body centre to the q_r axis of a leg.
    pub r_rot_m: f64,
    /// e_b: plate thickness of the main body.
    pub e_b_m: f64,
    /// H: gap between the two rings of the main body.
    pub ring_gap_h_m: f64,
}

/// Pantograph dimensions (Table 2.1, Table B.1, Eqs. B.1-B.2).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Pantograph {
    /// L_0 = AC, upper link.
    pub l_0_m: f64,
    /// L_1 = BD = CE, left link.
    pub l_1_m: f64,
    /// L_2 = DE = BC, lower link.
    pub l_2_m: f64,
    /// L_3 = CF, upper joint to foot.
    pub l_3_m: f64,
    /// c = AB.
    pub c_m: f64,
    /// e: thickness of the leg bodies.
    pub e_m: f64,
    /// h: joint-to-extremity distance of the bodies.
    pub h_m: f64,
    /// x_G_leg: centre of mass of the leg.
    pub x_g_leg_m: f64,
    /// L_G0: centre of mass 0 w.r.t. the bottom of the chassis.
    pub l_g0_m: f64,
    /// Eq. B.1: z_foot ~ -6 q_v (for checks).
    pub z_foot_per_q_v: f64,
    /// Eq. B.2: x_foot ~ 7 q_h (for checks).
    pub x_foot_per_q_h: f64,
}

/// Leg chassis offsets (Table B.1, Eq. 3.64).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ChassisOffsets {
    pub l_x1_m: f64,
    pub l_y1_m: f64,
    pub l_z1_m: f64,
    pub l_xc_m: f64,
    pub l_yc_m: f64,
    pub l_zc_m: f64,
}

/// Rotor body positions (Table B.1).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ActuatorOffsets {
    /// Main body CM to the q_r rotor, along the leg axis.
    pub l_x6_m: f64,
    /// C* to the q_v rotor.
    pub l_x7_m: f64,
    pub l_y7_m: f64,
    pub l_z7_m: f64,
    /// C* to the q_h rotor.
    pub l_x8_m: f64,
    pub l_y8_m: f64,
    pub l_z8_m: f64,
}

/// Masses and inertias, Table B.2.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Inertia {
    /// m_leg as printed (checked against the sum of its parts).
    pub leg_mass_kg: f64,
    /// m_tot as printed ("about 34 kg").
    pub total_mass_kg: f64,
    pub rho_duralumin_kg_m3: f64,
    pub rho_steel_kg_m3: f64,
    /// m_0, I^0.
    pub main_body: RigidBody,
    /// m_1, I^1 (body supporting the leg).
    pub chassis: RigidBody,
    /// m_2, I^2: pantograph link 0 (A-B-C).
    pub pantograph_upper: RigidBody,
    /// m_3, I^3: pantograph link 1 (B-D).
    pub pantograph_left: RigidBody,
    /// m_4, I^4: pantograph link 2 (D-E).
    pub pantograph_lower: RigidBody,
    /// m_5, I^5: pantograph link 3, the leg (C-E-F).
    pub pantograph_leg: RigidBody,
    /// m_rot, I_a^rot, I_e^rot.
    pub rotor: Rotor,
}

/// Mass and central principal inertias of one body (Table B.2).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RigidBody {
    pub mass_kg: f64,
    pub i_xx_kg_m2: f64,
    pub i_yy_kg_m2: f64,
    pub i_zz_kg_m2: f64,
}

impl RigidBody {
    /// Principal moments (I_xx, I_yy, I_zz) in kg m^2.
    pub fn principal_moments(&self) -> [f64; 3] {
        [self.i_xx_kg_m2, self.i_yy_kg_m2, self.i_zz_kg_m2]
    }
}

/// A motor rotor: axisymmetric body (Table B.2).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Rotor {
    pub mass_kg: f64,
    /// I_a^rot, about the shaft axis.
    pub i_axial_kg_m2: f64,
    /// I_e^rot, about any axis normal to the shaft.
    pub i_equatorial_kg_m2: f64,
}

/// Global reductions, Table 3.1: theta_motor_dot = n q_dot (Eq. 3.92).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Reductions {
    /// n_r (rad/rad).
    pub n_r: f64,
    /// n_v (rad/m).
    pub n_v_rad_per_m: f64,
    /// n_h (rad/m).
    pub n_h_rad_per_m: f64,
    pub components: ReductionComponents,
}

/// The transmission elements of Table 3.1.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ReductionComponents {
    pub gearbox_r: f64,
    /// Sprocket chain teeth (driven, driving) = 38:12.
    pub sprocket_r_teeth: Vec<u32>,
    pub gearbox_v: f64,
    pub gearbox_h: f64,
    pub ball_screw_rad_per_m: f64,
}

/// DC motor, Table 3.4 (the 18 motors are identical).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Motor {
    /// u_sat: nominal voltage, also the controller saturation (Section 4.3.4).
    pub nominal_voltage_v: f64,
    /// R.
    pub resistance_ohm: f64,
    /// L (mH).
    pub inductance_mh: f64,
    /// k_t (= k_v).
    pub torque_constant_nm_per_a: f64,
    /// J_r (g cm^2).
    pub rotor_inertia_g_cm2: f64,
    pub mass_kg: f64,
    pub no_load_speed_rpm: f64,
}

impl Motor {
    /// L in H.
    pub fn inductance_h(&self) -> f64 {
        self.inductance_mh * 1e-3
    }

    /// J_r in kg m^2 (1 g cm^2 = 1e-7 kg m^2).
    pub fn rotor_inertia_kg_m2(&self) -> f64 {
        self.rotor_inertia_g_cm2 * 1e-7
    }

    /// Speed without load in rad/s.
    pub fn no_load_speed_rad_per_s(&self) -> f64 {
        self.no_load_speed_rpm * 2.0 * PI / 60.0
    }
}

/// Motor drive electronics (Sections 2.3.2, 4.4.3, 5.3, 6.4).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Driver {
    /// On-board supply, "slightly superior to 12 V" (Section 4.4.3).
    pub supply_voltage_v: f64,
    /// Factor on the no-load speed used in the controller design (Section 4.4.3).
    pub velocity_derating: f64,
    /// Per conducting MOSFET of the LMD18200 (Section 6.4).
    pub mosfet_resistance_ohm: f64,
    pub mosfets_in_series: u32,
    pub diode_drop_v: f64,
    pub pwm_bits: u32,
    /// Below this voltage the H-bridge does not switch (Section 5.3).
    pub dead_band_v: f64,
    pub current_sensor_range_a: f64,
}

impl Driver {
    /// Series resistance of the H-bridge added to the armature: 2 x 0.3 Ohm (Section 6.4).
    pub fn series_resistance_ohm(&self) -> f64 {
        self.mosfet_resistance_ohm * f64::from(self.mosfets_in_series)
    }
}

/// Foot/ground contact, Table 3.3 (Eqs. 3.72-3.73).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Ground {
    /// p_K.
    pub p_k: f64,
    /// p_D.
    pub p_d: f64,
    /// K_gnd, N/m^p_K.
    pub k_gnd_n_per_m_pk: f64,
    /// D_gnd, N s/m^(p_D+1).
    pub d_gnd_ns_per_m_pd1: f64,
    /// Coulomb coefficient.
    pub mu: f64,
    /// v_glim, m/s.
    pub v_glim_m_per_s: f64,
}

/// Joint PI controllers, Table 4.1 and Section 4.4.5.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Controller {
    /// Control sampling time (s).
    pub period_s: f64,
    /// Encoder impulses per motor revolution.
    pub encoder_impulses_per_rev: u32,
    pub q_r: RotationalPi,
    pub q_v: LinearPi,
    pub q_h: LinearPi,
}

/// PI gains of q_r (Table 4.1).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RotationalPi {
    pub k_v_per_rad: f64,
    pub t_i_s: f64,
    pub bandwidth_hz: f64,
    pub phase_margin_deg: f64,
    pub overshoot_percent: f64,
}

/// PI gains of q_v or q_h (Table 4.1).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LinearPi {
    pub k_v_per_m: f64,
    pub t_i_s: f64,
    pub bandwidth_hz: f64,
    pub phase_margin_deg: f64,
    pub overshoot_percent: f64,
}

/// SI PI gains of one joint: u = K (e + 1/T_i int e) (Eq. 4.18).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PiGains {
    /// K in V/rad (q_r) or V/m (q_v, q_h).
    pub k: f64,
    /// T_i in s.
    pub t_i: f64,
}

/// Joint ranges, Table 5.2.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct JointRanges {
    pub q_r_deg: Interval,
    pub q_v_m: Interval,
    pub q_h_m: Interval,
    pub identification_velocities: IdentificationVelocities,
}

/// A closed interval [min, max].
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Interval {
    pub min: f64,
    pub max: f64,
}

/// Constant-velocity sweeps of the friction identification (Table 5.2, lower half).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct IdentificationVelocities {
    pub q_r_dot_deg_per_s: Sweep,
    pub q_v_dot_mm_per_s: Sweep,
    pub q_h_dot_mm_per_s: Sweep,
}

/// min, max and increment of a sweep.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    pub min: f64,
    pub max: f64,
    pub increment: f64,
}

/// Section 6.1: what to do with the negative (non-physical) viscous coefficients.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
pub enum NegativeViscousRule {
    /// Force them to zero (the thesis rule).
    #[serde(rename = "zero")]
    Zero,
    /// Keep the measured value.
    #[serde(rename = "keep")]
    Keep,
}

/// Section 6.1: value of a stiction parameter that was not identified ("-").
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
pub enum MissingStictionRule {
    /// The unloaded dry friction of Table 5.3 for the same leg and sense.
    #[serde(rename = "unloaded_dry")]
    UnloadedDry,
}

/// Value of the a_1^- coefficients, whose row of Table 5.5 is lost in the extracted text.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
pub enum MissingA1MinusRule {
    /// Drop the linear term (quadratic-only fit, as Section 5.4 does for some legs).
    #[serde(rename = "zero")]
    Zero,
    /// a_1^- = -a_1^+ (symmetric load dependence).
    #[serde(rename = "mirror_a1_plus")]
    MirrorA1Plus,
}

/// Joint friction (Chapter 5, Section 6.1).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Friction {
    pub negative_viscous: NegativeViscousRule,
    pub missing_stiction: MissingStictionRule,
    /// Load case of Table 5.4 used for the vertical stiction in simulation (10 kg).
    pub vertical_stiction_load_kg: f64,
    pub missing_a1_minus: MissingA1MinusRule,
    pub lugre: LuGre,
    pub q_r: RotationalFriction,
    pub q_v: VerticalFriction,
    pub q_h: HorizontalFriction,
}

/// LuGre parameters, Table 6.1, Eqs. 3.84 and 6.1 (same numbers for the three joint kinds;
/// units N/m, N s/m, m/s for q_v and q_h, Nm/rad, Nm s/rad, rad/s for q_r).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LuGre {
    /// sigma_0, bristle stiffness (1e9, NOTES.md).
    pub sigma_0: f64,
    /// sigma_1, bristle damping.
    pub sigma_1: f64,
    /// Stribeck velocity of the vertical joint (m/s).
    pub q_st_v_m_per_s: f64,
    /// v_d of Eq. 3.84.
    pub v_d: f64,
    /// delta_d of Eq. 3.84.
    pub delta_d: f64,
    /// epsilon of Eq. 6.1.
    pub dry_viscous_epsilon: f64,
}

/// Mean and standard deviation per leg (arrays of six, indexed by leg).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PerLeg {
    pub mu: Vec<f64>,
    pub sigma: Vec<f64>,
}

/// Like [`PerLeg`], with `"-"` allowed where the thesis gives no value.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PerLegMaybe {
    pub mu: Vec<Measured>,
    pub sigma: Vec<Measured>,
}

/// A number, or `"-"` for a value the thesis does not give.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Measured {
    Value(f64),
    Missing,
}

impl Measured {
    pub fn value(self) -> Option<f64> {
        match self {
            Measured::Value(v) => Some(v),
            Measured::Missing => None,
        }
    }
}

impl fmt::Display for Measured {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Measured::Value(v) => write!(f, "{v}"),
            Measured::Missing => f.write_str("\"-\""),
        }
    }
}

impl<'de> Deserialize<'de> for Measured {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Measured;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a number or \"-\" (value not given by the thesis)")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> std::result::Result<Measured, E> {
                Ok(Measured::Value(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> std::result::Result<Measured, E> {
                Ok(Measured::Value(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> std::result::Result<Measured, E> {
                Ok(Measured::Value(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> std::result::Result<Measured, E> {
                if v == "-" {
                    Ok(Measured::Missing)
                } else {
                    Err(E::invalid_value(de::Unexpected::Str(v), &self))
                }
            }
        }
        d.deserialize_any(V)
    }
}

/// Table 5.3, rotational joints (Nm, Nm s/rad).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RotationalFriction {
    pub tau_f_d_plus_nm: PerLeg,
    pub f_v_plus_nms: PerLeg,
    pub tau_f_d_minus_nm: PerLeg,
    pub f_v_minus_nms: PerLeg,
}

/// Table 5.3 and Table 5.4, vertical joints (N, N s/m).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct VerticalFriction {
    pub tau_f_d_plus_n: PerLeg,
    pub f_v_plus_ns_per_m: PerLeg,
    pub tau_f_d_minus_n: PerLeg,
    pub f_v_minus_ns_per_m: PerLeg,
    /// Table 5.4, one entry per foot load.
    pub stiction: Vec<StictionCase>,
}

/// Breakaway forces of the vertical joints for one foot load (Table 5.4, N).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StictionCase {
    pub load_kg: f64,
    pub tau_f_s_plus_n: PerLegMaybe,
    pub tau_f_s_minus_n: PerLegMaybe,
}

/// Table 5.3 and Table 5.5, horizontal joints (N, N s/m).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct HorizontalFriction {
    pub tau_f_d_plus_n: PerLeg,
    pub f_v_plus_ns_per_m: PerLeg,
    pub tau_f_d_minus_n: PerLeg,
    pub f_v_minus_ns_per_m: PerLeg,
    pub load_dependence: LoadDependence,
}

/// Table 5.5: coefficients of Eq. 5.12 (load x in kg).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LoadDependence {
    pub a_2_plus_n_per_kg2: PerLeg,
    pub a_2_minus_n_per_kg2: PerLeg,
    pub a_1_plus_n_per_kg: PerLegMaybe,
    pub a_1_minus_n_per_kg: PerLegMaybe,
}

/// Monte Carlo friction distributions, Section 6.5 and Table 6.7.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MonteCarlo {
    pub runs_per_velocity: u32,
    /// Samples outside +-truncation_sigmas sigma are redrawn.
    pub truncation_sigmas: f64,
    pub velocities_m_per_s: Vec<f64>,
    pub excluded_legs_a_2_plus: Vec<usize>,
    pub excluded_legs_a_2_minus: Vec<usize>,
    pub excluded_legs_a_1_plus: Vec<usize>,
    pub excluded_legs_a_1_minus: Vec<usize>,
    pub q_r: MonteCarloRotation,
    pub q_v: MonteCarloVertical,
    pub q_h: MonteCarloHorizontal,
}

/// A Gaussian distribution N(mu, sigma^2).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Gaussian {
    pub mu: f64,
    pub sigma: f64,
}

/// Table 6.7, rotation (Nm, Nm s/rad).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MonteCarloRotation {
    pub tau_f_d_plus_nm: Gaussian,
    pub f_v_plus_nms: Gaussian,
    pub tau_f_d_minus_nm: Gaussian,
    pub f_v_minus_nms: Gaussian,
}

/// Table 6.7, vertical (N, N s/m).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MonteCarloVertical {
    pub tau_f_d_plus_n: Gaussian,
    pub f_v_plus_ns_per_m: Gaussian,
    pub tau_f_d_minus_n: Gaussian,
    pub f_v_minus_ns_per_m: Gaussian,
}

/// Table 6.7, horizontal (N; viscous neglected).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MonteCarloHorizontal {
    pub tau_f_d_plus_n: Gaussian,
    pub tau_f_d_minus_n: Gaussian,
}

// =============================================================================================
// SI views
// =============================================================================================

/// Friction parameters of one joint of one leg, in joint units (N or Nm; N s/m or Nm s/rad),
/// after the rules of Section 6.1. "+" values hold for q_dot >= 0, "-" for q_dot < 0; the
/// minus dry and breakaway values are negative, the viscous coefficients are slopes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointFriction {
    pub leg: usize,
    pub joint: Joint,
    /// tau_f_d^+, dry friction (Table 5.3).
    pub tau_f_d_plus: f64,
    /// tau_f_d^- (< 0).
    pub tau_f_d_minus: f64,
    /// tau_f_s^+, breakaway: Table 5.4 at `vertical_stiction_load_kg` for q_v (unloaded dry
    /// where not identified); equal to the dry friction for q_r and q_h, whose g(q_dot) has no
    /// Stribeck term (Eqs. 5.4, 6.2-6.3, 6.5).
    pub tau_f_s_plus: f64,
    /// tau_f_s^- (< 0).
    pub tau_f_s_minus: f64,
    /// f_v^+, viscous coefficient (negative values forced to 0 under the Section 6.1 rule).
    pub f_v_plus: f64,
    /// f_v^-.
    pub f_v_minus: f64,
    /// Viscous coefficients as measured (Table 5.3), before the rule.
    pub f_v_plus_measured: f64,
    pub f_v_minus_measured: f64,
    /// Stribeck velocity q_st (Table 6.1): Some for q_v only.
    pub q_st: Option<f64>,
    /// LuGre sigma_0, sigma_1, v_d, delta_d (Table 6.1, Eq. 3.84).
    pub sigma_0: f64,
    pub sigma_1: f64,
    pub v_d: f64,
    pub delta_d: f64,
    /// Linear-zone half width of the dry/viscous model (Eq. 6.1).
    pub epsilon: f64,
    /// Load dependence of the dry friction (Table 5.5, Eq. 5.12): Some for q_h only.
    pub load_dependence: Option<LoadCoefficients>,
}

/// Coefficients of Eq. 5.12 for one leg: tilde_tau_f_d = a_2 x^2 + a_1 x + a_0, x the load at
/// the foot in kg (a vertical foot force F in N corresponds to x = F / 9.81).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoadCoefficients {
    /// a_2^+ (N/kg^2).
    pub a_2_plus: f64,
    /// a_2^- (N/kg^2, <= 0).
    pub a_2_minus: f64,
    /// a_1^+ (N/kg).
    pub a_1_plus: f64,
    /// a_1^- (N/kg, <= 0), after the `missing_a1_minus` rule.
    pub a_1_minus: f64,
}

impl JointFriction {
    /// Dry friction under a foot load of `load_kg` (Eq. 5.12 with a_0 the unloaded dry
    /// friction, Section 6.4.4), as (tilde_tau_f_d^+, tilde_tau_f_d^-). Joints without a load
    /// dependence return the unloaded values.
    pub fn dry_under_load(&self, load_kg: f64) -> (f64, f64) {
        match self.load_dependence {
            Some(a) => (
                a.a_2_plus * load_kg * load_kg + a.a_1_plus * load_kg + self.tau_f_d_plus,
                a.a_2_minus * load_kg * load_kg + a.a_1_minus * load_kg + self.tau_f_d_minus,
            ),
            None => (self.tau_f_d_plus, self.tau_f_d_minus),
        }
    }
}

/// Monte Carlo distributions of the Eq. 5.12 coefficients, computed from Table 5.5 like
/// Table 6.7 was (mean and n-1 standard deviation of the leg means, excluded legs left out).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoadDependenceDistribution {
    pub a_2_plus: Option<Gaussian>,
    pub a_2_minus: Option<Gaussian>,
    pub a_1_plus: Option<Gaussian>,
    pub a_1_minus: Option<Gaussian>,
}

/// Mean and sample (n-1) standard deviation of the given values, skipping `excluded`
/// indices and missing values; None when fewer than two values remain.
pub fn across_legs(values: &[Option<f64>], excluded: &[usize]) -> Option<Gaussian> {
    let kept: Vec<f64> =
        values.iter().enumerate().filter(|(i, _)| !excluded.contains(i)).filter_map(|(_, v)| *v).collect();
    if kept.len() < 2 {
        return None;
    }
    let n = kept.len() as f64;
    let mu = kept.iter().sum::<f64>() / n;
    let var = kept.iter().map(|x| (x - mu).powi(2)).sum::<f64>() / (n - 1.0);
    Some(Gaussian { mu, sigma: var.sqrt() })
}

impl MonteCarlo {
    /// Distributions of a_2^+-, a_1^+- for the Monte Carlo runs with load influence
    /// (Section 6.5: "the same process is performed on polynomial coefficients").
    pub fn load_dependence_distribution(&self, table: &LoadDependence) -> LoadDependenceDistribution {
        let plain = |p: &PerLeg| p.mu.iter().map(|&v| Some(v)).collect::<Vec<_>>();
        let maybe = |p: &PerLegMaybe| p.mu.iter().map(|v| v.value()).collect::<Vec<_>>();
        LoadDependenceDistribution {
            a_2_plus: across_legs(&plain(&table.a_2_plus_n_per_kg2), &self.excluded_legs_a_2_plus),
            a_2_minus: across_legs(&plain(&table.a_2_minus_n_per_kg2), &self.excluded_legs_a_2_minus),
            a_1_plus: across_legs(&maybe(&table.a_1_plus_n_per_kg), &self.excluded_legs_a_1_plus),
            a_1_minus: across_legs(&maybe(&table.a_1_minus_n_per_kg), &self.excluded_legs_a_1_minus),
        }
    }
}

// =============================================================================================
// Loading
// =============================================================================================

impl RobotDescription {
    /// The shipped AMRU5 description (embedded `robots/amru5.toml`).
    ///
    /// # Panics
    /// Never in a tested build: the embedded file is validated by the unit tests.
    pub fn amru5() -> RobotDescription {
        Self::from_str(AMRU5_TOML, AMRU5_ORIGIN)
            .unwrap_or_else(|e| panic!("the embedded AMRU5 description is invalid: {e}"))
    }

    /// Reads and validates a description file; errors name `path`.
    pub fn from_file(path: impl AsRef<Path>) -> Result<RobotDescription> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| DescriptionError::Io { file: file.clone(), reason: e.to_string() })?;
        Self::from_str(&text, &file)
    }

    /// Parses and validates a description; `origin_name` (a file name) is used in errors.
    #[allow(clippy::should_implement_trait)]
    pub fn from_str(text: &str, origin_name: &str) -> Result<RobotDescription> {
        let index = SpanIndex::build(text, origin_name)?;
        let mut robot: RobotDescription = toml::from_str(text).map_err(|e| index.serde_error(&e))?;
        robot.origin = origin_name.to_string();
        let ctx = Ctx { file: origin_name, index: Some(&index) };
        robot.validate(&ctx)?;
        robot.legs.sort_by_key(|l| l.id);
        Ok(robot)
    }

    /// Validates an in-memory description (e.g. after editing fields in code).
    pub fn validate_all(&self) -> Result<()> {
        self.validate(&Ctx { file: &self.origin, index: None })
    }
}

/// Byte spans of every key and value of the document, to turn serde errors and validation
/// paths into dotted field paths and line numbers. Shared with the scenario loader
/// (`crate::scenario`), which reports errors the same way.
pub(crate) struct SpanIndex<'t> {
    file: String,
    text: &'t str,
    /// Where a reader finds the required fields, quoted in "missing field" errors.
    reference: String,
    /// (dotted path, key span, value span); array elements use the element span for both.
    nodes: Vec<(String, Range<usize>, Range<usize>)>,
}

fn contains(outer: &Range<usize>, inner: &Range<usize>) -> bool {
    outer.start <= inner.start && inner.end <= outer.end && outer.start < outer.end
}

fn shorten(s: &str) -> String {
    let s = s.trim();
    if s.chars().count() > 60 {
        format!("{}...", s.chars().take(57).collect::<String>())
    } else {
        s.to_string()
    }
}

impl<'t> SpanIndex<'t> {
    fn build(text: &'t str, file: &str) -> Result<Self> {
        Self::build_for(text, file, "robots/amru5.toml")
    }

    /// Indexes `text` (read from `file`); `reference` names the file or document that shows
    /// the required fields, for "missing field" errors.
    pub(crate) fn build_for(text: &'t str, file: &str, reference: &str) -> Result<Self> {
        let doc = toml::de::DeTable::parse(text).map_err(|e| {
            let (line, column) = e.span().map(|s| line_col(text, s.start)).unwrap_or((1, 1));
            DescriptionError::Syntax {
                file: file.to_string(),
                line,
                column,
                message: e.message().trim().to_string(),
            }
        })?;
        let mut index = SpanIndex { file: file.to_string(), text, reference: reference.to_string(), nodes: Vec::new() };
        index.walk_table(doc.get_ref(), "");
        Ok(index)
    }

    fn walk_table(&mut self, table: &toml::de::DeTable<'_>, prefix: &str) {
        for (k, v) in table.iter() {
            let path =
                if prefix.is_empty() { k.get_ref().to_string() } else { format!("{prefix}.{}", k.get_ref()) };
            self.nodes.push((path.clone(), k.span(), v.span()));
            self.walk_value(v.get_ref(), &path);
        }
    }

    fn walk_value(&mut self, value: &toml::de::DeValue<'_>, path: &str) {
        match value {
            toml::de::DeValue::Table(t) => self.walk_table(t, path),
            toml::de::DeValue::Array(a) => {
                for (i, e) in a.iter().enumerate() {
                    let p = format!("{path}[{i}]");
                    self.nodes.push((p.clone(), e.span(), e.span()));
                    self.walk_value(e.get_ref(), &p);
                }
            }
            _ => {}
        }
    }

    /// The most specific node whose key or value span contains `span`: (path, value span).
    fn node_at(&self, span: &Range<usize>) -> Option<(&str, Range<usize>)> {
        let mut best: Option<(usize, usize, &str, Range<usize>)> = None;
        for (path, key, value) in &self.nodes {
            for s in [key, value] {
                if contains(s, span) {
                    let size = s.end - s.start;
                    let depth = path.len();
                    let better = match &best {
                        None => true,
                        Some((bs, bd, ..)) => size < *bs || (size == *bs && depth > *bd),
                    };
                    if better {
                        best = Some((size, depth, path, value.clone()));
                    }
                }
            }
        }
        best.map(|(_, _, p, v)| (p, v))
    }

    /// Line of the field at `path`, or of its closest enclosing table or array element that is
    /// in the file (a missing field is reported at its table).
    pub(crate) fn line_of(&self, path: &str) -> Option<usize> {
        let mut path = path;
        loop {
            if let Some((_, key, _)) = self.nodes.iter().find(|(p, ..)| p == path) {
                return Some(line_col(self.text, key.start).0);
            }
            let cut = path.rfind(['.', '['])?;
            path = &path[..cut];
        }
    }

    pub(crate) fn serde_error(&self, e: &toml::de::Error) -> DescriptionError {
        let msg = e.message().trim().to_string();
        let span = e.span().filter(|s| s.start < s.end);
        let line = span.as_ref().map(|s| line_col(self.text, s.start).0);
        let field_err = |field: String, value: String, problem: &str, allowed: String| {
            DescriptionError::field_error(&self.file, line, field, value, problem.to_string(), allowed)
        };
        let quoted = |m: &str| m.split('`').nth(1).unwrap_or("").to_string();
        let join = |parent: &str, child: &str| {
            if parent.is_empty() {
                child.to_string()
            } else {
                format!("{parent}.{child}")
            }
        };
        let node = span.as_ref().and_then(|s| self.node_at(s));
        if msg.starts_with("missing field `") {
            let parent = node.map(|(p, _)| p.to_string()).unwrap_or_default();
            return field_err(
                join(&parent, &quoted(&msg)),
                "<missing>".to_string(),
                "missing field",
                format!("the field is required (see {})", self.reference),
            );
        }
        let expected = msg
            .split_once(", expected ")
            .map(|(_, x)| format!("expected {x}"))
            .or_else(|| msg.split_once(", there are no fields").map(|_| "no fields here".to_string()))
            .unwrap_or_else(|| msg.clone());
        if msg.starts_with("unknown field `") {
            let (path, value) = match node {
                Some((p, v)) => (p.to_string(), shorten(&self.text[v])),
                None => (quoted(&msg), "?".to_string()),
            };
            return field_err(path, value, "unknown field", expected);
        }
        let (path, value) = match (node, span) {
            (Some((p, _)), Some(s)) => (p.to_string(), shorten(&self.text[s])),
            _ => ("<document>".to_string(), "?".to_string()),
        };
        let problem = msg.split(", expected ").next().unwrap_or(&msg).to_string();
        field_err(path, value, &problem, expected)
    }
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.len() - before.rfind('\n').map(|i| i + 1).unwrap_or(0) + 1;
    (line, column)
}

// =============================================================================================
// Validation
// =============================================================================================

pub(crate) struct Ctx<'a> {
    pub(crate) file: &'a str,
    pub(crate) index: Option<&'a SpanIndex<'a>>,
}

impl Ctx<'_> {
    pub(crate) fn err(
        &self,
        field: &str,
        value: impl fmt::Display,
        problem: &str,
        allowed: impl Into<String>,
    ) -> DescriptionError {
        DescriptionError::field_error(
            self.file,
            self.index.and_then(|i| i.line_of(field)),
            field.to_string(),
            value.to_string(),
            problem.to_string(),
            allowed.into(),
        )
    }

    pub(crate) fn check(&self, ok: bool, field: &str, value: f64, allowed: &str) -> Result<()> {
        if !value.is_finite() {
            return Err(self.err(field, value, "not a finite number", allowed));
        }
        if ok {
            Ok(())
        } else {
            Err(self.err(field, value, "out of range", allowed))
        }
    }

    pub(crate) fn finite(&self, field: &str, v: f64) -> Result<()> {
        self.check(true, field, v, "a finite number")
    }

    pub(crate) fn positive(&self, field: &str, v: f64) -> Result<()> {
        self.check(v > 0.0, field, v, "a finite number > 0")
    }

    pub(crate) fn non_negative(&self, field: &str, v: f64) -> Result<()> {
        self.check(v >= 0.0, field, v, "a finite number >= 0")
    }

    fn negative(&self, field: &str, v: f64) -> Result<()> {
        self.check(v < 0.0, field, v, "a finite number < 0 (minus sense, q_dot < 0)")
    }

    pub(crate) fn within(&self, field: &str, v: f64, lo: f64, hi: f64) -> Result<()> {
        self.check(v >= lo && v <= hi, field, v, &format!("a finite number in [{lo}, {hi}]"))
    }

    fn close(&self, field: &str, v: f64, target: f64, rel: f64, what: &str) -> Result<()> {
        let ok = (v - target).abs() <= rel * target.abs();
        self.check(ok, field, v, &format!("{target:.6} within {:.2} % ({what})", rel * 100.0))
    }

    fn interval(&self, field: &str, i: &Interval) -> Result<()> {
        self.finite(&format!("{field}.min"), i.min)?;
        self.finite(&format!("{field}.max"), i.max)?;
        if i.min >= i.max {
            return Err(self.err(
                &format!("{field}.min"),
                i.min,
                "out of range",
                format!("min < max (max = {})", i.max),
            ));
        }
        Ok(())
    }

    fn rigid_body(&self, field: &str, b: &RigidBody) -> Result<()> {
        self.positive(&format!("{field}.mass_kg"), b.mass_kg)?;
        let names = ["i_xx_kg_m2", "i_yy_kg_m2", "i_zz_kg_m2"];
        let m = b.principal_moments();
        for (n, v) in names.iter().zip(m) {
            self.positive(&format!("{field}.{n}"), v)?;
        }
        for k in 0..3 {
            let (a, c) = (m[(k + 1) % 3], m[(k + 2) % 3]);
            if m[k] > (a + c) * (1.0 + 1e-9) {
                return Err(self.err(
                    &format!("{field}.{}", names[k]),
                    m[k],
                    "violates the triangle inequality of principal moments",
                    format!(
                        "a value <= {} + {} = {} ({} + {}; a rigid body needs each principal moment <= the sum of the other two)",
                        a,
                        c,
                        a + c,
                        names[(k + 1) % 3],
                        names[(k + 2) % 3]
                    ),
                ));
            }
        }
        Ok(())
    }

    fn per_leg(&self, field: &str, p: &PerLeg, sign: Sign) -> Result<()> {
        self.six(&format!("{field}.mu"), p.mu.len())?;
        self.six(&format!("{field}.sigma"), p.sigma.len())?;
        for (i, &v) in p.mu.iter().enumerate() {
            self.signed(&format!("{field}.mu[{i}]"), v, sign)?;
        }
        for (i, &v) in p.sigma.iter().enumerate() {
            self.non_negative(&format!("{field}.sigma[{i}]"), v)?;
        }
        Ok(())
    }

    fn per_leg_maybe(&self, field: &str, p: &PerLegMaybe, sign: Sign) -> Result<()> {
        self.six(&format!("{field}.mu"), p.mu.len())?;
        self.six(&format!("{field}.sigma"), p.sigma.len())?;
        for (i, (mu, sigma)) in p.mu.iter().zip(&p.sigma).enumerate() {
            match (mu, sigma) {
                (Measured::Value(m), Measured::Value(s)) => {
                    self.signed(&format!("{field}.mu[{i}]"), *m, sign)?;
                    self.non_negative(&format!("{field}.sigma[{i}]"), *s)?;
                }
                (Measured::Missing, Measured::Missing) => {}
                (Measured::Value(_), Measured::Missing) => {
                    return Err(self.err(
                        &format!("{field}.sigma[{i}]"),
                        sigma,
                        "missing standard deviation",
                        "a number >= 0 where the mean is given (\"-\" only together with mu = \"-\")",
                    ))
                }
                (Measured::Missing, Measured::Value(_)) => {
                    return Err(self.err(
                        &format!("{field}.sigma[{i}]"),
                        sigma,
                        "standard deviation without a mean",
                        "\"-\" where mu is \"-\"",
                    ))
                }
            }
        }
        Ok(())
    }

    fn six(&self, field: &str, len: usize) -> Result<()> {
        if len == LEG_COUNT {
            Ok(())
        } else {
            Err(self.err(
                field,
                format!("an array of {len} values"),
                "wrong length",
                "exactly 6 values, one per leg 0..5",
            ))
        }
    }

    fn signed(&self, field: &str, v: f64, sign: Sign) -> Result<()> {
        match sign {
            Sign::Positive => self.positive(field, v),
            Sign::Negative => self.negative(field, v),
            Sign::NonNegative => self.non_negative(field, v),
            Sign::NonPositive => self.check(v <= 0.0, field, v, "a finite number <= 0 (minus sense)"),
            Sign::Any => self.finite(field, v),
        }
    }

    fn gaussian(&self, field: &str, g: &Gaussian, sign: Sign) -> Result<()> {
        self.signed(&format!("{field}.mu"), g.mu, sign)?;
        self.non_negative(&format!("{field}.sigma"), g.sigma)
    }
}

#[derive(Clone, Copy)]
enum Sign {
    Positive,
    Negative,
    NonNegative,
    NonPositive,
    Any,
}

impl RobotDescription {
    fn validate(&self, c: &Ctx) -> Result<()> {
        if self.name.trim().is_empty() {
            return Err(c.err("name", "\"\"", "empty", "a non-empty robot name"));
        }
        self.validate_legs(c)?;
        self.validate_geometry(c)?;
        self.validate_inertia(c)?;
        self.validate_reductions(c)?;
        self.validate_electrics(c)?;
        self.validate_ground_and_control(c)?;
        self.validate_ranges(c)?;
        self.validate_friction(c)?;
        self.validate_monte_carlo(c)
    }

    fn validate_legs(&self, c: &Ctx) -> Result<()> {
        if self.legs.len() != LEG_COUNT {
            return Err(c.err(
                "legs",
                format!("{} [[legs]] entries", self.legs.len()),
                "wrong number of legs",
                "exactly six [[legs]] tables with ids 0..5",
            ));
        }
        let mut seen = BTreeSet::new();
        for (i, leg) in self.legs.iter().enumerate() {
            if leg.id >= LEG_COUNT || !seen.insert(leg.id) {
                return Err(c.err(
                    &format!("legs[{i}].id"),
                    leg.id,
                    if leg.id >= LEG_COUNT { "out of range" } else { "duplicate leg id" },
                    "each id 0..5 exactly once",
                ));
            }
            c.check(
                leg.angle_deg > -180.0 && leg.angle_deg <= 180.0,
                &format!("legs[{i}].angle_deg"),
                leg.angle_deg,
                "a finite angle in (-180, 180] degrees",
            )?;
        }
        for i in 0..LEG_COUNT {
            for j in 0..i {
                let d = (self.legs[i].angle_deg - self.legs[j].angle_deg).rem_euclid(360.0);
                if d.min(360.0 - d) < 1.0 {
                    return Err(c.err(
                        &format!("legs[{i}].angle_deg"),
                        self.legs[i].angle_deg,
                        "leg axes coincide",
                        format!(
                            "an angle at least 1 degree away from leg {} ({} deg)",
                            self.legs[j].id, self.legs[j].angle_deg
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    fn validate_geometry(&self, c: &Ctx) -> Result<()> {
        let g = &self.geometry;
        c.positive("geometry.body.r_rot_m", g.body.r_rot_m)?;
        c.positive("geometry.body.e_b_m", g.body.e_b_m)?;
        c.positive("geometry.body.ring_gap_h_m", g.body.ring_gap_h_m)?;
        let p = &g.pantograph;
        for (n, v) in [
            ("l_0_m", p.l_0_m),
            ("l_1_m", p.l_1_m),
            ("l_2_m", p.l_2_m),
            ("l_3_m", p.l_3_m),
            ("c_m", p.c_m),
            ("e_m", p.e_m),
            ("h_m", p.h_m),
            ("x_g_leg_m", p.x_g_leg_m),
            ("l_g0_m", p.l_g0_m),
        ] {
            c.positive(&format!("geometry.pantograph.{n}"), v)?;
        }
        c.check(
            p.c_m < p.l_0_m,
            "geometry.pantograph.c_m",
            p.c_m,
            &format!("c = AB < l_0 = AC = {}", p.l_0_m),
        )?;
        let bc = p.l_0_m - p.c_m;
        c.check(
            (p.l_2_m - bc).abs() <= 1e-6,
            "geometry.pantograph.l_2_m",
            p.l_2_m,
            &format!("l_2 = DE = BC = l_0 - c = {bc} (parallelogram B-C-E-D, Table 2.1)"),
        )?;
        c.check(
            p.l_3_m > p.l_1_m,
            "geometry.pantograph.l_3_m",
            p.l_3_m,
            &format!("CF > CE = l_1 = {}", p.l_1_m),
        )?;
        let ratio = p.l_0_m / p.c_m;
        c.close("geometry.pantograph.x_foot_per_q_h", p.x_foot_per_q_h, ratio, 0.05, "AC/AB, Eq. B.2")?;
        c.close(
            "geometry.pantograph.z_foot_per_q_v",
            p.z_foot_per_q_v,
            -(ratio - 1.0),
            0.05,
            "-(AC/AB - 1), Eq. B.1",
        )?;
        let ch = &g.chassis;
        for (n, v) in [
            ("l_x1_m", ch.l_x1_m),
            ("l_y1_m", ch.l_y1_m),
            ("l_z1_m", ch.l_z1_m),
            ("l_xc_m", ch.l_xc_m),
            ("l_yc_m", ch.l_yc_m),
            ("l_zc_m", ch.l_zc_m),
        ] {
            c.within(&format!("geometry.chassis.{n}"), v, -1.0, 1.0)?;
        }
        let a = &g.actuators;
        for (n, v) in [
            ("l_x6_m", a.l_x6_m),
            ("l_x7_m", a.l_x7_m),
            ("l_y7_m", a.l_y7_m),
            ("l_z7_m", a.l_z7_m),
            ("l_x8_m", a.l_x8_m),
            ("l_y8_m", a.l_y8_m),
            ("l_z8_m", a.l_z8_m),
        ] {
            c.within(&format!("geometry.actuators.{n}"), v, -1.0, 1.0)?;
        }
        Ok(())
    }

    fn validate_inertia(&self, c: &Ctx) -> Result<()> {
        let m = &self.inertia;
        for (n, b) in [
            ("main_body", &m.main_body),
            ("chassis", &m.chassis),
            ("pantograph_upper", &m.pantograph_upper),
            ("pantograph_left", &m.pantograph_left),
            ("pantograph_lower", &m.pantograph_lower),
            ("pantograph_leg", &m.pantograph_leg),
        ] {
            c.rigid_body(&format!("inertia.{n}"), b)?;
        }
        let r = &m.rotor;
        c.positive("inertia.rotor.mass_kg", r.mass_kg)?;
        c.positive("inertia.rotor.i_axial_kg_m2", r.i_axial_kg_m2)?;
        c.positive("inertia.rotor.i_equatorial_kg_m2", r.i_equatorial_kg_m2)?;
        c.check(
            r.i_axial_kg_m2 <= 2.0 * r.i_equatorial_kg_m2 * (1.0 + 1e-9),
            "inertia.rotor.i_axial_kg_m2",
            r.i_axial_kg_m2,
            &format!("<= 2 I_e = {} (triangle inequality)", 2.0 * r.i_equatorial_kg_m2),
        )?;
        c.positive("inertia.rho_duralumin_kg_m3", m.rho_duralumin_kg_m3)?;
        c.positive("inertia.rho_steel_kg_m3", m.rho_steel_kg_m3)?;
        c.positive("inertia.leg_mass_kg", m.leg_mass_kg)?;
        let leg = self.leg_mass_kg();
        c.check(
            (m.leg_mass_kg - leg).abs() <= 5e-3,
            "inertia.leg_mass_kg",
            m.leg_mass_kg,
            &format!("m_1 + m_2 + m_3 + m_4 + m_5 + 3 m_rot = {leg:.4} within 0.005 kg (Table B.2)"),
        )?;
        c.positive("inertia.total_mass_kg", m.total_mass_kg)?;
        c.close("inertia.total_mass_kg", m.total_mass_kg, self.total_mass_kg(), 0.05, "m_0 + 6 m_leg")
    }

    fn validate_reductions(&self, c: &Ctx) -> Result<()> {
        let r = &self.reductions;
        c.positive("reductions.n_r", r.n_r)?;
        c.positive("reductions.n_v_rad_per_m", r.n_v_rad_per_m)?;
        c.positive("reductions.n_h_rad_per_m", r.n_h_rad_per_m)?;
        let k = &r.components;
        c.positive("reductions.components.gearbox_r", k.gearbox_r)?;
        c.positive("reductions.components.gearbox_v", k.gearbox_v)?;
        c.positive("reductions.components.gearbox_h", k.gearbox_h)?;
        c.positive("reductions.components.ball_screw_rad_per_m", k.ball_screw_rad_per_m)?;
        if k.sprocket_r_teeth.len() != 2 {
            return Err(c.err(
                "reductions.components.sprocket_r_teeth",
                format!("{:?}", k.sprocket_r_teeth),
                "wrong length",
                "two tooth counts [driven, driving], e.g. [38, 12]",
            ));
        }
        for (i, t) in k.sprocket_r_teeth.iter().enumerate() {
            if *t == 0 {
                return Err(c.err(
                    &format!("reductions.components.sprocket_r_teeth[{i}]"),
                    t,
                    "out of range",
                    "a tooth count >= 1",
                ));
            }
        }
        let sprocket = f64::from(k.sprocket_r_teeth[0]) / f64::from(k.sprocket_r_teeth[1]);
        c.close("reductions.n_r", r.n_r, k.gearbox_r * sprocket, 0.005, "gearbox x sprocket, Table 3.1")?;
        c.close(
            "reductions.n_v_rad_per_m",
            r.n_v_rad_per_m,
            k.gearbox_v * k.ball_screw_rad_per_m,
            0.005,
            "gearbox x ball screw",
        )?;
        c.close(
            "reductions.n_h_rad_per_m",
            r.n_h_rad_per_m,
            k.gearbox_h * k.ball_screw_rad_per_m,
            0.005,
            "gearbox x ball screw",
        )
    }

    fn validate_electrics(&self, c: &Ctx) -> Result<()> {
        let m = &self.motor;
        c.positive("motor.nominal_voltage_v", m.nominal_voltage_v)?;
        c.positive("motor.resistance_ohm", m.resistance_ohm)?;
        c.non_negative("motor.inductance_mh", m.inductance_mh)?;
        c.positive("motor.torque_constant_nm_per_a", m.torque_constant_nm_per_a)?;
        c.positive("motor.rotor_inertia_g_cm2", m.rotor_inertia_g_cm2)?;
        c.close(
            "motor.rotor_inertia_g_cm2",
            m.rotor_inertia_kg_m2(),
            self.inertia.rotor.i_axial_kg_m2,
            0.01,
            "in kg m^2: J_r must match inertia.rotor.i_axial_kg_m2",
        )?;
        c.positive("motor.mass_kg", m.mass_kg)?;
        c.positive("motor.no_load_speed_rpm", m.no_load_speed_rpm)?;
        let d = &self.driver;
        c.positive("driver.supply_voltage_v", d.supply_voltage_v)?;
        c.check(
            d.velocity_derating > 0.0 && d.velocity_derating <= 1.0,
            "driver.velocity_derating",
            d.velocity_derating,
            "a factor in (0, 1]",
        )?;
        c.non_negative("driver.mosfet_resistance_ohm", d.mosfet_resistance_ohm)?;
        c.non_negative("driver.diode_drop_v", d.diode_drop_v)?;
        if d.pwm_bits == 0 || d.pwm_bits > 32 {
            return Err(c.err("driver.pwm_bits", d.pwm_bits, "out of range", "an integer in [1, 32]"));
        }
        c.check(
            d.dead_band_v >= 0.0 && d.dead_band_v < d.supply_voltage_v,
            "driver.dead_band_v",
            d.dead_band_v,
            &format!("a voltage in [0, supply_voltage_v = {})", d.supply_voltage_v),
        )?;
        c.positive("driver.current_sensor_range_a", d.current_sensor_range_a)
    }

    fn validate_ground_and_control(&self, c: &Ctx) -> Result<()> {
        let g = &self.ground;
        c.positive("ground.p_k", g.p_k)?;
        c.positive("ground.p_d", g.p_d)?;
        c.positive("ground.k_gnd_n_per_m_pk", g.k_gnd_n_per_m_pk)?;
        c.non_negative("ground.d_gnd_ns_per_m_pd1", g.d_gnd_ns_per_m_pd1)?;
        c.positive("ground.mu", g.mu)?;
        c.positive("ground.v_glim_m_per_s", g.v_glim_m_per_s)?;
        let k = &self.controller;
        c.positive("controller.period_s", k.period_s)?;
        if k.encoder_impulses_per_rev == 0 {
            return Err(c.err("controller.encoder_impulses_per_rev", 0, "out of range", "an integer >= 1"));
        }
        let pis = [
            (
                "q_r",
                "k_v_per_rad",
                k.q_r.k_v_per_rad,
                k.q_r.t_i_s,
                k.q_r.bandwidth_hz,
                k.q_r.phase_margin_deg,
                k.q_r.overshoot_percent,
            ),
            (
                "q_v",
                "k_v_per_m",
                k.q_v.k_v_per_m,
                k.q_v.t_i_s,
                k.q_v.bandwidth_hz,
                k.q_v.phase_margin_deg,
                k.q_v.overshoot_percent,
            ),
            (
                "q_h",
                "k_v_per_m",
                k.q_h.k_v_per_m,
                k.q_h.t_i_s,
                k.q_h.bandwidth_hz,
                k.q_h.phase_margin_deg,
                k.q_h.overshoot_percent,
            ),
        ];
        for (j, kname, gain, ti, bw, pm, os) in pis {
            c.positive(&format!("controller.{j}.{kname}"), gain)?;
            c.positive(&format!("controller.{j}.t_i_s"), ti)?;
            c.non_negative(&format!("controller.{j}.bandwidth_hz"), bw)?;
            c.within(&format!("controller.{j}.phase_margin_deg"), pm, 0.0, 180.0)?;
            c.non_negative(&format!("controller.{j}.overshoot_percent"), os)?;
        }
        Ok(())
    }

    fn validate_ranges(&self, c: &Ctx) -> Result<()> {
        let r = &self.joint_ranges;
        c.interval("joint_ranges.q_r_deg", &r.q_r_deg)?;
        c.within("joint_ranges.q_r_deg.min", r.q_r_deg.min, -180.0, 180.0)?;
        c.within("joint_ranges.q_r_deg.max", r.q_r_deg.max, -180.0, 180.0)?;
        c.interval("joint_ranges.q_v_m", &r.q_v_m)?;
        c.interval("joint_ranges.q_h_m", &r.q_h_m)?;
        c.positive("joint_ranges.q_v_m.min", r.q_v_m.min)?;
        c.non_negative("joint_ranges.q_h_m.min", r.q_h_m.min)?;
        // The triangle A-B-D (sides c, l_1, k = AD = sqrt(q_v^2 + q_h^2)) must close over the
        // whole range (Eqs. 3.57-3.63).
        let p = &self.geometry.pantograph;
        let (lo, hi) = ((p.l_1_m - p.c_m).abs(), p.l_1_m + p.c_m);
        for (qv_name, qv) in [("min", r.q_v_m.min), ("max", r.q_v_m.max)] {
            for (qh_name, qh) in [("min", r.q_h_m.min), ("max", r.q_h_m.max)] {
                let k = qv.hypot(qh);
                if k <= lo || k >= hi {
                    return Err(c.err(
                        &format!("joint_ranges.q_v_m.{qv_name}"),
                        qv,
                        &format!("the pantograph cannot close at q_v = {qv}, q_h.{qh_name} = {qh} (AD = {k:.4} m)"),
                        format!("ranges with |l_1 - c| = {lo:.4} < sqrt(q_v^2 + q_h^2) < l_1 + c = {hi:.4} m at every corner"),
                    ));
                }
            }
        }
        let v = &r.identification_velocities;
        for (n, s) in [
            ("q_r_dot_deg_per_s", &v.q_r_dot_deg_per_s),
            ("q_v_dot_mm_per_s", &v.q_v_dot_mm_per_s),
            ("q_h_dot_mm_per_s", &v.q_h_dot_mm_per_s),
        ] {
            let f = format!("joint_ranges.identification_velocities.{n}");
            c.positive(&format!("{f}.min"), s.min)?;
            c.interval(&f, &Interval { min: s.min, max: s.max })?;
            c.positive(&format!("{f}.increment"), s.increment)?;
        }
        Ok(())
    }

    fn validate_friction(&self, c: &Ctx) -> Result<()> {
        let f = &self.friction;
        let l = &f.lugre;
        c.positive("friction.lugre.sigma_0", l.sigma_0)?;
        c.non_negative("friction.lugre.sigma_1", l.sigma_1)?;
        c.positive("friction.lugre.q_st_v_m_per_s", l.q_st_v_m_per_s)?;
        c.positive("friction.lugre.v_d", l.v_d)?;
        c.positive("friction.lugre.delta_d", l.delta_d)?;
        c.positive("friction.lugre.dry_viscous_epsilon", l.dry_viscous_epsilon)?;

        let r = &f.q_r;
        c.per_leg("friction.q_r.tau_f_d_plus_nm", &r.tau_f_d_plus_nm, Sign::Positive)?;
        c.per_leg("friction.q_r.f_v_plus_nms", &r.f_v_plus_nms, Sign::Any)?;
        c.per_leg("friction.q_r.tau_f_d_minus_nm", &r.tau_f_d_minus_nm, Sign::Negative)?;
        c.per_leg("friction.q_r.f_v_minus_nms", &r.f_v_minus_nms, Sign::Any)?;

        let v = &f.q_v;
        c.per_leg("friction.q_v.tau_f_d_plus_n", &v.tau_f_d_plus_n, Sign::Positive)?;
        c.per_leg("friction.q_v.f_v_plus_ns_per_m", &v.f_v_plus_ns_per_m, Sign::Any)?;
        c.per_leg("friction.q_v.tau_f_d_minus_n", &v.tau_f_d_minus_n, Sign::Negative)?;
        c.per_leg("friction.q_v.f_v_minus_ns_per_m", &v.f_v_minus_ns_per_m, Sign::Any)?;
        let mut loads: Vec<f64> = Vec::new();
        for (i, s) in v.stiction.iter().enumerate() {
            let p = format!("friction.q_v.stiction[{i}]");
            c.non_negative(&format!("{p}.load_kg"), s.load_kg)?;
            if loads.contains(&s.load_kg) {
                return Err(c.err(
                    &format!("{p}.load_kg"),
                    s.load_kg,
                    "duplicate load case",
                    "each load_kg once",
                ));
            }
            loads.push(s.load_kg);
            c.per_leg_maybe(&format!("{p}.tau_f_s_plus_n"), &s.tau_f_s_plus_n, Sign::Positive)?;
            c.per_leg_maybe(&format!("{p}.tau_f_s_minus_n"), &s.tau_f_s_minus_n, Sign::Negative)?;
        }
        if !loads.contains(&f.vertical_stiction_load_kg) {
            return Err(c.err(
                "friction.vertical_stiction_load_kg",
                f.vertical_stiction_load_kg,
                "no such load case",
                format!("one of the friction.q_v.stiction load_kg values {loads:?}"),
            ));
        }

        let h = &f.q_h;
        c.per_leg("friction.q_h.tau_f_d_plus_n", &h.tau_f_d_plus_n, Sign::Positive)?;
        c.per_leg("friction.q_h.f_v_plus_ns_per_m", &h.f_v_plus_ns_per_m, Sign::Any)?;
        c.per_leg("friction.q_h.tau_f_d_minus_n", &h.tau_f_d_minus_n, Sign::Negative)?;
        c.per_leg("friction.q_h.f_v_minus_ns_per_m", &h.f_v_minus_ns_per_m, Sign::Any)?;
        // Section 5.4: a_2 and a_1 of one sense share the sign of a_0 so that the friction
        // grows with the load.
        let a = &h.load_dependence;
        let p = "friction.q_h.load_dependence";
        c.per_leg(&format!("{p}.a_2_plus_n_per_kg2"), &a.a_2_plus_n_per_kg2, Sign::NonNegative)?;
        c.per_leg(&format!("{p}.a_2_minus_n_per_kg2"), &a.a_2_minus_n_per_kg2, Sign::NonPositive)?;
        c.per_leg_maybe(&format!("{p}.a_1_plus_n_per_kg"), &a.a_1_plus_n_per_kg, Sign::NonNegative)?;
        c.per_leg_maybe(&format!("{p}.a_1_minus_n_per_kg"), &a.a_1_minus_n_per_kg, Sign::NonPositive)?;
        Ok(())
    }

    fn validate_monte_carlo(&self, c: &Ctx) -> Result<()> {
        let m = &self.monte_carlo;
        if m.runs_per_velocity == 0 {
            return Err(c.err("monte_carlo.runs_per_velocity", 0, "out of range", "an integer >= 1"));
        }
        c.positive("monte_carlo.truncation_sigmas", m.truncation_sigmas)?;
        if m.velocities_m_per_s.is_empty() {
            return Err(c.err("monte_carlo.velocities_m_per_s", "[]", "empty", "at least one velocity > 0"));
        }
        for (i, &v) in m.velocities_m_per_s.iter().enumerate() {
            c.positive(&format!("monte_carlo.velocities_m_per_s[{i}]"), v)?;
        }
        for (n, list) in [
            ("excluded_legs_a_2_plus", &m.excluded_legs_a_2_plus),
            ("excluded_legs_a_2_minus", &m.excluded_legs_a_2_minus),
            ("excluded_legs_a_1_plus", &m.excluded_legs_a_1_plus),
            ("excluded_legs_a_1_minus", &m.excluded_legs_a_1_minus),
        ] {
            for (i, &leg) in list.iter().enumerate() {
                if leg >= LEG_COUNT {
                    return Err(c.err(
                        &format!("monte_carlo.{n}[{i}]"),
                        leg,
                        "out of range",
                        "a leg id 0..5",
                    ));
                }
            }
        }
        let r = &m.q_r;
        c.gaussian("monte_carlo.q_r.tau_f_d_plus_nm", &r.tau_f_d_plus_nm, Sign::Positive)?;
        c.gaussian("monte_carlo.q_r.f_v_plus_nms", &r.f_v_plus_nms, Sign::NonNegative)?;
        c.gaussian("monte_carlo.q_r.tau_f_d_minus_nm", &r.tau_f_d_minus_nm, Sign::Negative)?;
        c.gaussian("monte_carlo.q_r.f_v_minus_nms", &r.f_v_minus_nms, Sign::NonNegative)?;
        let v = &m.q_v;
        c.gaussian("monte_carlo.q_v.tau_f_d_plus_n", &v.tau_f_d_plus_n, Sign::Positive)?;
        c.gaussian("monte_carlo.q_v.f_v_plus_ns_per_m", &v.f_v_plus_ns_per_m, Sign::NonNegative)?;
        c.gaussian("monte_carlo.q_v.tau_f_d_minus_n", &v.tau_f_d_minus_n, Sign::Negative)?;
        c.gaussian("monte_carlo.q_v.f_v_minus_ns_per_m", &v.f_v_minus_ns_per_m, Sign::NonNegative)?;
        let h = &m.q_h;
        c.gaussian("monte_carlo.q_h.tau_f_d_plus_n", &h.tau_f_d_plus_n, Sign::Positive)?;
        c.gaussian("monte_carlo.q_h.tau_f_d_minus_n", &h.tau_f_d_minus_n, Sign::Negative)
    }
}

// =============================================================================================
// SI accessors
// =============================================================================================

impl RobotDescription {
    /// Angle of leg `leg` from x_b about z_b, in radians.
    ///
    /// # Panics
    /// If `leg` is not 0..5.
    pub fn leg_angle_rad(&self, leg: usize) -> f64 {
        self.leg(leg).angle_deg.to_radians()
    }

    /// The six leg angles in radians, indexed by leg id.
    pub fn leg_angles_rad(&self) -> [f64; LEG_COUNT] {
        std::array::from_fn(|i| self.leg_angle_rad(i))
    }

    /// Position of the q_r axis of leg `leg` in the body frame (m): R_rot (cos a, sin a, 0).
    pub fn leg_origin_m(&self, leg: usize) -> [f64; 3] {
        let a = self.leg_angle_rad(leg);
        let r = self.geometry.body.r_rot_m;
        [r * a.cos(), r * a.sin(), 0.0]
    }

    fn leg(&self, leg: usize) -> &Leg {
        self.legs
            .iter()
            .find(|l| l.id == leg)
            .unwrap_or_else(|| panic!("leg {leg} does not exist (ids 0..5)"))
    }

    /// Mass of one leg: m_1 + m_2 + m_3 + m_4 + m_5 + 3 m_rot (Table B.2), kg.
    pub fn leg_mass_kg(&self) -> f64 {
        let m = &self.inertia;
        m.chassis.mass_kg
            + m.pantograph_upper.mass_kg
            + m.pantograph_left.mass_kg
            + m.pantograph_lower.mass_kg
            + m.pantograph_leg.mass_kg
            + 3.0 * m.rotor.mass_kg
    }

    /// Total mass m_0 + 6 m_leg (Table B.2), kg: 34.447 for AMRU5.
    pub fn total_mass_kg(&self) -> f64 {
        self.inertia.main_body.mass_kg + LEG_COUNT as f64 * self.leg_mass_kg()
    }

    /// Global reduction n of a joint (Table 3.1): rad/rad for q_r, rad/m for q_v and q_h.
    pub fn reduction(&self, joint: Joint) -> f64 {
        match joint {
            Joint::Rotation => self.reductions.n_r,
            Joint::Vertical => self.reductions.n_v_rad_per_m,
            Joint::Horizontal => self.reductions.n_h_rad_per_m,
        }
    }

    /// k_t n: joint torque (Nm) or force (N) per ampere of motor current (Eq. 5.17), and the
    /// factor between a joint velocity and the back-emf (V per rad/s or per m/s).
    pub fn joint_torque_per_ampere(&self, joint: Joint) -> f64 {
        self.motor.torque_constant_nm_per_a * self.reduction(joint)
    }

    /// Armature circuit resistance seen by the controller output: R + H-bridge (Section 6.4).
    pub fn circuit_resistance_ohm(&self) -> f64 {
        self.motor.resistance_ohm + self.driver.series_resistance_ohm()
    }

    /// Joint range (Table 5.2) in SI: rad for q_r, m for q_v and q_h.
    pub fn joint_range(&self, joint: Joint) -> (f64, f64) {
        let r = &self.joint_ranges;
        match joint {
            Joint::Rotation => (r.q_r_deg.min.to_radians(), r.q_r_deg.max.to_radians()),
            Joint::Vertical => (r.q_v_m.min, r.q_v_m.max),
            Joint::Horizontal => (r.q_h_m.min, r.q_h_m.max),
        }
    }

    /// PI gains of a joint in SI (Table 4.1).
    pub fn pi_gains(&self, joint: Joint) -> PiGains {
        let k = &self.controller;
        match joint {
            Joint::Rotation => PiGains { k: k.q_r.k_v_per_rad, t_i: k.q_r.t_i_s },
            Joint::Vertical => PiGains { k: k.q_v.k_v_per_m, t_i: k.q_v.t_i_s },
            Joint::Horizontal => PiGains { k: k.q_h.k_v_per_m, t_i: k.q_h.t_i_s },
        }
    }

    /// Joint-side resolution of the motor encoder: 2 pi / (impulses n), rad or m.
    pub fn encoder_resolution(&self, joint: Joint) -> f64 {
        2.0 * PI / (f64::from(self.controller.encoder_impulses_per_rev) * self.reduction(joint))
    }

    /// Breakaway forces of the vertical joint of `leg` at a Table 5.4 load case, as given
    /// (None for "-"); None if there is no such load case.
    pub fn vertical_stiction_measured(&self, leg: usize, load_kg: f64) -> Option<(Option<f64>, Option<f64>)> {
        self.friction
            .q_v
            .stiction
            .iter()
            .find(|s| s.load_kg == load_kg)
            .map(|s| (s.tau_f_s_plus_n.mu[leg].value(), s.tau_f_s_minus_n.mu[leg].value()))
    }

    /// Friction parameters of one joint of one leg in joint units, with the Section 6.1
    /// rules applied (negative viscous -> 0, missing stiction -> unloaded dry, vertical
    /// stiction of the `vertical_stiction_load_kg` case, a_0 of Eq. 5.12 = unloaded dry).
    ///
    /// # Panics
    /// If `leg` is not 0..5.
    pub fn friction(&self, leg: usize, joint: Joint) -> JointFriction {
        assert!(leg < LEG_COUNT, "leg {leg} does not exist (ids 0..5)");
        let f = &self.friction;
        let (dp, vp, dm, vm) = match joint {
            Joint::Rotation => {
                (&f.q_r.tau_f_d_plus_nm, &f.q_r.f_v_plus_nms, &f.q_r.tau_f_d_minus_nm, &f.q_r.f_v_minus_nms)
            }
            Joint::Vertical => (
                &f.q_v.tau_f_d_plus_n,
                &f.q_v.f_v_plus_ns_per_m,
                &f.q_v.tau_f_d_minus_n,
                &f.q_v.f_v_minus_ns_per_m,
            ),
            Joint::Horizontal => (
                &f.q_h.tau_f_d_plus_n,
                &f.q_h.f_v_plus_ns_per_m,
                &f.q_h.tau_f_d_minus_n,
                &f.q_h.f_v_minus_ns_per_m,
            ),
        };
        let (tau_f_d_plus, tau_f_d_minus) = (dp.mu[leg], dm.mu[leg]);
        let viscous = |v: f64| match f.negative_viscous {
            NegativeViscousRule::Zero => v.max(0.0),
            NegativeViscousRule::Keep => v,
        };
        let (tau_f_s_plus, tau_f_s_minus) = match joint {
            Joint::Vertical => {
                let (p, m) = self
                    .vertical_stiction_measured(leg, f.vertical_stiction_load_kg)
                    .expect("validated: the stiction load case exists");
                match f.missing_stiction {
                    MissingStictionRule::UnloadedDry => {
                        (p.unwrap_or(tau_f_d_plus), m.unwrap_or(tau_f_d_minus))
                    }
                }
            }
            _ => (tau_f_d_plus, tau_f_d_minus),
        };
        let load_dependence = (joint == Joint::Horizontal).then(|| {
            let a = &f.q_h.load_dependence;
            let a_1_plus = a.a_1_plus_n_per_kg.mu[leg].value().unwrap_or(0.0);
            let a_1_minus = a.a_1_minus_n_per_kg.mu[leg].value().unwrap_or(match f.missing_a1_minus {
                MissingA1MinusRule::Zero => 0.0,
                MissingA1MinusRule::MirrorA1Plus => -a_1_plus,
            });
            LoadCoefficients {
                a_2_plus: a.a_2_plus_n_per_kg2.mu[leg],
                a_2_minus: a.a_2_minus_n_per_kg2.mu[leg],
                a_1_plus,
                a_1_minus,
            }
        });
        JointFriction {
            leg,
            joint,
            tau_f_d_plus,
            tau_f_d_minus,
            tau_f_s_plus,
            tau_f_s_minus,
            f_v_plus: viscous(vp.mu[leg]),
            f_v_minus: viscous(vm.mu[leg]),
            f_v_plus_measured: vp.mu[leg],
            f_v_minus_measured: vm.mu[leg],
            q_st: (joint == Joint::Vertical).then_some(f.lugre.q_st_v_m_per_s),
            sigma_0: f.lugre.sigma_0,
            sigma_1: f.lugre.sigma_1,
            v_d: f.lugre.v_d,
            delta_d: f.lugre.delta_d,
            epsilon: f.lugre.dry_viscous_epsilon,
            load_dependence,
        }
    }

    /// Distributions of Table 6.7 for one joint kind, as (tau_f_d^+, f_v^+, tau_f_d^-, f_v^-);
    /// the viscous entries are None for q_h (neglected in Section 6.5).
    pub fn monte_carlo_distribution(
        &self,
        joint: Joint,
    ) -> (Gaussian, Option<Gaussian>, Gaussian, Option<Gaussian>) {
        let m = &self.monte_carlo;
        match joint {
            Joint::Rotation => (
                m.q_r.tau_f_d_plus_nm,
                Some(m.q_r.f_v_plus_nms),
                m.q_r.tau_f_d_minus_nm,
                Some(m.q_r.f_v_minus_nms),
            ),
            Joint::Vertical => (
                m.q_v.tau_f_d_plus_n,
                Some(m.q_v.f_v_plus_ns_per_m),
                m.q_v.tau_f_d_minus_n,
                Some(m.q_v.f_v_minus_ns_per_m),
            ),
            Joint::Horizontal => (m.q_h.tau_f_d_plus_n, None, m.q_h.tau_f_d_minus_n, None),
        }
    }
}

// =============================================================================================
// Tests
// =============================================================================================

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn amru5() -> RobotDescription {
        RobotDescription::from_str(AMRU5_TOML, "amru5.toml").expect("shipped description loads")
    }

    #[test]
    fn shipped_file_loads_and_is_sorted() {
        let r = amru5();
        assert_eq!(r.name, "AMRU5");
        assert_eq!(r.origin, "amru5.toml");
        let ids: Vec<usize> = r.legs.iter().map(|l| l.id).collect();
        assert_eq!(ids, vec![0, 1, 2, 3, 4, 5]);
        assert_eq!(RobotDescription::amru5().origin, "robots/amru5.toml");
    }

    #[test]
    fn leg_angles_follow_notes() {
        let r = amru5();
        let deg = [30.0, -30.0, 90.0, -90.0, 150.0, -150.0];
        for (leg, d) in deg.iter().enumerate() {
            assert_relative_eq!(r.leg_angle_rad(leg), d * PI / 180.0, epsilon = 1e-12);
            // even legs on the left (y > 0), odd on the right
            let y = r.leg_origin_m(leg)[1];
            assert_eq!(y > 0.0, leg % 2 == 0, "leg {leg}");
        }
        assert_relative_eq!(r.leg_origin_m(2)[1], 0.175, epsilon = 1e-12);
    }

    #[test]
    fn masses_of_table_b2() {
        let r = amru5();
        // m_leg = 2.895 + 0.157 + 0.055 + 0.143 + 0.564 + 3 x 0.186 = 4.372 (Table B.2)
        assert_relative_eq!(r.leg_mass_kg(), 4.372, epsilon = 1e-9);
        // m_0 + 6 m_leg = 8.215 + 26.232 = 34.447 kg, "about 34 kg" in the thesis
        assert_relative_eq!(r.total_mass_kg(), 34.447, epsilon = 1e-9);
        assert!((r.total_mass_kg() - 34.0).abs() / 34.0 < 0.015);
    }

    #[test]
    fn motor_and_reductions_in_si() {
        let r = amru5();
        assert_relative_eq!(r.motor.inductance_h(), 0.09e-3, epsilon = 1e-15);
        assert_relative_eq!(r.motor.rotor_inertia_kg_m2(), 6.55e-6, epsilon = 1e-15);
        assert_relative_eq!(r.circuit_resistance_ohm(), 0.934, epsilon = 1e-12);
        assert_eq!(r.reduction(Joint::Rotation), 1682.0);
        assert_eq!(r.reduction(Joint::Vertical), 69115.0);
        assert_eq!(r.reduction(Joint::Horizontal), 58643.0);
        // Eq. 4.13 with k_t = 0.02 gives C_emf = 3388 for q_r; with 19.4e-3 about 6 % less.
        let c_emf = r.joint_torque_per_ampere(Joint::Rotation).powi(2) / r.motor.resistance_ohm;
        assert!((c_emf / 3388.0 - 0.94).abs() < 0.01, "C_emf = {c_emf}");
        // Section 5.6: 100 N vertically at the foot ~ 0.4 A (100 N x 6 / (k_t n_v))
        let amps = 100.0 * 6.0 / r.joint_torque_per_ampere(Joint::Vertical);
        assert!((amps - 0.45).abs() < 0.05, "{amps}");
        let (lo, hi) = r.joint_range(Joint::Rotation);
        assert_relative_eq!(hi, 25f64.to_radians(), epsilon = 1e-15);
        assert_relative_eq!(lo, -25f64.to_radians(), epsilon = 1e-15);
        assert_eq!(r.joint_range(Joint::Horizontal), (0.005, 0.055));
        assert_eq!(r.pi_gains(Joint::Vertical), PiGains { k: 19863.0, t_i: 0.5 });
        assert_relative_eq!(r.encoder_resolution(Joint::Rotation), 2.0 * PI / (500.0 * 1682.0));
    }

    #[test]
    fn friction_rules_of_section_6_1() {
        let r = amru5();
        // Table 5.3 spot checks
        let f = r.friction(3, Joint::Rotation);
        assert_eq!((f.tau_f_d_plus, f.tau_f_d_minus), (14.9, -15.6));
        assert_eq!((f.tau_f_s_plus, f.tau_f_s_minus), (14.9, -15.6));
        assert!(f.q_st.is_none() && f.load_dependence.is_none());
        // negative viscous forced to zero, measured kept
        let f = r.friction(5, Joint::Rotation);
        assert_eq!((f.f_v_plus, f.f_v_plus_measured), (0.0, -0.3));
        let f = r.friction(0, Joint::Horizontal);
        assert_eq!((f.f_v_plus, f.f_v_plus_measured, f.f_v_minus), (0.0, -4112.7, 247.5));
        // vertical stiction of the 10 kg case; legs 1 and 3 minus sense from Table 5.3
        let f = r.friction(0, Joint::Vertical);
        assert_eq!((f.tau_f_s_plus, f.tau_f_s_minus), (673.0, -679.5));
        assert_eq!(f.q_st, Some(1e-4));
        let f = r.friction(1, Joint::Vertical);
        assert_eq!((f.tau_f_s_plus, f.tau_f_s_minus), (482.6, -351.6));
        let f = r.friction(3, Joint::Vertical);
        assert_eq!((f.tau_f_s_plus, f.tau_f_s_minus), (571.6, -381.8));
        assert_eq!(r.vertical_stiction_measured(3, 10.0), Some((Some(571.6), None)));
        assert_eq!(r.vertical_stiction_measured(5, 5.0), Some((Some(1010.4), Some(-435.8))));
        // LuGre (Table 6.1 with the NOTES exponent fix)
        assert_eq!((f.sigma_0, f.sigma_1), (1e9, 0.02));
    }

    #[test]
    fn horizontal_load_dependence_eq_5_12() {
        let r = amru5();
        let f = r.friction(0, Joint::Horizontal);
        let a = f.load_dependence.unwrap();
        assert_eq!((a.a_2_plus, a.a_2_minus, a.a_1_plus, a.a_1_minus), (3.84, -3.84, 20.3, 0.0));
        let (p, m) = f.dry_under_load(10.0);
        assert_relative_eq!(p, 3.84 * 100.0 + 20.3 * 10.0 + 465.1, epsilon = 1e-9);
        assert_relative_eq!(m, -3.84 * 100.0 - 563.1, epsilon = 1e-9);
        assert_eq!(f.dry_under_load(0.0), (465.1, -563.1));
        // the mirror rule
        let mut r2 = r.clone();
        r2.friction.missing_a1_minus = MissingA1MinusRule::MirrorA1Plus;
        assert_eq!(r2.friction(1, Joint::Horizontal).load_dependence.unwrap().a_1_minus, -48.0);
    }

    #[test]
    fn table_6_7_is_the_spread_of_the_leg_means() {
        // Table 6.7 was built as mean and (n-1) standard deviation of the six leg means of
        // Table 5.3: check the translational rows, which follow the text exactly.
        let r = amru5();
        let col = |p: &PerLeg| p.mu.iter().map(|&v| Some(v)).collect::<Vec<_>>();
        let f = &r.friction;
        let m = &r.monte_carlo;
        for (rows, table) in [
            (&f.q_v.tau_f_d_plus_n, m.q_v.tau_f_d_plus_n),
            (&f.q_v.f_v_plus_ns_per_m, m.q_v.f_v_plus_ns_per_m),
            (&f.q_v.tau_f_d_minus_n, m.q_v.tau_f_d_minus_n),
            (&f.q_v.f_v_minus_ns_per_m, m.q_v.f_v_minus_ns_per_m),
            (&f.q_h.tau_f_d_plus_n, m.q_h.tau_f_d_plus_n),
            (&f.q_h.tau_f_d_minus_n, m.q_h.tau_f_d_minus_n),
            (&f.q_r.tau_f_d_minus_nm, m.q_r.tau_f_d_minus_nm),
            (&f.q_r.f_v_minus_nms, m.q_r.f_v_minus_nms),
        ] {
            let g = across_legs(&col(rows), &[]).unwrap();
            assert!((g.mu - table.mu).abs() <= 0.01 * table.mu.abs() + 0.05, "{g:?} vs {table:?}");
            assert!((g.sigma - table.sigma).abs() <= 0.01 * table.sigma + 0.05, "{g:?} vs {table:?}");
        }
        // the 3.56 fix of NOTES.md
        assert_eq!(m.q_r.tau_f_d_minus_nm.sigma, 3.56);
        let d = m.load_dependence_distribution(&f.q_h.load_dependence);
        let a2p = d.a_2_plus.unwrap();
        assert_relative_eq!(a2p.mu, (3.84 + 4.09 + 6.84 + 5.07 + 7.66) / 5.0, epsilon = 1e-12);
        assert!(d.a_1_minus.is_none());
        assert_eq!(r.monte_carlo_distribution(Joint::Horizontal).1, None);
    }

    #[test]
    fn inertias_satisfy_the_triangle_inequality() {
        let r = amru5();
        let m = &r.inertia;
        for b in [
            &m.main_body,
            &m.chassis,
            &m.pantograph_upper,
            &m.pantograph_left,
            &m.pantograph_lower,
            &m.pantograph_leg,
        ] {
            let [a, b2, c] = b.principal_moments();
            assert!(a <= b2 + c && b2 <= a + c && c <= a + b2, "{b:?}");
        }
    }

    #[test]
    fn geometry_reconstruction_of_notes() {
        let r = amru5();
        let c = &r.geometry.chassis;
        // C* at (0.112, 0, -0.052) from the q_r axis (NOTES.md)
        assert_relative_eq!(c.l_x1_m + c.l_xc_m, 0.112, epsilon = 1e-12);
        assert_relative_eq!(c.l_y1_m + c.l_yc_m, 0.0, epsilon = 1e-12);
        assert_relative_eq!(c.l_z1_m + c.l_zc_m, -0.052, epsilon = 1e-12);
    }

    fn with(replace: &str, by: &str) -> String {
        assert!(AMRU5_TOML.contains(replace), "test pattern `{replace}` not in the file");
        AMRU5_TOML.replacen(replace, by, 1)
    }

    fn field_error(text: &str) -> (DescriptionError, String) {
        let e = RobotDescription::from_str(text, "bad.toml").expect_err("must be rejected");
        let s = e.to_string();
        assert!(s.starts_with("bad.toml"), "{s}");
        (e, s)
    }

    #[test]
    fn errors_name_file_field_value_and_allowed() {
        let (e, s) = field_error(&with("resistance_ohm = 0.334", "resistance_ohm = -0.334"));
        assert_eq!(e.field(), Some("motor.resistance_ohm"));
        assert!(s.contains("-0.334") && s.contains("> 0"), "{s}");
        // line number of the field
        let line = AMRU5_TOML.lines().position(|l| l.starts_with("resistance_ohm")).unwrap() + 1;
        assert!(s.starts_with(&format!("bad.toml:{line}:")), "{s}");

        let (e, s) = field_error(&with("resistance_ohm = 0.334", "resistance_ohm = nan"));
        assert_eq!(e.field(), Some("motor.resistance_ohm"));
        assert!(s.contains("NaN") && s.contains("finite"), "{s}");

        let (e, s) = field_error(&with("resistance_ohm = 0.334", ""));
        assert_eq!(e.field(), Some("motor.resistance_ohm"));
        assert!(s.contains("<missing>") && s.contains("required"), "{s}");

        let (e, s) =
            field_error(&with("resistance_ohm = 0.334", "resistance_ohm = 0.334\nresistanse_ohm = 1.0"));
        assert_eq!(e.field(), Some("motor.resistanse_ohm"));
        assert!(s.contains("unknown field") && s.contains("1.0") && s.contains("resistance_ohm"), "{s}");

        let (e, s) = field_error(&with("resistance_ohm = 0.334", "resistance_ohm = \"low\""));
        assert_eq!(e.field(), Some("motor.resistance_ohm"));
        assert!(s.contains("\"low\"") && s.contains("expected"), "{s}");

        let (e, s) =
            field_error(&with("q_v_m = { min = 0.04, max = 0.075 }", "q_v_m = { min = 0.075, max = 0.04 }"));
        assert_eq!(e.field(), Some("joint_ranges.q_v_m.min"));
        assert!(s.contains("0.075") && s.contains("min < max"), "{s}");
    }

    #[test]
    fn nested_and_array_paths() {
        let (e, s) = field_error(&with("mass_kg = 0.157", "mass_kg = -0.157"));
        assert_eq!(e.field(), Some("inertia.pantograph_upper.mass_kg"));
        assert!(s.contains("-0.157"), "{s}");

        let (e, s) = field_error(&with("angle_deg = 90.0", "angle_deg = 190.0"));
        assert_eq!(e.field(), Some("legs[2].angle_deg"));
        assert!(s.contains("190") && s.contains("(-180, 180]"), "{s}");

        let (e, _) =
            field_error(&with("[7.7, 6.3, 5.6, 14.9, 5.3, 8.3]", "[7.7, 6.3, -5.6, 14.9, 5.3, 8.3]"));
        assert_eq!(e.field(), Some("friction.q_r.tau_f_d_plus_nm.mu[2]"));

        let (e, s) =
            field_error(&with("[7.7, 6.3, 5.6, 14.9, 5.3, 8.3]", "[7.7, 6.3, \"x\", 14.9, 5.3, 8.3]"));
        assert_eq!(e.field(), Some("friction.q_r.tau_f_d_plus_nm.mu[2]"));
        assert!(s.contains("\"x\""), "{s}");

        let (e, s) = field_error(&with("[7.7, 6.3, 5.6, 14.9, 5.3, 8.3]", "[7.7, 6.3, 5.6, 14.9, 5.3]"));
        assert_eq!(e.field(), Some("friction.q_r.tau_f_d_plus_nm.mu"));
        assert!(s.contains("exactly 6"), "{s}");

        let (e, s) = field_error(&with("[-679.5, \"-\",", "[-679.5, \"?\","));
        assert_eq!(e.field(), Some("friction.q_v.stiction[2].tau_f_s_minus_n.mu[1]"));
        assert!(s.contains("\"-\""), "{s}");

        let (e, s) = field_error(&with("i_zz_kg_m2 = 0.0000047", "i_zz_kg_m2 = 0.00047"));
        assert_eq!(e.field(), Some("inertia.pantograph_left.i_zz_kg_m2"));
        assert!(s.contains("triangle"), "{s}");

        let (e, s) = field_error(&with("negative_viscous = \"zero\"", "negative_viscous = \"clamp\""));
        assert_eq!(e.field(), Some("friction.negative_viscous"));
        assert!(s.contains("clamp") && s.contains("keep"), "{s}");

        let (e, _) = field_error(&with("[[legs]]\nid = 5\nangle_deg = -150.0\n", ""));
        assert_eq!(e.field(), Some("legs"));
    }

    #[test]
    fn missing_fields_in_inline_tables_and_arrays_of_tables() {
        let (e, _) = field_error(&with("q_r_deg = { min = -25.0, max = 25.0 }", "q_r_deg = { min = -25.0 }"));
        assert_eq!(e.field(), Some("joint_ranges.q_r_deg.max"));
        let (e, _) = field_error(&with("id = 3\nangle_deg = -90.0", "id = 3"));
        assert_eq!(e.field(), Some("legs[3].angle_deg"));
        let (e, s) = field_error(&with("name = \"AMRU5\"", "name = \"AMRU5\"\nmass = 34"));
        assert_eq!(e.field(), Some("mass"));
        assert!(s.contains("34") && s.contains("`legs`"), "{s}");
        let (e, s) = field_error(&with("sprocket_r_teeth = [38, 12]", "sprocket_r_teeth = [38, 12, 5]"));
        assert_eq!(e.field(), Some("reductions.components.sprocket_r_teeth"), "{s}");
    }

    #[test]
    fn syntax_errors_have_a_line() {
        let e = RobotDescription::from_str("name = \"x\"\nfoo = = 1\n", "syn.toml").unwrap_err();
        assert!(matches!(e, DescriptionError::Syntax { line: 2, .. }), "{e}");
        assert!(e.to_string().starts_with("syn.toml:2:"), "{e}");
    }

    #[test]
    fn missing_top_level_table() {
        let start = AMRU5_TOML.find("[ground]").unwrap();
        let end = AMRU5_TOML.find("# Joint controllers").unwrap();
        let text = format!("{}{}", &AMRU5_TOML[..start], &AMRU5_TOML[end..]);
        let (e, s) = field_error(&text);
        assert_eq!(e.field(), Some("ground"), "{s}");
    }
}
