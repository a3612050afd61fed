//! The stability of a lift in the free gait (beyond the thesis: its conclusion's "integration
//! of stability issues in the choice of the swinging leg"): which of the legs Rules 2 and 3 allow
//! may lift with the feet left keeping the robot balanced (the normalized energy stability
//! margin, [`super::super::stability`], and the tip against the pushes of the feet in the air,
//! [`super::super::rules::stability_margin`]), the fallbacks and the body sway that keep a
//! five-legged walk going, and the robot's centre of mass they are computed from.

use nalgebra::{Vector2, Vector3};

use super::super::rules::{deadlocked, rule_2, stability_margin, Push};
use super::super::stability::energy_stability_margin;
use super::{FreeGaitController, REACH_ROOM};
#[cfg(doc)]
use super::super::landing::LandingDetector;
#[cfg(doc)]
use super::FreeGaitOptions;
#[cfg(doc)]
use crate::hexapod::LegDynamics;
use crate::control::gait::pattern::FootPhase;
use crate::control::Measurements;
use crate::hexapod::Leg as LegMechanism;
use crate::spatial::Htm;

impl<L: LegMechanism> FreeGaitController<L> {
    /// The legs that lift now among the Rule 2-3 candidates, in order of increasing margin, those
    /// whose lift keeps the support balanced ([`Self::balanced`]). With a failed leg, if that
    /// leaves the robot deadlocked (Section 7.7.4: a support leg at its boundary, `boundary`,
    /// that does not lift), or if every working foot is down and the stability refuses all of
    /// Rule 3's candidates, the leg of lowest margin among those that Rule 2 alone allows and
    /// that keep the stability margin lifts instead.
    ///
    /// INTERPRETATION (beyond the thesis): on five legs Rule 3's candidate can be a leg whose
    /// lift would tip the robot; at the start, with the feet at their workspace centres and equal
    /// margins, the tie-break makes it the only candidate, and the robot would stay halted for
    /// good (legs 0, 1 and 2 failed). Lifting another leg that Rule 2 allows is the smallest
    /// change that lets the walk go on: Rule 3 orders the legs, the stability decides.
    ///
    /// INTERPRETATION: during a deadlock the fallback lifts only a leg at its boundary (or the
    /// leg the body sways for, [`Self::sway`]). A leg far from its boundary that just landed at
    /// its AEP gains nothing by stepping again during a deadlock, since the body stands still,
    /// and holds its neighbours back under Rule 2: with leg 0 failed, legs 3 and 4 stepped in
    /// place for good while legs 1, 2 and 5 stood at their boundaries (measured). The deadlock
    /// also lasts while the body sways for a blocked leg, until that leg lifts.
    ///
    /// INTERPRETATION: with every foot down and the body walking, a refused candidate would hold
    /// every other leg down until it reached its boundary. At the start the feet stand at their
    /// workspace centres with equal margins, and the tie-break makes the lone leg at the leading
    /// end (leg 1 with leg 0 failed) Rule 3's only candidate; its lift is unstable (the middle
    /// feet beside the body centre are the front edge of the support left), so no leg lifted for
    /// 29.6 s while the body walked a whole stroke, and the walk then deadlocked with every foot
    /// at its boundary (0.88 m of 1 m with a front leg failed walking forwards, measured
    /// 2026-11-29). The next leg in Rule 3's order that may lift, lifts.
    pub(super) fn lifting(&self, candidates: [bool; 6], support: &[bool; 6], margins: &[f64; 6], centre: &Vector3<f64>, boundary: f64) -> [bool; 6] {
        let lifting = self.stable_lifts(candidates, margins, support, centre);
        if self.options.failed_leg.is_none() {
            return lifting;
        }
        let swaying = self.sway.map(|(b, _)| b);
        let deadlock = deadlocked(support, margins, &lifting, boundary) || swaying.is_some_and(|b| support[b] && !lifting[b]);
        let all_down = (0..6).all(|l| !self.working(l) || support[l]);
        let refused = !deadlock && all_down && candidates.contains(&true) && !lifting.contains(&true);
        if !deadlock && !refused {
            return lifting;
        }
        let allowed: [bool; 6] = std::array::from_fn(|l| rule_2(l, support, &self.neighbours) && ((refused && margins[l].is_finite()) || margins[l] < boundary || swaying == Some(l)));
        let fallback = self.stable_lifts(allowed, margins, support, centre);
        let first = (0..6).filter(|&l| fallback[l]).min_by(|&a, &b| margins[a].total_cmp(&margins[b]));
        std::array::from_fn(|l| Some(l) == first)
    }

