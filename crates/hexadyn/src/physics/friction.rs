//! Joint friction (thesis Section 3.4.3, Chapter 5 and Section 6.1).
//!
//! Sign convention: every law returns the friction torque τ_f that opposes the motion, as in the
//! thesis (Eq. 3.79, 3.87, 6.1: τ_f > 0 when q' > 0); the generalized force the friction applies
//! to the joint is -τ_f. For a translational joint the "torque" is a force in N and q' is in m/s
//! (footnote of Eq. 3.86).
//!
//! Direction-dependent parameters (Section 6.1): the `_plus` parameters hold for q' ≥ 0 and the
//! `_minus` ones for q' < 0. As in Tables 5.3-5.5, the negative-direction dry friction τ_f,d^-,
//! stiction τ_f,s^- and load coefficients a_2^-, a_1^- are negative numbers, while both viscous
//! coefficients f_v^± are non-negative (Eq. 6.1 adds f_v^- q' with q' < 0).
//!
//! Non-smooth points: |q'| and the switch between `_plus` and `_minus` parameters make the laws
//! non-differentiable at q' = 0 (Eq. 6.1 also at q' = ±ε); the values are continuous there.
//! Every partial derivative returned at such a point is the one-sided derivative of the branch
//! that owns the point: q' = 0 belongs to the q' ≥ 0 branch (right derivative, d|q'|/dq' = +1 with
//! the `_plus` parameters) and q' = ±ε to the linear zone of Eq. 6.1.
//!
//! Per joint, the quantities worth recording are the friction torque ([`FrictionTorque::tau`]),
//! the bristle state z = q'_z and the load fed to [`FrictionElement`].

use serde::{Deserialize, Serialize};

// AMRU5 values of the thesis, for the unit tests of this module only: the engine takes every
// parameter from the robot description (robots/amru5.toml).
/// Half width ε of the linear zone of Eq. 6.1 (rad/s or m/s), Section 6.1.
#[cfg(test)]
const LINEAR_ZONE: f64 = 1e-4;
/// Bristle stiffness σ0 of Table 6.1 (Nm/rad or N/m; the table's "1e-9" lost its sign).
#[cfg(test)]
const BRISTLE_STIFFNESS: f64 = 1e9;
/// Bristle damping σ1 of Table 6.1 (Nms/rad or Ns/m).
#[cfg(test)]
const BRISTLE_DAMPING: f64 = 0.02;
/// Stribeck velocity q'_st of the vertical joints, Table 6.1 (m/s).
#[cfg(test)]
const STRIBECK_VELOCITY: f64 = 1e-4;
/// Weight of one kilogram (N/kg): the foot loads of Section 5.4 are masses hung at the foot
/// (Section 5.3 uses 9.81 m/s²), so a load force F enters Eq. 5.12 as x = F / LOAD_GRAVITY kg.
pub const LOAD_GRAVITY: f64 = 9.81;

/// A friction parameter outside its physical range.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("invalid friction parameter {parameter} = {value}: expected {expected}")]
pub struct FrictionError {
    pub parameter: &'static str,
    pub value: f64,
    pub expected: &'static str,
}

fn require(parameter: &'static str, value: f64, ok: bool, expected: &'static str) -> Result<(), FrictionError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(FrictionError { parameter, value, expected })
    }
}

/// Whether q' uses the `_plus` parameters (Section 6.1: q' ≥ 0).
fn positive(qd: f64) -> bool {
    qd >= 0.0
}

/// exp(−r²), the Gaussian decay of the Stribeck curve (Eq. 3.82) and of σ1 (Eq. 3.84). Far from
/// zero velocity r² is huge (r = q'/q'_St with q'_St = 1e-4 m/s) and libm's exp takes its slow
/// underflow path; beyond r² = 746 the double result is exactly 0, returned directly.
fn gaussian(r: f64) -> f64 {
    let x = r * r;
    if x > 746.0 {
        0.0
    } else {
        (-x).exp()
    }
}

