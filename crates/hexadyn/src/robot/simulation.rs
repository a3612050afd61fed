//! The simulated robot as a [`Plant`]: the robot model integrated by Newmark between control
//! instants, encoders quantizing the joint positions, the current sensors (analog 30 Hz filter and
//! optional noise, Section 5.6.2) integrated at every accepted step, and an energy account integrated at every
//! accepted step (electrical input, Joule, friction and contact losses, stored energies).

use std::ops::ControlFlow;
use std::sync::Arc;

use super::model::{FrictionModel, ModelOptions, Robot, RobotModel};
use crate::control::{BodyPose, Command, Controller, Encoder, Measurements, Plant};
use crate::hexapod::JOINTS;
use crate::mbs;
use crate::physics::{CurrentSensing, CurrentSensors, JointFriction};
use crate::sim::{Newmark, NewmarkOptions, SimError, State, System};

/// Energies (J) accumulated since the start, by trapezoidal integration of the powers at the
/// accepted integration steps, and the stored energies at the current state.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EnergyAccount {
    /// ∫ u i dt per joint (electrical energy drawn, Eq. 6.7).
    pub electrical: [f64; JOINTS],
    /// ∫ (R + R_bridge) i² dt per joint.
    pub joule: [f64; JOINTS],
    /// ∫ τ_f q' dt per joint: work done against friction (including the energy momentarily
    /// stored in the LuGre bristles, see `bristle_energy`), at the drive position (a series-elastic
    /// drive's θ'), plus the work dissipated by a series spring's damper, ∫ c (θ' − q')² dt.
    pub friction_work: [f64; JOINTS],
    /// ∫ τ_m q' dt per joint: mechanical work of the motor on its drive.
    pub motor_work: [f64; JOINTS],
    /// ∫ −F·v dt per foot: work done by the feet on the ground and on the stand's loads
    /// (`model.foot_load_kg`), including the elastic energy stored in the ground, see
    /// `contact_energy`.
    pub contact_work: [f64; 6],
    /// Stored energies at the current state: kinetic (of the multibody model and of the
    /// series-elastic drives, ½ J θ'²), potential (gravity), bristles ½ σ0 z², series springs
    /// ½ k (θ − q)², ground ∫ K δ^p_K dδ, inductances ½ L i².
    pub kinetic: f64,
    pub potential: f64,
    pub bristle_energy: f64,
    pub spring_energy: f64,
    pub contact_energy: f64,
    pub magnetic_energy: f64,
    powers: Option<Powers>,
}

#[derive(Clone, Debug, PartialEq)]
struct Powers {
    t: f64,
    electrical: [f64; JOINTS],
    joule: [f64; JOINTS],
    friction: [f64; JOINTS],
    motor: [f64; JOINTS],
    contact: [f64; 6],
}

impl EnergyAccount {
    /// Adds the powers of the state the robot outputs were just evaluated at.
    fn accumulate(&mut self, robot: &Robot, state: &State) {
        let m = &*robot.model;
        let out = &robot.outputs;
        let (q, qd) = (state.q.as_slice(), state.qd.as_slice());
        let mut p = Powers { t: state.t, electrical: [0.0; JOINTS], joule: [0.0; JOINTS], friction: [0.0; JOINTS], motor: [0.0; JOINTS], contact: [0.0; 6] };
        self.bristle_energy = 0.0;
        self.spring_energy = 0.0;
        self.magnetic_energy = 0.0;
        for k in 0..JOINTS {
            let v = qd[m.drive_index(k)];
            let motor = &m.motors[k];
            p.electrical[k] = motor.electrical_power(out.voltage[k], out.current[k]);
            p.joule[k] = motor.joule_loss(out.current[k]);
            p.friction[k] = out.friction_torque[k] * v;
            p.motor[k] = out.motor_torque[k] * v;
            if let Some(series) = &m.series {
                let (d, j) = (m.drive_index(k), 6 + k);
                p.friction[k] += series[k].spring.dissipation(qd[d] - qd[j]);
                self.spring_energy += series[k].spring.energy(q[d] - q[j]);
            }
            if let JointFriction::LuGre(law) = &m.friction[k].law {
                self.bristle_energy += 0.5 * law.sigma_0 * out.bristle[k].powi(2);
            }
            if motor.inductance {
                self.magnetic_energy += 0.5 * motor.l * out.current[k].powi(2);
            }
        }
        for (leg, c) in out.contact.iter().enumerate() {
            p.contact[leg] = c.absorbed_power;
        }
        self.contact_energy = out.contact.iter().map(|c| c.elastic_energy).sum();
        // At a control instant the reset after the input jump moves q'' alone: (q, q'), and with
        // them the kinetic and potential energies, are those accumulated last, at the same t.
        if self.powers.as_ref().is_none_or(|prev| prev.t != state.t) {
            self.kinetic = mbs::kinetic_energy(&m.multibody, robot.data());
            if let Some(series) = &m.series {
                self.kinetic += (0..JOINTS).map(|k| 0.5 * series[k].drive_inertia * qd[m.drive_index(k)].powi(2)).sum::<f64>();
            }
            self.potential = mbs::potential_energy(&m.multibody, robot.data());
        }
        if let Some(prev) = &self.powers {
            let h = 0.5 * (p.t - prev.t);
            for k in 0..JOINTS {
                self.electrical[k] += h * (prev.electrical[k] + p.electrical[k]);
                self.joule[k] += h * (prev.joule[k] + p.joule[k]);
                self.friction_work[k] += h * (prev.friction[k] + p.friction[k]);
                self.motor_work[k] += h * (prev.motor[k] + p.motor[k]);
            }
            for leg in 0..6 {
                self.contact_work[leg] += h * (prev.contact[leg] + p.contact[leg]);
            }
        }
        self.powers = Some(p);
    }

