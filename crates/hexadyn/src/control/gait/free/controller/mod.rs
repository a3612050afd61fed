//! The free gait controller (thesis Section 7.7, flowchart of Fig. 7.29): heading velocities →
//! posture on each new touchdown (Rule 1, [`super::posture`]) → corrected global velocities
//! ([`super::velocity`]) → desired body HTM (Eq. 7.12-7.23) → foot references by leg state
//! (support: anchors, Eq. 7.11; takeoff, swing to the AEP of maximum kinematic margin, landing
//! until the ground is detected) → inverse kinematics (Eq. 7.7) → 18 digital PI → then Rules 2
//! and 3 choose the legs that lift ([`super::rules`]) and the deadlock condition halts the
//! support legs (Section 7.7.4).
//!
//! Like the periodic [`GaitController`](crate::control::gait::controller::GaitController) it sees
//! only the measurements (and the navigation system's pose when there is one); the landing
//! detector decides from the measurements too ([`super::landing`]). Which candidate may lift
//! with the robot balanced is the `lift` module's.

mod lift;

use nalgebra::Vector3;

use super::elevator::{resistance, retreat};
use super::five_legs::{bands, Band};
use crate::control::settling_time;
use super::landing::LandingDetector;
use super::posture::{ground_plane, solve_posture};
use super::rules::{deadlocked, neighbours, swing_candidates};
use super::velocity::corrected_velocities;
use crate::control::gait::body_motion::{BodyMotion, Pose};
use crate::control::gait::walk::{LegState, Walk};
use crate::control::gait::controller::{centre_velocity, estimated_pose, joints_of, pose_of, GaitDiagnostics};
use crate::control::gait::heading::{Heading, HeadingSource};
use crate::control::gait::pattern::FootPhase;
use crate::control::{joint_command, Command, Controller, DigitalPi, FrictionFeedForward, Measurements};
use crate::hexapod::{Leg as LegMechanism, LegDynamics, LegKinematics, Workspace, JOINTS};
use crate::mbs::Data;
use crate::spatial::Htm;

/// Security margin of the AEP inside the workspace boundary (m).
///
/// INTERPRETATION: Section 7.1.1 restricts the working volume "for a degree of security"
/// without a figure. The anchor of a new support is where the encoders put the foot seen from
/// the estimated body pose, while its reference is computed from the desired pose (Eq. 7.11):
/// the difference, the body's tracking error, moves the support foot reference. On the 20°
/// slope that error reaches about 1 cm (and the horizontal joints' tracking error about 6 mm),
/// and a foot landing on the boundary starts its support outside its workspace, lifts again at
/// once (lowest margin, Rule 3) and keeps a neighbour at its boundary deadlocked. 1 cm.
pub const AEP_SECURITY: f64 = 0.01;

/// The fastest a landing foot approaches the ground (m/s): 3 cm/s, the foot speed at which
/// Section 5.6.3 validated the detection from the motor currents (the Table 5.6 sawtooth, 5 mm/s
/// of q_v; docs/ground-detection.md). INTERPRETATION (beyond the thesis, issue 37).
pub const APPROACH_SPEED_M_S: f64 = 0.03;

/// Room (m) the support feet keep below the top of their reach when the body goes down after a
/// landing foot at the bottom of its reach.
///
/// INTERPRETATION: the security margin of the working volume ([`AEP_SECURITY`]).
pub const REACH_ROOM: f64 = AEP_SECURITY;

/// How far (m) a support foot may go down or up from its anchor before it counts as off its
/// foothold.
///
/// INTERPRETATION (beyond the thesis, issue 37): a foot that lands on a tread's nosing, or on a
/// ridge of rough ground, is detected there (Section 5.6.3) and slides off down the face when
/// the load shifts onto it, typically as a neighbour lifts; the body sinks 1-3 cm with it and the
/// lifting foot, still on the ground, carries it (in the staircases and ramp drops of the
/// terrain-class benchmark, 2026-11-29, all but one of the takeoffs that carried load without
/// rising had a support foot 1.6-5.6 cm below its anchor). The encoders in the estimated body
/// pose (the navigation system's) see it; the foot then lands again from where it is (down the
/// face to the tread below, detected from the currents), and the takeoffs under way come back
/// down, as the support they were checked against has changed. The same holds for a support
/// foot lifted off its foothold: when a foot slides off, the body tips onto it and raises the
/// feet across (4-5 cm on a staircase up at the thesis' lift, 2026-11-30), which stay in support
/// for the controller and let their neighbours lift; lowered again, they carry the body. 1 cm:
/// the security margin of the working volume ([`AEP_SECURITY`]), well above the millimetres a
/// loaded foot sinks into the ground of Table 3.3. Without a navigation system the body pose is
/// the desired one and the encoders follow their references: nothing is seen.
pub const OFF_FOOTHOLD: f64 = AEP_SECURITY;

