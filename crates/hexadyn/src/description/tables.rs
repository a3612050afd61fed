//! The mirror of the description file: one struct per table of `robots/amru5.toml`, named
//! after the table with the suffix `Table` (`[motor]` is [`MotorTable`], `[friction.lugre]`
//! is [`LuGreTable`]), with the thesis units in the field names (`resistance_ohm`,
//! `inductance_mh`, `angle_deg`, ...). Every struct denies unknown fields.
//!
//! Each field declares its own allowed values, checked while the file is read
//! (`#[serde(deserialize_with = "Positive::checked")]`, `"Negative::per_leg"`, see
//! `values.rs`); the relations between fields are checked afterwards
//! (`validate.rs`).

use serde::de::Deserializer;
use serde::Deserialize;

use super::values::{
    AtLeastOne, Fraction, Gaussian, HalfTurn, Interval, LegAngle, LegId, LegIndex, Negative, NonPositive, Offset, PerLeg,
    PerLegMaybe, PhaseMargin, PwmBits, Shapes, Sweep, ToothCount,
};
use crate::fields::{seq, Bound, Finite, NonNegative, Positive, Violation};
use crate::hexapod::{LegJoints, PantographJoint};

/// The whole robot description, mirroring `robots/amru5.toml`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RobotDescription {
    /// Robot name (`"AMRU5"`).
    #[serde(deserialize_with = "robot_name")]
    pub name: String,
    /// The six legs, sorted by id after loading (NOTES.md, Fig. 2.14).
    pub legs: Vec<LegTable>,
    /// The names of a leg's joints; `q_r, q_v, q_h` when the table is absent.
    #[serde(default)]
    pub joints: JointsTable,
    /// Table 2.1, Table B.1.
    pub geometry: GeometryTable,
    /// Table B.2.
    pub inertia: InertiaTable,
    /// Table 3.1.
    pub reductions: ReductionsTable,
    /// Table 3.4.
    pub motor: MotorTable,
    /// Sections 2.3.2, 4.4.3, 5.3, 6.4.
    pub driver: DriverTable,
    /// Table 3.3.
    pub ground: GroundTable,
    /// Table 4.1, Section 4.4.5.
    pub controller: ControllerTable,
    /// Table 5.2.
    pub joint_ranges: JointRangesTable,
    /// Tables 5.3, 5.4, 5.5, 6.1 and the rules of Section 6.1.
    pub friction: FrictionTable,
    /// Section 6.5, Table 6.7.
    pub monte_carlo: MonteCarloTable,
    /// Series-elastic transmissions (issue 40's "AMRU5 bis"): a spring between each gear output
    /// and its joint; absent on AMRU5, whose drives are rigid.
    #[serde(default)]
    pub series_elastic: Option<SeriesElasticTable>,
    /// Where the description was read from (file path or origin name); not in the file.
    #[serde(skip)]
    pub origin: String,
}

fn robot_name<'de, D: Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    let name = String::deserialize(d)?;
    if name.trim().is_empty() {
        return Err(Violation::new("\"\"", "empty", "a non-empty robot name").into_error());
    }
    Ok(name)
}

/// One `[[legs]]` entry: the leg's number and the direction of its q_r axis from the body
/// centre.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LegTable {
    /// Leg number 0..5 (0-2-4 on the left front to rear, 1-3-5 on the right).
    #[serde(deserialize_with = "LegId::checked")]
    pub id: usize,
    /// Angle of the leg from x_b about z_b, degrees (NOTES.md: 0 at +30, 2 at +90, ...).
    #[serde(deserialize_with = "LegAngle::checked")]
    pub angle_deg: f64,
}

/// `[joints]`: the names of a leg's three actuated joints, in the order of the pantograph's
/// q_r (revolute), q_v and q_h (prismatic): the names of the results columns (`q_v[2]`,
/// `u_q_v[2]`), plots, power tables and scenario motions. The description's own joint tables
/// (`[controller.q_r]`, `[friction.q_v]`, ...) keep the thesis symbols.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct JointsTable {
    #[serde(deserialize_with = "pantograph_joint_names")]
    pub names: LegJoints,
}

impl Default for JointsTable {
    fn default() -> Self {
        JointsTable { names: PantographJoint::leg_joints(PantographJoint::ALL.map(|j| j.symbol().to_string())).expect("the thesis symbols are valid joint names") }
    }
}

