//! The summary of a run: totals and diagnostics ([`Summary`], in gait mode with a
//! [`GaitSummary`]), accumulated control instant by control instant while the scenario runs.

use std::borrow::Cow;

use super::episodes::WalkEpisodes;
use super::gait::GaitScenario;
use super::Scenario;
use crate::control::gait::controller::GaitDiagnostics;
use crate::control::gait::heading::HeadingSource;
use crate::control::gait::pattern::FootCycle;
use crate::control::gait::schedule::GaitState;
use crate::control::Command;
use crate::hexapod::{LegJoints, Workspace, JOINTS};
use crate::robot::simulation::SimulatedRobot;

/// One summary value, typed as it is written to `summary.json`: a string, an integer, a float
/// or a boolean.
#[derive(Clone, Debug, PartialEq)]
pub enum SummaryValue {
    Text(String),
    Count(u64),
    Number(f64),
    Flag(bool),
}

/// Totals and diagnostics of a run. Energies in J, lengths in m, times in s.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    pub scenario: String,
    pub friction: &'static str,
    pub control: &'static str,
    /// Simulated time (s).
    pub duration_s: f64,
    pub wall_time_s: f64,
    pub control_periods: u64,
    pub rows: u64,
    pub integration_steps: u64,
    pub rejected_steps: u64,
    pub newton_iterations: u64,
    /// Evaluations of the residual f by the integrator: Newton iterations and consistent
    /// accelerations (those inside a Jacobian evaluation are not counted).
    pub residual_evaluations: u64,
    /// Evaluations of the surrogate residual (`System::surrogate_residual`: the force laws at the
    /// feet and joints, no kinematics): the Newton iterations between two of f and the resets
    /// of q'' at the control instants.
    pub surrogate_evaluations: u64,
    /// Steps accepted on the surrogate's Newton test (`NewmarkOptions::unverified_steps`).
    pub unverified_steps: u64,
    pub jacobian_evaluations: u64,
    pub factorizations: u64,
    /// Body height Z at the start (after settling and offset).
    pub initial_body_height_m: f64,
    /// Z at the end minus Z at the start.
    pub body_height_change_m: f64,
    /// Horizontal displacement of the body centre over the run.
    pub body_horizontal_drift_m: f64,
    /// Mass of the robot m of Eq. 6.6 (kg).
    pub robot_mass_kg: f64,
    /// Electrical energy E = sum of u i dt over the actuators (Eq. 6.7).
    pub energy_electrical_j: f64,
    /// The same per joint of a leg (q_r, q_v, q_h on AMRU5), summed over the legs.
    pub energy_electrical_by_joint_j: [f64; 3],
    /// The robot's joint names and kinds: the names and units of the per-joint entries.
    pub joints: LegJoints,
    /// E over the simulated time: the averaged power of the robot (W).
    pub average_power_w: f64,
    pub energy_joule_j: f64,
    pub energy_friction_j: f64,
    pub energy_motor_work_j: f64,
    pub energy_contact_j: f64,
    pub kinetic_change_j: f64,
    pub potential_change_j: f64,
    /// Electrical energy minus everything it became (Δ kinetic, Δ potential, Joule, friction,
    /// contact, Δ magnetic): zero up to integration error.
    pub energy_balance_error_j: f64,
    /// The balance error over the sum of the magnitudes of its terms.
    pub energy_balance_error_relative: f64,
    /// Largest |voltage| across a motor (V).
    pub max_abs_voltage_v: f64,
    /// Fraction of the controller commands (all joints and instants) at the supply voltage.
    pub saturated_fraction: f64,
    /// Commands cut by a limit switch (joint at a stroke end, pushed further out).
    pub limit_switch_cuts: u64,
    /// Largest |reference − q| per joint of a leg (rad or m), PI mode only.
    pub max_tracking_error: Option<[f64; 3]>,
    /// Largest foot penetration into the ground.
    pub max_penetration_m: f64,
    /// The first foot beyond the border of a terrain mesh (where there is no ground), and when
    /// (s).
    pub left_terrain: Option<(usize, f64)>,
    /// The penetration of three feet carrying the robot's weight at rest (Eq. 3.72): the scale
    /// of [`Self::max_penetration_m`] on this ground (2.3 mm on the ground of Table 3.3).
    pub static_penetration_m: f64,
    /// Walking figures, in gait mode.
    pub gait: Option<GaitSummary>,
}

