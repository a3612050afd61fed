//! Controller design from the model (thesis Sections 4.1-4.4): linearize one leg of the complete
//! robot model, read the SISO plants of its three joints off the linearization and synthesize
//! their PI position controllers (Table 4.1).
//!
//! # The leg model of Eq. 4.9
//!
//! The leg is linearized *inside the complete robot*: the robot ([`Robot`]) is built without
//! friction and without inductance (so the motors follow Eq. 4.4 and the leg obeys Eq. 4.9),
//! its body is placed high above the ground ([`AIR_HEIGHT`]) so that no foot touches it, all
//! legs are set to the same joint configuration, and [`linearize`] gives the 24 × 24 blocks
//! M, CT, KT and the 24 × 18 input matrix F = −∂f/∂u. The leg's 3 × 3 diagonal blocks are the
//! fixed-base leg model of Section 4.1: with the body coordinates held, the rows and columns of
//! one leg's joints see neither the floating base nor the other legs (the coupling through the
//! body lives in the off-diagonal blocks, which are left out). So
//!
//! - M (Eq. 4.12) is the leg block of the mass matrix,
//! - C + C_emf (Eq. 4.9, 4.13) is the leg block of CT: the motor torque n k_t (u − n k_t q')/R of
//!   Eq. 4.7 is part of the residual, so its back-emf damping (n k_t)²/R appears in CT next to the
//!   Coriolis/centrifugal tangent damping C (zero at rest),
//! - K (Section 4.3.3) is the leg block of KT (gravity only: no contact, no friction),
//! - F_elec (Eq. 4.11) is the leg block of F, diag(n k_t / R).
//!
//! # Which resistance
//!
//! The robot model puts the H-bridge (2 × 0.3 Ω, Section 6.4) in series with the coil
//! (R = 0.334 Ω, Table 3.4): the linearized C_emf and F_elec use R + R_bridge = 0.934 Ω
//! ([`LegLinearization::resistance`]). The thesis' controller design (Eq. 4.10-4.17, Table 4.1)
//! uses the coil resistance alone: Eq. 4.3 quotes R = 0.334 Ω, and Eq. 4.13 (3388 N s/m for q_r)
//! is (n_r k_t)² / 0.334 with k_t = 0.02. The design therefore takes an explicit
//! [`DesignResistance`]; [`design_leg_controllers`] uses [`DesignResistance::Coil`] as the thesis
//! does, and every [`JointDesign`] also reports the damping and the plant with the model's circuit
//! resistance, and the closed-loop performance of the designed gain on that plant, so the gap
//! between the design and the simulated robot stays visible.
//!
//! The torque constant is the Table 3.4 value k_t = 19.4e-3 Nm/A. The gains and time constants
//! of Eq. 4.15-4.17 are reproduced with it; the C_emf of Eq. 4.13 corresponds to k_t = 0.02, so
//! the design C_emf comes out about 6 % lower (NOTES.md).

use std::fmt;
use std::sync::Arc;

use nalgebra::Matrix3;

use super::pi_design::{JointPlant, PiDesign};
use crate::physics::FlatGround;
use crate::hexapod::{joint_index, DOF};
use crate::description::RobotDescription;
use crate::hexapod::{JointKind, PantographJoint, JOINTS};
use crate::robot::model::{FrictionModel, ModelOptions, Robot, RobotModel};
use crate::sim::{linearize, System};

/// Neutral leg configuration of Section 4.4.1 where J is read: (q_r, q_v, q_h) = (0, 0.06, 0.04)
/// (rad, m, m).
pub const NEUTRAL: [f64; 3] = [0.0, 0.06, 0.04];

/// Height of the body centre of mass above the ground (m) during the linearization: legs in the
/// air, no ground contact (Section 4.1).
pub const AIR_HEIGHT: f64 = 2.0;

/// Default closed-loop bandwidth of the design (Hz), Section 4.4.4.
pub const DEFAULT_BANDWIDTH_HZ: f64 = 3.0;

