//! The gait controller (thesis Sections 7.3-7.6): heading velocities → desired body HTM →
//! foot references (support: anchor points, Eq. 7.11; swing: AEP, Eq. 7.24-7.31) → inverse
//! kinematics (Eq. 7.7) → joint references → 18 digital PI (Eq. 4.18-4.20) → motor voltages.
//!
//! It sees only what the real robot measures (encoder positions, currents, supply voltage) and,
//! when the robot has one, the navigation system's body pose: the same code drives the
//! simulated and the real robot.

use nalgebra::Vector3;

use super::body_motion::{BodyMotion, Pose};
use super::walk::{LegState, Walk};
use super::heading::{Heading, HeadingSource};
use super::pattern::{FootCycle, FootPhase, GaitPattern};
use crate::control::{joint_command, BodyPose, Command, Controller, DigitalPi, FrictionFeedForward, Measurements};
use crate::hexapod::{Leg as LegMechanism, LegKinematics, Workspace, JOINTS};
use crate::spatial::Htm;

/// How the AEP is found during the swing (Section 7.5).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AepMode {
    /// Computed once at the start of the swing, constant swing velocity (Eq. 7.24-7.28, 7.30-7.31).
    Periodic,
    /// Recomputed at every control step, swing velocity of Eq. 7.29 saturated at twice its
    /// steady-state value (Section 7.5.2).
    Omnidirectional,
}

/// Parameters of the gait.
#[derive(Clone, Debug, PartialEq)]
pub struct GaitOptions {
    /// Leg cycle time T (s).
    pub period: f64,
    pub pattern: GaitPattern,
    pub cycle: FootCycle,
    pub aep: AepMode,
    /// Foot clearance: the top of the foot's lift above its support level at mid-swing (m). The
    /// enhanced cycle reaches it rising at the constant speed of its takeoff (Section 7.6), the
    /// plain cycle with a triangular profile (Fig. 7.12).
    pub lift: f64,
    /// Control period Δt (s).
    pub dt: f64,
}

/// The state of one leg.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Leg {
    phase: FootPhase,
    /// Anchor point {p_F/0}_0 of the support (Eq. 7.10), or the virtual one of the landing.
    anchor: Vector3<f64>,
    /// Horizontal foot reference in the leg frame during the swing.
    swing_xy: Vector3<f64>,
    /// Start of the current swing (leg frame), its AEP and its duration, for the periodic mode.
    swing_from: Vector3<f64>,
    aep: Vector3<f64>,
    swing_time: f64,
    /// Current foot reference (leg frame) and joint references.
    foot: Vector3<f64>,
    joints: Vector3<f64>,
}

/// Counters of what went wrong, for reports and tests.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GaitDiagnostics {
    /// Foot references the inverse kinematics had to clamp into the joint ranges, and the last
    /// instant it happened (the first step starts from the workspace centres, so its stroke is
    /// not centred, Section 7.5.1, and may overrun at high velocities).
    pub clamped_references: usize,
    pub last_clamped_at: Option<f64>,
    pub gait_switches: usize,
}

/// The periodic/omnidirectional gait controller on flat ground, for legs of any mechanism
/// (AMRU5's pantographs by default, [`crate::hexapod::SerialLegKinematics`] for serial legs).
pub struct GaitController<L: LegMechanism = LegKinematics> {
    pub options: GaitOptions,
    legs_kinematics: [L; 6],
    workspaces: [Workspace; 6],
    pis: [DigitalPi; JOINTS],
    /// The servo goals' friction feed-forward, when the master adds one.
    feedforward: Option<FrictionFeedForward>,
    heading: Box<dyn HeadingSource>,
    walk: Walk<Leg>,
    /// Time of the gait's origin (phase 0 of the pattern).
    origin: f64,
    pending: Option<GaitPattern>,
    pub diagnostics: GaitDiagnostics,
}

