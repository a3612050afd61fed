//! The complete robot model as one residual system (thesis Section 3.5, Fig. 3.16, Table 3.5):
//! the 24-DOF multibody mechanics, ground contact at the six feet, joint friction (none,
//! dry/viscous, LuGre with its 18 bristle states, or transmission efficiency) and the 18 DC motors with their H-bridge
//! (inductance neglected, Eq. 4.4, or kept as 18 current states, Eq. 3.91).
//!
//! Rows and coordinates: q (24, Eq. 3.51), then with series-elastic transmissions the drive
//! coordinates θ (18, the gear outputs in joint units: what the motor turns, the transmission's
//! friction slides and the encoder reads; the spring between θ and q moves the joint), then the
//! bristle states z = q'_z (Eq. 3.85), then the
//! motor currents i = q'_i (Eq. 3.91) when they are states, then, with continuous joint
//! controllers (the 96-DOF model of Table 3.5), per joint the PID states q_u (u = q'_u) and q_I
//! (Eq. 3.96-3.97). Inputs: the 18 voltages commanded by the digital controllers, held between
//! control instants (cut by the limit switches at the ends of the joint strokes, Section 2.3.1,
//! see [`Robot::command`]) and saturated at the supply voltage; with continuous controllers, the
//! 18 joint references instead.

use std::ops::RangeInclusive;
use std::sync::Arc;

use nalgebra::{DMatrix, Vector3};

use crate::description::RobotDescription;
use crate::hexapod::{joint_index, JointKind, LegJoints, DOF, JOINTS};
use crate::mbs::{self, BodyId, Data};
use crate::physics::{ContactForce, Proximity, Terrain, Vicinity};
use crate::physics::{FrictionElement, JointFriction};
use crate::physics::{limit_switch, saturate, DcMotor};
use crate::control::{Command, ContinuousPid, Encoder, PositionServo};
use crate::sim::{Jacobian, Layout, Order, System};

mod inertial;
mod options;
mod parts;
mod surrogate;
pub use options::{FrictionModel, JointControl, ModelOptions};
pub use parts::{RobotParts, SeriesElastic};
use inertial::InertialJacobian;
use surrogate::Surrogate;


/// Error scale of a bristle deflection z (Eq. 3.85) as a fraction of its steady-state value
/// while sliding ([`LuGre::sliding_deflection`]): z carries the friction torque σ0 z, so its
/// error is measured against the deflection that holds the dry friction, the same relative
/// accuracy for every joint whatever its σ0 and τ_f,d.
const BRISTLE_SCALE: f64 = 1.0 / 30.0;

/// The immutable robot model: mechanics, motors, friction elements, contact and terrain.
#[derive(Clone)]
pub struct RobotModel {
    /// The multibody model (Section 3.3.3): AMRU5's 49 bodies, or a serial robot's 19.
    pub multibody: mbs::Model,
    /// Each foot: its body and the foot point in that body's frame.
    pub feet: [(BodyId, Vector3<f64>); 6],
    /// The names and kinds of a leg's joints: the layout's and the results' column names.
    pub joints: LegJoints,
    /// Per joint k = 3 leg + j (AMRU5: 0 q_r, 1 q_v, 2 q_h).
    pub motors: [DcMotor; JOINTS],
    pub friction: [FrictionElement; JOINTS],
    /// Joint strokes (limit switches), per joint.
    pub strokes: [RangeInclusive<f64>; JOINTS],
    pub options: ModelOptions,
    pub terrain: Arc<dyn Terrain>,
    /// Continuous joint controllers (Eq. 3.96-3.97), with [`JointControl::ContinuousPid`].
    pub pids: Option<[ContinuousPid; JOINTS]>,
    /// The position sensor of each joint.
    pub encoders: [Encoder; JOINTS],
    /// Position servos ([`PositionServo`]): the motors are driven by the servos' own loops and
    /// the model's inputs are the goal positions.
    pub servos: Option<[PositionServo; JOINTS]>,
    /// Series-elastic transmissions ([`SeriesElastic`]), per joint.
    pub series: Option<[SeriesElastic; JOINTS]>,
    layout: Layout,
    /// First drive coordinate θ (series-elastic transmissions).
    drives: Option<usize>,
    bristles: Option<usize>,
    currents: Option<usize>,
    /// First PID state: q_u of joint k at `pid + 2k`, q_I at `pid + 2k + 1`.
    pid: Option<usize>,
}

impl RobotModel {
    /// The robot of a (pantograph) robot description.
    pub fn new(d: &RobotDescription, options: ModelOptions, terrain: Arc<dyn Terrain>) -> Self {
        Self::assemble(RobotParts::from_description(d, &options), options, terrain)
    }