fn pantograph_joint_names<'de, D: Deserializer<'de>>(d: D) -> Result<LegJoints, D::Error> {
    let names = Vec::<String>::deserialize(d)?;
    let shown = format!("{names:?}");
    let three: [String; 3] = names.try_into().map_err(|n: Vec<String>| Violation::new(&shown, &format!("{} names", n.len()), "three names, for q_r, q_v and q_h").into_error())?;
    PantographJoint::leg_joints(three).map_err(|e| Violation::new(&shown, &e.to_string(), "three distinct identifiers that are not per-leg column names").into_error())
}

/// `[geometry]`, Table 2.1 and Table B.1 (metres).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GeometryTable {
    pub body: BodyGeometryTable,
    pub pantograph: PantographTable,
    pub chassis: ChassisOffsetsTable,
    pub actuators: ActuatorOffsetsTable,
}

/// `[geometry.body]`: main body dimensions (Table B.1).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BodyGeometryTable {
    /// R_rot: body centre to the q_r axis of a leg.
    #[serde(deserialize_with = "Positive::checked")]
    pub r_rot_m: f64,
    /// e_b: plate thickness of the main body.
    #[serde(deserialize_with = "Positive::checked")]
    pub e_b_m: f64,
    /// H: gap between the two rings of the main body.
    #[serde(deserialize_with = "Positive::checked")]
    pub ring_gap_h_m: f64,
}

/// `[geometry.pantograph]`: pantograph dimensions (Table 2.1, Table B.1, Eqs. B.1-B.2).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PantographTable {
    /// L_0 = AC, upper link.
    #[serde(deserialize_with = "Positive::checked")]
    pub l_0_m: f64,
    /// L_1 = BD = CE, left link.
    #[serde(deserialize_with = "Positive::checked")]
    pub l_1_m: f64,
    /// L_2 = DE = BC, lower link.
    #[serde(deserialize_with = "Positive::checked")]
    pub l_2_m: f64,
    /// L_3 = CF, upper joint to foot.
    #[serde(deserialize_with = "Positive::checked")]
    pub l_3_m: f64,
    /// c = AB.
    #[serde(deserialize_with = "Positive::checked")]
    pub c_m: f64,
    /// e: thickness of the leg bodies.
    #[serde(deserialize_with = "Positive::checked")]
    pub e_m: f64,
    /// h: joint-to-extremity distance of the bodies.
    #[serde(deserialize_with = "Positive::checked")]
    pub h_m: f64,
    /// x_G_leg: centre of mass of the leg.
    #[serde(deserialize_with = "Positive::checked")]
    pub x_g_leg_m: f64,
    /// L_G0: centre of mass 0 w.r.t. the bottom of the chassis.
    #[serde(deserialize_with = "Positive::checked")]
    pub l_g0_m: f64,
    /// Eq. B.1: z_foot ~ -6 q_v (for checks).
    pub z_foot_per_q_v: f64,
    /// Eq. B.2: x_foot ~ 7 q_h (for checks).
    pub x_foot_per_q_h: f64,
}

/// `[geometry.chassis]`: leg chassis offsets (Table B.1, Eq. 3.64).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ChassisOffsetsTable {
    #[serde(deserialize_with = "Offset::checked")]
    pub l_x1_m: f64,
    #[serde(deserialize_with = "Offset::checked")]
    pub l_y1_m: f64,
    #[serde(deserialize_with = "Offset::checked")]
    pub l_z1_m: f64,
    #[serde(deserialize_with = "Offset::checked")]
    pub l_xc_m: f64,
    #[serde(deserialize_with = "Offset::checked")]
    pub l_yc_m: f64,
    #[serde(deserialize_with = "Offset::checked")]
    pub l_zc_m: f64,
}

/// `[geometry.actuators]`: rotor body positions (Table B.1).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ActuatorOffsetsTable {
    /// Main body CM to the q_r rotor, along the leg axis.
    #[serde(deserialize_with = "Offset::checked")]
    pub l_x6_m: f64,
    /// C* to the q_v rotor.
    #[serde(deserialize_with = "Offset::checked")]
    pub l_x7_m: f64,
    #[serde(deserialize_with = "Offset::checked")]
    pub l_y7_m: f64,
    #[serde(deserialize_with = "Offset::checked")]
    pub l_z7_m: f64,
    /// C* to the q_h rotor.
    #[serde(deserialize_with = "Offset::checked")]
    pub l_x8_m: f64,
    #[serde(deserialize_with = "Offset::checked")]
    pub l_y8_m: f64,
    #[serde(deserialize_with = "Offset::checked")]
    pub l_z8_m: f64,
}