/// Dry/viscous friction with a linear zone around zero velocity, Eq. 6.1.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DryViscous {
    /// τ_f,d^+ ≥ 0 (Nm or N).
    pub tau_f_d_plus: f64,
    /// τ_f,d^- ≤ 0 (Nm or N).
    pub tau_f_d_minus: f64,
    /// f_v^+ ≥ 0 (Nms/rad or Ns/m).
    pub f_v_plus: f64,
    /// f_v^- ≥ 0 (Nms/rad or Ns/m).
    pub f_v_minus: f64,
    /// Half width ε > 0 of the linear zone (rad/s or m/s).
    pub epsilon: f64,
}

impl DryViscous {
    /// Eq. 6.1 with ε = LINEAR_ZONE, from the identified parameters of Table 5.3; negative
    /// (non-physical) viscous coefficients are forced to zero as in Section 6.1.
    #[cfg(test)]
    fn new(tau_f_d_plus: f64, tau_f_d_minus: f64, f_v_plus: f64, f_v_minus: f64) -> Result<Self, FrictionError> {
        let law = DryViscous { tau_f_d_plus, tau_f_d_minus, f_v_plus: f_v_plus.max(0.0), f_v_minus: f_v_minus.max(0.0), epsilon: LINEAR_ZONE };
        law.validate()?;
        Ok(law)
    }

    pub fn validate(&self) -> Result<(), FrictionError> {
        require("tau_f_d_plus", self.tau_f_d_plus, self.tau_f_d_plus >= 0.0, ">= 0")?;
        require("tau_f_d_minus", self.tau_f_d_minus, self.tau_f_d_minus <= 0.0, "<= 0 (negative-direction dry friction, Table 5.3)")?;
        require("f_v_plus", self.f_v_plus, self.f_v_plus >= 0.0, ">= 0")?;
        require("f_v_minus", self.f_v_minus, self.f_v_minus >= 0.0, ">= 0")?;
        require("epsilon", self.epsilon, self.epsilon > 0.0, "> 0")
    }

    /// Dry friction of the direction of q'.
    fn dry(&self, qd: f64) -> f64 {
        if positive(qd) {
            self.tau_f_d_plus
        } else {
            self.tau_f_d_minus
        }
    }

    /// τ_f(q') and ∂τ_f/∂q', Eq. 6.1.
    pub fn torque(&self, qd: f64) -> (f64, f64) {
        let (tau, dtau_dqd, _) = self.torque_with_dry(qd, self.dry(qd));
        (tau, dtau_dqd)
    }

    /// Eq. 6.1 with the dry friction `tau_d` of the direction of q' (unloaded or Eq. 5.12):
    /// (τ_f, ∂τ_f/∂q', ∂τ_f/∂τ_d).
    ///
    /// The linear zone joins the origin to the value of the outer branch at q' = ±ε, so that τ_f
    /// is continuous. Eq. 6.1 prints the slope (τ_f,d^- + f_v^- ε)/ε for -ε ≤ q' < 0, which with
    /// the negative τ_f,d^- of Table 5.3 would reverse the friction in that zone; the continuous
    /// slope is (f_v^- ε - τ_f,d^-)/ε.
    fn torque_with_dry(&self, qd: f64, tau_d: f64) -> (f64, f64, f64) {
        let eps = self.epsilon;
        if qd > eps {
            (tau_d + self.f_v_plus * qd, self.f_v_plus, 1.0)
        } else if qd >= 0.0 {
            let slope = (tau_d + self.f_v_plus * eps) / eps;
            (slope * qd, slope, qd / eps)
        } else if qd >= -eps {
            let slope = (self.f_v_minus * eps - tau_d) / eps;
            (slope * qd, slope, -qd / eps)
        } else {
            (tau_d + self.f_v_minus * qd, self.f_v_minus, 1.0)
        }
    }
}