/// Parameters of the free gait.
#[derive(Clone, Debug, PartialEq)]
pub struct FreeGaitOptions {
    /// Height of the body frame above the ground in the well-conditioned posture (m): the feet
    /// at z = −body_height in their leg frames, the references p_z,C/b of Eq. 7.32.
    pub body_height: f64,
    /// Rise of the foot during the takeoff (m), kept through the swing (Section 7.7.3: "the
    /// takeoff has given a foot clearance high enough to avoid obstacles").
    pub lift: f64,
    /// Duration of the takeoff (s); the landing descends at the same speed lift / takeoff_time.
    pub takeoff_time: f64,
    /// Duration of the swing, the constant denominator of Eq. 7.31 (3 s in Section 7.7.3).
    pub swing_time: f64,
    /// t_post of Eq. 7.35-7.37 (2 s for AMRU5).
    pub posture_time: f64,
    /// A failed leg, held up (beyond the thesis: the rules extend to five legs).
    pub failed_leg: Option<usize>,
    /// Smallest static stability margin (m) that the feet left in support must keep when a leg
    /// lifts against the pushes of the feet in the air (each at the landing threshold where it
    /// is), with a failed leg; on six legs the bound is zero (no tip-over).
    pub stability_margin: f64,
    /// Smallest normalized energy stability margin (m, [`super::stability`]) that the feet left
    /// in support must keep when a leg lifts, on six legs and on five (beyond the thesis: its
    /// conclusion's "stability issues in the choice of the swinging leg").
    pub energy_margin: f64,
    /// Control period Δt (s).
    pub dt: f64,
    /// The elevator reflex of the swing ([`super::elevator`], beyond the thesis) with its
    /// threshold (N) on the estimated force resisting the swing, or None: a swinging foot
    /// stopped by an obstacle rises by the lift and goes on.
    pub elevator: Option<f64>,
}

/// The state of one leg.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Leg {
    phase: FootPhase,
    /// Anchor {p_F/0}_0 of the support (Eq. 7.10); in the air, the last contact point (used by
    /// Eq. 7.32); during the landing, the virtual anchor of the descending foot.
    anchor: Vector3<f64>,
    /// Last contact point (global), for the posture of the legs in the air.
    contact: Vector3<f64>,
    /// Time spent in the current phase (s).
    elapsed: f64,
    /// Foot reference (leg frame) at the start of the swing, p_PEP,takeoff of Eq. 7.31 (after
    /// an elevator reflex, where the foot swings on from).
    pep: Vector3<f64>,
    /// Duration of the swing from `pep` (s): the swing time, or what was left of it when an
    /// elevator reflex began.
    swing_time: f64,
    /// Height (leg frame) the foot rises to while an elevator reflex lifts it.
    rise_to: Option<f64>,
    /// How far the landing foot has gone down below its virtual anchor (m).
    descent: f64,
    /// How long the swing has been resisted above the elevator threshold without a break (s).
    resisted: f64,
    /// Current foot reference (leg frame) and joint references.
    foot: Vector3<f64>,
    joints: Vector3<f64>,
}

/// What the free gait did at its last update, for the results columns.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FreeGaitState {
    /// Height of the body above the ground plane estimated from the contact points (m).
    pub clearance: f64,
    /// Roll and pitch of the body as the controller knows them (rad): the navigation system's,
    /// else the desired ones.
    pub roll: f64,
    pub pitch: f64,
    /// Legs whose landing was detected at this update.
    pub touchdowns: [bool; 6],
    /// The support legs are halted (Section 7.7.4).
    pub deadlock: bool,
    /// Posture computations (Rule 1) so far.
    pub postures: usize,
    /// Instants spent deadlocked so far.
    pub deadlocked_periods: usize,
    /// Elevator reflexes so far ([`super::elevator`]).
    pub elevations: usize,
    /// A landing foot went a lift below the ground level of the posture, or to the bottom of
    /// its leg's reach, without finding the ground: the body goes down.
    pub reaching_down: bool,
    /// Normalized energy stability margin (m, [`super::stability`]) of the feet in support
    /// after this update's lifts, as the controller knows them (their anchors, the centre of
    /// mass in the estimated body pose, [`FreeGaitController::with_masses`]); −∞ with fewer
    /// than three.
    pub stability_margin: f64,
}