/// `[inertia]`: masses and inertias, Table B.2.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct InertiaTable {
    /// m_leg as printed (checked against the sum of its parts).
    #[serde(deserialize_with = "Positive::checked")]
    pub leg_mass_kg: f64,
    /// m_tot as printed ("about 34 kg").
    #[serde(deserialize_with = "Positive::checked")]
    pub total_mass_kg: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub rho_duralumin_kg_m3: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub rho_steel_kg_m3: f64,
    /// m_0, I^0.
    pub main_body: RigidBodyTable,
    /// m_1, I^1 (body supporting the leg).
    pub chassis: RigidBodyTable,
    /// m_2, I^2: pantograph link 0 (A-B-C).
    pub pantograph_upper: RigidBodyTable,
    /// m_3, I^3: pantograph link 1 (B-D).
    pub pantograph_left: RigidBodyTable,
    /// m_4, I^4: pantograph link 2 (D-E).
    pub pantograph_lower: RigidBodyTable,
    /// m_5, I^5: pantograph link 3, the leg (C-E-F).
    pub pantograph_leg: RigidBodyTable,
    /// m_rot, I_a^rot, I_e^rot.
    pub rotor: RotorTable,
}

/// `[inertia.<body>]`: mass and central principal inertias of one body (Table B.2).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RigidBodyTable {
    #[serde(deserialize_with = "Positive::checked")]
    pub mass_kg: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub i_xx_kg_m2: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub i_yy_kg_m2: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub i_zz_kg_m2: f64,
}

impl RigidBodyTable {
    /// Principal moments (I_xx, I_yy, I_zz) in kg m^2.
    pub fn principal_moments(&self) -> [f64; 3] {
        [self.i_xx_kg_m2, self.i_yy_kg_m2, self.i_zz_kg_m2]
    }
}

/// `[inertia.rotor]`: a motor rotor, an axisymmetric body (Table B.2).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RotorTable {
    #[serde(deserialize_with = "Positive::checked")]
    pub mass_kg: f64,
    /// I_a^rot, about the shaft axis.
    #[serde(deserialize_with = "Positive::checked")]
    pub i_axial_kg_m2: f64,
    /// I_e^rot, about any axis normal to the shaft.
    #[serde(deserialize_with = "Positive::checked")]
    pub i_equatorial_kg_m2: f64,
}

/// `[reductions]`: global reductions, Table 3.1: theta_motor_dot = n q_dot (Eq. 3.92).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ReductionsTable {
    /// n_r (rad/rad).
    #[serde(deserialize_with = "Positive::checked")]
    pub n_r: f64,
    /// n_v (rad/m).
    #[serde(deserialize_with = "Positive::checked")]
    pub n_v_rad_per_m: f64,
    /// n_h (rad/m).
    #[serde(deserialize_with = "Positive::checked")]
    pub n_h_rad_per_m: f64,
    pub components: ReductionComponentsTable,
}

/// `[reductions.components]`: the transmission elements of Table 3.1.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ReductionComponentsTable {
    #[serde(deserialize_with = "Positive::checked")]
    pub gearbox_r: f64,
    /// Sprocket chain teeth (driven, driving) = 38:12.
    #[serde(deserialize_with = "sprocket_teeth")]
    pub sprocket_r_teeth: [u32; 2],
    #[serde(deserialize_with = "Positive::checked")]
    pub gearbox_v: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub gearbox_h: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub ball_screw_rad_per_m: f64,
}

fn sprocket_teeth<'de, D: Deserializer<'de>>(d: D) -> Result<[u32; 2], D::Error> {
    let teeth = seq::<u32, ToothCount, D>(d, |t| {
        (t.len() != 2)
            .then(|| Violation::new(format!("{t:?}"), "wrong length", "two tooth counts [driven, driving], e.g. [38, 12]"))
    })?;
    Ok(teeth.try_into().unwrap_or_else(|_| unreachable!("the length is checked")))
}