/// Steady-state function of the LuGre model, σ0 g(q') (Section 6.1).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum SteadyState {
    /// Dry friction only, g = τ_f,d^+ / σ0 for q' ≥ 0 and -τ_f,d^- / σ0 for q' < 0: the
    /// rotational joints (Eq. 6.2-6.3) and the horizontal joints (Eq. 5.4, 6.5).
    Dry { tau_f_d_plus: f64, tau_f_d_minus: f64 },
    /// With the Stribeck effect, g = |τ_f,d + (τ_f,s - τ_f,d) exp(-(q'/q'_st)²)| / σ0: the
    /// vertical joints (Eq. 3.86, 6.4). τ_f,s^± are the stiction of Table 5.4 (10 kg load; the
    /// unloaded dry friction where Table 5.4 has no value, Section 6.1).
    Stribeck { tau_f_d_plus: f64, tau_f_d_minus: f64, tau_f_s_plus: f64, tau_f_s_minus: f64, qd_st: f64 },
}

impl SteadyState {
    pub fn validate(&self) -> Result<(), FrictionError> {
        match *self {
            SteadyState::Dry { tau_f_d_plus, tau_f_d_minus } => {
                require("tau_f_d_plus", tau_f_d_plus, tau_f_d_plus > 0.0, "> 0 (g must be positive)")?;
                require("tau_f_d_minus", tau_f_d_minus, tau_f_d_minus < 0.0, "< 0 (g must be positive)")
            }
            SteadyState::Stribeck { tau_f_d_plus, tau_f_d_minus, tau_f_s_plus, tau_f_s_minus, qd_st } => {
                require("tau_f_d_plus", tau_f_d_plus, tau_f_d_plus > 0.0, "> 0 (g must be positive)")?;
                require("tau_f_d_minus", tau_f_d_minus, tau_f_d_minus < 0.0, "< 0 (g must be positive)")?;
                require("tau_f_s_plus", tau_f_s_plus, tau_f_s_plus > 0.0, "> 0 (g must be positive)")?;
                require("tau_f_s_minus", tau_f_s_minus, tau_f_s_minus < 0.0, "< 0 (g must be positive)")?;
                require("qd_st", qd_st, qd_st > 0.0, "> 0")
            }
        }
    }

    /// Unloaded dry friction τ_f,d of the direction of q'.
    pub fn dry(&self, qd: f64) -> f64 {
        let (SteadyState::Dry { tau_f_d_plus, tau_f_d_minus } | SteadyState::Stribeck { tau_f_d_plus, tau_f_d_minus, .. }) = *self;
        if positive(qd) {
            tau_f_d_plus
        } else {
            tau_f_d_minus
        }
    }

    /// Signed steady-state friction s(q') = σ0 g(q') sgn(q') for the dry friction `tau_d` of the
    /// direction of q': (s, ∂s/∂q', ∂s/∂τ_d). Its sign is the direction's (positive for q' ≥ 0).
    fn level(&self, qd: f64, tau_d: f64) -> (f64, f64, f64) {
        match *self {
            SteadyState::Dry { .. } => (tau_d, 0.0, 1.0),
            SteadyState::Stribeck { tau_f_s_plus, tau_f_s_minus, qd_st, .. } => {
                let tau_s = if positive(qd) { tau_f_s_plus } else { tau_f_s_minus };
                let r = qd / qd_st;
                let e = gaussian(r);
                (tau_d + (tau_s - tau_d) * e, (tau_s - tau_d) * e * (-2.0 * r / qd_st), 1.0 - e)
            }
        }
    }
}

