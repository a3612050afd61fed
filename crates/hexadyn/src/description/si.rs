//! SI views of a description: the thesis units of the file (degrees, mH, g cm^2, rpm)
//! converted, and the per-leg friction parameters in joint units with the rules of Section 6.1
//! ([`RobotDescription::friction`]).

use std::f64::consts::PI;

use super::tables::{DriverTable, LegTable, MissingA1MinusRule, MissingStictionRule, MotorTable, NegativeViscousRule, RobotDescription};
use crate::hexapod::{PantographJoint, JOINTS, LEG_COUNT};
use crate::physics::{DryViscous, Efficiency, LoadDependence, SeriesSpring};

impl MotorTable {
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

impl DriverTable {
    /// Series resistance of the H-bridge added to the armature: 2 x 0.3 Ohm (Section 6.4).
    pub fn series_resistance_ohm(&self) -> f64 {
        self.mosfet_resistance_ohm * f64::from(self.mosfets_in_series)
    }
}

/// SI PI gains of one joint: u = K (e + 1/T_i int e) (Eq. 4.18).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PiGains {
    /// K in V/rad (q_r) or V/m (q_v, q_h).
    pub k: f64,
    /// T_i in s.
    pub t_i: f64,
}

/// Friction parameters of one joint of one leg, in joint units (N or Nm; N s/m or Nm s/rad),
/// after the rules of Section 6.1. "+" values hold for q_dot >= 0, "-" for q_dot < 0; the
/// minus dry and breakaway values are negative, the viscous coefficients are slopes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointFrictionParameters {
    pub leg: usize,
    pub joint: PantographJoint,
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
    /// Load dependence of the dry friction (Table 5.5, Eq. 5.12; a_1^- after the
    /// `missing_a1_minus` rule): Some for q_h only.
    pub load_dependence: Option<LoadDependence>,
    /// Forward and backward efficiencies of the transmission (`[friction.efficiency]`).
    pub eta_forward: f64,
    pub eta_backward: f64,
}

impl JointFrictionParameters {
    /// The dry/viscous law of Eq. 6.1 with these parameters (unloaded dry friction).
    pub fn dry_viscous(&self) -> DryViscous {
        DryViscous { tau_f_d_plus: self.tau_f_d_plus, tau_f_d_minus: self.tau_f_d_minus, f_v_plus: self.f_v_plus, f_v_minus: self.f_v_minus, epsilon: self.epsilon }
    }

    /// The efficiency law with these efficiencies on the no-load friction of Eq. 6.1 (the
    /// unloaded dry and viscous friction of Table 5.3).
    pub fn efficiency(&self) -> Efficiency {
        Efficiency { eta_forward: self.eta_forward, eta_backward: self.eta_backward, no_load: self.dry_viscous() }
    }

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