    /// The robot of `parts` as one residual system: the layout of its coordinates (the joints'
    /// scales by their kind: 1e-5 rad, 1e-7 m), the bristle, current and PID states the options
    /// ask for.
    pub fn assemble(parts: RobotParts, options: ModelOptions, terrain: Arc<dyn Terrain>) -> Self {
        let RobotParts { multibody, feet, joints, mut motors, friction, strokes, pi_gains, encoders, servos, series } = parts;
        assert!(servos.is_none() || options.control == JointControl::Digital, "position servos run their own loops: no continuous PID on them");
        for motor in &mut motors {
            motor.inductance = options.inductance;
        }
        let mut layout = Layout::default();
        let names = ["X", "Y", "Z", "yaw", "pitch", "roll"];
        for (i, name) in names.iter().enumerate() {
            layout.push(*name, Order::Second, if i < 3 { 1e-6 } else { 1e-5 }, "multibody (main body)");
        }
        let joint_name = |k: usize| joints.column("", k, "");
        let revolute = |k: usize| joints.kind(k % 3) == JointKind::Revolute;
        let joint_scale = |k: usize| if revolute(k) { 1e-5 } else { 1e-7 };
        for k in 0..JOINTS {
            layout.push(joint_name(k), Order::Second, joint_scale(k), format!("multibody (leg {})", k / 3));
        }
        let drives = series.is_some().then(|| {
            let first = layout.len();
            for k in 0..JOINTS {
                layout.push(format!("drive_{}", joint_name(k)), Order::Second, joint_scale(k), format!("series-elastic drive {}", joint_name(k)));
            }
            first
        });
        let bristles = (options.friction == FrictionModel::LuGre).then(|| {
            let first = layout.len();
            for (k, f) in friction.iter().enumerate() {
                let JointFriction::LuGre(law) = &f.law else { unreachable!("LuGre friction on every joint") };
                let scale = BRISTLE_SCALE * law.sliding_deflection();
                layout.push(format!("z_{}", joint_name(k)), Order::First, scale, format!("LuGre bristle {}", joint_name(k)));
            }
            first
        });
        let currents = options.inductance.then(|| {
            let first = layout.len();
            for k in 0..JOINTS {
                layout.push(format!("i_{}", joint_name(k)), Order::First, 1e-5, format!("motor {}", joint_name(k)));
            }
            first
        });
        let pids = match options.control {
            JointControl::Digital => None,
            JointControl::ContinuousPid { t_d, n, omega_0 } => Some(std::array::from_fn(|k| ContinuousPid { k: pi_gains[k].k, t_i: pi_gains[k].t_i, t_d, n, omega_0 })),
        };
        let pid = pids.is_some().then(|| {
            let first = layout.len();
            for k in 0..JOINTS {
                let element = format!("PID {}", joint_name(k));
                layout.push(format!("q_u_{}", joint_name(k)), Order::First, 1e-3, element.clone());
                layout.push(format!("q_I_{}", joint_name(k)), Order::Second, if revolute(k) { 1e-6 } else { 1e-8 }, element);
            }
            first
        });
        RobotModel { multibody, feet, joints, motors, friction, strokes, options, terrain, pids, encoders, servos, series, layout, drives, bristles, currents, pid }
    }

    /// Number of coordinates: 24, + 18 drive coordinates with series-elastic transmissions,
    /// + 18 bristles with LuGre, + 18 currents with inductance,
    /// + 36 with continuous PID controllers (42 for the model of Section 4.5, 96 for Table 3.5).
    pub fn coordinate_count(&self) -> usize {
        self.layout.len()
    }
    /// Index of the drive position of joint k: what its motor turns, its transmission's friction
    /// slides, its encoder reads and its limit switches watch. The drive coordinate θ of a
    /// series-elastic transmission, else the joint itself (6 + k).
    pub fn drive_index(&self, k: usize) -> usize {
        self.drives.map_or(6 + k, |d| d + k)
    }
    /// Index of the bristle state of joint k, if any.
    pub fn bristle_index(&self, k: usize) -> Option<usize> {
        self.bristles.map(|b| b + k)
    }
    /// Index of the current state of joint k, if any.
    pub fn current_index(&self, k: usize) -> Option<usize> {
        self.currents.map(|c| c + k)
    }

    /// Whether the model's inputs are joint references (continuous PID controllers or position
    /// servos) rather than motor voltages.
    pub fn takes_references(&self) -> bool {
        self.pids.is_some() || self.servos.is_some()
    }

    /// The feet's centres (global frame) at the coordinates `q`.
    pub fn foot_positions(&self, q: &[f64]) -> [Vector3<f64>; 6] {
        let mut data = Data::new(&self.multibody);
        mbs::kinematics(&self.multibody, &mut data, &q[..DOF], &[0.0; DOF]);
        std::array::from_fn(|f| data.point(self.feet[f].0, &self.feet[f].1))
    }