/// The LuGre model in the residual form of the thesis (Eq. 3.85-3.87, Section 6.1): the bristle
/// deflection is the first-order state z = q'_z, z' = q''_z.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LuGre {
    /// Bristle stiffness σ0 > 0 (Nm/rad or N/m).
    pub sigma_0: f64,
    /// Bristle damping σ1 ≥ 0 at zero velocity (Nms/rad or Ns/m).
    pub sigma_1: f64,
    /// Velocity v_d > 0 of the vanishing damping σ1(q') = σ1 exp(-(q'/v_d)²), Eq. 3.84
    /// (`f64::INFINITY` keeps σ1 constant).
    pub v_d: f64,
    /// f_v^+ ≥ 0 (Nms/rad or Ns/m).
    pub f_v_plus: f64,
    /// f_v^- ≥ 0 (Nms/rad or Ns/m).
    pub f_v_minus: f64,
    pub steady: SteadyState,
}

impl LuGre {
    /// The smaller steady-state bristle deflection while sliding, min(τ_f,d^+, −τ_f,d^-) / σ0
    /// (Eq. 3.80 with g of Eq. 6.2-6.5 away from zero velocity): the size of z in motion.
    pub fn sliding_deflection(&self) -> f64 {
        self.steady.dry(1.0).min(-self.steady.dry(-1.0)) / self.sigma_0
    }

    /// The LuGre law with σ0, σ1 of Table 6.1 and v_d = q'_st of Table 6.1 (Olsson's choice of
    /// v_d "in relation to the Stribeck velocity", Section 3.4.3; the thesis gives no value).
    /// Negative (non-physical) viscous coefficients are forced to zero as in Section 6.1.
    #[cfg(test)]
    fn new(steady: SteadyState, f_v_plus: f64, f_v_minus: f64) -> Result<Self, FrictionError> {
        let law = LuGre {
            sigma_0: BRISTLE_STIFFNESS,
            sigma_1: BRISTLE_DAMPING,
            v_d: STRIBECK_VELOCITY,
            f_v_plus: f_v_plus.max(0.0),
            f_v_minus: f_v_minus.max(0.0),
            steady,
        };
        law.validate()?;
        Ok(law)
    }

    pub fn validate(&self) -> Result<(), FrictionError> {
        require("sigma_0", self.sigma_0, self.sigma_0 > 0.0, "> 0")?;
        require("sigma_1", self.sigma_1, self.sigma_1 >= 0.0, ">= 0")?;
        if self.v_d.is_nan() || self.v_d <= 0.0 {
            return Err(FrictionError { parameter: "v_d", value: self.v_d, expected: "> 0 (infinity for a constant sigma_1)" });
        }
        require("f_v_plus", self.f_v_plus, self.f_v_plus >= 0.0, ">= 0")?;
        require("f_v_minus", self.f_v_minus, self.f_v_minus >= 0.0, ">= 0")?;
        self.steady.validate()
    }

    fn viscous(&self, qd: f64) -> f64 {
        if positive(qd) {
            self.f_v_plus
        } else {
            self.f_v_minus
        }
    }

    /// Unloaded steady-state function g(q') > 0 (m or rad), Eq. 6.2-6.5.
    pub fn g(&self, qd: f64) -> f64 {
        self.steady.level(qd, self.steady.dry(qd)).0.abs() / self.sigma_0
    }

    /// σ1(q') and dσ1/dq', Eq. 3.84.
    pub fn sigma_1_at(&self, qd: f64) -> (f64, f64) {
        let r = qd / self.v_d;
        let s = self.sigma_1 * gaussian(r);
        (s, s * (-2.0 * r / self.v_d))
    }

    /// Dissipativity condition of Eq. 3.83 at q': 0 ≤ σ1(q') ≤ 4 σ0 g(q') / |q'| (unloaded g).
    pub fn dissipative(&self, qd: f64) -> bool {
        let (s1, _) = self.sigma_1_at(qd);
        s1 >= 0.0 && s1 * qd.abs() <= 4.0 * self.sigma_0 * self.g(qd)
    }