impl<L: LegMechanism> GaitController<L> {
    pub fn new(options: GaitOptions, legs: [L; 6], workspaces: [Workspace; 6], pis: [DigitalPi; JOINTS], heading: Box<dyn HeadingSource>) -> Self {
        let idle = Leg { phase: FootPhase::Support, anchor: Vector3::zeros(), swing_xy: Vector3::zeros(), swing_from: Vector3::zeros(), aep: Vector3::zeros(), swing_time: 0.0, foot: Vector3::zeros(), joints: Vector3::zeros() };
        GaitController { options, legs_kinematics: legs, workspaces, pis, feedforward: None, heading, walk: Walk { body: None, legs: [idle; 6] }, origin: 0.0, pending: None, diagnostics: GaitDiagnostics::default() }
    }

    /// The same controller sending its servos the goals of `feedforward` (none: the references).
    pub fn with_friction_feedforward(self, feedforward: Option<FrictionFeedForward>) -> Self {
        GaitController { feedforward, ..self }
    }

    pub fn workspaces(&self) -> &[Workspace; 6] {
        &self.workspaces
    }

    /// Asks for another gait while walking. Legs in the air finish their swing; legs on the
    /// ground do not lift until all six are down; then the new pattern starts at the phase of
    /// one of its swing starts where no leg is caught mid-swing (or the fewest), so that no
    /// more legs than the pattern lifts at once are ever in the air.
    pub fn change_gait(&mut self, pattern: GaitPattern) {
        self.pending = Some(pattern);
    }

    /// T_{0,b} T_{b,l} for a body pose.
    fn leg_frame(&self, leg: usize, body: &Htm) -> Htm {
        body.compose(&self.legs_kinematics[leg].body_from_leg())
    }

    /// First update: the body pose (navigation, or the feet on flat ground at z = 0) and the
    /// anchors of the six feet from the measured joints, on one support level (their mean
    /// height: the ground is flat, and the encoders' quantization must not give each foot a
    /// support level of its own).
    fn start(&mut self, m: &Measurements) {
        let feet: Vec<Vector3<f64>> = (0..6).map(|l| self.legs_kinematics[l].foot_in_body(&joints_of(m, l))).collect();
        let pose = m.pose.map_or_else(
            || Pose { position: Vector3::new(0.0, 0.0, -feet.iter().map(|f| f.z).sum::<f64>() / 6.0), angles: Vector3::zeros() },
            |p| pose_of(&p),
        );
        let htm = pose.htm();
        for l in 0..6 {
            let q = joints_of(m, l);
            let foot = self.legs_kinematics[l].foot(&q);
            self.walk.legs[l].foot = foot;
            self.walk.legs[l].joints = q;
            self.walk.legs[l].anchor = self.leg_frame(l, &htm).apply(&foot);
        }
        let level = self.walk.legs.iter().map(|l| l.anchor.z).sum::<f64>() / 6.0;
        for leg in &mut self.walk.legs {
            leg.anchor.z = level;
        }
        self.walk.body = Some(BodyMotion::new(pose));
        self.origin = m.t;
    }

    /// The body pose the anchors are computed with: the navigation system's, or the desired
    /// one when the robot has none (it is assumed to follow its reference, Section 7.4).
    fn estimated_pose(&self, m: &Measurements, desired: &Pose) -> Htm {
        estimated_pose(m, desired)
    }

    /// Foot lift (normal to the body plane) at local phase φ, a triangle of height `lift`: over
    /// the swing for the plain cycle (Fig. 7.12); from the start of the takeoff to the end of
    /// the landing for the enhanced cycle, which so rises at constant speed through the takeoff
    /// and the first half of the swing and comes down symmetrically (Section 7.6; the takeoff
    /// rise ΔZ is a third of the clearance for β = 1/2, Δφ = 5 %).
    fn lift(&self, phi: f64) -> f64 {
        let o = &self.options;
        let beta = self.current_pattern().beta;
        let (from, to) = match o.cycle {
            FootCycle::Plain => (beta, 1.0),
            FootCycle::Enhanced { overlap } => (beta + overlap / 2.0, 1.0 - overlap / 2.0),
        };
        let s = ((phi - from) / (to - from)).clamp(0.0, 1.0);
        o.lift * (1.0 - (2.0 * s - 1.0).abs())
    }