/// The 3 × 3 linearized model of one leg, Eq. 4.9: M q'' + (C + C_emf) q' + K q = F_elec u, at
/// joint positions `q` and velocities `qd`, with the robot model's circuit resistance.
#[derive(Clone, Debug, PartialEq)]
pub struct LegLinearization {
    /// Leg whose block was taken (0-5).
    pub leg: usize,
    /// (q_r, q_v, q_h) in rad, m, m.
    pub q: [f64; 3],
    /// (q_r', q_v', q_h') in rad/s, m/s, m/s.
    pub qd: [f64; 3],
    /// Mass matrix M (Eq. 4.12): kg m² (q_r), kg (q_v, q_h), kg m (couplings).
    pub m: Matrix3<f64>,
    /// Tangent damping C + C_emf (Eq. 4.9), the leg block of CT.
    pub c: Matrix3<f64>,
    /// Tangent stiffness K (gravity, Section 4.3.3), the leg block of KT.
    pub k: Matrix3<f64>,
    /// Input matrix F_elec (Eq. 4.11), the leg block of F = −∂f/∂u.
    pub f_elec: Matrix3<f64>,
    /// Global reductions (n_r, n_v, n_h), Table 3.1.
    pub reductions: [f64; 3],
    /// Motor torque constant k_t (Nm/A).
    pub k_t: f64,
    /// Resistance of the armature circuit in the robot model: coil + H-bridge (Ω).
    pub resistance: f64,
}

impl LegLinearization {
    /// Linearizes leg `leg` of the complete robot at joint positions `q` and velocities `qd`
    /// (all six legs placed alike, body at rest at [`AIR_HEIGHT`], no friction, no inductance,
    /// zero commanded voltages and accelerations).
    pub fn at(description: &RobotDescription, leg: usize, q: [f64; 3], qd: [f64; 3]) -> Self {
        assert!(leg < 6, "leg index {leg} out of 0..6");
        let mut options = ModelOptions::from_description(description, FrictionModel::None);
        options.inductance = false;
        options.load_dependence = false;
        let model = RobotModel::new(description, options, Arc::new(FlatGround { height: 0.0 }));
        let resistance = model.motors[3 * leg].resistance();
        let k_t = model.motors[3 * leg].k_t;
        let reductions = [0, 1, 2].map(|j| model.motors[3 * leg + j].n);
        let mut robot = Robot::new(Arc::new(model));
        let n = robot.layout().len();
        assert_eq!(n, DOF, "no friction and no inductance: the robot has only its 24 mechanical coordinates");
        let (mut x, mut xd) = (vec![0.0; n], vec![0.0; n]);
        x[2] = AIR_HEIGHT;
        for l in 0..6 {
            for j in 0..3 {
                x[joint_index(l, j)] = q[j];
                xd[joint_index(l, j)] = qd[j];
            }
        }
        for k in 0..JOINTS {
            robot.set_input(k, 0.0);
        }
        let lin = linearize(&mut robot, 0.0, &x, &xd, &vec![0.0; n]);
        assert!(
            robot.outputs.contact.iter().all(|c| c.normal_force == 0.0),
            "the legs must be in the air for the leg model of Section 4.1"
        );
        let block = |a: &nalgebra::DMatrix<f64>, col: &dyn Fn(usize) -> usize| {
            Matrix3::from_fn(|i, j| a[(joint_index(leg, i), col(j))])
        };
        LegLinearization {
            leg,
            q,
            qd,
            m: block(&lin.m, &|j| joint_index(leg, j)),
            c: block(&lin.ct, &|j| joint_index(leg, j)),
            k: block(&lin.kt, &|j| joint_index(leg, j)),
            f_elec: block(&lin.f, &|j| 3 * leg + j),
            reductions,
            k_t,
            resistance,
        }
    }

    /// Leg 0 at the neutral configuration [`NEUTRAL`], at rest (the point of Section 4.4.1).
    pub fn neutral(description: &RobotDescription) -> Self {
        Self::at(description, 0, NEUTRAL, [0.0; 3])
    }

    /// The largest joint velocities, the motors' no-load speed over the reductions (Table 3.4):
    /// Section 4.3.2 computes the tangent damping there to maximize C(q, q').
    pub fn max_velocities(description: &RobotDescription) -> [f64; 3] {
        PantographJoint::ALL.map(|j| description.motor.no_load_speed_rad_per_s() / description.reduction(j))
    }

    /// Back-emf damping C_emf = diag((n k_t)² / r) (Eq. 4.10) for a circuit resistance `r`.
    pub fn c_emf_for(&self, r: f64) -> Matrix3<f64> {
        Matrix3::from_diagonal(&self.reductions.map(|n| (n * self.k_t).powi(2) / r).into())
    }