    /// Bristle residual of Eq. 3.85, f_z = q''_z - q' + |q'| / g(q') q'_z, with z = q'_z and
    /// z' = q''_z: (f_z, ∂f_z/∂q', ∂f_z/∂z, ∂f_z/∂z').
    pub fn bristle_residual(&self, qd: f64, z: f64, zdot: f64) -> (f64, f64, f64, f64) {
        let (f, df_dqd, df_dz, df_dzdot, _) = self.bristle_residual_with_dry(qd, z, zdot, self.steady.dry(qd));
        (f, df_dqd, df_dz, df_dzdot)
    }

    /// Eq. 3.85 with the dry friction `tau_d` of the direction of q' (unloaded or Eq. 5.12), plus
    /// ∂f_z/∂τ_d. Since g and q' share their sign convention, |q'| / g(q') = σ0 q' / s(q') with
    /// s the signed steady-state friction, which is how it is evaluated.
    fn bristle_residual_with_dry(&self, qd: f64, z: f64, zdot: f64, tau_d: f64) -> (f64, f64, f64, f64, f64) {
        let (s, ds_dqd, ds_dtau_d) = self.steady.level(qd, tau_d);
        let rate = self.sigma_0 * qd / s;
        let drate_dqd = self.sigma_0 / s - rate * ds_dqd / s;
        let drate_dtau_d = -rate * ds_dtau_d / s;
        (zdot - qd + rate * z, -1.0 + drate_dqd * z, rate, 1.0, drate_dtau_d * z)
    }

    /// Friction torque of Eq. 3.87, τ_f = σ0 q'_z + σ1(q') q''_z + f_v q':
    /// (τ_f, ∂τ_f/∂q', ∂τ_f/∂z, ∂τ_f/∂z').
    pub fn torque(&self, qd: f64, z: f64, zdot: f64) -> (f64, f64, f64, f64) {
        let (s1, ds1_dqd) = self.sigma_1_at(qd);
        let f_v = self.viscous(qd);
        (self.sigma_0 * z + s1 * zdot + f_v * qd, ds1_dqd * zdot + f_v, self.sigma_0, s1)
    }
}

/// Load dependence of the dry friction of a horizontal joint, Eq. 5.12 (Section 5.4, 6.4.4):
/// τ̃_f,d = a_2 x² + a_1 x + a_0 with x the foot load in kg (Table 5.5 is in N/kg² and N/kg) and
/// a_0 the unloaded dry friction of the law it modifies (Table 5.3, Section 6.4.4).
///
/// Section 5.4: a_2^±, a_1^± have the sign of a_0^± (positive for q' ≥ 0, negative for q' < 0), so
/// that |τ̃_f,d| grows with the load and never falls below |a_0|.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LoadDependence {
    /// a_2^+ ≥ 0 (N/kg²).
    pub a_2_plus: f64,
    /// a_1^+ ≥ 0 (N/kg).
    pub a_1_plus: f64,
    /// a_2^- ≤ 0 (N/kg²).
    pub a_2_minus: f64,
    /// a_1^- ≤ 0 (N/kg).
    pub a_1_minus: f64,
}

impl LoadDependence {
    pub fn validate(&self) -> Result<(), FrictionError> {
        require("a_2_plus", self.a_2_plus, self.a_2_plus >= 0.0, ">= 0 (Section 5.4)")?;
        require("a_1_plus", self.a_1_plus, self.a_1_plus >= 0.0, ">= 0 (Section 5.4)")?;
        require("a_2_minus", self.a_2_minus, self.a_2_minus <= 0.0, "<= 0 (Section 5.4)")?;
        require("a_1_minus", self.a_1_minus, self.a_1_minus <= 0.0, "<= 0 (Section 5.4)")
    }