    fn current_pattern(&self) -> &GaitPattern {
        &self.options.pattern
    }

    /// AEP in the leg frame (Eq. 7.24 / 7.30): the workspace centre C moved by the velocity of C
    /// over half the support.
    fn aep(&self, leg: usize, frame: &Htm, body: &BodyMotion, heading: &Heading, z: f64) -> Vector3<f64> {
        let o = &self.options;
        let c_leg = self.workspaces[leg].centre_at(z);
        let v_c = centre_velocity(&self.legs_kinematics[leg], &c_leg, frame, &body.pose.htm(), heading);
        let mut aep = c_leg + v_c * (o.cycle.support_fraction(self.current_pattern().beta) * o.period / 2.0);
        aep.z = z;
        aep
    }

    /// Switches to the pending pattern when all feet are down.
    fn try_switch(&mut self, t: f64) {
        if self.pending.is_none() || self.walk.legs.iter().any(|l| l.phase != FootPhase::Support) {
            return;
        }
        let next = self.pending.take().expect("pending");
        let cycle = self.options.cycle;
        // Candidate origins: the new pattern started just at one of its swing starts.
        let mut best = (usize::MAX, 0.0);
        for leg in 0..6 {
            let g = (next.beta - next.offsets[leg]).rem_euclid(1.0);
            let mid_swing = (0..6)
                .filter(|&l| {
                    let phi = (g + next.offsets[l]).rem_euclid(1.0);
                    let start = cycle.swing_start(next.beta) - cycle.transition_fraction();
                    !cycle.phase(phi, next.beta).on_ground() && phi > start + 1e-9
                })
                .count();
            if mid_swing < best.0 {
                best = (mid_swing, g);
            }
        }
        // Phase g at time t: origin = t − g T, nudged back by a step so that the first legs
        // start their cycle at this update.
        self.origin = t - best.1 * self.options.period + 1e-9;
        self.options.pattern = next;
        self.diagnostics.gait_switches += 1;
    }
}

/// The joints that put every foot at its foothold (leg frames), found by Eq. 7.7 from each
/// leg's neutral posture ([`LegMechanism::neutral`]). The error is the first leg that cannot reach its foothold.
pub fn joints_at<L: LegMechanism>(legs: &[L; 6], footholds: &[Vector3<f64>; 6]) -> Result<[f64; JOINTS], usize> {
    let mut joints = [0.0; JOINTS];
    for l in 0..6 {
        match legs[l].inverse(&footholds[l], &legs[l].neutral()) {
            Ok(ik) if ik.is_reached() => joints[3 * l..3 * l + 3].copy_from_slice(ik.joints.as_slice()),
            _ => return Err(l),
        }
    }
    Ok(joints)
}

/// The standing posture: every foot at the centre of its workspace on the ground `height` below
/// the body (leg frame z = −height).
pub fn joints_at_workspace_centres<L: LegMechanism>(legs: &[L; 6], workspaces: &[Workspace; 6], height: f64) -> Result<[f64; JOINTS], usize> {
    joints_at(legs, &std::array::from_fn(|l| workspaces[l].centre_at(-height)))
}