impl Summary {
    /// The values in a fixed order, names with units as suffixes; the per-joint entries carry
    /// the robot's joint names (`energy_electrical_q_v_j`, `max_tracking_error_q_v_m` on AMRU5).
    pub fn entries(&self) -> Vec<(Cow<'static, str>, SummaryValue)> {
        use SummaryValue::{Count, Flag, Number, Text};
        let mut v: Vec<(Cow<'static, str>, SummaryValue)> = vec![
            ("scenario", Text(self.scenario.clone())),
            ("friction", Text(self.friction.to_string())),
            ("control", Text(self.control.to_string())),
            ("duration_s", Number(self.duration_s)),
            ("wall_time_s", Number(self.wall_time_s)),
            ("control_periods", Count(self.control_periods)),
            ("rows", Count(self.rows)),
            ("integration_steps", Count(self.integration_steps)),
            ("rejected_steps", Count(self.rejected_steps)),
            ("newton_iterations", Count(self.newton_iterations)),
            ("residual_evaluations", Count(self.residual_evaluations)),
            ("surrogate_evaluations", Count(self.surrogate_evaluations)),
            ("unverified_steps", Count(self.unverified_steps)),
            ("jacobian_evaluations", Count(self.jacobian_evaluations)),
            ("factorizations", Count(self.factorizations)),
            ("initial_body_height_m", Number(self.initial_body_height_m)),
            ("body_height_change_m", Number(self.body_height_change_m)),
            ("body_horizontal_drift_m", Number(self.body_horizontal_drift_m)),
            ("robot_mass_kg", Number(self.robot_mass_kg)),
            ("energy_electrical_j", Number(self.energy_electrical_j)),
        ]
        .into_iter()
        .map(|(n, x)| (Cow::Borrowed(n), x))
        .collect();
        v.extend(per_joint_entries(&self.joints, "energy_electrical", self.energy_electrical_by_joint_j, ("j", "j")));
        let rest = [
            ("average_power_w", Number(self.average_power_w)),
            ("energy_joule_j", Number(self.energy_joule_j)),
            ("energy_friction_j", Number(self.energy_friction_j)),
            ("energy_motor_work_j", Number(self.energy_motor_work_j)),
            ("energy_contact_j", Number(self.energy_contact_j)),
            ("kinetic_change_j", Number(self.kinetic_change_j)),
            ("potential_change_j", Number(self.potential_change_j)),
            ("energy_balance_error_j", Number(self.energy_balance_error_j)),
            ("energy_balance_error_relative", Number(self.energy_balance_error_relative)),
            ("max_abs_voltage_v", Number(self.max_abs_voltage_v)),
            ("saturated_fraction", Number(self.saturated_fraction)),
            ("limit_switch_cuts", Count(self.limit_switch_cuts)),
        ];
        v.extend(rest.into_iter().map(|(n, x)| (Cow::Borrowed(n), x)));
        if let Some(errors) = self.max_tracking_error {
            v.extend(per_joint_entries(&self.joints, "max_tracking_error", errors, ("rad", "m")));
        }
        v.push((Cow::Borrowed("max_penetration_m"), Number(self.max_penetration_m)));
        if let Some((foot, t)) = self.left_terrain {
            v.push((Cow::Borrowed("foot_left_terrain"), Count(foot as u64)));
            v.push((Cow::Borrowed("foot_left_terrain_t_s"), Number(t)));
        }
        v.push((Cow::Borrowed("static_penetration_m"), Number(self.static_penetration_m)));
        if let Some(g) = &self.gait {
            v.push((Cow::Borrowed("gait_pattern"), Text(g.pattern.clone())));
            v.push((Cow::Borrowed("gait_cycle"), Text(g.cycle.to_string())));
            v.push((Cow::Borrowed("gait_heading"), Text(g.heading.to_string())));
            v.push((Cow::Borrowed("navigation"), Flag(g.navigation)));
            v.push((Cow::Borrowed("tracking_error_xy_max_m"), Number(g.tracking_error_xy_max_m)));
            v.push((Cow::Borrowed("tracking_error_xy_final_m"), Number(g.tracking_error_xy_final_m)));
            v.push((Cow::Borrowed("tracking_error_yaw_max_rad"), Number(g.tracking_error_yaw_max_rad)));
            v.push((Cow::Borrowed("distance_walked_m"), Number(g.distance_walked_m)));
            v.push((Cow::Borrowed("reference_distance_m"), Number(g.reference_distance_m)));
            v.push((Cow::Borrowed("commanded_path_length_m"), Number(g.commanded_path_length_m)));
            v.push((Cow::Borrowed("net_displacement_m"), Number(g.net_displacement_m)));
            v.push((Cow::Borrowed("specific_resistance"), Number(specific_resistance(self.energy_electrical_j, self.robot_mass_kg, g.distance_walked_m))));
            v.push((Cow::Borrowed("clamped_ik_references"), Count(g.clamped_ik_references)));
            v.push((Cow::Borrowed("gait_switches"), Count(g.gait_switches)));
            v.push((Cow::Borrowed("min_feet_on_ground"), Count(g.min_feet_on_ground)));
            v.push((Cow::Borrowed("max_foot_reference_outside_workspace_m"), Number(g.max_foot_reference_outside_workspace_m)));
            if let Some((margin, t)) = g.min_stability_margin {
                v.push((Cow::Borrowed("min_stability_margin_m"), Number(margin)));
                v.push((Cow::Borrowed("min_stability_margin_t_s"), Number(t)));
            }
            // The duration (0 when it never happened) and, when it did, its start.
            let mut episode = |name: &'static str, longest: Option<(f64, f64)>| {
                v.push((Cow::Owned(format!("longest_{name}_s")), Number(longest.map_or(0.0, |(d, _)| d))));
                if let Some((_, t)) = longest {
                    v.push((Cow::Owned(format!("longest_{name}_t_s")), Number(t)));
                }
            };
            episode("deadlock", g.episodes.deadlock.longest);
            episode("support_loss", g.episodes.support_loss.longest);
            let airborne = g.episodes.longest_airborne_load();
            episode("airborne_load", airborne.map(|(d, t, _)| (d, t)));
            if let Some((_, _, leg)) = airborne {
                v.push((Cow::Borrowed("longest_airborne_load_leg"), Count(leg as u64)));
            }
            v.push((Cow::Borrowed("deadlocked_at_end"), Flag(g.episodes.deadlock.ongoing())));
            if let Some(t) = g.last_clamped_t_s {
                v.push((Cow::Borrowed("last_clamped_ik_reference_t_s"), Number(t)));
            }
        }
        v
    }
}