    /// τ̃_f,d of the direction of q' for the foot load `load` (N) and its derivative with respect
    /// to the load (per N), Eq. 5.12 with x = load / [`LOAD_GRAVITY`]. A negative load (which the
    /// contact model never produces) counts as no load; at zero load the derivative is the right
    /// one.
    pub fn dry_friction(&self, a0: f64, qd: f64, load: f64) -> (f64, f64) {
        if load < 0.0 {
            return (a0, 0.0);
        }
        let (a2, a1) = if positive(qd) { (self.a_2_plus, self.a_1_plus) } else { (self.a_2_minus, self.a_1_minus) };
        let x = load / LOAD_GRAVITY;
        ((a2 * x + a1) * x + a0, (2.0 * a2 * x + a1) / LOAD_GRAVITY)
    }
}

/// Transmission-efficiency friction of a joint's drive (the thesis' second prospect, Chapter 8:
/// "efficiency of transmission naturally accounts for the load acting on it").
///
/// The standard form of a gearbox's or a screw's losses splits them into a no-load part, which
/// the drive needs to move without any transmitted load (seals, bearings, lubricant, preload),
/// and a load-dependent part, the mesh loss, a fraction of the power the transmission carries
/// (ISO/TR 14179-1; Niemann & Winter, Maschinenelemente II, Ch. 22), whose efficiency depends on
/// the direction of the power flow (for a screw of lead angle λ and friction angle φ, forward
/// η_f = tan λ / tan(λ + φ) when the motor drives the load, backward η_b = tan(λ − φ) / tan λ
/// when the load drives the motor; Modelica's `LossyGear` has the same two efficiencies).
///
/// Written at the joint, with τ_m = n k_t i the motor torque (Eq. 5.17) and N(q') the no-load
/// friction (Eq. 6.1 with the unloaded dry and viscous parameters of Table 5.3, which are the
/// motor torque of a joint moving without transmitted load, Eq. 5.3), the torque the
/// transmission carries beyond the no-load friction is e = τ_m − N(q'). In steady motion the
/// joint passes on the load torque τ_L = τ_m − τ_f:
///
/// - forward, e q' > 0 (the motor's torque beyond N is in the direction of motion):
///   τ_L = η_f e, so τ_f = N + (1 − η_f) e;
/// - backward, e q' < 0 (the load drives the motion against the motor): the motor receives
///   e = η_b τ_L, so τ_f = N + (1 − 1/η_b) e.
///
/// Hence τ_f = N(q') + L(q', e) with L = (1 − η_f) e forward and (1 − 1/η_b) e backward; L has
/// the sign of q' (|L| = (1 − η_f)|e| or (1/η_b − 1)|e|): the friction still opposes the motion
/// and grows with the transmitted load, whatever its direction. With η_f = η_b = 1 the law is
/// Eq. 6.1 itself; without transmitted load (e = 0) it is too, so the unloaded identification
/// of Section 5.2 reads the same parameters.
///
/// Non-smooth points: the power-flow direction sgn(e q') switches (1) with the direction of
/// motion at q' = 0, where L jumps between its forward and backward value (the discontinuity
/// of a dry friction's sign), and (2) with e at e = 0, where L is continuous (zero) with a kink.
/// (1) is regularised as the dry friction's sign is: L is added to the dry friction τ_f,d^± of
/// the direction of q' and the sum goes through the linear zone of Eq. 6.1
/// ([`DryViscous::torque_with_dry`], as the load-dependent dry friction of Eq. 5.12 does), so
/// that τ_f is continuous and zero at q' = 0. (2) is a kink like |q'| in the LuGre laws: the
/// partial derivative there is the forward branch's (e = 0 belongs to the forward branch).
///
/// Partial derivatives (for the implicit Newmark Jacobian; τ_m depends on the current, itself a
/// state or, without inductance, a function of q' and of the voltage through Eq. 4.4): with
/// (T, ∂T/∂q', ∂T/∂τ_d) of the linear zone at τ_d = τ_f,d^± + L and L' = ∂L/∂e,
/// ∂τ_f/∂τ_m = ∂T/∂τ_d L' and ∂τ_f/∂q' = ∂T/∂q' − ∂T/∂τ_d L' ∂N/∂q'.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Efficiency {
    /// η_f in (0, 1]: the motor drives the load.
    pub eta_forward: f64,
    /// η_b in (0, 1]: the load drives the motor (backdrivable transmission; a self-locking one
    /// would have η_b ≤ 0, outside this law).
    pub eta_backward: f64,
    /// The no-load friction N(q') of Eq. 6.1.
    pub no_load: DryViscous,
}