    /// Input matrix F_elec = diag(n k_t / r) (Eq. 4.11) for a circuit resistance `r`.
    pub fn f_elec_for(&self, r: f64) -> Matrix3<f64> {
        Matrix3::from_diagonal(&self.reductions.map(|n| n * self.k_t / r).into())
    }

    /// C_emf of the robot model (coil + H-bridge resistance).
    pub fn c_emf(&self) -> Matrix3<f64> {
        self.c_emf_for(self.resistance)
    }

    /// The mechanical tangent damping C(q, q') alone: CT minus the model's C_emf.
    pub fn coriolis(&self) -> Matrix3<f64> {
        self.c - self.c_emf()
    }
}

/// Resistance used in the controller synthesis (Eq. 4.10-4.14).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DesignResistance {
    /// The coil resistance R of Table 3.4 alone, as the thesis' design (Eq. 4.3, 4.13, 4.15-4.17).
    Coil,
    /// Coil + H-bridge, the armature circuit of the robot model (Section 6.4).
    Circuit,
}

impl DesignResistance {
    /// The resistance in Ω for `description`.
    pub fn ohms(self, description: &RobotDescription) -> f64 {
        match self {
            DesignResistance::Coil => description.motor.resistance_ohm,
            DesignResistance::Circuit => description.circuit_resistance_ohm(),
        }
    }
}

/// Plant and controller of one joint.
#[derive(Clone, Debug, PartialEq)]
pub struct JointDesign {
    /// The joint's name in the robot description (`[joints] names`) and its kind.
    pub name: String,
    pub kind: JointKind,
    /// Global reduction n.
    pub n: f64,
    /// J = M_ii at the neutral configuration (kg m² or kg).
    pub inertia: f64,
    /// (n k_t)² / R with the design resistance (Eq. 4.10, 4.13).
    pub c_emf_design: f64,
    /// The diagonal of CT in the robot model at rest: (n k_t)² / (R + R_bridge).
    pub c_emf_model: f64,
    /// Open loop of Eq. 4.14-4.17 with the design resistance.
    pub plant: JointPlant,
    /// The same open loop with the model's circuit resistance.
    pub plant_model: JointPlant,
    /// PI designed on [`Self::plant`] for the requested bandwidth, with its performance.
    pub controller: PiDesign,
    /// The same gains evaluated on [`Self::plant_model`] (the closed loop of the simulated robot).
    pub controller_on_model: PiDesign,
}

/// The controller design of one leg (Sections 4.1-4.4, Table 4.1).
#[derive(Clone, Debug, PartialEq)]
pub struct LegDesign {
    pub linearization: LegLinearization,
    /// Which resistance the synthesis used, and its value (Ω).
    pub resistance: DesignResistance,
    pub design_resistance: f64,
    /// Requested closed-loop bandwidth (Hz).
    pub bandwidth_hz: f64,
    /// (q_r, q_v, q_h).
    pub joints: [JointDesign; 3],
}

/// The thesis' design: leg 0 at [`NEUTRAL`], coil resistance only, T_i of the description
/// (0.5 s, Table 4.1), PI gains for `bandwidth_hz` ([`DEFAULT_BANDWIDTH_HZ`] in Section 4.4.4).
pub fn design_leg_controllers(description: &RobotDescription, bandwidth_hz: f64) -> LegDesign {
    design_leg_controllers_with(description, bandwidth_hz, DesignResistance::Coil)
}

/// [`design_leg_controllers`] with an explicit design resistance.
pub fn design_leg_controllers_with(description: &RobotDescription, bandwidth_hz: f64, resistance: DesignResistance) -> LegDesign {
    let lin = LegLinearization::neutral(description);
    let r = resistance.ohms(description);
    let c_emf_design = lin.c_emf_for(r);
    let joints = std::array::from_fn(|i| {
        let joint = PantographJoint::ALL[i];
        let (name, kind) = (description.joints.names.name(i).to_string(), description.joints.names.kind(i));
        let n = lin.reductions[i];
        let inertia = lin.m[(i, i)];
        let plant = JointPlant::from_motor(inertia, n, lin.k_t, r);
        let plant_model = JointPlant::from_motor(inertia, n, lin.k_t, lin.resistance);
        let t_i = description.pi_gains(joint).t_i;
        let controller = PiDesign::for_bandwidth(&plant, bandwidth_hz, t_i);
        let controller_on_model = PiDesign::evaluate(&plant_model, controller.k, t_i);
        JointDesign { name, kind, n, inertia, c_emf_design: c_emf_design[(i, i)], c_emf_model: lin.c[(i, i)], plant, plant_model, controller, controller_on_model }
    });
    LegDesign { linearization: lin, resistance, design_resistance: r, bandwidth_hz, joints }
}