/// The gait part of a run's summary: body XY tracking error (largest and final), yaw error,
/// distance walked and its reference, clamped IK references, gait switches, fewest feet on the
/// ground, largest excursion of a foot reference outside its workspace.
#[derive(Clone, Debug, PartialEq)]
pub struct GaitSummary {
    /// Initial pattern name, foot cycle and heading kind.
    pub pattern: String,
    pub cycle: &'static str,
    pub heading: &'static str,
    pub navigation: bool,
    /// |(X, Y) − (X*, Y*)|: largest over the run and at the end (m).
    pub tracking_error_xy_max_m: f64,
    pub tracking_error_xy_final_m: f64,
    /// Largest |yaw − yaw*| (rad).
    pub tracking_error_yaw_max_rad: f64,
    /// Path length of the body centre (X, Y), of its desired pose (which halts while the free
    /// gait is deadlocked) and of the commanded heading ∫|V| dt, sampled at the control instants
    /// (m). The first is Eq. 6.6's distance travelled, of the specific resistance.
    pub distance_walked_m: f64,
    pub reference_distance_m: f64,
    pub commanded_path_length_m: f64,
    /// Horizontal displacement of the body centre (X, Y) from the first control instant to the
    /// last (m): without the sway and the back-and-forth that the path length counts.
    pub net_displacement_m: f64,
    /// Foot references the inverse kinematics clamped into the joint ranges (count of leg
    /// updates).
    pub clamped_ik_references: u64,
    pub gait_switches: u64,
    /// Fewest feet with a normal force > 0 at a control instant.
    pub min_feet_on_ground: u64,
    /// Largest distance of a foot reference outside its workspace cylinder (m).
    pub max_foot_reference_outside_workspace_m: f64,
    /// The free gait's smallest stability margin (m, the `stability_margin` column) and when
    /// (s).
    pub min_stability_margin: Option<(f64, f64)>,
    /// The longest deadlock (free gait), loss of support (fewer than three loaded feet) and
    /// load on a foot in takeoff or swing ([`WalkEpisodes`]).
    pub episodes: WalkEpisodes,
    /// When the last foot reference was clamped (s).
    pub last_clamped_t_s: Option<f64>,
}