impl Efficiency {
    pub fn validate(&self) -> Result<(), FrictionError> {
        require("eta_forward", self.eta_forward, self.eta_forward > 0.0 && self.eta_forward <= 1.0, "0 < eta <= 1")?;
        require("eta_backward", self.eta_backward, self.eta_backward > 0.0 && self.eta_backward <= 1.0, "0 < eta <= 1")?;
        self.no_load.validate()
    }

    /// The load-dependent loss L(q', e) of the direction of q' and ∂L/∂e for the transmitted
    /// torque e = τ_m − N(q'): forward when e has the direction's sign (or is zero).
    fn loss(&self, qd: f64, e: f64) -> (f64, f64) {
        let forward = if positive(qd) { e >= 0.0 } else { e <= 0.0 };
        let slope = if forward { 1.0 - self.eta_forward } else { 1.0 - 1.0 / self.eta_backward };
        (slope * e, slope)
    }

    /// τ_f(q', τ_m) with ∂τ_f/∂q' and ∂τ_f/∂τ_m (see the type's doc).
    pub fn torque(&self, qd: f64, tau_m: f64) -> (f64, f64, f64) {
        let (n, dn_dqd) = self.no_load.torque(qd);
        let (l, dl_de) = self.loss(qd, tau_m - n);
        let (tau, dtau_dqd, dtau_dtau_d) = self.no_load.torque_with_dry(qd, self.no_load.dry(qd) + l);
        (tau, dtau_dqd - dtau_dtau_d * dl_de * dn_dqd, dtau_dtau_d * dl_de)
    }
}

/// Friction law of one joint (Section 6.1: the three cases compared in Chapter 6; the
/// transmission efficiency of the thesis' prospects, Chapter 8).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum JointFriction {
    None,
    DryViscous(DryViscous),
    LuGre(LuGre),
    Efficiency(Efficiency),
}

impl JointFriction {
    /// Whether the law has the bristle state z = q'_z (one extra first-order coordinate).
    pub fn has_bristle_state(&self) -> bool {
        matches!(self, JointFriction::LuGre(_))
    }

    pub fn validate(&self) -> Result<(), FrictionError> {
        match self {
            JointFriction::None => Ok(()),
            JointFriction::DryViscous(law) => law.validate(),
            JointFriction::LuGre(law) => law.validate(),
            JointFriction::Efficiency(law) => law.validate(),
        }
    }
}

/// Friction torque of a [`FrictionElement`] and its partial derivatives.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrictionTorque {
    /// τ_f, opposing the motion (the generalized force on the joint is -τ_f).
    pub tau: f64,
    pub dtau_dqd: f64,
    /// With respect to the bristle state z = q'_z (zero without bristle).
    pub dtau_dz: f64,
    /// With respect to z' = q''_z (zero without bristle).
    pub dtau_dzdot: f64,
    /// With respect to the foot load in N (zero without load dependence).
    pub dtau_dload: f64,
    /// With respect to the motor torque τ_m = n k_t i at the joint (zero but for the
    /// efficiency law).
    pub dtau_dtau_m: f64,
}

/// Bristle residual row (Eq. 3.85) of a [`FrictionElement`] and its partial derivatives.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BristleResidual {
    pub f: f64,
    pub df_dqd: f64,
    /// With respect to z = q'_z (a CT entry).
    pub df_dz: f64,
    /// With respect to z' = q''_z (an M entry).
    pub df_dzdot: f64,
    /// With respect to the foot load in N (zero without load dependence).
    pub df_dload: f64,
}