/// The free gait controller of Section 7.7, for legs of any mechanism (AMRU5's pantographs by
/// default, [`crate::hexapod::SerialLegKinematics`] for serial legs).
pub struct FreeGaitController<L: LegMechanism = LegKinematics> {
    pub options: FreeGaitOptions,
    legs_kinematics: [L; 6],
    workspaces: [Workspace; 6],
    pis: [DigitalPi; JOINTS],
    /// The friction feed-forward of the servo goals, as the periodic gait's.
    feedforward: Option<FrictionFeedForward>,
    heading: Box<dyn HeadingSource>,
    landing: Box<dyn LandingDetector>,
    neighbours: [Option<(usize, usize)>; 6],
    /// Offset of each leg's footholds from its workspace centre (leg frame): zero on six legs.
    foothold_offset: [Vector3<f64>; 6],
    /// The half-planes of the body frame the support feet keep to on five legs
    /// ([`super::five_legs`]), for the walk of the current update.
    bands: [Option<Band>; 6],
    /// Highest foot of each leg's reach (leg frame, m).
    reach_top: [f64; 6],
    /// Where the failed leg's foot is held ([`held_up`]), found once (leg frame).
    held_up: Option<Vector3<f64>>,
    walk: Walk<Leg>,
    /// Body-frame posture velocities (v_z, ω_x, ω_y) of Eq. 7.35-7.37 and when they end.
    posture: (Vector3<f64>, f64),
    /// The body sway of a deadlock on five legs ([`Self::sway`]): global velocity (m/s).
    sway: Option<(usize, Vector3<f64>)>,
    /// The robot's masses, for its centre of mass in the stability of a lift
    /// ([`Self::with_masses`]); without them the centre of mass is the body frame's origin.
    masses: Option<(Data, LegDynamics)>,
    state: FreeGaitState,
    pub diagnostics: GaitDiagnostics,
}

impl<L: LegMechanism> FreeGaitController<L> {
    pub fn new(
        options: FreeGaitOptions,
        legs: [L; 6],
        workspaces: [Workspace; 6],
        pis: [DigitalPi; JOINTS],
        heading: Box<dyn HeadingSource>,
        landing: Box<dyn LandingDetector>,
    ) -> Self {
        let z = Vector3::zeros();
        let idle = Leg { phase: FootPhase::Support, anchor: z, contact: z, elapsed: 0.0, pep: z, swing_time: options.swing_time, rise_to: None, descent: 0.0, resisted: 0.0, foot: z, joints: z };
        let neighbours = neighbours(options.failed_leg);
        let foothold_offset = foothold_offsets(&options, &legs, &workspaces);
        let reach_top: [f64; 6] = std::array::from_fn(|l| legs[l].height_range().1);
        let held_up = options.failed_leg.map(|l| held_up(&legs[l], &workspaces[l], reach_top[l]));
        FreeGaitController {
            options,
            legs_kinematics: legs,
            workspaces,
            pis,
            feedforward: None,
            heading,
            landing,
            neighbours,
            foothold_offset,
            bands: [None; 6],
            reach_top,
            held_up,
            walk: Walk { body: None, legs: [idle; 6] },
            posture: (z, f64::NEG_INFINITY),
            sway: None,
            masses: None,
            state: FreeGaitState::default(),
            diagnostics: GaitDiagnostics::default(),
        }
    }

    /// The same controller sending its servos the goals of `feedforward` (none: the references),
    /// as [`GaitController::with_friction_feedforward`](crate::control::gait::controller::GaitController::with_friction_feedforward).
    pub fn with_friction_feedforward(self, feedforward: Option<FrictionFeedForward>) -> Self {
        FreeGaitController { feedforward, ..self }
    }

    /// The robot's masses ([`LegDynamics`], the multibody model of the ground detection's
    /// torque estimate, Section 5.6.2) for the centre of mass of the stability check; builder
    /// style.
    pub fn with_masses(mut self, dynamics: LegDynamics) -> Self {
        self.masses = Some((Data::new(&dynamics.model), dynamics));
        self
    }

    pub fn state(&self) -> FreeGaitState {
        self.state
    }

    /// True when the foot reference `p` (leg frame) is within the leg's reach (Eq. 7.7 from `q`).
    fn reaches(&self, leg: usize, p: &Vector3<f64>, q: &Vector3<f64>) -> bool {
        self.legs_kinematics[leg].inverse(p, q).is_ok_and(|ik| ik.is_reached())
    }

    /// The foot reference `p` (leg frame) of a foot in the air, lowered when it is beyond the
    /// leg's reach to the highest point the leg reaches above its horizontal position less the
    /// room of [`REACH_ROOM`] (the security margin of the working volume, which keeps the joint
    /// references off their end-stops), down to `floor` at most (the height of the ground it
    /// took off from): `p` itself when the leg reaches it or reaches nothing down to `floor`.
    /// Reached means Eq. 7.7 from the joints `q` (the last references) reaches it, the test
    /// that counts the clamped references.
    ///
    /// Beyond the thesis, whose takeoff rises by the lift wherever the foot is: after a step up
    /// the foot on the step starts its takeoff high in its leg frame, and the lift took legs 1
    /// and 5 of `free_gait_step` against their top end-stop (546 limit-switch cuts, 1712
    /// references clamped by Eq. 7.7; issue 37). The periodic gaits keep their references
    /// inside the workspace; the free gait keeps them inside the reach.
    fn within_reach(&self, leg: usize, p: Vector3<f64>, floor: f64, q: &Vector3<f64>) -> Vector3<f64> {
        let at = |z: f64| Vector3::new(p.x, p.y, z);
        if self.reaches(leg, &p, q) || !(floor < p.z) || !self.reaches(leg, &at(floor), q) {
            return p;
        }
        let (mut low, mut high) = (floor, p.z);
        while high - low > 1e-6 {
            let mid = 0.5 * (low + high);
            if self.reaches(leg, &at(mid), q) { low = mid } else { high = mid }
        }
        at((low - REACH_ROOM).max(floor))
    }