impl GaitSummary {
    /// From the walking set-up, the figures accumulated over the run and the gait controller's
    /// diagnostics at its end.
    pub(super) fn new(g: &GaitScenario, stats: &GaitStats, diagnostics: &GaitDiagnostics) -> Self {
        GaitSummary {
            pattern: g.options.pattern.name.clone(),
            cycle: cycle_name(g.options.cycle),
            heading: g.heading.kind(),
            navigation: g.navigation,
            tracking_error_xy_max_m: stats.max_xy_error,
            tracking_error_xy_final_m: stats.final_xy_error,
            tracking_error_yaw_max_rad: stats.max_yaw_error,
            distance_walked_m: stats.path_length,
            net_displacement_m: stats.net_displacement(),
            commanded_path_length_m: stats.commanded_path_length,
            reference_distance_m: stats.reference_distance,
            clamped_ik_references: diagnostics.clamped_references as u64,
            gait_switches: diagnostics.gait_switches as u64,
            min_feet_on_ground: stats.min_feet as u64,
            max_foot_reference_outside_workspace_m: stats.max_outside,
            min_stability_margin: stats.min_stability_margin,
            episodes: stats.episodes,
            last_clamped_t_s: diagnostics.last_clamped_at,
        }
    }
}

fn cycle_name(c: FootCycle) -> &'static str {
    match c {
        FootCycle::Plain => "plain",
        FootCycle::Enhanced { .. } => "enhanced",
    }
}

/// Specific resistance xi = E / (m g l) (Eq. 6.6), g the standard gravity of the multibody
/// model; NaN when nothing was walked.
pub fn specific_resistance(energy_j: f64, mass_kg: f64, distance_m: f64) -> f64 {
    if distance_m > 0.0 {
        energy_j / (mass_kg * crate::mbs::STANDARD_GRAVITY * distance_m)
    } else {
        f64::NAN
    }
}

/// Figures of a run, accumulated control instant by control instant.
pub(super) struct RunStats {
    /// Control instants seen.
    rows: u64,
    max_penetration: f64,
    commands: u64,
    saturated: u64,
    cuts: u64,
    max_abs_voltage: f64,
    tracking: [f64; 3],
    /// The first foot beyond the border of a terrain mesh, and when.
    left_terrain: Option<(usize, f64)>,
}

impl Default for RunStats {
    fn default() -> Self {
        RunStats { rows: 0, max_penetration: f64::NEG_INFINITY, commands: 0, saturated: 0, cuts: 0, max_abs_voltage: 0.0, tracking: [0.0; 3], left_terrain: None }
    }
}

impl RunStats {
    /// One control instant: the robot after the period and the command computed at its end;
    /// `pi`: the joint references are tracked (modes `pi` and `gait`).
    pub(super) fn observe(&mut self, p: &SimulatedRobot, cmd: &Command, supply: f64, pi: bool) {
        let q = p.state().q.as_slice();
        let out = &p.robot.outputs;
        let model = &p.robot.model;
        self.rows += 1;
        self.max_penetration = out.contact.iter().map(|c| c.penetration).fold(self.max_penetration, f64::max);
        if self.left_terrain.is_none() {
            let terrain = &p.robot.model.terrain;
            self.left_terrain = (0..6).find(|&f| !terrain.covers(out.foot[f].x, out.foot[f].y)).map(|f| (f, p.state().t));
        }
        for k in 0..JOINTS {
            self.commands += 1;
            if cmd.voltages[k].abs() >= supply {
                self.saturated += 1;
            }
            let held = crate::physics::limit_switch(cmd.voltages[k], q[model.drive_index(k)], &model.strokes[k]);
            if held == 0.0 && cmd.voltages[k] != 0.0 {
                self.cuts += 1;
            }
            self.max_abs_voltage = self.max_abs_voltage.max(out.voltage[k].abs());
            if pi {
                self.tracking[k % 3] = self.tracking[k % 3].max((cmd.references[k] - q[6 + k]).abs());
            }
        }
    }
}

