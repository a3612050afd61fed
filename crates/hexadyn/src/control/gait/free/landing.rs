//! Landing detection of the free gait (thesis Section 7.7): a landing leg descends until its
//! foot is detected on the ground. The real robot, which has no foot sensors, detects it from
//! its motor currents (Section 5.6.3, [`MotorCurrent`], the default of the scenarios); in
//! simulation the thesis detects the ground when the normal force exceeds 10 N
//! ([`NormalForce`]). Any [`LandingDetector`] plugs into the free gait controller
//! ([`super::FreeGaitController::new`]).

use nalgebra::Vector3;

use crate::control::{settling_time, GroundDetector, GroundSensingLeg, LegDetection, Measurements};
#[cfg(doc)]
use crate::control::SETTLING_TIME_CONSTANTS;
use crate::description::Robot;

/// Decides, at each control instant, which feet are on the ground, from the measurements. The
/// free gait controller calls it once per update (so a detector may filter its signals over
/// time) and reads its answer for the legs that are landing.
pub trait LandingDetector: Send {
    fn ground_contact(&mut self, m: &Measurements) -> [bool; 6];

    /// The ground force (N) at which a landing is detected: what a landing foot may press on
    /// the ground with while its leg still lowers it.
    fn threshold_n(&self) -> f64;

    /// The ground force on each foot (leg frame, N) estimated from the measurements at the
    /// last [`Self::ground_contact`], when the detector estimates it (the elevator reflex of
    /// the swing reads it, [`super::elevator`]).
    fn foot_forces(&self) -> Option<[Option<Vector3<f64>>; 6]> {
        None
    }

    /// `leg` starts its landing: a detector that waits for the signals to follow the motion
    /// starts waiting from here.
    fn landing_starts(&mut self, _leg: usize) {}

    /// The feet pushed up by the ground at the last [`Self::ground_contact`]: the ground force
    /// estimated above the threshold while the foot rises against its leg ([`MotorCurrent`]).
    /// Beyond the thesis: the free gait reads it for the feet it lowers or holds (landing and
    /// swing), whose rise only the ground explains. None by default.
    fn pushed_up(&self) -> [bool; 6] {
        [false; 6]
    }

    /// The foot reference of `leg` rises at this update (takeoff, elevator reflex): the foot's
    /// rise is commanded, not a push of the ground, until its joints have come to rest.
    fn raises(&mut self, _leg: usize) {}

    /// How long (s) the detector's signals lag the ground force: the time a landing foot
    /// presses on before its landing is detected. 0 for a detector that reads the force
    /// itself ([`NormalForce`]).
    fn lag_s(&self) -> f64 {
        0.0
    }
}

/// The simulation mode of Section 7.7: the ground is detected when the true normal force on the
/// foot ([`Measurements::foot_normal_forces`], filled by the simulated plant only) exceeds the
/// threshold. Without the forces (the real robot) no landing is ever detected.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalForce {
    /// N; 10 N in Section 7.7.
    pub threshold: f64,
}

/// Section 7.7: "ground is detected when the normal force is higher than a threshold of 10 N".
pub const THESIS_FORCE_THRESHOLD: f64 = 10.0;

impl LandingDetector for NormalForce {
    fn ground_contact(&mut self, m: &Measurements) -> [bool; 6] {
        m.foot_normal_forces.map_or([false; 6], |f| f.map(|f| f > self.threshold))
    }

    fn threshold_n(&self) -> f64 {
        self.threshold
    }
}