fn unit(kind: JointKind) -> (&'static str, &'static str) {
    (kind.unit(("rad", "m")), kind.unit(("kg m2", "kg")))
}

impl fmt::Display for LegLinearization {
    /// The four 3 × 3 matrices of Eq. 4.9, rows and columns (q_r, q_v, q_h), SI units.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "Leg {} at (q_r, q_v, q_h) = ({}, {}, {}), velocities ({:.4}, {:.4}, {:.4}), circuit R = {:.3} Ohm",
            self.leg, self.q[0], self.q[1], self.q[2], self.qd[0], self.qd[1], self.qd[2], self.resistance
        )?;
        for (name, a) in [("M", &self.m), ("C + C_emf", &self.c), ("K", &self.k), ("F_elec", &self.f_elec)] {
            writeln!(f, "{name}:")?;
            for i in 0..3 {
                writeln!(f, "  {:>13.5e} {:>13.5e} {:>13.5e}", a[(i, 0)], a[(i, 1)], a[(i, 2)])?;
            }
        }
        Ok(())
    }
}

impl fmt::Display for LegDesign {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let lin = &self.linearization;
        let which = match self.resistance {
            DesignResistance::Coil => "coil only, as Section 4.4.1",
            DesignResistance::Circuit => "coil + H-bridge",
        };
        writeln!(
            f,
            "Leg {} at (q_r, q_v, q_h) = ({}, {}, {}); k_t = {} Nm/A; design R = {:.3} Ohm ({which}); model R = {:.3} Ohm (coil + H-bridge)",
            lin.leg, lin.q[0], lin.q[1], lin.q[2], lin.k_t, self.design_resistance, lin.resistance
        )?;
        writeln!(f, "Open loop Q(s)/U(s) = (1/s) K / (1 + tau_m s), Eq. 4.14-4.17 (C_emf in N s/m or Nm s/rad):")?;
        writeln!(
            f,
            "{:<6}{:>8}  {:>16}  {:>14}  {:>14}  {:>18}  {:>8}  {:>14}",
            "Joint", "n", "J", "C_emf (design)", "C_emf (model)", "K", "tau_m", "tau_m (model)"
        )?;
        for j in &self.joints {
            let (q, m) = unit(j.kind);
            writeln!(
                f,
                "{:<6}{:>8.0}  {:>16}  {:>14.4e}  {:>14.4e}  {:>18}  {:>8}  {:>14}",
                j.name,
                j.n,
                format!("{:.3} {m}", j.inertia),
                j.c_emf_design,
                j.c_emf_model,
                format!("{:.3e} {q}/Vs", j.plant.gain),
                format!("{:.2} ms", j.plant.time_constant * 1e3),
                format!("{:.2} ms", j.plant_model.time_constant * 1e3),
            )?;
        }
        writeln!(f, "PI controllers for {} Hz (Table 4.1); the last columns apply the same gains to the model's circuit:", self.bandwidth_hz)?;
        writeln!(
            f,
            "{:<6}{:>12}  {:>7}  {:>14}  {:>16}  {:>13}  {:>28}",
            "Joint", "K", "T_i (s)", "Bandwidth (Hz)", "Phase margin (°)", "Overshoot (%)", "model: BW (Hz)/PM (°)/OS (%)"
        )?;
        for j in &self.joints {
            let (q, _) = unit(j.kind);
            let (c, m) = (&j.controller, &j.controller_on_model);
            writeln!(
                f,
                "{:<6}{:>12}  {:>7}  {:>14.2}  {:>16.1}  {:>13.1}  {:>28}",
                j.name,
                format!("{:.0} V/{q}", c.k),
                c.t_i,
                c.bandwidth_hz,
                c.phase_margin_deg,
                c.overshoot_percent,
                format!("{:.2} / {:.1} / {:.1}", m.bandwidth_hz, m.phase_margin_deg, m.overshoot_percent),
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn amru5() -> RobotDescription {
        RobotDescription::amru5()
    }

    fn within(what: &str, value: f64, thesis: f64, tolerance: f64) {
        let rel = (value - thesis) / thesis;
        println!("{what}: {value:.5e} vs thesis {thesis:.5e} ({:+.2} %)", 100.0 * rel);
        assert!(rel.abs() <= tolerance, "{what}: {value} vs thesis {thesis}: {:+.2} % exceeds {} %", 100.0 * rel, 100.0 * tolerance);
    }

    /// Eq. 4.15-4.17: K = 1/(n k_t) and τ_m = R J/(n k_t)² with J the diagonal of the leg's mass
    /// matrix at the neutral configuration and the coil resistance, within 5 %.
    #[test]
    fn leg_design_open_loop_matches_eq_4_15_to_4_17() {
        let d = design_leg_controllers(&amru5(), DEFAULT_BANDWIDTH_HZ);
        assert_eq!(d.design_resistance, 0.334);
        let thesis = [(0.031, 0.0059), (0.00075, 0.0058), (0.00088, 0.0058)];
        for (j, (k, tau)) in d.joints.iter().zip(thesis) {
            within(&format!("{} gain", j.name), j.plant.gain, k, 0.05);
            within(&format!("{} tau_m", j.name), j.plant.time_constant, tau, 0.05);
            assert!((5.7e-3..=6.0e-3).contains(&j.plant.time_constant), "{}: tau_m = {}", j.name, j.plant.time_constant);
        }
    }

    /// Eq. 4.13 with the coil resistance, within 10 %; with k_t = 19.4e-3 instead of the 0.02 behind
    /// Eq. 4.13 the model is (19.4/20)² ≈ 0.94 of it (NOTES.md).
    #[test]
    fn leg_design_c_emf_matches_eq_4_13() {
        let d = design_leg_controllers(&amru5(), DEFAULT_BANDWIDTH_HZ);
        for (j, thesis) in d.joints.iter().zip([3388.0, 5.72e6, 4.12e6]) {
            within(&format!("{} C_emf (coil R)", j.name), j.c_emf_design, thesis, 0.10);
            assert!(j.c_emf_design < thesis, "k_t = 19.4e-3 < 0.02 puts C_emf below Eq. 4.13");
            // The model's circuit (coil + H-bridge) damps less, by R / (R + R_bridge).
            assert_relative_eq!(j.c_emf_model, j.c_emf_design * 0.334 / 0.934, max_relative = 1e-6);
        }
    }

    /// At rest the leg block of CT is exactly the model's C_emf (C(q, 0) = 0, no friction) and the
    /// leg block of F is F_elec of Eq. 4.11 with the model's circuit resistance.
    #[test]
    fn leg_design_damping_and_input_blocks_are_the_motor_terms() {
        let lin = LegLinearization::neutral(&amru5());
        assert_relative_eq!(lin.resistance, 0.934, max_relative = 1e-12);
        let c_emf = lin.c_emf();
        let f_elec = lin.f_elec_for(lin.resistance);
        for i in 0..3 {
            for j in 0..3 {
                assert!((lin.c[(i, j)] - c_emf[(i, j)]).abs() <= 1e-6 * c_emf[(i, i)], "C[{i},{j}] = {} vs C_emf {}", lin.c[(i, j)], c_emf[(i, j)]);
                assert!((lin.f_elec[(i, j)] - f_elec[(i, j)]).abs() <= 1e-6 * f_elec[(i, i)], "F[{i},{j}] = {} vs {}", lin.f_elec[(i, j)], f_elec[(i, j)]);
            }
        }
    }

    /// Table 4.1: gains for a ~3 Hz closed loop with T_i = 0.5 s within 10 %, and their bandwidth,
    /// phase margin and overshoot within 10 %.
    #[test]
    fn leg_design_pi_gains_match_table_4_1() {
        let description = amru5();
        let d = design_leg_controllers(&description, DEFAULT_BANDWIDTH_HZ);
        println!("{d}");
        let table = [(483.0, 2.94, 77.3, 9.5), (19863.0, 2.92, 77.4, 9.6), (16854.0, 2.91, 77.4, 9.6)];
        for ((j, joint), (k, bw, pm, os)) in d.joints.iter().zip(PantographJoint::ALL).zip(table) {
            let c = &j.controller;
            assert_eq!(c.t_i, 0.5);
            assert_eq!(description.pi_gains(joint).k, k, "the description holds Table 4.1");
            within(&format!("{} K_p", j.name), c.k, k, 0.10);
            within(&format!("{} bandwidth", j.name), c.bandwidth_hz, bw, 0.10);
            within(&format!("{} phase margin", j.name), c.phase_margin_deg, pm, 0.10);
            within(&format!("{} overshoot", j.name), c.overshoot_percent, os, 0.10);
        }
    }

    /// Section 4.3.1: M is nearly diagonal: m_20 null, m_10 below 3 % of m_00 and m_12 negligible,
    /// at the neutral configuration and over the thesis grid (q_v 0.04-0.09, q_h 0.02-0.05); the
    /// diagonal is quasi-constant (m_00 grows a little with q_h).
    #[test]
    fn leg_design_mass_matrix_is_nearly_diagonal() {
        let description = amru5();
        let neutral = LegLinearization::neutral(&description);
        let mut diag_range = [(f64::INFINITY, 0.0f64); 3];
        for q_v in [0.04, 0.05, 0.06, 0.07, 0.08, 0.09] {
            for q_h in [0.02, 0.03, 0.04, 0.05] {
                let m = LegLinearization::at(&description, 0, [0.0, q_v, q_h], [0.0; 3]).m;
                assert_relative_eq!(m, m.transpose(), max_relative = 1e-9);
                assert!(m[(2, 0)].abs() < 1e-9 * m[(0, 0)], "m20 = {} is not null", m[(2, 0)]);
                assert!(m[(1, 0)].abs() < 0.03 * m[(0, 0)], "m10 = {} vs m00 = {}", m[(1, 0)], m[(0, 0)]);
                assert!(m[(1, 2)].abs() < 1e-3 * m[(1, 1)].min(m[(2, 2)]), "m12 = {}", m[(1, 2)]);
                for i in 0..3 {
                    diag_range[i] = (diag_range[i].0.min(m[(i, i)]), diag_range[i].1.max(m[(i, i)]));
                }
            }
        }
        for (i, (lo, hi)) in diag_range.iter().enumerate() {
            println!("m{i}{i} in [{lo:.5}, {hi:.5}], neutral {:.5}", neutral.m[(i, i)]);
            assert!(hi - lo < 0.01 * neutral.m[(i, i)], "m{i}{i} varies by more than 1 %");
        }
        println!("neutral m10/m00 = {:.4}", neutral.m[(1, 0)] / neutral.m[(0, 0)]);
    }

    /// Section 4.3.2: at the maximum joint velocities the diagonal of C + C_emf stays within
    /// 0.01 % of C_emf and the other terms are tiny, the largest being c_12 at about 40 N s/m.
    #[test]
    fn leg_design_damping_is_back_emf_dominated() {
        let description = amru5();
        let v = LegLinearization::max_velocities(&description);
        let mut worst = (0.0f64, 0, 0, 0.0, 0.0);
        for q_v in [0.04, 0.05, 0.06, 0.07, 0.08, 0.09] {
            for q_h in [0.02, 0.03, 0.04, 0.05] {
                for signs in [[1.0, 1.0, 1.0], [1.0, -1.0, 1.0], [1.0, 1.0, -1.0], [-1.0, 1.0, 1.0]] {
                    let lin = LegLinearization::at(&description, 0, [0.0, q_v, q_h], [0, 1, 2].map(|i| signs[i] * v[i]));
                    let (c, c_emf) = (lin.c, lin.c_emf());
                    for i in 0..3 {
                        assert!((c[(i, i)] - c_emf[(i, i)]).abs() <= 1e-4 * c_emf[(i, i)], "c{i}{i} = {} vs C_emf {}", c[(i, i)], c_emf[(i, i)]);
                        for j in (0..3).filter(|&j| j != i) {
                            assert!(c[(i, j)].abs() < 1e-4 * (c[(i, i)] * c[(j, j)]).sqrt(), "c{i}{j} = {}", c[(i, j)]);
                            if c[(i, j)].abs() > worst.0 {
                                worst = (c[(i, j)].abs(), i, j, q_v, q_h);
                            }
                        }
                    }
                }
            }
        }
        println!("largest off-diagonal damping: |c{}{}| = {:.2} N s/m at q_v = {}, q_h = {}", worst.1, worst.2, worst.0, worst.3, worst.4);
        assert_eq!((worst.1.min(worst.2), worst.1.max(worst.2)), (1, 2), "the largest coupling is c_12");
        within("max |c12|", worst.0, 40.0, 0.25);
    }

    /// Section 4.3.3: gravity does not act on the rotation: k_00, k_01, k_02 and their symmetric
    /// terms are null; k_11, k_22 and k_12 are not.
    #[test]
    fn leg_design_gravity_stiffness_spares_the_rotation() {
        let lin = LegLinearization::neutral(&amru5());
        println!("{lin}");
        for j in 0..3 {
            assert!(lin.k[(0, j)].abs() < 1e-6 && lin.k[(j, 0)].abs() < 1e-6, "k0{j} = {}, k{j}0 = {}", lin.k[(0, j)], lin.k[(j, 0)]);
        }
        assert!(lin.k[(1, 1)].abs() > 1.0 && lin.k[(2, 2)].abs() > 1.0 && lin.k[(1, 2)].abs() > 1.0);
        assert_relative_eq!(lin.k[(1, 2)], lin.k[(2, 1)], max_relative = 1e-4);
    }

    /// Every leg has the same 3 × 3 model (same construction rotated about z_b), to 1e-6 of the
    /// block's largest entry: the finite differences of the linearization leave rounding noise
    /// of that order on the entries that vanish (k_00 ~ 3e-6 against k_22 ~ 5e2).
    #[test]
    fn leg_design_same_block_for_every_leg() {
        let description = amru5();
        let v = LegLinearization::max_velocities(&description);
        let reference = LegLinearization::at(&description, 0, NEUTRAL, v);
        for leg in 1..6 {
            let lin = LegLinearization::at(&description, leg, NEUTRAL, v);
            for (a, b) in [(&lin.m, &reference.m), (&lin.c, &reference.c), (&lin.k, &reference.k), (&lin.f_elec, &reference.f_elec)] {
                for i in 0..3 {
                    for j in 0..3 {
                        let scale = b.amax().max(1.0);
                        assert!((a[(i, j)] - b[(i, j)]).abs() <= 1e-6 * scale, "leg {leg} [{i},{j}]: {} vs {} (largest entry {scale})", a[(i, j)], b[(i, j)]);
                    }
                }
            }
        }
    }

    /// The explicit choice of the design resistance: with the model's circuit the time constants
    /// grow by (R + R_bridge)/R and the 3 Hz gains drop.
    #[test]
    fn leg_design_with_the_circuit_resistance() {
        let description = amru5();
        let coil = design_leg_controllers(&description, DEFAULT_BANDWIDTH_HZ);
        let circuit = design_leg_controllers_with(&description, DEFAULT_BANDWIDTH_HZ, DesignResistance::Circuit);
        assert_relative_eq!(circuit.design_resistance, 0.934, max_relative = 1e-12);
        for (a, b) in coil.joints.iter().zip(&circuit.joints) {
            assert_relative_eq!(b.plant.time_constant, a.plant.time_constant * 0.934 / 0.334, max_relative = 1e-9);
            assert_relative_eq!(b.plant.gain, a.plant.gain, max_relative = 1e-12);
            assert_eq!(b.plant, a.plant_model);
            assert_relative_eq!(b.controller.bandwidth_hz, 3.0, max_relative = 1e-3);
            assert!(b.controller.k < a.controller.k);
            // The coil design on the model's circuit is faster and less damped than designed.
            assert!(a.controller_on_model.bandwidth_hz > a.controller.bandwidth_hz);
            assert!(a.controller_on_model.phase_margin_deg < a.controller.phase_margin_deg);
        }
        let text = coil.to_string();
        for s in ["q_r", "q_v", "q_h", "V/rad", "V/m", "0.334", "0.934"] {
            assert!(text.contains(s), "{s} missing from\n{text}");
        }
    }
}
