//! The modelling choices of a simulation: the joint friction model (Section 6.1), where the
//! joint position controllers live (Section 4.5 or Eq. 3.93-3.97), the ground, supply and the
//! identification rig's stand and foot load.

use crate::description::RobotDescription;
use crate::physics::GroundContact;

/// Joint friction model of a simulation (Section 6.1: the three cases compared in Chapter 6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FrictionModel {
    /// `"none"`: no joint friction.
    None,
    /// `"dry_viscous"`: dry and viscous friction regularised around zero velocity (Eq. 6.1).
    DryViscous,
    /// `"lugre"`: the LuGre model with one bristle state per joint (Eq. 3.83-3.87).
    #[serde(rename = "lugre")]
    LuGre,
    /// `"efficiency"`: the no-load friction of Eq. 6.1 plus a loss that follows the torque the
    /// transmission carries, with a forward and a backward efficiency
    /// ([`crate::physics::Efficiency`]).
    Efficiency,
}

impl FrictionModel {
    /// The name used in scenario files: `none`, `dry_viscous`, `lugre` or `efficiency`.
    pub fn name(self) -> &'static str {
        match self {
            FrictionModel::None => "none",
            FrictionModel::DryViscous => "dry_viscous",
            FrictionModel::LuGre => "lugre",
            FrictionModel::Efficiency => "efficiency",
        }
    }
}

/// Where the joint position controllers live.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum JointControl {
    /// Digital PI controllers outside the model at the control period (Eq. 4.18-4.20): the
    /// model's inputs are the motor voltages (the 42-DOF model of Section 4.5).
    Digital,
    /// Continuous PID controllers inside the model (Eq. 3.93-3.97) with the gains K, T_I of the
    /// description: 36 more states, and the model's inputs are the joint references.
    ContinuousPid { t_d: f64, n: f64, omega_0: f64 },
}

/// The modelling choices of a simulation.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelOptions {
    pub friction: FrictionModel,
    /// Load-dependent dry friction of the horizontal joints (Eq. 5.12, Section 6.4.4).
    pub load_dependence: bool,
    /// Keep the motor inductance and the currents as states (Eq. 3.91) instead of Eq. 4.4.
    pub inductance: bool,
    /// Ground contact parameters (Table 3.3 unless overridden).
    pub ground: GroundContact,
    /// Supply voltage at the H-bridges (V).
    pub supply_voltage: f64,
    pub control: JointControl,
    /// The body held still on a stand (the identification rig of Section 5.2, "leg in the
    /// air"): the six body rows of the residual become q''_body = 0.
    pub stand: bool,
    /// Upward force on each foot (N), the load of the identification rig (Fig. 5.6: 10 kg at
    /// the foot playing the role of the ground reaction, Sections 5.3-5.4). It acts like a
    /// ground force: it is added to the foot force and to the leg load of Eq. 5.12.
    pub foot_load: [f64; 6],
}

impl ModelOptions {
    /// The description's ground, supply and the given friction model; no inductance (Section 4.5).
    pub fn from_description(d: &RobotDescription, friction: FrictionModel) -> Self {
        let g = &d.ground;
        ModelOptions {
            friction,
            load_dependence: false,
            inductance: false,
            ground: GroundContact { k_gnd: g.k_gnd_n_per_m_pk, d_gnd: g.d_gnd_ns_per_m_pd1, p_k: g.p_k, p_d: g.p_d, mu: g.mu, v_glim: g.v_glim_m_per_s, foot_radius: 0.0 },
            supply_voltage: d.driver.supply_voltage_v,
            control: JointControl::Digital,
            stand: false,
            foot_load: [0.0; 6],
        }
    }
}