/// The friction element of one joint: a law, optionally with the load-dependent dry friction of
/// Eq. 5.12 (horizontal joints, Section 6.4.4), which then replaces τ_f,d^± in Eq. 6.1 or in the
/// steady-state function g (Eq. 5.6).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrictionElement {
    pub law: JointFriction,
    pub load: Option<LoadDependence>,
}

impl FrictionElement {
    pub fn new(law: JointFriction) -> Self {
        FrictionElement { law, load: None }
    }

    pub fn with_load(self, load: LoadDependence) -> Self {
        FrictionElement { load: Some(load), ..self }
    }

    pub fn validate(&self) -> Result<(), FrictionError> {
        self.law.validate()?;
        self.load.as_ref().map_or(Ok(()), LoadDependence::validate)
    }

    pub fn has_bristle_state(&self) -> bool {
        self.law.has_bristle_state()
    }

    /// The dry friction in force for the direction of q' and the foot load `load` (N): τ_f,d^±
    /// or τ̃_f,d^± of Eq. 5.12, with its derivative with respect to the load. Zero without friction.
    pub fn dry_friction(&self, qd: f64, load: f64) -> (f64, f64) {
        let a0 = match &self.law {
            JointFriction::None => return (0.0, 0.0),
            JointFriction::DryViscous(law) => law.dry(qd),
            JointFriction::LuGre(law) => law.steady.dry(qd),
            JointFriction::Efficiency(law) => law.no_load.dry(qd),
        };
        self.load.map_or((a0, 0.0), |l| l.dry_friction(a0, qd, load))
    }

    /// Friction torque τ_f(q', z, z', load, τ_m) with its partials: Eq. 6.1 (z, z', τ_m
    /// ignored), Eq. 3.87 (τ_m ignored) or the efficiency law (z, z', load ignored), with τ_m
    /// the motor torque at the joint.
    pub fn torque(&self, qd: f64, z: f64, zdot: f64, load: f64, tau_m: f64) -> FrictionTorque {
        match &self.law {
            JointFriction::None => FrictionTorque::default(),
            JointFriction::DryViscous(law) => {
                let (tau_d, dtau_d_dload) = self.dry_friction(qd, load);
                let (tau, dtau_dqd, dtau_dtau_d) = law.torque_with_dry(qd, tau_d);
                FrictionTorque { tau, dtau_dqd, dtau_dload: dtau_dtau_d * dtau_d_dload, ..FrictionTorque::default() }
            }
            JointFriction::LuGre(law) => {
                let (tau, dtau_dqd, dtau_dz, dtau_dzdot) = law.torque(qd, z, zdot);
                FrictionTorque { tau, dtau_dqd, dtau_dz, dtau_dzdot, ..FrictionTorque::default() }
            }
            JointFriction::Efficiency(law) => {
                let (tau, dtau_dqd, dtau_dtau_m) = law.torque(qd, tau_m);
                FrictionTorque { tau, dtau_dqd, dtau_dtau_m, ..FrictionTorque::default() }
            }
        }
    }

    /// Bristle residual of Eq. 3.85 (with g of Eq. 5.6 under load) and its partials; `None` when
    /// the law has no bristle state.
    pub fn bristle_residual(&self, qd: f64, z: f64, zdot: f64, load: f64) -> Option<BristleResidual> {
        let JointFriction::LuGre(law) = &self.law else { return None };
        let (tau_d, dtau_d_dload) = self.dry_friction(qd, load);
        let (f, df_dqd, df_dz, df_dzdot, df_dtau_d) = law.bristle_residual_with_dry(qd, z, zdot, tau_d);
        Some(BristleResidual { f, df_dqd, df_dz, df_dzdot, df_dload: df_dtau_d * dtau_d_dload })
    }
}

#[cfg(test)]
mod tests;