/// The summary of a finished run: `q0` the state at the start (after settling), `wall` the wall
/// time (s); the gait part is left to [`GaitSummary::new`].
pub(super) fn summarize(s: &Scenario, plant: &SimulatedRobot, stats: &RunStats, q0: &[f64], wall: f64) -> Summary {
    let e = &plant.energy;
    let e0 = &plant.initial_energy;
    let sum = |a: &[f64]| a.iter().sum::<f64>();
    let q = plant.state().q.as_slice();
    let n = plant.integrator.stats();
    let balance = e.balance_error(e0);
    let terms = sum(&e.electrical).abs()
        + (e.kinetic - e0.kinetic).abs()
        + (e.potential - e0.potential).abs()
        + sum(&e.joule)
        + sum(&e.friction_work).abs()
        + sum(&e.contact_work).abs()
        + (e.spring_energy - e0.spring_energy).abs()
        + (e.magnetic_energy - e0.magnetic_energy).abs();
    let rows = stats.rows;
    Summary {
        scenario: s.name.clone(),
        friction: s.model.friction.name(),
        control: s.control.name(),
        duration_s: plant.state().t,
        wall_time_s: wall,
        control_periods: rows.saturating_sub(1),
        rows,
        integration_steps: n.steps as u64,
        rejected_steps: n.rejected_steps as u64,
        newton_iterations: n.newton_iterations as u64,
        residual_evaluations: n.residual_evaluations as u64,
        surrogate_evaluations: n.surrogate_evaluations as u64,
        unverified_steps: n.unverified_steps as u64,
        jacobian_evaluations: n.jacobian_evaluations as u64,
        factorizations: n.factorizations as u64,
        initial_body_height_m: q0[2],
        body_height_change_m: q[2] - q0[2],
        body_horizontal_drift_m: (q[0] - q0[0]).hypot(q[1] - q0[1]),
        robot_mass_kg: plant.robot.model.multibody.total_mass(),
        energy_electrical_j: sum(&e.electrical),
        energy_electrical_by_joint_j: std::array::from_fn(|j| e.electrical.iter().skip(j).step_by(3).sum()),
        joints: plant.robot.model.joints.clone(),
        average_power_w: if plant.state().t > 0.0 { sum(&e.electrical) / plant.state().t } else { 0.0 },
        energy_joule_j: sum(&e.joule),
        energy_friction_j: sum(&e.friction_work),
        energy_motor_work_j: sum(&e.motor_work),
        energy_contact_j: sum(&e.contact_work),
        kinetic_change_j: e.kinetic - e0.kinetic,
        potential_change_j: e.potential - e0.potential,
        energy_balance_error_j: balance,
        energy_balance_error_relative: if terms > 0.0 { balance / terms } else { 0.0 },
        max_abs_voltage_v: stats.max_abs_voltage,
        saturated_fraction: if stats.commands > 0 { stats.saturated as f64 / stats.commands as f64 } else { 0.0 },
        limit_switch_cuts: stats.cuts,
        max_tracking_error: s.control.tracks_references().then_some(stats.tracking),
        max_penetration_m: stats.max_penetration,
        left_terrain: stats.left_terrain,
        static_penetration_m: s.model.ground.static_penetration(plant.robot.model.multibody.total_mass() * crate::mbs::STANDARD_GRAVITY / 3.0),
        gait: None,
    }
}