/// The walking start posture: each foot on the ground `height` below the body where the steady
/// gait of `options` under the heading `start` would have it at the leg's initial phase, so that
/// the first support stroke is centred on the workspace centre C like every later one.
///
/// INTERPRETATION: the thesis starts from the workspace centres and notes that "during the
/// first step, the stroke is not centered in the workspace" (Section 7.5.1); from a centre, the
/// first support stroke |v_C| (β + 4Δφ) T runs from C to a full stroke behind it and leaves the
/// workspace as soon as the stroke exceeds its radius (2.5 cm/s with T = 12 s). Here a foot
/// whose phase is e T into its motion with the body, which begins at the AEP (the landing's
/// start, φ = 1 − 2Δφ, or φ = 0 for the plain cycle) and lasts the support fraction s
/// (Eq. 7.24, 7.30), stands at AEP − v_C e T = C + v_C (s/2 − e) T; a foot whose phase is a
/// fraction u into its swing stands where the steady swing would carry it, PEP + u (AEP − PEP) =
/// C + v_C s T (u − 1/2), and swings to its AEP in the rest of the swing. Every AEP is the
/// steady one, so the walk from the first swing on is the steady walk.
pub fn steady_footholds<L: LegMechanism>(legs: &[L; 6], workspaces: &[Workspace; 6], height: f64, options: &GaitOptions, start: &Heading) -> [Vector3<f64>; 6] {
    let beta = options.pattern.beta;
    let cycle = options.cycle;
    let support = cycle.support_fraction(beta);
    let moving_from = cycle.swing_start(beta) + cycle.swing_fraction(beta);
    std::array::from_fn(|l| {
        let centre = workspaces[l].centre_at(-height);
        let elapsed = (options.pattern.phase(l, 0.0, options.period) - moving_from).rem_euclid(1.0);
        // Eq. 7.25 at the start (yaw 0: the global and body frames coincide), in the leg frame.
        let v_c = legs[l].direction_to_leg(&start.point_velocity(&legs[l].to_body(&centre)));
        let behind_aep = if elapsed < support { elapsed } else { support * (1.0 - (elapsed - support) / (1.0 - support)) };
        let mut foot = centre + v_c * ((support / 2.0 - behind_aep) * options.period);
        foot.z = -height;
        foot
    })
}

/// The encoder positions (q_r, q_v, q_h) of one leg.
pub(super) fn joints_of(m: &Measurements, leg: usize) -> Vector3<f64> {
    Vector3::new(m.positions[3 * leg], m.positions[3 * leg + 1], m.positions[3 * leg + 2])
}

/// The navigation system's body pose.
pub(super) fn pose_of(p: &BodyPose) -> Pose {
    Pose { position: p.position, angles: Vector3::new(p.yaw, p.pitch, p.roll) }
}

/// The body pose the anchors are computed with (Section 7.4): the navigation system's, or the
/// desired one when the robot has none (it is assumed to follow its reference).
pub(super) fn estimated_pose(m: &Measurements, desired: &Pose) -> Htm {
    m.pose.map_or_else(|| desired.htm(), |p| pose_of(&p).htm())
}

/// Eq. 7.25 in the leg frame: the commanded velocity v_C/0 of the workspace centre `c_leg` (leg
/// frame), for the leg frame `frame` = T_{0,b} T_{b,l} and the body pose `body` = T_{0,b}.
pub(super) fn centre_velocity<L: LegMechanism>(kin: &L, c_leg: &Vector3<f64>, frame: &Htm, body: &Htm, heading: &Heading) -> Vector3<f64> {
    frame.rotation.transpose() * heading.point_velocity(&(body.rotation * kin.to_body(c_leg)))
}