    /// Where the encoders put the foot of `leg` (global) seen from the body pose `estimated`.
    fn measured_foot(&self, leg: usize, m: &Measurements, estimated: &Htm) -> Vector3<f64> {
        self.leg_frame(leg, estimated).apply(&self.legs_kinematics[leg].foot(&joints_of(m, leg)))
    }

    fn working(&self, leg: usize) -> bool {
        self.options.failed_leg != Some(leg)
    }

    fn leg_frame(&self, leg: usize, body: &Htm) -> Htm {
        body.compose(&self.legs_kinematics[leg].body_from_leg())
    }

    /// First update: the body pose (navigation, or level with the body frame at the mean foot
    /// height) and an anchor under every working foot, where the encoders put it.
    fn start(&mut self, m: &Measurements) {
        let working: Vec<usize> = (0..6).filter(|&l| self.working(l)).collect();
        let mean_z = working.iter().map(|&l| self.legs_kinematics[l].foot_in_body(&joints_of(m, l)).z).sum::<f64>() / working.len() as f64;
        let pose = m.pose.map_or_else(|| Pose { position: Vector3::new(0.0, 0.0, -mean_z), angles: Vector3::zeros() }, |p| pose_of(&p));
        let htm = pose.htm();
        for l in 0..6 {
            let q = joints_of(m, l);
            let foot = self.legs_kinematics[l].foot(&q);
            let anchor = self.leg_frame(l, &htm).apply(&foot);
            let phase = if self.working(l) { FootPhase::Support } else { FootPhase::Swing };
            self.walk.legs[l] = Leg { phase, anchor, contact: anchor, elapsed: 0.0, pep: foot, swing_time: self.options.swing_time, rise_to: None, descent: 0.0, resisted: 0.0, foot, joints: q };
        }
        self.walk.body = Some(BodyMotion::new(pose));
    }

    /// Rule 1 (Eq. 7.32-7.37): the posture that puts the last contact points of the working
    /// legs (seen from the estimated body pose) closest to their references, as body velocities
    /// over t_post from now.
    fn compute_posture(&mut self, estimated: &Htm, t: f64) {
        let to_body = estimated.inverse();
        let (mut p0, mut reference) = (Vec::with_capacity(6), Vec::with_capacity(6));
        for l in (0..6).filter(|&l| self.working(l)) {
            p0.push(to_body.apply(&self.walk.legs[l].contact));
            let kin = &self.legs_kinematics[l];
            reference.push(kin.to_body(&self.workspaces[l].centre_at(-self.options.body_height)).z);
        }
        // The simplex does not fail on finite inputs; if it ever did, the posture is kept.
        let c = solve_posture(&p0, &reference).unwrap_or_default();
        let (vz, wx, wy) = c.velocities(self.options.posture_time);
        self.posture = (Vector3::new(vz, wx, wy), t + self.options.posture_time);
        self.state.postures += 1;
    }

    /// The AEP of maximum kinematic margin (Section 7.7.3, from Eq. 7.24): the point of the
    /// workspace from which the foot, moving at −v_C in support, travels the longest before the
    /// boundary, i.e. C + v̂_C R (leg frame, horizontal).
    ///
    /// INTERPRETATION: the foot touches down after its landing, which carries it with the
    /// support motion for about the takeoff time; the AEP is set back by that distance,
    /// |v_C| t_takeoff, and by the security margin of the constrained working volume (Section
    /// 7.1.1, [`AEP_SECURITY`]), so that the touchdown is inside the boundary and not beyond it.
    /// With a band ([`super::five_legs`]) the AEP is moved across the body, along the band's
    /// normal, to the security margin inside it.
    fn aep(&self, leg: usize, v_c: &Vector3<f64>, z: f64) -> Vector3<f64> {
        let w = &self.workspaces[leg];
        let v = Vector3::new(v_c.x, v_c.y, 0.0);
        let speed = v.norm();
        let offset = self.foothold_offset[leg];
        let mut aep = w.centre_at(z) + offset;
        if speed > 0.0 {
            // The boundary along v̂ from the (offset) centre: |o + s v̂| = R.
            let u = v / speed;
            let ou = offset.dot(&u);
            let reach = -ou + (ou * ou + w.radius * w.radius - offset.norm_squared()).max(0.0).sqrt();
            aep += u * (reach - speed * self.options.takeoff_time - AEP_SECURITY).max(0.0);
        }
        let kin = &self.legs_kinematics[leg];
        self.bands[leg].map_or(aep, |b| aep + kin.direction_to_leg(&b.normal) * b.shortfall(&kin.to_body(&aep), AEP_SECURITY))
    }