    /// Beyond the thesis, the deadlock of Section 7.7.4 on five legs: the body velocity (global,
    /// horizontal) that sways the body towards the feet that would stay in support if the
    /// blocked leg lifted, `None` to halt as in the thesis.
    ///
    /// INTERPRETATION: on six legs a deadlock clears when the neighbour in the air lands (Rule
    /// 2), and halting is "the safest way to operate". On five legs a support leg at its
    /// boundary that Rule 2 allows can be held back by the stability margin alone; halting then
    /// changes nothing, since the body and the feet in support stand still, and the walk halted
    /// for good (measured with leg 0, 1 or 5 failed). The blocked leg is the one of lowest margin
    /// (the lower leg number on a tie, as in Rule 3) among the support legs at their boundary
    /// that Rule 2 allows and that do not lift. The body moves at the commanded walking speed
    /// towards the centroid of the feet left in support without it (the body sway of the
    /// quadruped crawl gaits, the usual remedy on a hexapod with a failed leg), until the lift
    /// keeps the stability margin and the leg lifts (Rule 3, [`Self::lifting`]). The feet at
    /// their boundary do not move outwards: the component of the sway that would push one out is
    /// removed, so they slide along the boundary or move inwards. The blocked foot is the
    /// exception while its leg reaches [`REACH_ROOM`] beyond it: it lifts once the sway is done,
    /// and held to its workspace it stopped the sway it waits for (with leg 4 failed, leg 2's
    /// foot at the rear and outer side of its workspace, offset outwards by the five-leg
    /// footholds, let the body sway 2 mm/s instead of 5, and the walks with a rear leg failed
    /// deadlocked 13-15 s at a time, 0.83-0.86 m of 1 m; with it 5 s, 0.95 m, measured
    /// 2026-11-29). If the sway would take another
    /// support foot out of its workspace, or leaves no motion, or fewer than three feet would
    /// stay down, the body halts as in the thesis.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn sway(&self, swaying: Option<usize>, support: &[bool; 6], lifting: &[bool; 6], margins: &[f64; 6], boundary: f64, centre: &Vector3<f64>, desired: &Htm, speed: f64) -> Option<(usize, Vector3<f64>)> {
        self.options.failed_leg?;
        let standing: [bool; 6] = std::array::from_fn(|l| support[l] && !lifting[l]);
        let blocked = swaying.filter(|&b| rule_2(b, support, &self.neighbours)).or_else(|| (0..6).filter(|&l| standing[l] && margins[l] < boundary && rule_2(l, support, &self.neighbours)).min_by(|&a, &b| margins[a].total_cmp(&margins[b]).then(a.cmp(&b))))?;
        let feet: Vec<Vector2<f64>> = (0..6).filter(|&k| standing[k] && k != blocked).map(|k| self.walk.legs[k].anchor.xy()).collect();
        let towards = feet.iter().sum::<Vector2<f64>>() / feet.len() as f64 - centre.xy();
        if feet.len() < 3 || !(speed > 0.0) || !(towards.norm() > 0.0) {
            return None;
        }
        let towards = towards.normalize() * speed;
        let mut u = Vector3::new(towards.x, towards.y, 0.0);
        // The outward normal (global, horizontal) of each foot at its boundary: its band's edge
        // when it is outside its band (at the start), else the side of its workspace.
        let outward = |k: usize| {
            let n = match self.bands[k].filter(|b| b.depth(&self.legs_kinematics[k].to_body(&self.walk.legs[k].foot)) < 0.0) {
                Some(b) => desired.rotation * -b.normal,
                None => {
                    let out = self.walk.legs[k].foot.xy() - self.workspaces[k].centre;
                    self.leg_frame(k, desired).rotation * Vector3::new(out.x, out.y, 0.0)
                }
            };
            Vector3::new(n.x, n.y, 0.0).normalize()
        };
        // The blocked foot, which lifts when the sway is done, may go on outwards while it keeps
        // the security margin inside its reach.
        let room = || {
            let foot = self.walk.legs[blocked].foot;
            let out = foot.xy() - self.workspaces[blocked].centre;
            out.norm() > 0.0 && self.legs_kinematics[blocked].reaches_point(&(foot + Vector3::new(out.x, out.y, 0.0).normalize() * REACH_ROOM))
        };
        let at_boundary: Vec<usize> = (0..6).filter(|&k| standing[k] && margins[k] < boundary && !(k == blocked && room())).collect();
        for &k in &at_boundary {
            let n = outward(k);
            u -= n * u.dot(&n).min(0.0);
        }
        // The foot moves by −u dt relative to its leg frame.
        let stays = |k: usize| {
            let p = self.walk.legs[k].foot - self.leg_frame(k, desired).rotation.transpose() * u * self.options.dt;
            (p.xy() - self.workspaces[k].centre).norm() <= self.workspaces[k].radius && self.bands[k].is_none_or(|b| b.depth(&self.legs_kinematics[k].to_body(&p)) >= 0.0)
        };
        let outwards = at_boundary.iter().any(|&k| u.dot(&outward(k)) < -1e-9 * speed);
        let leaves = (0..6).any(|k| standing[k] && margins[k] >= boundary && !stays(k));
        (u.norm() > 1e-3 * speed && !outwards && !leaves).then_some((blocked, u))
    }

    /// Among `candidates`, in order of increasing margin, the legs whose lift keeps the feet
    /// still in support balanced ([`Self::balanced`]).
    fn stable_lifts(&self, candidates: [bool; 6], margins: &[f64; 6], support: &[bool; 6], centre: &Vector3<f64>) -> [bool; 6] {
        let mut order: Vec<usize> = (0..6).filter(|&l| candidates[l]).collect();
        order.sort_by(|&a, &b| margins[a].total_cmp(&margins[b]));
        let pushes = self.landing_pushes();
        let mut support = *support;
        let mut lifting = [false; 6];
        for l in order {
            support[l] = false;
            if self.balanced(&support, centre, &pushes) {
                lifting[l] = true;
            } else {
                support[l] = true;
            }
        }
        lifting
    }

    /// Whether the feet `support` keep the robot balanced with its centre of mass at `centre`
    /// ([`Self::centre_of_mass`]): the normalized energy stability margin of their anchors at
    /// least [`FreeGaitOptions::energy_margin`] (any number of legs) and the centre of mass
    /// inside their polygon against `pushes`, those of the feet in the air when they land
    /// ([`Self::landing_pushes`]): by [`FreeGaitOptions::stability_margin`] with a failed leg, at
    /// all on six legs.
    fn balanced(&self, support: &[bool; 6], centre: &Vector3<f64>, pushes: &[Push]) -> bool {
        let horizontal = || {
            let feet: Vec<Vector2<f64>> = (0..6).filter(|&k| support[k]).map(|k| self.walk.legs[k].anchor.xy()).collect();
            let bound = if self.options.failed_leg.is_some() { self.options.stability_margin } else { 0.0 };
            stability_margin(&centre.xy(), &feet, pushes) >= bound
        };
        self.energy_margin_of(support, centre) >= self.options.energy_margin && horizontal()
    }

    /// The pushes on the body of the working feet in the air (takeoff, swing, landing; not the
    /// legs about to lift, still in support), each at the landing detection's threshold
    /// ([`LandingDetector::threshold_n`]) over the robot's weight, where the foot is now (the
    /// landing's virtual anchor, else the foot reference in the desired pose). None without the
    /// robot's masses ([`Self::with_masses`]).
    ///
    /// INTERPRETATION (beyond the thesis, issue 37): a landing foot presses on the ground until
    /// its landing is detected; the support must bear that push without tipping. On five legs
    /// the support of three feet left while two legs step can be tipped by much less than the
    /// threshold: with leg 4 failed, leg 2 lifted with the centre of mass 22.6 mm inside the
    /// diagonal of legs 0 and 5 (2 cm asked), leg 1 landed 0.46 m from it on the support's
    /// side, and about 15 N there (a fraction of the 40 N at which the currents detect it) rolled
    /// the body onto the diagonal: leg 3 lost its load, the body rolled 3.7° while leg 1 went on
    /// lowering its foot at 3 cm/s, undetected (measured 2026-11-29). The feet in the air are
    /// counted where they are, not where they will land: taking the landing feet alone left
    /// 0.7-1.1 s on two feet in the walks with a rear leg failed (a swinging foot landed during
    /// the next lift), counting every foot in the air none. On six legs the support of Rule 2
    /// is wider and the check only keeps a lift from leaving a support that a landing tips (no
    /// margin): on the seeded terrain classes (`benches/src/bin/terrain_classes.rs`, 980 runs,
    /// 2026-11-29) the tripods on 20-25° slopes at the 4.5 cm lift and the staircases down at
    /// the thesis' lift tipped onto a lifting foot after a landing less often with it (slopes
    /// 65-85 % to 100 %, staircases down 4-8 cm 50-80 % to 60-85 %; docs/benchmarks.md).
    fn landing_pushes(&self) -> Vec<Push> {
        let (Some((_, dynamics)), Some(body)) = (self.masses.as_ref(), self.walk.body.as_ref()) else { return Vec::new() };
        let share = self.landing.threshold_n() / (dynamics.model.total_mass() * dynamics.model.gravity.norm());
        let desired = body.pose.htm();
        (0..6)
            .filter(|&k| self.working(k) && self.walk.legs[k].phase != FootPhase::Support)
            .map(|k| {
                let leg = &self.walk.legs[k];
                let at = if leg.phase == FootPhase::Landing { leg.anchor } else { self.leg_frame(k, &desired).apply(&leg.foot) };
                Push { at: at.xy(), share }
            })
            .collect()
    }

    /// The normalized energy stability margin ([`super::super::stability`]) of the anchors of
    /// the feet `support`, the centre of mass at `centre`.
    pub(super) fn energy_margin_of(&self, support: &[bool; 6], centre: &Vector3<f64>) -> f64 {
        let feet: Vec<Vector3<f64>> = (0..6).filter(|&k| support[k]).map(|k| self.walk.legs[k].anchor).collect();
        energy_stability_margin(centre, &feet)
    }

    /// The centre of mass of the robot in the estimated body pose, the joints where the
    /// encoders put them ([`LegDynamics::centre_of_mass`]); the body frame's origin without
    /// [`Self::with_masses`].
    ///
    /// INTERPRETATION (beyond the thesis, issue 37): the controller of Chapter 7 works from
    /// kinematics alone, and the body frame sits at the centre of the main body, about which
    /// the legs are mounted symmetrically (AMRU5, the PhantomX). But AMRU5's legs are two thirds
    /// of its mass (6 x 3.9 kg of 34.4 kg, Table B.2), and on five legs they do not stand
    /// symmetrically: the footholds are offset towards the failed leg, which is held folded up,
    /// and one leg swings. With leg 4 failed and navigation, the body tipped over the diagonal
    /// of legs 0 and 5 onto the failed corner when leg 2 lifted with the body origin inside the
    /// support by the 2 cm the check asks (measured, 6-9 s). The ground detection already
    /// carries the robot's multibody model (the torque estimate of Fig. 5.12); the stability
    /// check takes its centre of mass from it.
    pub(super) fn centre_of_mass(&mut self, m: &Measurements, estimated: &Htm) -> Vector3<f64> {
        let Some((data, dynamics)) = self.masses.as_mut() else { return estimated.translation };
        estimated.apply(&dynamics.centre_of_mass(data, &m.positions))
    }
}