impl<L: LegMechanism> Controller for GaitController<L> {
    fn update(&mut self, m: &Measurements) -> Command {
        let h = self.heading.heading(m.t);
        if let Some(body) = &mut self.walk.body {
            // Eq. 7.12-7.23: the desired body HTM from the heading velocities.
            body.step(h.velocity, Vector3::new(0.0, 0.0, h.yaw_rate), self.options.dt);
        } else {
            self.start(m);
        }
        self.try_switch(m.t);
        let body = self.walk.body.clone().expect("started");
        let desired = body.pose.htm();
        let estimated = self.estimated_pose(m, &body.pose);
        let o = self.options.clone();
        let beta = o.pattern.beta;
        let swing_time = o.cycle.swing_fraction(beta) * o.period;
        let mut references = [0.0; JOINTS];
        for l in 0..6 {
            let phi = o.pattern.phase(l, m.t - self.origin, o.period);
            let mut target = o.cycle.phase(phi, beta);
            let leg = self.walk.legs[l];
            // While a new gait is pending, no foot leaves the ground.
            if self.pending.is_some() && leg.phase == FootPhase::Support {
                target = FootPhase::Support;
            }
            // A foot only lands through the landing (or, plain cycle, ends its swing).
            if leg.phase == FootPhase::Support && target == FootPhase::Landing {
                target = FootPhase::Support;
            }
            let frame_desired = self.leg_frame(l, &desired);
            let frame_estimated = self.leg_frame(l, &estimated);
            let support_foot = frame_desired.inverse().apply(&leg.anchor); // Eq. 7.11
            let mut next = leg;
            next.phase = target;
            match (leg.phase, target) {
                // Entering the swing: start from the current horizontal reference. A swing entered
                // late (a walk that starts with the leg's phase in the swing) has only the rest of
                // the swing to reach its AEP.
                (FootPhase::Support | FootPhase::Takeoff, FootPhase::Swing) => {
                    next.swing_from = Vector3::new(leg.foot.x, leg.foot.y, support_foot.z);
                    next.swing_xy = next.swing_from;
                    next.aep = self.aep(l, &frame_desired, &body, &h, support_foot.z);
                    let late = (phi - o.cycle.swing_start(beta)) * o.period;
                    next.swing_time = if late < o.dt { swing_time } else { ((o.cycle.swing_start(beta) + o.cycle.swing_fraction(beta) - phi) * o.period).max(o.dt) };
                }
                // Landing: the virtual AEP of Section 7.6 where the foot reference is, seen with
                // the estimated body pose, so that the support algorithm runs during the landing.
                (FootPhase::Swing, FootPhase::Landing) => {
                    let mut foot = leg.swing_xy;
                    foot.z = support_foot.z;
                    next.anchor = frame_estimated.apply(&foot);
                    next.anchor.z = leg.anchor.z;
                }
                // Touchdown, the beginning of the support (Section 7.4): the anchor is where the
                // encoders put the foot, seen with the estimated body pose, at the support level,
                // so that the legs on the ground do not fight each other.
                (FootPhase::Swing | FootPhase::Landing, FootPhase::Support) => {
                    let measured = frame_estimated.apply(&self.legs_kinematics[l].foot(&joints_of(m, l)));
                    next.anchor = Vector3::new(measured.x, measured.y, leg.anchor.z);
                }
                _ => {}
            }
            let lift = if target == FootPhase::Support { 0.0 } else { self.lift(phi) };
            next.foot = match target {
                FootPhase::Support | FootPhase::Takeoff | FootPhase::Landing => {
                    let mut p = frame_desired.inverse().apply(&next.anchor);
                    p.z += lift;
                    p
                }
                FootPhase::Swing => {
                    let remaining = ((o.cycle.swing_start(beta) + o.cycle.swing_fraction(beta) - phi) * o.period).max(o.dt);
                    let velocity = match o.aep {
                        // Eq. 7.26 / 7.31.
                        AepMode::Periodic => (next.aep - next.swing_from) / next.swing_time,
                        // Eq. 7.29 with the saturation at twice the steady swing velocity.
                        AepMode::Omnidirectional => {
                            let aep = self.aep(l, &frame_desired, &body, &h, support_foot.z);
                            next.aep = aep;
                            let v = (aep - next.swing_xy) / remaining;
                            let steady = 2.0 * (aep - self.workspaces[l].centre_at(aep.z)).norm() / swing_time;
                            let limit = 2.0 * steady;
                            if v.norm() > limit && limit > 0.0 {
                                v * (limit / v.norm())
                            } else {
                                v
                            }
                        }
                    };
                    // Eq. 7.27-7.28 (the vertical is the lift profile).
                    next.swing_xy += Vector3::new(velocity.x, velocity.y, 0.0) * o.dt;
                    Vector3::new(next.swing_xy.x, next.swing_xy.y, support_foot.z + lift)
                }
            };
            // Eq. 7.7 from the previous references.
            let ik = self.legs_kinematics[l].inverse(&next.foot, &leg.joints).expect("finite foot reference");
            if !ik.is_reached() {
                self.diagnostics.clamped_references += 1;
                self.diagnostics.last_clamped_at = Some(m.t);
            }
            next.joints = ik.joints;
            self.walk.legs[l] = next;
            references[3 * l..3 * l + 3].copy_from_slice(ik.joints.as_slice());
        }
        joint_command(&mut self.pis, self.feedforward.as_mut(), references, m)
    }
}