    /// Kinematic margin (Section 7.7.3) of the foot at `p` moving at −v_C in its leg frame:
    /// the horizontal distance to the side of the workspace cylinder.
    ///
    /// INTERPRETATION: on uneven ground the feet leave the cylinder's height range (its caps
    /// bound the foot heights on flat ground); the posture control keeps the heights, and the
    /// margin that selects the swing and the deadlock is the horizontal one, "the remaining
    /// distance to travel (in the direction of the robot motion)". With a band
    /// ([`super::five_legs`]), the smaller of that and the distance to the band's edge.
    fn margin(&self, leg: usize, p: &Vector3<f64>, v_c: &Vector3<f64>) -> f64 {
        let w = &self.workspaces[leg];
        let level = Vector3::new(p.x, p.y, p.z.clamp(w.z_min, w.z_max));
        let motion = Vector3::new(-v_c.x, -v_c.y, 0.0);
        let kinematic = w.margin(&level, &motion);
        let kin = &self.legs_kinematics[leg];
        let along = kin.body_from_leg().rotation * motion;
        self.bands[leg].filter(|_| along.norm() > 0.0).map_or(kinematic, |b| kinematic.min(b.margin(&kin.to_body(p), &along.normalize())))
    }

    /// The bands of the feet for the walk commanded by `h` with the body at `desired`
    /// ([`super::five_legs::bands`]): the feet keep the stability margin and the security margin
    /// of the working volume beyond the body centre. None on six legs.
    fn bands_for(&self, desired: &Htm, h: &Heading) -> [Option<Band>; 6] {
        let Some(failed) = self.options.failed_leg else { return [None; 6] };
        let centres = std::array::from_fn(|l| self.legs_kinematics[l].to_body(&self.workspaces[l].centre_at(-self.options.body_height)));
        let radii = self.workspaces.map(|w| w.radius);
        bands(failed, &(desired.rotation.transpose() * h.velocity), &centres, &radii, self.options.stability_margin + AEP_SECURITY)
    }

}

/// Where a failed leg is held: above its workspace centre `w`, as high as the leg reaches there
/// (below `reach_top`, the top of its reach) less the security margin of the working volume
/// ([`AEP_SECURITY`]).
///
/// INTERPRETATION (beyond the thesis): "held up" is read as high as the leg can be held. At
/// the top of the workspace, the height of a foot in the air (one lift above the ground),
/// the held-up foot of a failed rear leg touched the ground when the body leaned 5.2°
/// towards its corner while a neighbour swung (measured with leg 4 failed): a failed leg
/// carries no weight and needs no room to step, so nothing keeps it as low as a swinging
/// foot. The highest reachable point above the centre is found by bisection between the
/// top of the workspace and the top of the leg's reach ([`LegMechanism::reaches_point`]:
/// on the pantograph its reachable radii, which shrink upwards; on a serial leg Eq. 7.7, so
/// the point is found once, not at every control instant).
fn held_up<L: LegMechanism>(kin: &L, w: &Workspace, reach_top: f64) -> Vector3<f64> {
    let reaches = |z: f64| kin.reaches_point(&w.centre_at(z));
    let (mut low, mut high) = (w.z_max, reach_top);
    if reaches(high) {
        low = high;
    }
    while high - low > 1e-6 {
        let mid = 0.5 * (low + high);
        if reaches(mid) { low = mid } else { high = mid }
    }
    w.centre_at((low - AEP_SECURITY).max(w.z_max))
}

/// Beyond the thesis: with a failed leg, the footholds of the five working legs are offset
/// towards the failed leg by a fifth of its workspace centre's horizontal distance from the body
/// centre (body frame), so that the body centre stands over the centroid of the five workspace
/// centres instead of the six; zero offsets on six legs (the thesis' AEP of Section 7.7.3).
///
/// INTERPRETATION: the thesis is silent on five legs. With the footholds of the six-legged
/// gait, the diagonal of the support polygon between the front and rear feet of the side
/// without the failed leg's neighbour on it passes through the body centre (the feet sit at
/// ±30°, 90°, ±150°); lifting the other foot of the failed leg's side leaves the centre on that
/// diagonal, 36 mm outside with leg 2 failed, and the walk deadlocks for good. Shifting the
/// body towards the side with three legs, over the centroid of the support, is the standard
/// remedy of fault-tolerant and quadruped gaits (the body sway of the quadruped crawl gaits;
/// J.-M. Yang and J.-H. Kim, "Fault-tolerant locomotion of the hexapod robot", IEEE Trans.
/// SMC-B 28(1), 1998, for a hexapod with a locked leg). Here it is done by the footholds, so
/// the body keeps the commanded heading: each foot lands offset in its workspace and moves
/// along the chord through its offset centre.
fn foothold_offsets<L: LegMechanism>(options: &FreeGaitOptions, legs: &[L; 6], workspaces: &[Workspace; 6]) -> [Vector3<f64>; 6] {
    let Some(failed) = options.failed_leg else { return [Vector3::zeros(); 6] };
    let c = legs[failed].to_body(&workspaces[failed].centre_at(-options.body_height));
    let shift = Vector3::new(c.x, c.y, 0.0) / 5.0;
    std::array::from_fn(|l| if l == failed { Vector3::zeros() } else { legs[l].direction_to_leg(&shift) })
}