    /// Electrical energy in minus everything it should have become: Δ(kinetic + potential) +
    /// Joule + friction work + contact work + Δ(series springs' energy) + Δ(magnetic energy).
    /// Zero up to integration error.
    pub fn balance_error(&self, initial: &EnergyAccount) -> f64 {
        let sum = |a: &[f64]| a.iter().sum::<f64>();
        sum(&self.electrical)
            - (self.kinetic - initial.kinetic + self.potential - initial.potential)
            - sum(&self.joule)
            - sum(&self.friction_work)
            - sum(&self.contact_work)
            - (self.spring_energy - initial.spring_energy)
            - (self.magnetic_energy - initial.magnetic_energy)
    }
}

/// Options of the simulated plant.
#[derive(Clone, Debug, PartialEq)]
pub struct PlantOptions {
    pub integrator: NewmarkOptions,
    /// Control period Δt (s), 10 ms on AMRU5.
    pub period: f64,
    /// Whether the controller receives the true body pose (navigation system, Section 7.4).
    pub navigation: bool,
    /// The current sensors (Section 5.6.2): analog filter cut-off, noise and its seed.
    pub current_sensing: CurrentSensing,
}

impl PlantOptions {
    /// The control period `period` (s) and the integrator for the model.
    pub fn new(period: f64, model: &ModelOptions) -> Self {
        // Modified Newton refreshes the Jacobian when a correction shrinks by less than this
        // factor. With LuGre the iteration matrix has 42 rows instead of 24, and a Jacobian and
        // its LU cost several residual evaluations more, so the stale one is kept longer
        // (benches/walk: 0.5 instead of 0.9 takes 10 % off the 60 s dry/viscous walk and adds
        // 4 % to the 75 s LuGre walk).
        let slow_contraction = if model.friction == FrictionModel::LuGre { 0.9 } else { 0.5 };
        // Newton goes on on the robot's surrogate residual between evaluations of f
        // (`robot/model/surrogate.rs`), at most this many iterations each. INTERPRETATION: the
        // thesis iterates on f alone (Section 3.3.2); with `unverified_steps` 0 every accepted
        // step passes the Newton test on f. The 75 s LuGre walk takes 31 810, 27 035, 25 865 and
        // 25 697 evaluations of f with 2, 4, 8 and 16 (44 416 on f alone), its figures against a
        // converged run (tolerance 0.01, h_max 1 ms) as close as on f alone: electrical energy
        // +0.20 % both (docs/performance-log.md, sessions 29-30).
        let surrogate_iterations = 8;
        // A step whose surrogate iteration converges is accepted on it, without the evaluation of
        // f that would verify it, in runs of at most this many steps while the last verification
        // passed and no step was rejected since (`NewmarkOptions::unverified_steps`).
        // INTERPRETATION: the thesis accepts on f (Section 3.3.2). The verification's Newton
        // correction is a median 0.02 and at most 13 times the Newton tolerance (1 % of the
        // error tolerance) on the 75 s LuGre walk; with 1, 2, 4, 8 and unbounded runs that walk
        // takes 14 158, 12 937, 11 787, 10 935 and 10 142 evaluations of f against 18 465, with
        // its figures unchanged (docs/performance-log.md, session 33). 8 keeps a verification at
        // least every 90 ms of walking.
        let unverified_steps = 8;
        PlantOptions {
            integrator: NewmarkOptions { tolerance: 1.0, h_max: period, h_initial: 1e-4, slow_contraction, gamma: 0.6, beta: 0.3025, surrogate_iterations, unverified_steps, ..Default::default() },
            period,
            navigation: false,
            current_sensing: CurrentSensing::default(),
        }
    }
}

/// The simulated robot driven like the real one.
pub struct SimulatedRobot {
    pub robot: Robot,
    pub integrator: Newmark,
    pub energy: EnergyAccount,
    /// The energy account at the start, for balances.
    pub initial_energy: EnergyAccount,
    /// The inputs (voltages or references) the accelerations of the integrator's state are
    /// consistent with: those held over the last period, until the next control instant.
    consistent_inputs: [f64; JOINTS],
    encoders: [Encoder; JOINTS],
    current_sensors: CurrentSensors<JOINTS>,
    period: f64,
    navigation: bool,
}