impl LegState for Leg {
    fn phase(&self) -> FootPhase {
        self.phase
    }
    fn foot(&self) -> Vector3<f64> {
        self.foot
    }
}

impl<L: LegMechanism> std::ops::Deref for GaitController<L> {
    type Target = Walk<Leg>;
    fn deref(&self) -> &Walk<Leg> {
        &self.walk
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::gait::heading::Constant;
    use crate::control::joint_pis;
    use crate::description::RobotDescription;
    use crate::test_util::rng;
    use rand::Rng;

    /// Issue 18: from the steady footholds, no foot reference leaves its workspace and none is
    /// clamped by the inverse kinematics, for random constant headings whose support stroke
    /// fits the workspace (the scenario check: (|v| + |Ω_z| r_C) (β + 4Δφ) T <= 2 R), for the
    /// three patterns and both foot cycles. The plant is ideal: the joints are their references.
    #[test]
    fn a_walk_from_the_steady_footholds_never_leaves_the_workspace() {
        let d = RobotDescription::amru5();
        let legs = LegKinematics::hexapod_from_description(&d).unwrap();
        let height = -legs[0].foot(&Vector3::new(0.0, 0.06, 0.035)).z;
        let lift = 0.045;
        let workspaces: [Workspace; 6] = std::array::from_fn(|l| legs[l].workspace_for_body_height(height, lift).unwrap());
        let dt = d.controller.period_s;
        let mut r = rng(18);
        for case in 0..120 {
            let pattern = match case % 3 {
                0 => GaitPattern::tripod(),
                1 => GaitPattern::wave(r.random_range(0.5..0.75)),
                _ => GaitPattern::equal_phase(r.random_range(0.5..0.75)),
            };
            let cycle = if case % 2 == 0 { FootCycle::Enhanced { overlap: 0.05 } } else { FootCycle::Plain };
            let period = r.random_range(6.0..15.0);
            let support = cycle.support_fraction(pattern.beta) * period;
            let direction = r.random_range(0.0..std::f64::consts::TAU);
            let turning = r.random_range(-1.0f64..1.0) * 0.02;
            let arm = (0..6).map(|l| legs[l].to_body(&workspaces[l].centre_at(-height)).xy().norm()).fold(0.0, f64::max);
            let radius = workspaces[0].radius;
            // The fastest speed whose stroke fits, and a random fraction of it.
            let speed = ((2.0 * radius / support - turning.abs() * arm) * r.random_range(0.3..1.0)).max(0.0);
            let heading = Heading::new(speed * direction.cos(), speed * direction.sin(), turning);
            let options = GaitOptions { period, pattern, cycle, aep: AepMode::Periodic, lift, dt };
            let footholds = steady_footholds(&legs, &workspaces, height, &options, &heading);
            let joints = joints_at(&legs, &footholds).unwrap();
            let mut controller = GaitController::new(options, legs.clone(), workspaces, joint_pis(&d.joint_pi_gains(), dt), Box::new(Constant(heading)));
            let mut m = Measurements { t: 0.0, positions: joints, currents: [0.0; JOINTS], supply_voltage: 12.0, pose: None, foot_normal_forces: None };
            let mut outside = 0.0f64;
            for k in 0..(2.0 * period / dt).round() as usize {
                m.t = k as f64 * dt;
                let command = controller.update(&m);
                for (l, foot) in controller.foot_references().iter().enumerate() {
                    outside = outside.max(workspaces[l].distance_outside(foot));
                }
                m.positions = command.references;
            }
            assert_eq!(controller.diagnostics.clamped_references, 0, "case {case}: {heading:?}, T = {period}, {:?}", controller.diagnostics);
            assert!(outside < 1e-9, "case {case}: a foot reference {outside} m outside its workspace ({heading:?}, T = {period})");
        }
    }
}