/// `[motor]`: the DC motor, Table 3.4 (the 18 motors are identical).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MotorTable {
    /// u_sat: nominal voltage, also the controller saturation (Section 4.3.4).
    #[serde(deserialize_with = "Positive::checked")]
    pub nominal_voltage_v: f64,
    /// R.
    #[serde(deserialize_with = "Positive::checked")]
    pub resistance_ohm: f64,
    /// L (mH).
    #[serde(deserialize_with = "NonNegative::checked")]
    pub inductance_mh: f64,
    /// k_t (= k_v).
    #[serde(deserialize_with = "Positive::checked")]
    pub torque_constant_nm_per_a: f64,
    /// J_r (g cm^2).
    #[serde(deserialize_with = "Positive::checked")]
    pub rotor_inertia_g_cm2: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub mass_kg: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub no_load_speed_rpm: f64,
}

/// `[driver]`: the motor drive electronics (Sections 2.3.2, 4.4.3, 5.3, 6.4).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DriverTable {
    /// On-board supply, "slightly superior to 12 V" (Section 4.4.3).
    #[serde(deserialize_with = "Positive::checked")]
    pub supply_voltage_v: f64,
    /// Factor on the no-load speed used in the controller design (Section 4.4.3).
    #[serde(deserialize_with = "Fraction::checked")]
    pub velocity_derating: f64,
    /// Per conducting MOSFET of the LMD18200 (Section 6.4).
    #[serde(deserialize_with = "NonNegative::checked")]
    pub mosfet_resistance_ohm: f64,
    pub mosfets_in_series: u32,
    #[serde(deserialize_with = "NonNegative::checked")]
    pub diode_drop_v: f64,
    #[serde(deserialize_with = "PwmBits::checked")]
    pub pwm_bits: u32,
    /// Below this voltage the H-bridge does not switch (Section 5.3); in [0, supply), checked
    /// with the supply.
    pub dead_band_v: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub current_sensor_range_a: f64,
}

/// `[ground]`: foot/ground contact, Table 3.3 (Eqs. 3.72-3.73).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GroundTable {
    /// p_K.
    #[serde(deserialize_with = "Positive::checked")]
    pub p_k: f64,
    /// p_D.
    #[serde(deserialize_with = "Positive::checked")]
    pub p_d: f64,
    /// K_gnd, N/m^p_K.
    #[serde(deserialize_with = "Positive::checked")]
    pub k_gnd_n_per_m_pk: f64,
    /// D_gnd, N s/m^(p_D+1).
    #[serde(deserialize_with = "NonNegative::checked")]
    pub d_gnd_ns_per_m_pd1: f64,
    /// Coulomb coefficient.
    #[serde(deserialize_with = "Positive::checked")]
    pub mu: f64,
    /// v_glim, m/s.
    #[serde(deserialize_with = "Positive::checked")]
    pub v_glim_m_per_s: f64,
}

/// `[controller]`: the joint PI controllers, Table 4.1 and Section 4.4.5.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ControllerTable {
    /// Control sampling time (s).
    #[serde(deserialize_with = "Positive::checked")]
    pub period_s: f64,
    /// Encoder impulses per motor revolution.
    #[serde(deserialize_with = "AtLeastOne::checked")]
    pub encoder_impulses_per_rev: u32,
    pub q_r: RotationalPiTable,
    pub q_v: LinearPiTable,
    pub q_h: LinearPiTable,
}