/// The landing detection of the real robot (Section 7.7: "on the real robot, method of ground
/// detection presented in Section 5.6.3 is employed"): the [`GroundDetector`] of the six legs,
/// fed at every control instant with the encoder positions and the measured motor currents
/// (and the navigation system's attitude when there is one); a landing foot is on the ground
/// when the estimated vertical force F̂_z,gnd (Eq. 5.22) reaches the threshold while the foot
/// goes down (q̂_v' > 0), the two conditions of Section 5.6.3. It never reads the simulated
/// foot forces.
///
/// INTERPRETATION of "the joint velocity must be positive": the foot is being lowered, i.e.
/// the vertical joint slides downwards (q̂_v' beyond the linear zone ε of its dry/viscous law,
/// Eq. 6.1), and has done so for [`SETTLING_TIME_CONSTANTS`] time constants of the 3 Hz
/// filters, from the start of the landing. On other legs: the foot goes down while every
/// joint that carries the vertical force ([`crate::control::ground_detection::CARRYING_SHARE`])
/// slides. Section 5.6.2 bases the estimate on the sliding friction ("low velocity behavior is
/// not relevant in the obstacle detection, because leg is moving quite fast during the landing
/// phase"): a still joint is held by its static friction, anywhere between the breakaway
/// forces, which no dry/viscous model knows. In the simulated swing the vertical joint stands
/// still under a PI current of up to 630 N (the LuGre joint creeps at 1e-5 m/s, inside ε),
/// 100 N at the foot; when the landing starts, the filtered current still carries that force
/// while the estimated friction turns to the sliding one, and the estimate crosses 40 N in the
/// air for about 20 ms. Both transients are over once the joint has slid for a few filter time
/// constants. A serial leg's femur and tibia slide through the swing, its foot often sinking
/// slowly with the body, and turn at the landing: the estimated friction flips with them at
/// once, the filtered current later (measured on the PhantomX: 4.9 N in the air against a 2.1 N
/// threshold at the first instant of a landing); hence the wait counts from the landing's
/// start ([`LandingDetector::landing_starts`]).
///
/// Beyond the thesis ([`LandingDetector::pushed_up`], issue 37): a foot is also pushed up when
/// the estimated force reaches the threshold while the carrying joints slide the foot upwards,
/// for the same settling time, unless its reference rose since its joints last came to rest
/// ([`LandingDetector::raises`]: the end of a takeoff reads as up to 65 N while the joint slows
/// down). The free gait lowers its landing feet and holds its swinging feet at their height: a
/// leg whose foot goes up against such a reference is driven back by a force its motors do not
/// hold, and the estimate of a sliding joint is the one of Section 5.6.2 whichever way it
/// slides. Measured on a staircase down (6 cm risers, 4.5 cm
/// lift): a landing foot held at the bottom of its reach while the body went down to it carried
/// 142 N for 2 s, estimated at 64-80 N from the currents, its vertical joint sliding up (q̂_v' <
/// 0), so never detected, and the body's weight went to a swinging foot (Section 5.6.3's test of
/// the sign of q̂_v' keeps a lifting leg, which carries load, from reading as a landing).
#[derive(Clone, Debug)]
pub struct MotorCurrent<L> {
    pub detector: GroundDetector<L>,
    /// The detector's output of the last update.
    pub detections: [LegDetection; 6],
    /// How long each foot has moved one way with its carrying joints sliding (s): > 0 lowered
    /// (in its landing, from its start), < 0 raised.
    sliding: [f64; 6],
    /// The feet pushed up at the last update ([`LandingDetector::pushed_up`]).
    pushed: [bool; 6],
    /// The foot reference rose since the joints last came to rest ([`LandingDetector::raises`]).
    raised: [bool; 6],
    /// Time the joint must have slid before a detection (s).
    settling: f64,
    dt: f64,
}

/// Threshold of the landing detection from the currents (N).
///
/// INTERPRETATION: Section 7.7 does not give the threshold of the real robot's free gait.
/// Section 5.6.3 tests 40, 50 and 60 N, finds that "a threshold of 30 N would be too small"
/// (the transmissions' disturbances would read as a contact in the air) and that a leg of a
/// tripod carries about 100 N, "high enough to catch the difference": the lowest threshold it
/// validated, 40 N, is taken, the one closest to the 10 N of the simulation mode.
pub const THESIS_CURRENT_THRESHOLD: f64 = 40.0;

impl<L: GroundSensingLeg> MotorCurrent<L> {
    /// The detector of `robot` with the kinematics `legs` of its legs at the control period
    /// `dt` (s) with the force `threshold` (N).
    pub fn new(robot: &Robot, legs: [L; 6], dt: f64, threshold: f64) -> Self {
        MotorCurrent {
            detector: GroundDetector::new(robot, legs, dt, threshold),
            detections: Default::default(),
            sliding: [0.0; 6],
            pushed: [false; 6],
            raised: [false; 6],
            settling: settling_time(),
            dt,
        }
    }
}

impl<L: GroundSensingLeg + Send> LandingDetector for MotorCurrent<L> {
    fn ground_contact(&mut self, m: &Measurements) -> [bool; 6] {
        self.detections = self.detector.update(m);
        let settled = self.settling - 0.5 * self.dt;
        for l in 0..6 {
            let d = self.detections[l];
            let way = if d.lowering > 0.0 { 1.0 } else { -1.0 };
            self.sliding[l] = if !d.sliding || d.lowering == 0.0 { 0.0 } else if self.sliding[l] * way >= 0.0 { self.sliding[l] + way * self.dt } else { way * self.dt };
            self.raised[l] &= d.sliding;
            self.pushed[l] = !self.raised[l] && self.sliding[l] <= -settled && d.force >= self.detector.threshold;
        }
        std::array::from_fn(|l| self.detections[l].detected && self.sliding[l] >= settled)
    }

    fn threshold_n(&self) -> f64 {
        self.detector.threshold
    }

    fn pushed_up(&self) -> [bool; 6] {
        self.pushed
    }