    /// Initial q for the given joint positions: body at (0, 0, Z) with zero yaw, parallel to the
    /// terrain below its origin (level on flat ground), Z chosen so that the lowest foot just
    /// touches the terrain (closest point: zero penetration); series springs undeflected; all
    /// other states zero.
    pub fn touching_ground(&self, joints: &[f64; JOINTS]) -> Vec<f64> {
        let mut q = vec![0.0; self.coordinate_count()];
        q[6..DOF].copy_from_slice(joints);
        if let Some(d) = self.drives {
            q[d..d + JOINTS].copy_from_slice(joints);
        }
        // z_b = n: R_y(Θ) R_x(Ψ) e_z = (sin Θ cos Ψ, −sin Ψ, cos Θ cos Ψ) (Eq. 3.52 with Φ = 0).
        let n = self.terrain.height_normal(0.0, 0.0).1;
        (q[4], q[5]) = (n.x.atan2(n.z), (-n.y).asin());
        let clearance = |q: &[f64]| {
            self.foot_positions(q).iter().map(|p| -self.terrain.proximity(p, self.options.ground.foot_radius).penetration).fold(f64::INFINITY, f64::min)
        };
        q[2] = -clearance(&q);
        // Off a plane the closest point is not below the foot: lowering the body by the
        // clearance leaves a clearance >= 0 (the distance is 1-Lipschitz); repeat until touching.
        for _ in 0..100 {
            let c = clearance(&q);
            if c.abs() <= 1e-12 {
                break;
            }
            q[2] -= c;
        }
        q
    }

    /// Coordinates that a static equilibrium of the standing robot must lock: the horizontal
    /// position and the yaw of the body (the ground friction of Eq. 3.73 has no stiffness), the
    /// joints (Section 6.2 locks them all) and every bristle and current state.
    pub fn standing_locks(&self) -> Vec<usize> {
        [0, 1, 3].into_iter().chain(6..self.coordinate_count()).collect()
    }
}

/// What the model computed at the last evaluation, per joint and per foot.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Outputs {
    /// Voltage across the motor and H-bridge after saturation and limit switches (V).
    pub voltage: [f64; JOINTS],
    /// Motor current (A).
    pub current: [f64; JOINTS],
    /// Joint torque of the motor n k_t i (Nm or N).
    pub motor_torque: [f64; JOINTS],
    /// The generalized force on each joint (Nm or N): τ_m − τ_f through a rigid drive, the
    /// spring's τ_s through a series-elastic one.
    pub joint_force: [f64; JOINTS],
    /// Friction torque τ_f opposing the motion (Nm or N).
    pub friction_torque: [f64; JOINTS],
    /// Bristle deflection z (rad or m); zero without LuGre.
    pub bristle: [f64; JOINTS],
    /// Ground force on each foot (N, global frame).
    pub contact: [ContactForce; 6],
    /// Foot positions (m, global frame).
    pub foot: [Vector3<f64>; 6],
}

/// The robot as a [`System`]: model, multibody workspace and held inputs.
#[derive(Clone)]
pub struct Robot {
    pub model: Arc<RobotModel>,
    /// The multibody workspace of the last evaluation (see [`Robot::data`]).
    data: Data,
    /// The (q, q') of the multibody coordinates `data` holds the kinematics of: the kinematics
    /// depend on nothing else, so an evaluation at the same (q, q') and another q'' (the
    /// consistent accelerations after an input jump, the mass matrix, the outputs of an accepted
    /// step) reuses them.
    kinematics_at: Option<([f64; DOF], [f64; DOF])>,
    /// Motor voltages held over the control period (inputs with digital control, V).
    pub voltages: [f64; JOINTS],
    /// Joint references (inputs with continuous PID control, rad or m).
    pub references: [f64; JOINTS],
    pub outputs: Outputs,
    /// The slowly varying part of the Jacobian (see [`Robot::jacobian`]) and where it was taken.
    inertial: Option<InertialJacobian>,
    /// The ground near each foot, kept between the contact queries of the evaluations.
    vicinity: [Vicinity; 6],
    /// The foot states of the last evaluation.
    feet: Option<[Foot; 6]>,
    /// The base of [`System::surrogate_residual`], boxed: taken out and put back at each
    /// surrogate evaluation.
    surrogate: Option<Box<Surrogate>>,
}

/// The state of a foot the contact law is evaluated at (Eq. 3.72-3.73).
#[derive(Clone, Copy, Debug)]
struct Foot {
    position: Vector3<f64>,
    velocity: Vector3<f64>,
    proximity: Proximity,
}

impl Robot {
    pub fn new(model: Arc<RobotModel>) -> Self {
        let data = Data::new(&model.multibody);
        Robot { model, data, kinematics_at: None, voltages: [0.0; JOINTS], references: [0.0; JOINTS], outputs: Outputs::default(), inertial: None, vicinity: Default::default(), feet: None, surrogate: None }
    }