/// The summary entries `{quantity}_{name}_{unit}` of a per-joint figure, one per joint of a
/// leg in the robot's order, `units.0` for a revolute joint and `units.1` for a prismatic one.
pub fn per_joint_entries(joints: &LegJoints, quantity: &str, values: [f64; 3], units: (&'static str, &'static str)) -> Vec<(Cow<'static, str>, SummaryValue)> {
    (0..3).map(|j| (Cow::Owned(format!("{quantity}_{}_{}", joints.name(j), joints.kind(j).unit(units))), SummaryValue::Number(values[j]))).collect()
}

/// Gait figures of a run, accumulated row by row.
pub(super) struct GaitStats {
    max_xy_error: f64,
    final_xy_error: f64,
    max_yaw_error: f64,
    /// Path lengths of the body and of its desired pose.
    path_length: f64,
    reference_distance: f64,
    /// The body's XY at the first instant.
    start: Option<[f64; 2]>,
    last: Option<([f64; 2], [f64; 2])>,
    /// The commanded heading, its path length ∫|V| dt (trapezoidal) and its last (t, |V|).
    heading: Box<dyn HeadingSource>,
    commanded_path_length: f64,
    last_speed: Option<(f64, f64)>,
    min_feet: usize,
    max_outside: f64,
    min_stability_margin: Option<(f64, f64)>,
    episodes: WalkEpisodes,
}

impl GaitStats {
    /// Before the first instant, with the walk's heading source (its own instance).
    pub(super) fn new(heading: Box<dyn HeadingSource>) -> Self {
        GaitStats {
            max_xy_error: 0.0,
            final_xy_error: 0.0,
            max_yaw_error: 0.0,
            path_length: 0.0,
            reference_distance: 0.0,
            start: None,
            last: None,
            heading,
            commanded_path_length: 0.0,
            last_speed: None,
            min_feet: 6,
            max_outside: 0.0,
            min_stability_margin: None,
            episodes: WalkEpisodes::default(),
        }
    }

    /// |(X, Y)| from the first instant to the last (m).
    fn net_displacement(&self) -> f64 {
        match (self.start, self.last) {
            (Some(a), Some((b, _))) => (b[0] - a[0]).hypot(b[1] - a[1]),
            _ => 0.0,
        }
    }

    /// One control instant `t`: body pose `q` (X, Y, Z, yaw, ...), the gait state, the feet's
    /// normal forces, the robot's weight (N) and the workspaces.
    pub(super) fn observe(&mut self, t: f64, q: &[f64], s: &GaitState, normal: &[f64; 6], weight: f64, workspaces: &[Workspace; 6]) {
        let feet_down = normal.iter().filter(|&&f| f > 0.0).count();
        self.episodes.observe(t, &s.phases, normal, weight, s.free.is_some_and(|f| f.deadlock));
        let actual = [q[0], q[1]];
        let desired = [s.pose.position.x, s.pose.position.y];
        let e = (actual[0] - desired[0]).hypot(actual[1] - desired[1]);
        self.max_xy_error = self.max_xy_error.max(e);
        self.final_xy_error = e;
        let yaw = (q[3] - s.pose.angles.x + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        self.max_yaw_error = self.max_yaw_error.max(yaw.abs());
        if let Some((a, d)) = self.last {
            self.path_length += (actual[0] - a[0]).hypot(actual[1] - a[1]);
            self.reference_distance += (desired[0] - d[0]).hypot(desired[1] - d[1]);
        }
        self.start.get_or_insert(actual);
        self.last = Some((actual, desired));
        let speed = self.heading.heading(t).velocity.xy().norm();
        if let Some((t0, v0)) = self.last_speed {
            self.commanded_path_length += 0.5 * (v0 + speed) * (t - t0);
        }
        self.last_speed = Some((t, speed));
        self.min_feet = self.min_feet.min(feet_down);
        for (w, f) in workspaces.iter().zip(&s.feet) {
            self.max_outside = self.max_outside.max(w.distance_outside(f));
        }
        if let Some(free) = &s.free {
            if self.min_stability_margin.is_none_or(|(m, _)| free.stability_margin < m) {
                self.min_stability_margin = Some((free.stability_margin, t));
            }
        }
    }
}