    fn raises(&mut self, leg: usize) {
        self.raised[leg] = true;
    }

    fn foot_forces(&self) -> Option<[Option<Vector3<f64>>; 6]> {
        self.detector.foot_forces()
    }

    fn landing_starts(&mut self, leg: usize) {
        self.sliding[leg] = 0.0;
    }

    /// The settling time of the 3 Hz filter of the currents the detection waits for.
    fn lag_s(&self) -> f64 {
        self.settling
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::RobotDescription;
    use crate::hexapod::{LegKinematics, PantographJoint};

    /// AMRU5's detector from the currents at the threshold of the free gait.
    fn amru5_detector(robot: &RobotDescription, dt: f64) -> MotorCurrent<LegKinematics> {
        MotorCurrent::new(&Robot::Pantograph(robot.clone()), LegKinematics::hexapod_from_description(robot).unwrap(), dt, THESIS_CURRENT_THRESHOLD)
    }

    /// The six legs going down from q_v = 0.05 m at `qd_v` (m/s) for `n` control periods with
    /// the motor current `current` (A) of their vertical joints, the other joints still and
    /// unpowered, the simulated foot forces `forces`. Returns the detections.
    fn drive(d: &mut MotorCurrent<LegKinematics>, dt: f64, n: usize, qd_v: f64, current: f64, forces: Option<[f64; 6]>) -> Vec<[bool; 6]> {
        drive_raised(d, dt, n, qd_v, current, forces, 0).into_iter().map(|(contact, _)| contact).collect()
    }

    /// [`drive`] with the foot references raised ([`LandingDetector::raises`]) over the first
    /// `raised` periods. Returns the detections and the feet pushed up.
    fn drive_raised(d: &mut MotorCurrent<LegKinematics>, dt: f64, n: usize, qd_v: f64, current: f64, forces: Option<[f64; 6]>, raised: usize) -> Vec<([bool; 6], [bool; 6])> {
        let mut m = Measurements { supply_voltage: 12.0, foot_normal_forces: forces, ..Default::default() };
        (0..n)
            .map(|k| {
                for l in 0..6 {
                    m.positions[3 * l..3 * l + 3].copy_from_slice(&[0.0, 0.05 + qd_v * k as f64 * dt, 0.03]);
                    m.currents[3 * l + 1] = current;
                    if k < raised {
                        d.raises(l);
                    }
                }
                m.t = k as f64 * dt;
                (d.ground_contact(&m), d.pushed_up())
            })
            .collect()
    }

    /// The current of the vertical joint that balances a vertical force `f` on the foot at
    /// q = (0, q_v, 0.03) going down at `qd_v`, plus the joint's own friction: the oracle is
    /// the leg Jacobian by finite differences (τ_gnd = −J^T F, Eq. 5.20) and Table 5.3, apart
    /// from the estimator. It leaves out the weight of the leg's links.
    fn balancing_current(robot: &RobotDescription, q_v: f64, qd_v: f64, f: f64) -> f64 {
        let leg = LegKinematics::hexapod_from_description(robot).unwrap()[0].clone();
        let q = Vector3::new(0.0, q_v, 0.03);
        let h = 1e-7;
        let dz = (leg.foot(&(q + Vector3::new(0.0, h, 0.0))).z - leg.foot(&(q - Vector3::new(0.0, h, 0.0))).z) / (2.0 * h);
        let tau_gnd = -dz * f;
        let friction = robot.friction(0, PantographJoint::Vertical).dry_viscous().torque(qd_v).0;
        (tau_gnd + friction) / robot.joint_torque_per_ampere(PantographJoint::Vertical)
    }

    /// The leg going down (or up) for 2 s (six time constants of the 3 Hz filters) with the
    /// current balancing `f`: the detections and the estimated force at the end.
    fn settled(robot: &RobotDescription, qd_v: f64, f: f64) -> (Vec<[bool; 6]>, f64) {
        let dt = robot.controller.period_s;
        let mut d = amru5_detector(robot, dt);
        // q_v moves by 1 cm over the 2 s: the current is that of the middle.
        let i = balancing_current(robot, 0.055, qd_v, f);
        let out = drive(&mut d, dt, (2.0 / dt) as usize, qd_v, i, None);
        (out, d.detections[0].force)
    }

    #[test]
    fn motor_current_detects_a_ground_force_above_the_threshold_going_down_only() {
        let robot = RobotDescription::amru5();
        let qd_v = 0.005;
        let (_, air) = settled(&robot, qd_v, 0.0);
        // In the air the estimate is the weight of the links the oracle leaves out: small
        // against the threshold (Section 5.6.2: gravity is "very small" for q_v).
        assert!(air.abs() < 0.25 * THESIS_CURRENT_THRESHOLD, "in the air: {air} N");
        for f in [0.0, 0.5 * THESIS_CURRENT_THRESHOLD, 1.5 * THESIS_CURRENT_THRESHOLD, 3.0 * THESIS_CURRENT_THRESHOLD] {
            let (out, e) = settled(&robot, qd_v, f);
            // Eq. 5.22 on the oracle's ground force, to 1 %.
            assert!((e - air - f).abs() < 0.01 * f.max(1.0), "F = {f} N: estimated {e} N, {air} N in the air");
            let last = out.last().unwrap();
            assert!(last.iter().all(|&c| c == (e >= THESIS_CURRENT_THRESHOLD)), "F = {f} N: {last:?}");
            assert_eq!(last[0], f > THESIS_CURRENT_THRESHOLD, "F = {f} N");
            // The same force with the foot going up (q_v' < 0): never a detection (Section 5.6.3).
            let (out, _) = settled(&robot, -qd_v, f);
            assert!(out.iter().flatten().all(|&c| !c), "F = {f} N going up detected");
        }
    }

    /// A vertical joint held still by its static friction (or creeping inside the linear zone
    /// of its dry/viscous law) under three times the threshold's current is not a landing, nor
    /// is the start of a descent before the filters have followed it.
    #[test]
    fn motor_current_needs_the_joint_sliding_down() {
        let robot = RobotDescription::amru5();
        let dt = robot.controller.period_s;
        let i = balancing_current(&robot, 0.05, 0.0, 3.0 * THESIS_CURRENT_THRESHOLD);
        for creep in [0.0, 1e-5] {
            let mut d = amru5_detector(&robot, dt);
            assert!(drive(&mut d, dt, 300, creep, i, None).iter().flatten().all(|&c| !c), "creeping at {creep} m/s");
        }
        let (out, _) = settled(&robot, 0.005, 3.0 * THESIS_CURRENT_THRESHOLD);
        let first = out.iter().position(|c| c[0]).unwrap();
        let settling = settling_time();
        assert!((first as f64 * dt - settling).abs() < 2.0 * dt, "first detection after {} s", first as f64 * dt);
    }

    /// Beyond the thesis: a foot going up (q_v' < 0) under three times the threshold is pushed
    /// up once its joint has slid for the settling time, never detected as a landing (Section
    /// 5.6.3); the same motion in the air, or commanded (its reference raised, and the joint
    /// never at rest since), is no push.
    #[test]
    fn motor_current_sees_a_foot_pushed_up_against_its_reference() {
        let robot = RobotDescription::amru5();
        let dt = robot.controller.period_s;
        let n = (2.0 / dt) as usize;
        let up = -0.005;
        let loaded = balancing_current(&robot, 0.045, up, 3.0 * THESIS_CURRENT_THRESHOLD);
        let out = drive_raised(&mut amru5_detector(&robot, dt), dt, n, up, loaded, None, 0);
        assert!(out.iter().all(|(contact, _)| contact.iter().all(|&c| !c)));
        let first = out.iter().position(|(_, pushed)| pushed[0]).expect("pushed up");
        assert!((first as f64 * dt - settling_time()).abs() < 2.0 * dt, "pushed up after {} s", first as f64 * dt);
        assert!(out[first..].iter().all(|(_, pushed)| pushed.iter().all(|&p| p)));
        let air = balancing_current(&robot, 0.045, up, 0.0);
        assert!(drive_raised(&mut amru5_detector(&robot, dt), dt, n, up, air, None, 0).iter().all(|(_, pushed)| pushed.iter().all(|&p| !p)));
        let commanded = drive_raised(&mut amru5_detector(&robot, dt), dt, n, up, loaded, None, n / 2);
        assert!(commanded.iter().all(|(_, pushed)| pushed.iter().all(|&p| !p)));
    }

    #[test]
    fn motor_current_ignores_the_simulated_foot_forces() {
        let robot = RobotDescription::amru5();
        let dt = robot.controller.period_s;
        let mut d = amru5_detector(&robot, dt);
        let i = balancing_current(&robot, 0.055, 0.005, 0.0);
        let out = drive(&mut d, dt, 200, 0.005, i, Some([500.0; 6]));
        assert!(out.iter().flatten().all(|&c| !c));
    }

    #[test]
    fn normal_force_detects_above_the_threshold_only_with_forces() {
        let mut d = NormalForce { threshold: THESIS_FORCE_THRESHOLD };
        let mut m = Measurements { foot_normal_forces: Some([0.0, 9.99, 10.0, 10.01, 50.0, -1.0]), ..Default::default() };
        assert_eq!(d.ground_contact(&m), [false, false, false, true, true, false]);
        m.foot_normal_forces = None;
        assert_eq!(d.ground_contact(&m), [false; 6]);
    }
}