    /// The multibody workspace: kinematics and applied forces of the last evaluation.
    pub fn data(&self) -> &Data {
        &self.data
    }

    /// Kinematics of the multibody coordinates at (q, q') into `data`, unless it holds them:
    /// what the residual needs ([`mbs::relative_kinematics`]); see [`Self::partial_velocities`]
    /// for the rest.
    fn kinematics(&mut self, q: &[f64], qd: &[f64]) {
        let at = (q[..DOF].try_into().expect("DOF coordinates"), qd[..DOF].try_into().expect("DOF coordinates"));
        if self.kinematics_at != Some(at) {
            mbs::relative_kinematics(&self.model.multibody, &mut self.data, &q[..DOF], &qd[..DOF]);
            self.kinematics_at = Some(at);
        }
    }

    /// The partial velocities of every body at the last kinematics (mass matrix, foot Jacobians).
    fn partial_velocities(&mut self) {
        mbs::partial_velocities(&self.model.multibody, &mut self.data);
    }

    /// Holds a command for the next control period. Digital control: the voltages, cut by the
    /// limit switches of the joints that are beyond their stroke and pushed further out
    /// (Section 2.3.1), read at the control instant as the slave boards apply the commands.
    /// Continuous PID control: the references; position servos: the goals (the references
    /// unless the master adds a feed-forward).
    pub fn command(&mut self, command: &Command, q: &[f64]) {
        if self.model.takes_references() {
            self.references = command.goals.unwrap_or(command.references);
        } else {
            for k in 0..JOINTS {
                self.voltages[k] = limit_switch(command.voltages[k], q[self.model.drive_index(k)], &self.model.strokes[k]);
            }
        }
    }

    /// Kinematics, contact forces and joint torques at (q, q', q''), written into the multibody
    /// workspace and [`Self::outputs`].
    pub fn evaluate(&mut self, q: &[f64], qd: &[f64], qdd: &[f64]) {
        self.kinematics(q, qd);
        let m = &*self.model;
        let feet: [Foot; 6] = std::array::from_fn(|leg| {
            let (link, point) = m.feet[leg];
            let position = self.data.point(link, &point);
            let velocity = self.data.point_velocity(link, &position);
            let proximity = m.terrain.proximity_near(&position, m.options.ground.foot_radius, &mut self.vicinity[leg]);
            Foot { position, velocity, proximity }
        });
        self.force_laws(q, qd, qdd, &feet);
        self.feet = Some(feet);
        self.data.clear_forces();
        for (leg, (body, _)) in self.model.feet.iter().enumerate() {
            let force = self.outputs.contact[leg].force;
            if force != Vector3::zeros() {
                self.data.add_force(*body, &feet[leg].position, &force);
            }
        }
        for k in 0..JOINTS {
            self.data.add_generalized_force(6 + k, self.outputs.joint_force[k]);
        }
    }

    /// Contact forces at the feet and motor and friction torques of the joints at the given foot
    /// states and (q, q', q''), into [`Self::outputs`].
    fn force_laws(&mut self, q: &[f64], qd: &[f64], qdd: &[f64], feet: &[Foot; 6]) {
        let m = &*self.model;
        let out = &mut self.outputs;
        // Ground contact at the feet (Eq. 3.72-3.73).
        for (leg, foot) in feet.iter().enumerate() {
            let mut c = m.options.ground.force_at(foot.proximity, &foot.velocity);
            // The rig's load: a constant vertical force, no change to ∂F/∂p, ∂F/∂v; the feet
            // work against it as against the ground (the energy balance's contact work).
            c.force.z += m.options.foot_load[leg];
            c.normal_force += m.options.foot_load[leg];
            c.absorbed_power -= m.options.foot_load[leg] * foot.velocity.z;
            out.contact[leg] = c;
            out.foot[leg] = foot.position;
        }
        // Motors (Eq. 3.90-3.92 or 4.4-4.7) and joint friction (Eq. 6.1 or 3.87) at the drive
        // position d; the series springs between the drives and the joints.
        for k in 0..JOINTS {
            let (j, d) = (6 + k, m.drive_index(k));
            let motor = &m.motors[k];
            let commanded = match (m.pid, &m.servos) {
                (Some(p), _) => qd[p + 2 * k],
                (None, Some(servos)) => servos[k].voltage(self.references[k], q[d], m.options.supply_voltage).u,
                (None, None) => self.voltages[k],
            };
            let u = saturate(commanded, m.options.supply_voltage);
            let i = match m.currents {
                Some(c) => qd[c + k],
                None => motor.current(qd[d], u).i,
            };
            let (z, zdot) = m.bristles.map_or((0.0, 0.0), |b| (qd[b + k], qdd[b + k]));
            let load = out.contact[k / 3].normal_force;
            out.voltage[k] = u;
            out.current[k] = i;
            out.motor_torque[k] = motor.joint_torque(i).0;
            out.friction_torque[k] = m.friction[k].torque(qd[d], z, zdot, load, out.motor_torque[k]).tau;
            out.joint_force[k] = match &m.series {
                Some(series) => series[k].spring.force(q[d] - q[j], qd[d] - qd[j]),
                None => out.motor_torque[k] - out.friction_torque[k],
            };
            out.bristle[k] = z;
        }
    }