impl<L: LegMechanism> Controller for FreeGaitController<L> {
    fn update(&mut self, m: &Measurements) -> Command {
        let o = self.options.clone();
        let h: Heading = self.heading.heading(m.t);
        let first = self.walk.body.is_none();
        if first {
            self.start(m);
        }
        let contact = self.landing.ground_contact(m);
        let pushed = self.landing.pushed_up();
        let forces = self.landing.foot_forces();
        let settling = settling_time();
        let lag = self.landing.lag_s();
        let before = self.walk.body.as_ref().expect("started").pose;
        let estimated = estimated_pose(m, &before);

        // Landings detected: the support begins where the encoders put the foot (Section 7.4).
        // Beyond the thesis (issue 37): so does a landing or swinging foot that the ground
        // pushes up ([`LandingDetector::pushed_up`]). It carries the body: a landing foot the
        // detection of Section 5.6.3 misses (its joint back-driven upwards) and a swinging foot
        // that met the ground from above have landed where they are. A swinging foot stopped
        // against its swing is the elevator reflex's ([`super::elevator`]); a foot whose
        // reference rises (takeoff, the reflex's rise) is never pushed up.
        self.state.touchdowns = [false; 6];
        let measured: [Vector3<f64>; 6] = std::array::from_fn(|l| self.measured_foot(l, m, &estimated));
        for l in 0..6 {
            let leg = &self.walk.legs[l];
            let landed = match leg.phase {
                FootPhase::Landing => contact[l] || pushed[l],
                FootPhase::Swing => leg.rise_to.is_none() && pushed[l],
                _ => false,
            };
            if self.working(l) && landed {
                let leg = &mut self.walk.legs[l];
                (leg.phase, leg.anchor, leg.contact, leg.elapsed) = (FootPhase::Support, measured[l], measured[l], 0.0);
                self.state.touchdowns[l] = true;
            }
        }
        // Beyond the thesis (issue 37): a support foot that slides down off the edge it landed
        // on, or that the body lifts off it, lands again from where it is, and the takeoffs it
        // was to carry turn back ([`OFF_FOOTHOLD`]).
        let slipping = |l: usize, leg: &Leg| self.working(l) && leg.phase == FootPhase::Support && (leg.anchor.z - measured[l].z).abs() > OFF_FOOTHOLD;
        if self.walk.legs.iter().enumerate().any(|(l, leg)| slipping(l, leg)) {
            let again: [bool; 6] = std::array::from_fn(|l| slipping(l, &self.walk.legs[l]) || self.walk.legs[l].phase == FootPhase::Takeoff);
            for l in (0..6).filter(|&l| again[l]) {
                let leg = &mut self.walk.legs[l];
                leg.land_from(measured[l]);
                self.landing.landing_starts(l);
            }
        }
        // Rule 1: the posture when a new leg touches the ground (and at the start).
        if first || self.state.touchdowns.iter().any(|&t| t) {
            self.compute_posture(&estimated, m.t);
        }

        // Section 7.7.2: the corrected global velocities; zero while deadlocked (Section 7.7.4).
        let rotation = before.htm().rotation;
        let landing_speed = o.lift / o.takeoff_time;
        let (mut v_b, omega_b) = if self.state.deadlock {
            (self.sway.map_or_else(Vector3::zeros, |(_, u)| u), Vector3::zeros())
        } else {
            let (local, until) = self.posture;
            let local = if m.t < until - 0.5 * o.dt { local } else { Vector3::zeros() };
            let n = rotation * Vector3::z();
            let v_post = n * local.x;
            let omega_post = rotation * Vector3::new(local.y, local.z, 0.0);
            corrected_velocities(&h.velocity, &Vector3::new(0.0, 0.0, h.yaw_rate), &v_post, &omega_post, &n)
        };
        // INTERPRETATION (beyond the thesis, issue 11): a landing foot that has gone one lift
        // below the ground level of the posture (z = −body height, leg frame) without finding
        // the ground meets a step down that may be deeper than the leg reaches from the body
        // height: the body goes down along its z axis at the landing speed, while the support
        // feet have room above them in their reach (the posture control of the next touchdown
        // then puts the body back at its height over the new contacts). The leg goes on
        // lowering its foot (the landing detection from the currents needs the vertical joint
        // sliding down, Section 5.6.3) until the bottom of its reach, where it holds. It is a
        // vertical motion, kept while deadlocked.
        if self.state.reaching_down {
            v_b -= rotation * Vector3::z() * landing_speed;
        }
        if !first {
            // Eq. 7.12-7.23.
            self.walk.body.as_mut().expect("started").step(v_b, omega_b, o.dt);
        }
        let body = self.walk.body.clone().expect("started");
        let desired = body.pose.htm();
        let estimated = estimated_pose(m, &body.pose);

        self.bands = self.bands_for(&desired, &h);
        let mut references = [0.0; JOINTS];
        let (mut reaching_down, mut room) = (false, f64::INFINITY);
        let mut margins = [f64::INFINITY; 6];
        let mut speed_max = 0.0f64;
        for l in 0..6 {
            let mut leg = self.walk.legs[l];
            let frame_desired = self.leg_frame(l, &desired);
            let c = self.workspaces[l].centre_at(-o.body_height);
            let v_c = centre_velocity(&self.legs_kinematics[l], &c, &frame_desired, &desired, &h);
            leg.elapsed += o.dt;
            let mut descent_speed = landing_speed;
            leg.foot = if !self.working(l) {
                self.held_up.expect("found for the failed leg")
            } else {
                match leg.phase {
                    // Eq. 7.11.
                    FootPhase::Support => frame_desired.inverse().apply(&leg.anchor),
                    // Lifted at constant speed with the support's horizontal motion.
                    FootPhase::Takeoff => {
                        self.landing.raises(l);
                        let ground = frame_desired.inverse().apply(&leg.anchor);
                        let lifted = ground + Vector3::z() * (landing_speed * leg.elapsed.min(o.takeoff_time));
                        let p = self.within_reach(l, lifted, ground.z, &leg.joints);
                        if leg.elapsed >= o.takeoff_time - 0.5 * o.dt {
                            (leg.phase, leg.elapsed, leg.pep, leg.swing_time) = (FootPhase::Swing, 0.0, p, o.swing_time);
                        }
                        p
                    }
                    // The elevator reflex: up at the takeoff's speed, held horizontally, to the
                    // height it aims at or as high as the leg reaches; then the swing goes on
                    // from there.
                    FootPhase::Swing if leg.rise_to.is_some() => {
                        self.landing.raises(l);
                        let mut p = leg.foot;
                        let top = leg.rise_to.unwrap_or(p.z);
                        p.z = (p.z + landing_speed * o.dt).min(top);
                        let reached = self.reaches(l, &p, &leg.joints);
                        if !reached {
                            p.z = leg.foot.z;
                        }
                        if !reached || p.z >= top {
                            (leg.rise_to, leg.pep, leg.elapsed) = (None, p, 0.0);
                        }
                        p
                    }
                    // Eq. 7.31 with the constant swing time and the AEP recomputed at every
                    // step; the foot height stays that of the end of the takeoff.
                    FootPhase::Swing => {
                        let aep = self.aep(l, &v_c, leg.pep.z);
                        let pushed = forces.and_then(|f| f[l]).map_or(0.0, |f| resistance(&f, &(aep - leg.pep)));
                        leg.resisted = if o.elevator.is_some_and(|threshold| pushed > threshold) && leg.elapsed >= settling - 0.5 * o.dt { leg.resisted + o.dt } else { 0.0 };
                        let settled = leg.resisted >= settling - 0.5 * o.dt;
                        let measured = self.legs_kinematics[l].foot(&joints_of(m, l));
                        let back = retreat(&leg.foot, &measured, &(aep - leg.pep));
                        if settled && self.reaches(l, &(back + Vector3::z() * (0.5 * o.lift)), &leg.joints) {
                            // An obstacle: back off and rise (super::elevator) in the swing
                            // time that is left.
                            leg.swing_time = (leg.swing_time - leg.elapsed).max(o.takeoff_time);
                            (leg.rise_to, leg.resisted) = (Some(back.z + o.lift), 0.0);
                            self.state.elevations += 1;
                            back
                        } else if settled {
                            // An obstacle above the leg's reach: back off and land in front of
                            // it (super::elevator).
                            leg.land_from(self.leg_frame(l, &estimated).apply(&back));
                            self.landing.landing_starts(l);
                            back
                        } else {
                            if self.state.reaching_down {
                                // Beyond the thesis (issue 37): the body goes down to a landing
                                // foot (see below); the swinging foot keeps its height above the
                                // ground instead of going down with the body onto the next tread.
                                leg.pep.z += landing_speed * o.dt;
                                self.landing.raises(l);
                            }
                            let v = (aep - leg.pep) / leg.swing_time;
                            let mut p = leg.foot + Vector3::new(v.x, v.y, 0.0) * o.dt;
                            p.z = leg.pep.z;
                            let p = self.within_reach(l, p, frame_desired.inverse().apply(&leg.anchor).z, &leg.joints);
                            if leg.elapsed >= leg.swing_time - 0.5 * o.dt {
                                // The landing: a virtual anchor where the foot is, so that the
                                // support algorithm runs while the foot descends (Section 7.6).
                                leg.land_from(self.leg_frame(l, &estimated).apply(&p));
                                self.landing.landing_starts(l);
                            }
                            p
                        }
                    }
                    // Down at constant speed until the ground is detected. INTERPRETATION
                    // (beyond the thesis, issue 37): for a detector that lags the ground force
                    // (LandingDetector::lag_s: the settling time of the filtered currents; none
                    // for the simulated normal force), within the distance the landing speed
                    // covers in that lag above the posture's ground level (z = −body height),
                    // and below it, at most APPROACH_SPEED_M_S: the foot presses on for that
                    // time before its landing is detected, and at the landing speed of the
                    // thesis' 10.5 cm lift (10.5 cm/s) it pushed the body up by a centimetre or
                    // more, unloading the other feet (docs/benchmarks.md).
                    FootPhase::Landing => {
                        let mut p = frame_desired.inverse().apply(&leg.anchor);
                        let above = p.z - leg.descent + o.body_height;
                        if lag > 0.0 && above <= landing_speed * lag {
                            descent_speed = landing_speed.min(APPROACH_SPEED_M_S);
                        }
                        leg.descent += descent_speed * o.dt;
                        p.z -= leg.descent;
                        if p.z > leg.foot.z + 0.5 * landing_speed * o.dt {
                            // The virtual anchor is where the encoders put the foot in the
                            // estimated pose; seen from the desired one, the landing may start
                            // above the swing's height (the body below its desired height): a
                            // commanded rise, not the ground's push.
                            self.landing.raises(l);
                        }
                        reaching_down |= p.z < -o.body_height - o.lift;
                        p
                    }
                }
            };
            if self.working(l) && leg.phase == FootPhase::Support {
                margins[l] = self.margin(l, &leg.foot, &v_c);
                speed_max = speed_max.max(v_c.xy().norm());
                room = room.min(self.reach_top[l] - leg.foot.z);
            }
            // Eq. 7.7 from the previous references.
            let mut ik = self.legs_kinematics[l].inverse(&leg.foot, &leg.joints).expect("finite foot reference");
            if self.working(l) && leg.phase == FootPhase::Landing && leg.foot.z < -o.body_height && !ik.is_reached() {
                // The landing foot at the bottom of its reach: it stays there while the body goes
                // down (see above).
                leg.descent -= descent_speed * o.dt;
                leg.foot.z += descent_speed * o.dt;
                ik = self.legs_kinematics[l].inverse(&leg.foot, &leg.joints).expect("finite foot reference");
                reaching_down = true;
            }
            if !ik.is_reached() {
                self.diagnostics.clamped_references += 1;
                self.diagnostics.last_clamped_at = Some(m.t);
            }
            leg.joints = ik.joints;
            references[3 * l..3 * l + 3].copy_from_slice(ik.joints.as_slice());
            self.walk.legs[l] = leg;
        }

        // Rules 2 and 3, and the deadlock condition (Section 7.7.4).
        let support: [bool; 6] = std::array::from_fn(|l| self.working(l) && self.walk.legs[l].phase == FootPhase::Support);
        // A neighbour's step: takeoff, swing and a landing as long as the takeoff on flat ground.
        let reserve = speed_max * (2.0 * o.takeoff_time + o.swing_time);
        let boundary = speed_max * o.dt;
        let centre = self.centre_of_mass(m, &estimated);
        let lifting = self.lifting(swing_candidates(&support, &margins, &self.neighbours, reserve), &support, &margins, &centre, boundary);
        for l in (0..6).filter(|&l| lifting[l]) {
            let leg = &mut self.walk.legs[l];
            (leg.phase, leg.elapsed, leg.contact) = (FootPhase::Takeoff, 0.0, leg.anchor);
        }
        let swaying = self.sway.map(|(b, _)| b).filter(|&b| support[b] && !lifting[b]);
        self.state.deadlock = deadlocked(&support, &margins, &lifting, boundary) || swaying.is_some();
        self.sway = if self.state.deadlock { self.sway(swaying, &support, &lifting, &margins, boundary, &centre, &desired, h.velocity.xy().norm()) } else { None };
        self.state.deadlocked_periods += usize::from(self.state.deadlock);
        let standing: [bool; 6] = std::array::from_fn(|l| support[l] && !lifting[l]);
        self.state.stability_margin = self.energy_margin_of(&standing, &centre);
        self.state.reaching_down = reaching_down && room > REACH_ROOM;

        // The posture as the controller knows it.
        let to_body = estimated.inverse();
        let contacts: Vec<Vector3<f64>> = (0..6).filter(|&l| self.working(l)).map(|l| to_body.apply(&self.walk.legs[l].contact)).collect();
        self.state.clearance = ground_plane(&contacts).map_or(f64::NAN, |(height, _)| height);
        let angles = m.pose.map_or(body.pose.angles, |p| pose_of(&p).angles);
        (self.state.pitch, self.state.roll) = (angles.y, angles.z);

        joint_command(&mut self.pis, self.feedforward.as_mut(), references, m)
    }
}

impl Leg {
    /// The landing begins from `anchor` (global), the virtual anchor of the descending foot
    /// (Section 7.6): the end of the swing, a swing stopped by an obstacle it cannot rise over
    /// ([`super::elevator`]), a support foot off its foothold ([`OFF_FOOTHOLD`]).
    fn land_from(&mut self, anchor: Vector3<f64>) {
        (self.phase, self.anchor, self.elapsed, self.descent) = (FootPhase::Landing, anchor, 0.0, 0.0);
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

impl<L: LegMechanism> std::ops::Deref for FreeGaitController<L> {
    type Target = Walk<Leg>;
    fn deref(&self) -> &Walk<Leg> {
        &self.walk
    }
}
