//! A gait schedule (thesis Sections 7.1.2, 7.2.4): the [`GaitController`] with gait changes
//! requested at given times ([`ScheduledGait`]), publishing what it did at each update in a
//! shared [`GaitState`] (desired body pose and velocities, foot phases and references,
//! diagnostics) that a recorder or a summary reads without reaching into the controller; the
//! free gait controller publishes the same state ([`PublishedFreeGait`]).

use std::cell::RefCell;
use std::rc::Rc;

use nalgebra::Vector3;

use super::body_motion::Pose;
use super::controller::{GaitController, GaitDiagnostics};
use super::free::{FreeGaitController, FreeGaitState};
use super::pattern::{FootPhase, GaitPattern};
use crate::control::{Command, Controller, Measurements};
use crate::hexapod::{Leg, LegKinematics};

/// A gait change while walking: at `at` (s) the controller is asked for `pattern`
/// ([`GaitController::change_gait`]); it switches once all six feet are down.
#[derive(Clone, Debug, PartialEq)]
pub struct GaitChange {
    pub at: f64,
    pub pattern: GaitPattern,
}

/// What the gait controller did at its last update.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GaitState {
    /// Desired body pose T*_{0,b}, its linear velocity and angular velocity (global).
    pub pose: Pose,
    pub velocity: Vector3<f64>,
    pub omega: Vector3<f64>,
    /// Phase codes ([`FootPhase::code`]).
    pub phases: [f64; 6],
    /// Foot references in the leg frames.
    pub feet: [Vector3<f64>; 6],
    /// Duty factor of the current pattern.
    pub beta: f64,
    pub diagnostics: GaitDiagnostics,
    /// The free gait's posture, detections and deadlock (free gait only).
    pub free: Option<FreeGaitState>,
}

/// Phase code of a failed leg held up (free gait), after the four of [`FootPhase::code`].
pub const FAILED_LEG_CODE: f64 = 4.0;

/// The gait controller with the scheduled gait changes, publishing its state after each update.
pub struct ScheduledGait<L: Leg = LegKinematics> {
    controller: GaitController<L>,
    changes: Vec<GaitChange>,
    next: usize,
    state: Rc<RefCell<GaitState>>,
}

impl<L: Leg> ScheduledGait<L> {
    /// `changes` at increasing times; returns the controller and the state it publishes.
    pub fn new(controller: GaitController<L>, changes: Vec<GaitChange>) -> (Self, Rc<RefCell<GaitState>>) {
        let state = Rc::new(RefCell::new(GaitState::default()));
        (ScheduledGait { controller, changes, next: 0, state: state.clone() }, state)
    }
}

impl<L: Leg> Controller for ScheduledGait<L> {
    fn update(&mut self, m: &Measurements) -> Command {
        let half = 0.5 * self.controller.options.dt;
        while let Some(change) = self.changes.get(self.next).filter(|ch| m.t >= ch.at - half) {
            self.controller.change_gait(change.pattern.clone());
            self.next += 1;
        }
        let command = self.controller.update(m);
        let c = &self.controller;
        let (velocity, omega) = c.desired_velocity().unwrap_or_default();
        *self.state.borrow_mut() = GaitState {
            pose: c.desired_pose().unwrap_or_default(),
            velocity,
            omega,
            phases: c.phases().map(FootPhase::code),
            feet: c.foot_references(),
            beta: c.options.pattern.beta,
            diagnostics: c.diagnostics,
            free: None,
        };
        command
    }
}

/// The free gait controller publishing its state after each update, like [`ScheduledGait`].
pub struct PublishedFreeGait<L: Leg = LegKinematics> {
    controller: FreeGaitController<L>,
    state: Rc<RefCell<GaitState>>,
}

impl<L: Leg> PublishedFreeGait<L> {
    pub fn new(controller: FreeGaitController<L>) -> (Self, Rc<RefCell<GaitState>>) {
        let state = Rc::new(RefCell::new(GaitState::default()));
        (PublishedFreeGait { controller, state: state.clone() }, state)
    }
}

impl<L: Leg> Controller for PublishedFreeGait<L> {
    fn update(&mut self, m: &Measurements) -> Command {
        let command = self.controller.update(m);
        let c = &self.controller;
        let (velocity, omega) = c.desired_velocity().unwrap_or_default();
        let failed = c.options.failed_leg;
        *self.state.borrow_mut() = GaitState {
            pose: c.desired_pose().unwrap_or_default(),
            velocity,
            omega,
            phases: std::array::from_fn(|l| if failed == Some(l) { FAILED_LEG_CODE } else { c.phases()[l].code() }),
            feet: c.foot_references(),
            // No duty factor: the free gait has no fixed pattern.
            beta: f64::NAN,
            diagnostics: c.diagnostics,
            free: Some(c.state()),
        };
        command
    }
}