impl SimulatedRobot {
    /// Starts from (q, q'); accelerations are made consistent.
    pub fn new(model: Arc<RobotModel>, q: &[f64], qd: &[f64], options: &PlantOptions) -> Result<Self, SimError> {
        let mut robot = Robot::new(model);
        let integrator = Newmark::new(&mut robot, 0.0, q, qd, options.integrator.clone())?;
        let encoders = robot.model.encoders;
        let current_sensors = CurrentSensors::new(&options.current_sensing, 0.0, &[0.0; JOINTS]);
        let consistent_inputs = std::array::from_fn(|k| robot.input(k));
        let mut plant = SimulatedRobot { robot, integrator, energy: EnergyAccount::default(), initial_energy: EnergyAccount::default(), consistent_inputs, encoders, current_sensors, period: options.period, navigation: options.navigation };
        plant.observe();
        plant.current_sensors = CurrentSensors::new(&options.current_sensing, plant.state().t, &plant.robot.outputs.current);
        plant.initial_energy = plant.energy.clone();
        Ok(plant)
    }

    pub fn state(&self) -> &State {
        self.integrator.state()
    }

    /// Re-evaluates the outputs at the current state and accumulates the energies.
    fn observe(&mut self) {
        let s = self.integrator.state();
        self.robot.evaluate(s.q.as_slice(), s.qd.as_slice(), s.qdd.as_slice());
        self.energy.accumulate(&self.robot, s);
    }
}

impl Plant for SimulatedRobot {
    type Error = SimError;

    fn period(&self) -> f64 {
        self.period
    }

    fn measure(&mut self) -> Measurements {
        let s = self.integrator.state();
        let q = s.q.as_slice();
        Measurements {
            t: s.t,
            positions: std::array::from_fn(|k| self.encoders[k].measure(q[self.robot.model.drive_index(k)])),
            currents: self.current_sensors.sample(),
            supply_voltage: self.robot.model.options.supply_voltage,
            pose: self.navigation.then(|| BodyPose { position: nalgebra::Vector3::new(q[0], q[1], q[2]), yaw: q[3], pitch: q[4], roll: q[5] }),
            foot_normal_forces: Some(self.robot.outputs.contact.map(|c| c.normal_force)),
        }
    }

    fn actuate(&mut self, command: &Command) {
        let q = self.integrator.state().q.clone();
        self.robot.command(command, q.as_slice());
    }

    fn wait_period(&mut self) -> Result<(), SimError> {
        // The voltages jumped at this instant: make q'' consistent before stepping on, and start
        // the power integration of the period from the powers under the new voltages: the
        // outputs of the reset's evaluation, at the state's (q, q') and the q'' after the jump
        // (the reset evaluates f once, then corrects q'').
        self.integrator.reset_accelerations_after_input_jump(&mut self.robot, &self.consistent_inputs)?;
        self.consistent_inputs = std::array::from_fn(|k| self.robot.input(k));
        self.energy.accumulate(&self.robot, self.integrator.state());
        let t_start = self.integrator.state().t;
        // The current jumps with the voltage: the input of the analog filters jumps.
        self.current_sensors.advance(t_start, &self.robot.outputs.current);
        let t_end = t_start + self.period;
        let (energy, sensors) = (&mut self.energy, &mut self.current_sensors);
        // The outputs of each accepted step are those of its last Newton iterate, within the
        // Newton tolerance of the accepted state: no extra evaluation per step. Between accepted
        // steps the current is taken linear for the analog filters.
        self.integrator.advance_to_observed(&mut self.robot, t_end, |robot, state| {
            energy.accumulate(robot, state);
            sensors.advance(state.t, &robot.outputs.current);
        })?;
        // The last accepted step landed on t_end: the outputs are those of the current state
        // (to the Newton tolerance).
        Ok(())
    }
}

/// Runs `controller` on `plant` for `duration` seconds: at every control instant, measure,
/// compute the command, hand it to `record`, apply it and let one period pass. `record` sees
/// the plant, the measurements and the command at each instant, the last one included.
pub fn run<P: Plant, C: Controller + ?Sized>(
    plant: &mut P,
    controller: &mut C,
    duration: f64,
    mut record: impl FnMut(&P, &Measurements, &Command),
) -> Result<(), P::Error> {
    run_until(plant, controller, duration, |p, m, c| {
        record(p, m, c);
        ControlFlow::Continue(())
    })
    .map(|_| ())
}

/// [`run`] with a `record` that may stop the run early (e.g. a user interrupt) by returning
/// `ControlFlow::Break(())` at an instant: that instant's command is not applied. Returns
/// `Break` when stopped so, `Continue` when the whole duration ran.
pub fn run_until<P: Plant, C: Controller + ?Sized>(
    plant: &mut P,
    controller: &mut C,
    duration: f64,
    mut record: impl FnMut(&P, &Measurements, &Command) -> ControlFlow<()>,
) -> Result<ControlFlow<()>, P::Error> {
    let periods = (duration / plant.period()).round() as usize;
    for i in 0..=periods {
        let m = plant.measure();
        let command = controller.update(&m);
        if record(plant, &m, &command).is_break() {
            return Ok(ControlFlow::Break(()));
        }
        if i == periods {
            break;
        }
        plant.actuate(&command);
        plant.wait_period()?;
    }
    Ok(ControlFlow::Continue(()))
}
