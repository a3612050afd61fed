//! The parts a robot model is assembled from ([`super::RobotModel::assemble`]), whatever the legs,
//! and how a pantograph robot description gives them.

use std::ops::RangeInclusive;

use nalgebra::Vector3;

use super::{FrictionModel, ModelOptions};
use crate::control::{Encoder, PositionServo};
use crate::description::{JointFrictionParameters, PiGains, RobotDescription};
use crate::hexapod::{LegDynamics, LegJoints, Mechanics, MechanicsParameters, PantographJoint, JOINTS};
use crate::mbs::{self, BodyId};
use crate::physics::{DcMotor, FrictionElement, JointFriction, LuGre, SeriesSpring, SteadyState};

/// A robot's mechanism and drives, whatever its legs (the pantograph of the description file,
/// serial legs): what [`super::RobotModel::assemble`] makes one residual system of.
#[derive(Clone)]
pub struct RobotParts {
    /// The multibody model on the coordinates of Eq. 3.51.
    pub multibody: mbs::Model,
    /// Each foot: its body and the foot point in that body's frame.
    pub feet: [(BodyId, Vector3<f64>); 6],
    /// The names and kinds of a leg's joints.
    pub joints: LegJoints,
    /// Per joint k = 3 leg + j.
    pub motors: [DcMotor; JOINTS],
    pub friction: [FrictionElement; JOINTS],
    /// Joint strokes (limit switches).
    pub strokes: [RangeInclusive<f64>; JOINTS],
    /// PI gains of each joint, for the continuous controllers of [`super::JointControl::ContinuousPid`].
    pub pi_gains: [PiGains; JOINTS],
    /// The position sensor of each joint (AMRU5: the motor encoders of Section 2.3.2).
    pub encoders: [Encoder; JOINTS],
    /// Position servos driving the motors (their own loop, goal positions as inputs), or none:
    /// the motors take the master's voltages.
    pub servos: Option<[PositionServo; JOINTS]>,
    /// Series-elastic transmissions (a spring between each gear output and its joint), or none:
    /// rigid drives.
    pub series: Option<[SeriesElastic; JOINTS]>,
}

/// The series-elastic transmission of one joint: its spring, and the inertia of the drive side
/// (the motor, gear and nut, at the drive coordinate θ in joint units), the rotor's axial
/// inertia reflected through the reduction, I_a n² (kg or kg m²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeriesElastic {
    pub spring: SeriesSpring,
    pub drive_inertia: f64,
}

impl RobotParts {
    /// The parts of a (pantograph) robot description: its 49-body mechanics (Eq. 3.51-3.71),
    /// the DC motors of Table 3.4 with the reductions of Table 3.1, the friction of Section 6.1,
    /// the strokes of Table 5.2 and the PI gains of Table 4.1.
    ///
    /// With series-elastic transmissions (`[series_elastic]`) the rotors turn with the drive
    /// coordinates, not the joints: their axial inertia leaves the multibody model (a rotor
    /// without it: its spin carries no inertia, Eq. 3.38) and becomes the drive side's, I_a n².
    /// INTERPRETATION: the coupling of a rotor's spin with its carrier's rotation, I_a n θ'
    /// (a·ω), is dropped with it (of order 1/n of the rotor's own energy: 6e-4 for q_r).
    pub fn from_description(d: &RobotDescription, options: &ModelOptions) -> Self {
        let mut parameters = MechanicsParameters::from_description(d);
        let series = d.series_elastic.is_some().then(|| {
            std::array::from_fn(|k| {
                let joint = PantographJoint::ALL[k % 3];
                SeriesElastic { spring: d.series_spring(joint).expect("[series_elastic] has every joint"), drive_inertia: parameters.rotor_axial * d.reduction(joint).powi(2) }
            })
        });
        if series.is_some() {
            parameters.rotor_axial = 0.0;
        }
        let mechanics = Mechanics::new(&parameters).expect("a validated description builds a valid mechanics");
        let motor = |joint: PantographJoint| DcMotor {
            r: d.motor.resistance_ohm,
            r_bridge: d.driver.series_resistance_ohm(),
            l: d.motor.inductance_h(),
            k_t: d.motor.torque_constant_nm_per_a,
            n: d.reduction(joint),
            inductance: options.inductance,
        };
        let LegDynamics { model, feet } = mechanics.into();
        RobotParts {
            multibody: model,
            feet,
            joints: d.joints.names.clone(),
            motors: std::array::from_fn(|k| motor(PantographJoint::ALL[k % 3])),
            friction: std::array::from_fn(|k| friction_element(d, k / 3, PantographJoint::ALL[k % 3], options)),
            strokes: std::array::from_fn(|k| {
                let (lo, hi) = d.joint_range(PantographJoint::ALL[k % 3]);
                lo..=hi
            }),
            pi_gains: std::array::from_fn(|k| d.pi_gains(PantographJoint::ALL[k % 3])),
            encoders: std::array::from_fn(|k| Encoder { counts_per_rev: d.controller.encoder_impulses_per_rev, n: d.reduction(PantographJoint::ALL[k % 3]) }),
            servos: None,
            series,
        }
    }
}

impl From<RobotParts> for LegDynamics {
    fn from(p: RobotParts) -> Self {
        LegDynamics { model: p.multibody, feet: p.feet }
    }
}

fn friction_element(d: &RobotDescription, leg: usize, joint: PantographJoint, options: &ModelOptions) -> FrictionElement {
    // The description's parameters carry the thesis names of the laws' parameters.
    let parameters = d.friction(leg, joint);
    let JointFrictionParameters { tau_f_d_plus, tau_f_d_minus, tau_f_s_plus, tau_f_s_minus, f_v_plus, f_v_minus, q_st, sigma_0, sigma_1, v_d, load_dependence, .. } = parameters;
    let law = match options.friction {
        FrictionModel::None => JointFriction::None,
        FrictionModel::DryViscous => JointFriction::DryViscous(parameters.dry_viscous()),
        FrictionModel::LuGre => {
            // Section 6.1: g of Eq. 6.2-6.3 (rotation), 6.4 (vertical, with stiction) and 6.5
            // (horizontal, viscous effects neglected).
            let (steady, f_v_plus, f_v_minus) = match (joint, q_st) {
                (PantographJoint::Vertical, Some(qd_st)) => (SteadyState::Stribeck { tau_f_d_plus, tau_f_d_minus, tau_f_s_plus, tau_f_s_minus, qd_st }, f_v_plus, f_v_minus),
                (PantographJoint::Horizontal, _) => (SteadyState::Dry { tau_f_d_plus, tau_f_d_minus }, 0.0, 0.0),
                _ => (SteadyState::Dry { tau_f_d_plus, tau_f_d_minus }, f_v_plus, f_v_minus),
            };
            JointFriction::LuGre(LuGre { sigma_0, sigma_1, v_d, f_v_plus, f_v_minus, steady })
        }
        FrictionModel::Efficiency => JointFriction::Efficiency(parameters.efficiency()),
    };
    let element = FrictionElement::new(law);
    match (options.load_dependence, options.friction, load_dependence) {
        (true, FrictionModel::DryViscous | FrictionModel::LuGre, Some(load)) => element.with_load(load),
        _ => element,
    }
}