/// The table of one joint's PI controller (Table 4.1): the gain K (Eq. 4.18), named `$gain`
/// after its unit, the integral time T_i and the design figures of Section 4.4.5.
macro_rules! pi_table {
    ($(#[$doc:meta])* $name:ident, $gain:ident) => {
        $(#[$doc])*
        #[derive(Clone, Debug, Deserialize, PartialEq)]
        #[serde(deny_unknown_fields)]
        pub struct $name {
            #[serde(deserialize_with = "Positive::checked")]
            pub $gain: f64,
            #[serde(deserialize_with = "Positive::checked")]
            pub t_i_s: f64,
            #[serde(deserialize_with = "NonNegative::checked")]
            pub bandwidth_hz: f64,
            #[serde(deserialize_with = "PhaseMargin::checked")]
            pub phase_margin_deg: f64,
            #[serde(deserialize_with = "NonNegative::checked")]
            pub overshoot_percent: f64,
        }
    };
}

pi_table!(
    /// `[controller.q_r]`: PI gains of q_r (Table 4.1), K in V/rad.
    RotationalPiTable,
    k_v_per_rad
);

pi_table!(
    /// `[controller.q_v]`, `[controller.q_h]`: PI gains of q_v or q_h (Table 4.1), K in V/m.
    LinearPiTable,
    k_v_per_m
);

/// `[joint_ranges]`: joint ranges, Table 5.2.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct JointRangesTable {
    #[serde(deserialize_with = "HalfTurn::interval")]
    pub q_r_deg: Interval,
    #[serde(deserialize_with = "Positive::interval")]
    pub q_v_m: Interval,
    #[serde(deserialize_with = "NonNegative::interval")]
    pub q_h_m: Interval,
    pub identification_velocities: IdentificationVelocitiesTable,
}

/// `[joint_ranges.identification_velocities]`: constant-velocity sweeps of the friction
/// identification (Table 5.2, lower half).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct IdentificationVelocitiesTable {
    pub q_r_dot_deg_per_s: Sweep,
    pub q_v_dot_mm_per_s: Sweep,
    pub q_h_dot_mm_per_s: Sweep,
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

/// `[friction]`: joint friction (Chapter 5, Section 6.1).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct FrictionTable {
    pub negative_viscous: NegativeViscousRule,
    pub missing_stiction: MissingStictionRule,
    /// Load case of Table 5.4 used for the vertical stiction in simulation (10 kg), one of the
    /// `friction.q_v.stiction` loads.
    pub vertical_stiction_load_kg: f64,
    pub missing_a1_minus: MissingA1MinusRule,
    /// The reductions of the drives the friction tables were identified on, when they are not
    /// this robot's (`[reductions]`): a drive variant of AMRU5 with other gear ratios (absent
    /// on AMRU5 itself). See [`IdentifiedReductionsTable`].
    #[serde(default)]
    pub identified_with_reductions: Option<IdentifiedReductionsTable>,
    pub lugre: LuGreTable,
    /// The transmission efficiencies of the efficiency law (`friction = "efficiency"`); ideal
    /// transmissions (Eq. 6.1 alone) where left out.
    #[serde(default)]
    pub efficiency: EfficiencyTable,
    pub q_r: RotationalFrictionTable,
    pub q_v: VerticalFrictionTable,
    pub q_h: HorizontalFrictionTable,
}

/// `[friction.efficiency]`: the forward and backward efficiencies of each joint kind's
/// transmission, every leg alike ([`crate::physics::Efficiency`]; the no-load friction is the
/// joint's Table 5.3 dry/viscous friction).
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EfficiencyTable {
    #[serde(default)]
    pub q_r: TransmissionEfficiency,
    #[serde(default)]
    pub q_v: TransmissionEfficiency,
    #[serde(default)]
    pub q_h: TransmissionEfficiency,
}

/// The two efficiencies of a transmission, each in (0, 1]; 1 (ideal) where left out.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TransmissionEfficiency {
    /// η_f: the motor drives the load.
    #[serde(default = "ideal", deserialize_with = "Fraction::checked")]
    pub eta_forward: f64,
    /// η_b: the load drives the motor.
    #[serde(default = "ideal", deserialize_with = "Fraction::checked")]
    pub eta_backward: f64,
}

impl Default for TransmissionEfficiency {
    fn default() -> Self {
        TransmissionEfficiency { eta_forward: ideal(), eta_backward: ideal() }
    }
}

/// The efficiency of a lossless transmission.
pub(super) fn ideal() -> f64 {
    1.0
}

/// `[friction.identified_with_reductions]`: the global reductions n_0 of the drives the
/// friction of Tables 5.3-5.5 was measured on. The friction is then taken as a torque at the
/// motor shaft (the motor and the gear train, reflected to the joint through n_0) and brought
/// to the joint through this robot's reductions n: the dry friction, the breakaway and the
/// load coefficients scale by n/n_0, the viscous coefficients (a viscous torque at the motor,
/// n_0 b n_0 q') by (n/n_0)^2; the LuGre bristle parameters are kept.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct IdentifiedReductionsTable {
    /// n_0 of q_r (rad/rad).
    #[serde(deserialize_with = "Positive::checked")]
    pub n_r: f64,
    /// n_0 of q_v (rad/m).
    #[serde(deserialize_with = "Positive::checked")]
    pub n_v_rad_per_m: f64,
    /// n_0 of q_h (rad/m).
    #[serde(deserialize_with = "Positive::checked")]
    pub n_h_rad_per_m: f64,
}