    fn leg(&self, leg: usize) -> &LegTable {
        self.legs.iter().find(|l| l.id == leg).unwrap_or_else(|| panic!("leg {leg} does not exist (ids 0..5)"))
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
    pub fn reduction(&self, joint: PantographJoint) -> f64 {
        match joint {
            PantographJoint::Rotation => self.reductions.n_r,
            PantographJoint::Vertical => self.reductions.n_v_rad_per_m,
            PantographJoint::Horizontal => self.reductions.n_h_rad_per_m,
        }
    }

    /// k_t n: joint torque (Nm) or force (N) per ampere of motor current (Eq. 5.17), and the
    /// factor between a joint velocity and the back-emf (V per rad/s or per m/s).
    pub fn joint_torque_per_ampere(&self, joint: PantographJoint) -> f64 {
        self.motor.torque_constant_nm_per_a * self.reduction(joint)
    }

    /// Armature circuit resistance seen by the controller output: R + H-bridge (Section 6.4).
    pub fn circuit_resistance_ohm(&self) -> f64 {
        self.motor.resistance_ohm + self.driver.series_resistance_ohm()
    }

    /// Joint range (Table 5.2) in SI: rad for q_r, m for q_v and q_h.
    pub fn joint_range(&self, joint: PantographJoint) -> (f64, f64) {
        let r = &self.joint_ranges;
        match joint {
            PantographJoint::Rotation => (r.q_r_deg.min.to_radians(), r.q_r_deg.max.to_radians()),
            PantographJoint::Vertical => (r.q_v_m.min, r.q_v_m.max),
            PantographJoint::Horizontal => (r.q_h_m.min, r.q_h_m.max),
        }
    }

    /// The series-elastic spring of a joint (stiffness in N/m or Nm/rad, damping in N s/m or
    /// Nm s/rad), None for AMRU5's rigid drives.
    pub fn series_spring(&self, joint: PantographJoint) -> Option<SeriesSpring> {
        let s = self.series_elastic.as_ref()?;
        Some(match joint {
            PantographJoint::Rotation => SeriesSpring { stiffness: s.q_r.stiffness_nm_per_rad, damping: s.q_r.damping_nms_per_rad },
            PantographJoint::Vertical => SeriesSpring { stiffness: s.q_v.stiffness_n_per_m, damping: s.q_v.damping_ns_per_m },
            PantographJoint::Horizontal => SeriesSpring { stiffness: s.q_h.stiffness_n_per_m, damping: s.q_h.damping_ns_per_m },
        })
    }

    /// PI gains of each joint k = 3 leg + j in SI (Table 4.1).
    pub fn joint_pi_gains(&self) -> [PiGains; JOINTS] {
        std::array::from_fn(|k| self.pi_gains(PantographJoint::ALL[k % 3]))
    }

    /// PI gains of a joint in SI (Table 4.1).
    pub fn pi_gains(&self, joint: PantographJoint) -> PiGains {
        let k = &self.controller;
        match joint {
            PantographJoint::Rotation => PiGains { k: k.q_r.k_v_per_rad, t_i: k.q_r.t_i_s },
            PantographJoint::Vertical => PiGains { k: k.q_v.k_v_per_m, t_i: k.q_v.t_i_s },
            PantographJoint::Horizontal => PiGains { k: k.q_h.k_v_per_m, t_i: k.q_h.t_i_s },
        }
    }

    /// Joint-side resolution of the motor encoder: 2 pi / (impulses n), rad or m.
    pub fn encoder_resolution(&self, joint: PantographJoint) -> f64 {
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

    /// n/n_0: this robot's reduction of `joint` over the one its friction was identified
    /// with (`friction.identified_with_reductions`), 1 when they are the same drives. The
    /// dry friction of [`Self::friction`] scales by it, the viscous coefficients by its square.
    pub fn friction_reduction_ratio(&self, joint: PantographJoint) -> f64 {
        let Some(n_0) = &self.friction.identified_with_reductions else { return 1.0 };
        let identified = match joint {
            PantographJoint::Rotation => n_0.n_r,
            PantographJoint::Vertical => n_0.n_v_rad_per_m,
            PantographJoint::Horizontal => n_0.n_h_rad_per_m,
        };
        self.reduction(joint) / identified
    }

    /// Friction parameters of one joint of one leg in joint units, with the Section 6.1
    /// rules applied (negative viscous -> 0, missing stiction -> unloaded dry, vertical
    /// stiction of the `vertical_stiction_load_kg` case, a_0 of Eq. 5.12 = unloaded dry),
    /// referred to this robot's reductions ([`Self::friction_reduction_ratio`]).
    ///
    /// # Panics
    /// If `leg` is not 0..5.
    pub fn friction(&self, leg: usize, joint: PantographJoint) -> JointFrictionParameters {
        assert!(leg < LEG_COUNT, "leg {leg} does not exist (ids 0..5)");
        let f = &self.friction;
        let (dp, vp, dm, vm) = match joint {
            PantographJoint::Rotation => (&f.q_r.tau_f_d_plus_nm, &f.q_r.f_v_plus_nms, &f.q_r.tau_f_d_minus_nm, &f.q_r.f_v_minus_nms),
            PantographJoint::Vertical => (&f.q_v.tau_f_d_plus_n, &f.q_v.f_v_plus_ns_per_m, &f.q_v.tau_f_d_minus_n, &f.q_v.f_v_minus_ns_per_m),
            PantographJoint::Horizontal => (&f.q_h.tau_f_d_plus_n, &f.q_h.f_v_plus_ns_per_m, &f.q_h.tau_f_d_minus_n, &f.q_h.f_v_minus_ns_per_m),
        };
        let (tau_f_d_plus, tau_f_d_minus) = (dp.mu[leg], dm.mu[leg]);
        let viscous = |v: f64| match f.negative_viscous {
            NegativeViscousRule::Zero => v.max(0.0),
            NegativeViscousRule::Keep => v,
        };
        let (tau_f_s_plus, tau_f_s_minus) = match joint {
            PantographJoint::Vertical => {
                let (p, m) = self
                    .vertical_stiction_measured(leg, f.vertical_stiction_load_kg)
                    .expect("validated: the stiction load case exists");
                match f.missing_stiction {
                    MissingStictionRule::UnloadedDry => (p.unwrap_or(tau_f_d_plus), m.unwrap_or(tau_f_d_minus)),
                }
            }
            _ => (tau_f_d_plus, tau_f_d_minus),
        };
        let load_dependence = (joint == PantographJoint::Horizontal).then(|| {
            let a = &f.q_h.load_dependence;
            let a_1_plus = a.a_1_plus_n_per_kg.mu[leg].value().unwrap_or(0.0);
            let a_1_minus = a.a_1_minus_n_per_kg.mu[leg].value().unwrap_or(match f.missing_a1_minus {
                MissingA1MinusRule::Zero => 0.0,
                MissingA1MinusRule::MirrorA1Plus => -a_1_plus,
            });
            LoadDependence {
                a_2_plus: a.a_2_plus_n_per_kg2.mu[leg],
                a_2_minus: a.a_2_minus_n_per_kg2.mu[leg],
                a_1_plus,
                a_1_minus,
            }
        });
        let efficiency = match joint {
            PantographJoint::Rotation => f.efficiency.q_r,
            PantographJoint::Vertical => f.efficiency.q_v,
            PantographJoint::Horizontal => f.efficiency.q_h,
        };
        // Dry (and load) friction by n/n_0, viscous by (n/n_0)^2: 1 on the identified drives.
        let ratio = self.friction_reduction_ratio(joint);
        let (dry, viscous_ratio) = (|v: f64| v * ratio, ratio * ratio);
        let load_dependence = load_dependence.map(|a| LoadDependence { a_2_plus: dry(a.a_2_plus), a_2_minus: dry(a.a_2_minus), a_1_plus: dry(a.a_1_plus), a_1_minus: dry(a.a_1_minus) });
        JointFrictionParameters {
            leg,
            joint,
            tau_f_d_plus: dry(tau_f_d_plus),
            tau_f_d_minus: dry(tau_f_d_minus),
            tau_f_s_plus: dry(tau_f_s_plus),
            tau_f_s_minus: dry(tau_f_s_minus),
            f_v_plus: viscous(vp.mu[leg]) * viscous_ratio,
            f_v_minus: viscous(vm.mu[leg]) * viscous_ratio,
            f_v_plus_measured: vp.mu[leg] * viscous_ratio,
            f_v_minus_measured: vm.mu[leg] * viscous_ratio,
            q_st: (joint == PantographJoint::Vertical).then_some(f.lugre.q_st_v_m_per_s),
            sigma_0: f.lugre.sigma_0,
            sigma_1: f.lugre.sigma_1,
            v_d: f.lugre.v_d,
            delta_d: f.lugre.delta_d,
            epsilon: f.lugre.dry_viscous_epsilon,
            load_dependence,
            eta_forward: efficiency.eta_forward,
            eta_backward: efficiency.eta_backward,
        }
    }
}