    fn write_residual(&mut self, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
        self.evaluate(q, qd, qdd);
        mbs::residual(&self.model.multibody, &mut self.data, &qdd[..DOF], &mut f[..DOF]);
        self.write_state_rows(q, qd, qdd, f);
    }

    /// The rows after the multibody ones: the series-elastic drives (J θ'' = τ_m − τ_f − τ_s),
    /// bristles (Eq. 3.85), currents (Eq. 3.91), continuous controllers (Eq. 3.96-3.97), from
    /// [`Self::outputs`]; the held body's on a stand.
    fn write_state_rows(&self, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
        let m = &*self.model;
        let out = &self.outputs;
        if m.options.stand {
            f[..BODY].copy_from_slice(&qdd[..BODY]);
        }
        for k in 0..JOINTS {
            let d = m.drive_index(k);
            if let Some(series) = &m.series {
                f[d] = series[k].drive_inertia * qdd[d] - out.motor_torque[k] + out.friction_torque[k] + out.joint_force[k];
            }
            if let Some(b) = m.bristles {
                let load = out.contact[k / 3].normal_force;
                f[b + k] = m.friction[k].bristle_residual(qd[d], qd[b + k], qdd[b + k], load).map_or(0.0, |r| r.f);
            }
            if let Some(c) = m.currents {
                f[c + k] = m.motors[k].current_residual(qd[c + k], qdd[c + k], qd[d], out.voltage[k]).f;
            }
            if let (Some(p), Some(pids)) = (m.pid, &m.pids) {
                let (u, i) = (p + 2 * k, p + 2 * k + 1);
                f[u] = pids[k].voltage_residual(qd[u], qdd[u], q[i], qd[i], qdd[i]).f;
                f[i] = pids[k].integral_residual(qd[i], qdd[i], self.references[k] - q[d]).f;
            }
        }
    }
}

impl Robot {
    /// M = ∂f/∂q'' (Eq. 3.39 for the multibody rows, plus the bristle and inductance terms) at
    /// the state of the last [`Robot::evaluate`].
    fn write_mass_matrix(&self, qd: &[f64], qdd: &[f64], mass: &mut DMatrix<f64>) {
        let m = &*self.model;
        mbs::mass_matrix(&m.multibody, &self.data, mass);
        self.write_state_mass(qd, qdd, mass);
    }

    /// The rows and columns of M that are not the multibody block of Eq. 3.39: the held body of
    /// a robot on a stand, the series-elastic drives' inertia, the bristle (Eq. 3.85-3.86),
    /// inductance (Eq. 3.91) and PID terms.
    fn write_state_mass(&self, qd: &[f64], qdd: &[f64], mass: &mut DMatrix<f64>) {
        let m = &*self.model;
        if m.options.stand {
            held_body_rows(mass, 1.0);
        }
        for k in 0..JOINTS {
            let d = m.drive_index(k);
            let load = self.outputs.contact[k / 3].normal_force;
            if let Some(series) = &m.series {
                mass[(d, d)] = series[k].drive_inertia;
            }
            if let Some(b) = m.bristles {
                mass[(d, b + k)] = m.friction[k].torque(qd[d], qd[b + k], qdd[b + k], load, self.outputs.motor_torque[k]).dtau_dzdot;
                mass[(b + k, b + k)] = m.friction[k].bristle_residual(qd[d], qd[b + k], qdd[b + k], load).expect("LuGre has a bristle state").df_dzdot;
            }
            if let Some(c) = m.currents {
                mass[(c + k, c + k)] = m.motors[k].l;
            }
            if let (Some(p), Some(pids)) = (m.pid, &m.pids) {
                let (u, i) = (p + 2 * k, p + 2 * k + 1);
                let r = pids[k].voltage_residual(0.0, 0.0, 0.0, 0.0, 0.0);
                mass[(u, u)] = r.df_dqdd_u;
                mass[(u, i)] = r.df_dqdd_i;
                mass[(i, i)] = pids[k].integral_residual(0.0, 0.0, 0.0).df_dqdd_i;
            }
        }
    }
}

impl System for Robot {
    fn layout(&self) -> &Layout {
        &self.model.layout
    }