/// `[friction.lugre]`: LuGre parameters, Table 6.1, Eqs. 3.84 and 6.1 (same numbers for the
/// three joint kinds; units N/m, N s/m, m/s for q_v and q_h, Nm/rad, Nm s/rad, rad/s for q_r).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LuGreTable {
    /// sigma_0, bristle stiffness (1e9, NOTES.md).
    #[serde(deserialize_with = "Positive::checked")]
    pub sigma_0: f64,
    /// sigma_1, bristle damping.
    #[serde(deserialize_with = "NonNegative::checked")]
    pub sigma_1: f64,
    /// Stribeck velocity of the vertical joint (m/s).
    #[serde(deserialize_with = "Positive::checked")]
    pub q_st_v_m_per_s: f64,
    /// v_d of Eq. 3.84.
    #[serde(deserialize_with = "Positive::checked")]
    pub v_d: f64,
    /// delta_d of Eq. 3.84.
    #[serde(deserialize_with = "Positive::checked")]
    pub delta_d: f64,
    /// epsilon of Eq. 6.1.
    #[serde(deserialize_with = "Positive::checked")]
    pub dry_viscous_epsilon: f64,
}

/// The table of one joint kind's friction: the per-leg dry and viscous friction of Table 5.3
/// (the field names carry the units), then the joint's own tables.
macro_rules! joint_friction_table {
    ($(#[$doc:meta])* $name:ident { $tau_f_d_plus:ident, $f_v_plus:ident, $tau_f_d_minus:ident, $f_v_minus:ident $(, $(#[$m:meta])* $extra:ident: $ty:ty)* }) => {
        $(#[$doc])*
        #[derive(Clone, Debug, Deserialize, PartialEq)]
        #[serde(deny_unknown_fields)]
        pub struct $name {
            /// tau_f_d^+ > 0.
            #[serde(deserialize_with = "Positive::per_leg")]
            pub $tau_f_d_plus: PerLeg,
            /// f_v^+ as measured (negative values are handled by the Section 6.1 rule).
            #[serde(deserialize_with = "Finite::per_leg")]
            pub $f_v_plus: PerLeg,
            /// tau_f_d^- < 0.
            #[serde(deserialize_with = "Negative::per_leg")]
            pub $tau_f_d_minus: PerLeg,
            /// f_v^- as measured.
            #[serde(deserialize_with = "Finite::per_leg")]
            pub $f_v_minus: PerLeg,
            $($(#[$m])* pub $extra: $ty,)*
        }
    };
}

joint_friction_table!(
    /// `[friction.q_r]`: Table 5.3, rotational joints (Nm, Nm s/rad).
    RotationalFrictionTable { tau_f_d_plus_nm, f_v_plus_nms, tau_f_d_minus_nm, f_v_minus_nms }
);

joint_friction_table!(
    /// `[friction.q_v]`: Table 5.3 and Table 5.4, vertical joints (N, N s/m).
    VerticalFrictionTable {
        tau_f_d_plus_n,
        f_v_plus_ns_per_m,
        tau_f_d_minus_n,
        f_v_minus_ns_per_m,
        /// Table 5.4, one entry per foot load.
        stiction: Vec<StictionCaseTable>
    }
);

/// `[[friction.q_v.stiction]]`: breakaway forces of the vertical joints for one foot load
/// (Table 5.4, N).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StictionCaseTable {
    #[serde(deserialize_with = "NonNegative::checked")]
    pub load_kg: f64,
    #[serde(deserialize_with = "Positive::per_leg_maybe")]
    pub tau_f_s_plus_n: PerLegMaybe,
    #[serde(deserialize_with = "Negative::per_leg_maybe")]
    pub tau_f_s_minus_n: PerLegMaybe,
}

joint_friction_table!(
    /// `[friction.q_h]`: Table 5.3 and Table 5.5, horizontal joints (N, N s/m).
    HorizontalFrictionTable {
        tau_f_d_plus_n,
        f_v_plus_ns_per_m,
        tau_f_d_minus_n,
        f_v_minus_ns_per_m,
        /// Table 5.5.
        load_dependence: LoadDependenceTable
    }
);

/// `[friction.q_h.load_dependence]`: Table 5.5, coefficients of Eq. 5.12 (load x in kg).
/// Section 5.4: a_2 and a_1 of one sense share the sign of a_0 so that the friction grows
/// with the load.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LoadDependenceTable {
    #[serde(deserialize_with = "NonNegative::per_leg")]
    pub a_2_plus_n_per_kg2: PerLeg,
    #[serde(deserialize_with = "NonPositive::per_leg")]
    pub a_2_minus_n_per_kg2: PerLeg,
    #[serde(deserialize_with = "NonNegative::per_leg_maybe")]
    pub a_1_plus_n_per_kg: PerLegMaybe,
    #[serde(deserialize_with = "NonPositive::per_leg_maybe")]
    pub a_1_minus_n_per_kg: PerLegMaybe,
}

/// `[monte_carlo]`: Monte Carlo friction distributions, Section 6.5 and Table 6.7.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MonteCarloTable {
    #[serde(deserialize_with = "AtLeastOne::checked")]
    pub runs_per_velocity: u32,
    /// Samples outside +-truncation_sigmas sigma are redrawn.
    #[serde(deserialize_with = "Positive::checked")]
    pub truncation_sigmas: f64,
    #[serde(deserialize_with = "velocities")]
    pub velocities_m_per_s: Vec<f64>,
    #[serde(deserialize_with = "LegIndex::list")]
    pub excluded_legs_a_2_plus: Vec<usize>,
    #[serde(deserialize_with = "LegIndex::list")]
    pub excluded_legs_a_2_minus: Vec<usize>,
    #[serde(deserialize_with = "LegIndex::list")]
    pub excluded_legs_a_1_plus: Vec<usize>,
    #[serde(deserialize_with = "LegIndex::list")]
    pub excluded_legs_a_1_minus: Vec<usize>,
    pub q_r: MonteCarloRotationTable,
    pub q_v: MonteCarloVerticalTable,
    pub q_h: MonteCarloHorizontalTable,
}

pub(super) fn velocities<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
    seq::<f64, Positive, D>(d, |v| v.is_empty().then(|| Violation::new("[]", "empty", "at least one velocity > 0")))
}