    fn residual(&mut self, _t: f64, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
        self.write_residual(q, qd, qdd, f);
    }

    /// Needs the kept mass matrix of a Jacobian (none before the first) and the evaluation at
    /// (q, q').
    fn keep_surrogate_base(&mut self, q: &[f64], qd: &[f64], qdd: &[f64], f: &[f64]) -> bool {
        self.keep_base(q, qd, qdd, f)
    }

    fn surrogate_residual(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], f: &mut [f64]) {
        match self.surrogate.take() {
            Some(mut base) => {
                self.write_surrogate(&mut base, q, qd, qdd, f);
                self.surrogate = Some(base);
            }
            None => self.residual(t, q, qd, qdd, f),
        }
    }

    /// Exact blocks for the columns of the bristle and current states and the mass matrix
    /// (Eq. 3.39); the columns of q and q' of the multibody coordinates by central differences
    /// of the whole residual (contact, inertia and joint forces depend on them through the
    /// kinematics). The mass matrix of the multibody rows and the inertial terms are those of the
    /// last configuration they were taken at (see `InertialJacobian::holds_at`).
    fn jacobian(&mut self, _t: f64, q: &[f64], qd: &[f64], qdd: &[f64], jac: &mut Jacobian) -> bool {
        // The inertial part is re-taken only when the configuration has moved (modified Newton
        // already tolerates an approximate Jacobian; the contact and joint terms, which carry
        // the fast and non-smooth changes, are exact at every call).
        if !self.inertial.as_ref().is_some_and(|c| c.holds_at(q, &self.model.joints)) {
            self.inertial = Some(self.inertial_jacobian(q, qd, qdd));
        }
        self.evaluate(q, qd, qdd);
        self.partial_velocities();
        if self.model.series.is_some() {
            // Series-elastic drives carry the rotors' reflected inertia (I_a n², 3e4 kg on a
            // nut) that dominates a rigid joint's row of M: without it a leg's M is its links'
            // alone, light and changing with the configuration (Newton on q'' with the one kept
            // over 2 cm oscillates at any h), so it is taken at every Jacobian.
            let inertial = self.inertial.as_mut().expect("taken above");
            mbs::mass_matrix(&self.model.multibody, &self.data, &mut inertial.mass);
        }
        let inertial = self.inertial.as_ref().expect("taken above");
        jac.m.view_mut((0, 0), (DOF, DOF)).copy_from(&inertial.mass);
        self.write_state_mass(qd, qdd, &mut jac.m);
        jac.kt.view_mut((0, 0), (DOF, DOF)).copy_from(&inertial.kt);
        jac.ct.view_mut((0, 0), (DOF, DOF)).copy_from(&inertial.ct);
        let m = &*self.model;
        // Contact (Eq. 3.72-3.73): f contains −J_footᵀ F, F(p(q), v(q, q')).
        let mut dfn_dq = [nalgebra::RowSVector::<f64, DOF>::zeros(); 6];
        let mut dfn_dqd = [nalgebra::RowSVector::<f64, DOF>::zeros(); 6];
        for (leg, (body, _)) in m.feet.iter().enumerate() {
            let c = &self.outputs.contact[leg];
            if c.df_dp == nalgebra::Matrix3::zeros() && c.df_dv == nalgebra::Matrix3::zeros() {
                continue;
            }
            let mut j_foot = nalgebra::SMatrix::<f64, 3, DOF>::zeros();
            for (col, d) in self.data.point_partial_velocities(&m.multibody, *body, &self.outputs.foot[leg]) {
                j_foot.set_column(col, &d);
            }
            let df_dq = c.df_dp * j_foot + c.df_dv * &inertial.dv_dq[leg];
            let df_dqd = c.df_dv * j_foot;
            // −J_footᵀ ∂F/∂q and −J_footᵀ ∂F/∂q', over the rows of the foot's columns only (the
            // body's and its leg's: J_foot is zero elsewhere).
            for (row, d) in j_foot.column_iter().enumerate().filter(|(_, d)| *d != Vector3::zeros()) {
                for col in 0..DOF {
                    jac.kt[(row, col)] -= d.dot(&df_dq.column(col));
                    jac.ct[(row, col)] -= d.dot(&df_dqd.column(col));
                }
            }
            // The normal force (the leg load of Eq. 5.12): F_n = n·F.
            let normal = m.terrain.height_normal(self.outputs.foot[leg].x, self.outputs.foot[leg].y).1;
            dfn_dq[leg] = normal.transpose() * df_dq;
            dfn_dqd[leg] = normal.transpose() * df_dqd;
        }
        // The motor and friction terms are in the rows and columns of the drive position d (the
        // joint's own, or a series-elastic drive coordinate θ).
        for k in 0..JOINTS {
            let d = m.drive_index(k);
            let leg = k / 3;
            let load = self.outputs.contact[leg].normal_force;
            let (z, zdot) = m.bristles.map_or((0.0, 0.0), |b| (qd[b + k], qdd[b + k]));
            // f_d contains −τ_m + τ_f(τ_m): a change of τ_m enters with the factor
            // −(1 − ∂τ_f/∂τ_m) (exactly −1 but for the efficiency law).
            let t = m.friction[k].torque(qd[d], z, zdot, load, self.outputs.motor_torque[k]);
            let passed = 1.0 - t.dtau_dtau_m;
            let motor = &m.motors[k];
            let dtau_m = if m.currents.is_some() { 0.0 } else { motor.joint_torque(motor.current(qd[d], 0.0).di_dqd).0 };
            jac.ct[(d, d)] += t.dtau_dqd - passed * dtau_m;
            if let Some(servos) = &m.servos {
                // The servo's voltage u(q_d − q) drives the motor (f_d contains −τ_m(u)).
                let du_dq = servos[k].voltage(self.references[k], q[d], m.options.supply_voltage).du_dq;
                match m.currents {
                    Some(c) => jac.kt[(c + k, d)] = -du_dq,
                    None => jac.kt[(d, d)] -= passed * motor.joint_torque(motor.current(qd[d], 0.0).di_du).0 * du_dq,
                }
            }
            for col in 0..DOF {
                jac.kt[(d, col)] += t.dtau_dload * dfn_dq[leg][col];
                jac.ct[(d, col)] += t.dtau_dload * dfn_dqd[leg][col];
            }
            if let Some(b) = m.bristles {
                let r = m.friction[k].bristle_residual(qd[d], z, zdot, load).expect("LuGre has a bristle state");
                jac.ct[(b + k, d)] = r.df_dqd;
                for col in 0..DOF {
                    jac.kt[(b + k, col)] += r.df_dload * dfn_dq[leg][col];
                    jac.ct[(b + k, col)] += r.df_dload * dfn_dqd[leg][col];
                }
            }
            if let Some(c) = m.currents {
                jac.ct[(c + k, d)] = motor.current_residual(qd[c + k], qdd[c + k], qd[d], self.outputs.voltage[k]).df_dqd;
            }
            if let (Some(p), Some(pids)) = (m.pid, &m.pids) {
                let i = p + 2 * k + 1;
                // ε = q_ref − q_d.
                jac.kt[(i, d)] = -pids[k].integral_residual(qd[i], qdd[i], self.references[k] - q[d]).df_depsilon;
            }
            if let Some(series) = &m.series {
                // f_j contains −τ_s and f_d contains +τ_s, τ_s = k (θ − q) + c (θ' − q').
                let (j, spring) = (6 + k, series[k].spring);
                for (row, sign) in [(j, -1.0), (d, 1.0)] {
                    jac.kt[(row, d)] += sign * spring.stiffness;
                    jac.kt[(row, j)] -= sign * spring.stiffness;
                    jac.ct[(row, d)] += sign * spring.damping;
                    jac.ct[(row, j)] -= sign * spring.damping;
                }
            }
        }
        let m = &*self.model;
        for k in 0..JOINTS {
            let d = m.drive_index(k);
            let load = self.outputs.contact[k / 3].normal_force;
            let (z, zdot) = m.bristles.map_or((0.0, 0.0), |b| (qd[b + k], qdd[b + k]));
            let t = m.friction[k].torque(qd[d], z, zdot, load, self.outputs.motor_torque[k]);
            let passed = 1.0 - t.dtau_dtau_m;
            if let Some(b) = m.bristles {
                // f_d contains +τ_f (the drive's force is τ_m − τ_f).
                jac.ct[(d, b + k)] = t.dtau_dz;
                jac.ct[(b + k, b + k)] = m.friction[k].bristle_residual(qd[d], qd[b + k], qdd[b + k], load).expect("LuGre has a bristle state").df_dz;
            }
            if let Some(c) = m.currents {
                jac.ct[(c + k, c + k)] = m.motors[k].current_residual(qd[c + k], qdd[c + k], qd[d], self.outputs.voltage[k]).df_di;
                // f_d contains −τ_m + τ_f(τ_m), τ_m = n k_t i.
                jac.ct[(d, c + k)] = -passed * m.motors[k].joint_torque(1.0).1;
            }
            if let (Some(p), Some(pids)) = (m.pid, &m.pids) {
                let (u, i) = (p + 2 * k, p + 2 * k + 1);
                let r = pids[k].voltage_residual(qd[u], qdd[u], q[i], qd[i], qdd[i]);
                jac.ct[(u, u)] = r.df_dqd_u;
                jac.ct[(u, i)] = r.df_dqd_i;
                jac.kt[(u, i)] = r.df_dq_i;
                jac.ct[(i, i)] = pids[k].integral_residual(qd[i], qdd[i], self.references[k] - q[d]).df_dqd_i;
                // The controller output q'_u drives the motor through the saturation.
                let passes = if qd[u].abs() < m.options.supply_voltage { 1.0 } else { 0.0 };
                match m.currents {
                    Some(c) => jac.ct[(c + k, u)] = -passes,
                    None => {
                        let motor = &m.motors[k];
                        jac.ct[(d, u)] = -passed * motor.joint_torque(motor.current(qd[d], 0.0).di_du).0 * passes;
                    }
                }
            }
        }
        if m.options.stand {
            held_body_rows(&mut jac.kt, 0.0);
            held_body_rows(&mut jac.ct, 0.0);
        }
        true
    }

    fn mass_matrix(&mut self, _t: f64, q: &[f64], qd: &[f64], qdd: &[f64], m: &mut DMatrix<f64>) -> bool {
        self.evaluate(q, qd, qdd);
        self.partial_velocities();
        self.write_mass_matrix(qd, qdd, m);
        true
    }

    fn input_count(&self) -> usize {
        JOINTS
    }
    fn input(&self, k: usize) -> f64 {
        if self.model.takes_references() {
            self.references[k]
        } else {
            self.voltages[k]
        }
    }
    fn set_input(&mut self, k: usize, value: f64) {
        if self.model.takes_references() {
            self.references[k] = value;
        } else {
            self.voltages[k] = value;
        }
    }

    /// The inputs enter only the rows of their own joint (its drive's, through a series-elastic
    /// transmission), at fixed (q, q', q''), affinely but for the efficiency law's friction,
    /// which follows the motor torque:
    /// a voltage (saturated at the supply; the limit switches were applied when it was
    /// commanded, [`Robot::command`]) through the current of Eq. 4.4 into the joint row
    /// (f_j contains −n k_t i) or, with inductance, into the current row of Eq. 3.91 (−u); a
    /// reference q_d of a continuous PID through its error ε = q_d − q_j into the integral row
    /// of Eq. 3.97; a goal of a position servo through the servo's voltage (not affinely: the
    /// change of the voltage between the two goals at the same q).
    fn input_change(&mut self, _t: f64, q: &[f64], qd: &[f64], qdd: &[f64], previous: &[f64], df: &mut [f64]) -> bool {
        if previous.len() != JOINTS || df.len() != self.model.layout.len() {
            return false;
        }
        df.fill(0.0);
        let m = &*self.model;
        for k in 0..JOINTS {
            let d = m.drive_index(k);
            match (m.pid, &m.pids) {
                (Some(p), Some(pids)) => {
                    let i = p + 2 * k + 1;
                    df[i] = pids[k].integral_residual(qd[i], qdd[i], 0.0).df_depsilon * (self.references[k] - previous[k]);
                }
                _ => {
                    let motor = &m.motors[k];
                    let supply = m.options.supply_voltage;
                    let (u, before) = match &m.servos {
                        Some(servos) => (servos[k].voltage(self.references[k], q[d], supply).u, servos[k].voltage(previous[k], q[d], supply).u),
                        None => (saturate(self.voltages[k], supply), saturate(previous[k], supply)),
                    };
                    let du = u - before;
                    match m.currents {
                        Some(c) => df[c + k] = motor.current_residual(qd[c + k], qdd[c + k], qd[d], 0.0).df_du * du,
                        None => {
                            // f_d contains −τ_m + τ_f(τ_m): the friction's change is exactly
                            // zero but for the efficiency law, whose loss follows τ_m.
                            let dtau_m = motor.joint_torque(motor.current(qd[d], 0.0).di_du * du).0;
                            let tau_m = motor.joint_torque(motor.current(qd[d], u).i).0;
                            let friction = |tau_m: f64| m.friction[k].torque(qd[d], 0.0, 0.0, 0.0, tau_m).tau;
                            df[d] = -dtau_m + (friction(tau_m) - friction(tau_m - dtau_m));
                        }
                    }
                }
            }
        }
        true
    }
}

/// Number of body coordinates (X, Y, Z, yaw, pitch, roll), first in q.
const BODY: usize = 6;

/// The body rows of a Jacobian block of the robot on a stand (f_body = q''_body): zero, with
/// `diagonal` on the diagonal (1 for M, 0 for CT and KT).
fn held_body_rows(block: &mut DMatrix<f64>, diagonal: f64) {
    block.rows_mut(0, BODY).fill(0.0);
    for i in 0..BODY {
        block[(i, i)] = diagonal;
    }
}

/// Index in q of joint k (k = 3 leg + joint type).
pub const fn joint_coordinate(k: usize) -> usize {
    joint_index(k / 3, k % 3)
}