/// `[monte_carlo.q_r]`: Table 6.7, rotation (Nm, Nm s/rad).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MonteCarloRotationTable {
    #[serde(deserialize_with = "Positive::gaussian")]
    pub tau_f_d_plus_nm: Gaussian,
    #[serde(deserialize_with = "NonNegative::gaussian")]
    pub f_v_plus_nms: Gaussian,
    #[serde(deserialize_with = "Negative::gaussian")]
    pub tau_f_d_minus_nm: Gaussian,
    #[serde(deserialize_with = "NonNegative::gaussian")]
    pub f_v_minus_nms: Gaussian,
}

/// `[monte_carlo.q_v]`: Table 6.7, vertical (N, N s/m).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MonteCarloVerticalTable {
    #[serde(deserialize_with = "Positive::gaussian")]
    pub tau_f_d_plus_n: Gaussian,
    #[serde(deserialize_with = "NonNegative::gaussian")]
    pub f_v_plus_ns_per_m: Gaussian,
    #[serde(deserialize_with = "Negative::gaussian")]
    pub tau_f_d_minus_n: Gaussian,
    #[serde(deserialize_with = "NonNegative::gaussian")]
    pub f_v_minus_ns_per_m: Gaussian,
}

/// `[monte_carlo.q_h]`: Table 6.7, horizontal (N; viscous neglected).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MonteCarloHorizontalTable {
    #[serde(deserialize_with = "Positive::gaussian")]
    pub tau_f_d_plus_n: Gaussian,
    #[serde(deserialize_with = "Negative::gaussian")]
    pub tau_f_d_minus_n: Gaussian,
}

/// `[series_elastic]`: the spring of each joint kind's series-elastic transmission, between the
/// gear output (the ball-screw nut, the q_r sprocket) and the joint, the same on every leg.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SeriesElasticTable {
    pub q_r: RotationalSpringTable,
    pub q_v: LinearSpringTable,
    pub q_h: LinearSpringTable,
}

/// `[series_elastic.q_r]`: a torsional spring and its damping.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RotationalSpringTable {
    #[serde(deserialize_with = "Positive::checked")]
    pub stiffness_nm_per_rad: f64,
    #[serde(deserialize_with = "NonNegative::checked")]
    pub damping_nms_per_rad: f64,
}

/// `[series_elastic.q_v]`, `[series_elastic.q_h]`: a linear spring and its damping.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LinearSpringTable {
    #[serde(deserialize_with = "Positive::checked")]
    pub stiffness_n_per_m: f64,
    #[serde(deserialize_with = "NonNegative::checked")]
    pub damping_ns_per_m: f64,
}
