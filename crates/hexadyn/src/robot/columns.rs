//! The columns a run of the simulated robot records: one row per control instant (the start
//! and the end included), filled into a [`Recorder`] by [`record_row`].
//!
//! Each row holds the state at that instant t; the electrical columns (`u_*`, `i_*`, `tau_m_*`)
//! are those of the voltage held during the control period that ends at t — what the current
//! sensors read at t —, the references (`q_*_ref`) those the controller computed at t. The
//! names follow the thesis symbols with the leg (i, l) or foot (f) number 0..5 in brackets:
//! `q_v[2]` is the q_v joint of leg 2. A joint's columns carry the robot's name for it
//! ([`crate::hexapod::LegJoints`], the description's `[joints] names`; AMRU5's are the thesis'
//! q_r, q_v, q_h, used in the table below), their units its kind: rad, rad/s, Nm for a
//! revolute joint, m, m/s, N for a prismatic one.
//!
//! | columns | unit | |
//! | --- | --- | --- |
//! | `t` | s | control instant |
//! | `X`, `Y`, `Z`; `yaw`, `pitch`, `roll` | m; rad | body pose (Eq. 3.51-3.52) |
//! | `X_dot` ... `roll_dot` | m/s; rad/s | body velocities |
//! | `q_r[i]`, `q_v[i]`, `q_h[i]` | rad, m, m | joints of leg i |
//! | `q_r_dot[i]` ... | rad/s, m/s | joint velocities |
//! | `q_r_ref[i]` ... | rad, m | joint references (modes `pi` and `gait`) |
//! | `coxa_goal[i]` ... | rad, m | goals sent to position servos with `gait.friction_feedforward` |
//! | `X_ref`, `Y_ref`, `Z_ref`; `yaw_ref`, `pitch_ref`, `roll_ref` | m; rad | desired body pose T*_{0,b} (gait) |
//! | `X_dot_ref`, `Y_dot_ref`; `omega_z_ref` | m/s; rad/s | commanded heading velocities (gait) |
//! | `duty_factor` | 1 | β of the current gait pattern (gait) |
//! | `phase[l]` | 1 | foot phase code of leg l: 0 support, 1 takeoff, 2 swing, 3 landing, 4 failed and held up (gait) |
//! | `foot_ref_x[l]`, `foot_ref_y[l]`, `foot_ref_z[l]` | m | foot reference in the leg frame (gait) |
//! | `body_clearance` | m | body height above the ground plane estimated from the contact points (free gait, Section 7.7.5) |
//! | `posture_roll`, `posture_pitch` | rad | body roll and pitch as the free gait knows them (navigation, else desired) |
//! | `touchdown[l]` | 1 | 1 when the landing of leg l was detected at t (free gait) |
//! | `deadlock` | 1 | 1 while the support legs are halted (free gait, Section 7.7.4) |
//! | `stability_margin` | m | normalized energy stability margin of the feet in support as the free gait knows them (beyond the thesis; −inf below three feet) |
//! | `u_q_v[i]` ... | V | voltage across motor + H-bridge (after saturation and limit switches) |
//! | `i_q_v[i]` ... | A | motor current |
//! | `i_meas_q_v[i]` ... | A | motor current as the controller measured it at t: through the analog 30 Hz filter, with the sensor noise (Section 5.6.2, [`crate::physics::CurrentSensors`]) |
//! | `tau_m_q_v[i]` ... | Nm (q_r), N | motor torque at the joint, n k_t i |
//! | `tau_f_q_v[i]` ... | Nm (q_r), N | joint friction torque |
//! | `z_q_v[i]` ... | rad (q_r), m | LuGre bristle deflection (friction `lugre` only) |
//! | `drive_q_v[i]` ... | rad (q_r), m | drive position θ of a series-elastic transmission (the gear output, what the encoder reads; the spring's deflection is θ − q) |
//! | `Fx[f]`, `Fy[f]`, `Fz[f]`, `Fn[f]` | N | ground force on foot f (global frame), normal part |
//! | `penetration[f]` | m | δ: > 0 in the ground, < 0 the clearance |
//! | `foot_x[f]`, `foot_y[f]`, `foot_z[f]` | m | foot position (global frame) |
//! | `E_el_q_v[i]`, `E_joule_q_v[i]`, `E_fric_q_v[i]` ... | J | cumulative electrical energy ∫u i dt, Joule losses, friction work ∫τ_f q' dt |
//! | `E_kin`, `E_pot` | J | kinetic and gravitational potential energy |
//! | `E_contact`, `E_stored`, `E_balance` | J | cumulative work on the ground; energy in bristles, series springs, ground springs and inductances; energy balance error |
//!
//! | `F_gnd_est[l]`, `gnd_detected[l]` | N; 1 | ground force estimate and detection flag of leg l (ground_detection) |
//! | `gd_leg`, `gd_threshold`, `gd_trial`, `gd_hold`, `gd_stop` | 1; N; 1; 1; 1 | tested leg, threshold, trial, stopped flag, stop instant (ground_detection) |
//!
//! The columns marked (ground_detection) are those of the ground detection experiment
//! ([`GroundExperimentState`], Section 5.6.3); a row with `gd_stop` = 1 is one trial of Table
//! 5.7, whose true contact force is `Fn[gd_leg]` of the same row.
//! The columns marked (gait) are those of the [`GaitState`] the gait controller publishes; the
//! references and the bristles are recorded when [`ColumnGroups`] says so. Each column also
//! carries a one-line description ([`crate::robot::recorder::Column`]).

use super::recorder::Recorder;
use super::simulation::SimulatedRobot;
use crate::control::gait::schedule::GaitState;
use crate::control::{Command, GroundExperimentState, Measurements};
use crate::hexapod::JOINTS;

/// The optional column groups of a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ColumnGroups {
    /// `q_*_ref[i]`: the joint references the controller computed (joint PI and gait control).
    pub references: bool,
    /// `z_*[i]`: the LuGre bristle deflections (friction `lugre`).
    pub bristles: bool,
}

/// Records the row of control instant `meas.t`: the robot `p` after the period, the command
/// `cmd` the controller computed at t and, walking, the state the gait controller published, or
/// in the ground detection experiment its state.
pub fn record_row(rec: &mut Recorder, p: &SimulatedRobot, meas: &Measurements, cmd: &Command, groups: ColumnGroups, gait: Option<&GaitState>, ground: Option<&GroundExperimentState>) {
    let st = p.state();
    let (q, qd) = (st.q.as_slice(), st.qd.as_slice());
    let out = &p.robot.outputs;
    let e = &p.energy;
    let joints = &p.robot.model.joints;
    let s = |x: &str| x.to_string();
    rec.begin_row();
    rec.put(meas.t, || (s("t"), "s", s("control instant")));
    const BODY: [(&str, &str, &str); 6] = [("X", "m", "body centre x"), ("Y", "m", "body centre y"), ("Z", "m", "body centre height"), ("yaw", "rad", "body yaw"), ("pitch", "rad", "body pitch"), ("roll", "rad", "body roll")];
    rec.put_each(&q[..6], |i| (s(BODY[i].0), BODY[i].1, s(BODY[i].2)));
    const BODY_DOT: [(&str, &str); 6] = [("X_dot", "m/s"), ("Y_dot", "m/s"), ("Z_dot", "m/s"), ("yaw_dot", "rad/s"), ("pitch_dot", "rad/s"), ("roll_dot", "rad/s")];
    rec.put_each(&qd[..6], |i| {
        let (n, u) = BODY_DOT[i];
        (s(n), u, format!("time derivative of {}", &n[..n.len() - 4]))
    });
    rec.put_each(&q[6..6 + JOINTS], |k| (joints.column("", k, ""), joints.unit(k, ("rad", "m")), format!("joint position, leg {}", k / 3)));
    rec.put_each(&qd[6..6 + JOINTS], |k| (joints.column("", k, "_dot"), joints.unit(k, ("rad/s", "m/s")), format!("joint velocity, leg {}", k / 3)));
    if groups.references {
        rec.put_each(&cmd.references, |k| (joints.column("", k, "_ref"), joints.unit(k, ("rad", "m")), format!("PI reference computed at t, leg {}", k / 3)));
        if let Some(goals) = &cmd.goals {
            rec.put_each(goals, |k| (joints.column("", k, "_goal"), joints.unit(k, ("rad", "m")), format!("servo goal sent at t (reference plus friction feed-forward), leg {}", k / 3)));
        }
    }
    if let Some(g) = gait {
        record_gait(rec, g);
    }
    if let Some(g) = ground {
        record_ground_detection(rec, g);
    }
    rec.put_each(&out.voltage, |k| (joints.column("u_", k, ""), "V", s("voltage across motor and H-bridge held over the period ending at t (after saturation and limit switches)")));
    rec.put_each(&out.current, |k| (joints.column("i_", k, ""), "A", s("motor current")));
    rec.put_each(&meas.currents, |k| (joints.column("i_meas_", k, ""), "A", s("motor current measured at t: analog 30 Hz low-pass, plus the sensor noise (Section 5.6.2)")));
    rec.put_each(&out.motor_torque, |k| (joints.column("tau_m_", k, ""), joints.unit(k, ("Nm", "N")), s("motor torque at the joint, n k_t i")));
    rec.put_each(&out.friction_torque, |k| (joints.column("tau_f_", k, ""), joints.unit(k, ("Nm", "N")), s("joint friction torque (opposing the motion)")));
    if p.robot.model.series.is_some() {
        let drives: [f64; JOINTS] = std::array::from_fn(|k| q[p.robot.model.drive_index(k)]);
        rec.put_each(&drives, |k| (joints.column("drive_", k, ""), joints.unit(k, ("rad", "m")), s("series-elastic drive position (gear output, read by the encoder)")));
    }
    if groups.bristles {
        rec.put_each(&out.bristle, |k| (joints.column("z_", k, ""), joints.unit(k, ("rad", "m")), s("LuGre bristle deflection")));
    }
    for (f, c) in out.contact.iter().enumerate() {
        rec.put(c.force.x, || (format!("Fx[{f}]"), "N", s("ground force on the foot, x (global)")));
        rec.put(c.force.y, || (format!("Fy[{f}]"), "N", s("ground force on the foot, y (global)")));
        rec.put(c.force.z, || (format!("Fz[{f}]"), "N", s("ground force on the foot, z (global)")));
        rec.put(c.normal_force, || (format!("Fn[{f}]"), "N", s("normal ground force on the foot")));
        rec.put(c.penetration, || (format!("penetration[{f}]"), "m", s("foot penetration into the ground (< 0: clearance)")));
    }
    for (f, x) in out.foot.iter().enumerate() {
        rec.put(x.x, || (format!("foot_x[{f}]"), "m", s("foot position x (global)")));
        rec.put(x.y, || (format!("foot_y[{f}]"), "m", s("foot position y (global)")));
        rec.put(x.z, || (format!("foot_z[{f}]"), "m", s("foot position z (global)")));
    }
    rec.put_each(&e.electrical, |k| (joints.column("E_el_", k, ""), "J", s("cumulative electrical energy drawn, integral of u i")));
    rec.put_each(&e.joule, |k| (joints.column("E_joule_", k, ""), "J", s("cumulative Joule losses in motor and H-bridge")));
    rec.put_each(&e.friction_work, |k| (joints.column("E_fric_", k, ""), "J", s("cumulative work against joint friction, integral of tau_f q'")));
    rec.put(e.kinetic, || (s("E_kin"), "J", s("kinetic energy")));
    rec.put(e.potential, || (s("E_pot"), "J", s("gravitational potential energy")));
    rec.put(e.contact_work.iter().sum(), || (s("E_contact"), "J", s("cumulative work of the feet on the ground")));
    rec.put(e.bristle_energy + e.spring_energy + e.contact_energy + e.magnetic_energy, || (s("E_stored"), "J", s("energy stored in bristles, series springs, ground springs and inductances")));
    rec.put(e.balance_error(&p.initial_energy), || (s("E_balance"), "J", s("energy balance error so far (electrical in minus what it became)")));
    rec.end_row();
}

/// The gait controller's columns: desired body pose and velocities, duty factor, foot phases
/// and foot references; with the free gait its posture, detections and deadlock.
pub fn record_gait(rec: &mut Recorder, g: &GaitState) {
    let s = |x: &str| x.to_string();
    let pose = [g.pose.position.x, g.pose.position.y, g.pose.position.z, g.pose.angles.x, g.pose.angles.y, g.pose.angles.z];
    const POSE: [(&str, &str); 6] = [("X_ref", "m"), ("Y_ref", "m"), ("Z_ref", "m"), ("yaw_ref", "rad"), ("pitch_ref", "rad"), ("roll_ref", "rad")];
    for ((n, u), v) in POSE.iter().zip(pose) {
        rec.put(v, || (s(n), u, format!("desired body pose {} (T*_0,b, Eq. 7.12-7.23)", &n[..n.len() - 4])));
    }
    rec.put(g.velocity.x, || (s("X_dot_ref"), "m/s", s("commanded heading velocity V_x (global)")));
    rec.put(g.velocity.y, || (s("Y_dot_ref"), "m/s", s("commanded heading velocity V_y (global)")));
    rec.put(g.omega.z, || (s("omega_z_ref"), "rad/s", s("commanded yaw rate Omega_z")));
    rec.put(g.beta, || (s("duty_factor"), "1", s("duty factor beta of the current gait pattern (NaN: free gait)")));
    for (l, phase) in g.phases.iter().enumerate() {
        rec.put(*phase, || (format!("phase[{l}]"), "1", s("foot phase code: 0 support, 1 takeoff, 2 swing, 3 landing, 4 failed (held up)")));
    }
    for (l, f) in g.feet.iter().enumerate() {
        rec.put(f.x, || (format!("foot_ref_x[{l}]"), "m", s("foot reference x, leg frame")));
        rec.put(f.y, || (format!("foot_ref_y[{l}]"), "m", s("foot reference y, leg frame")));
        rec.put(f.z, || (format!("foot_ref_z[{l}]"), "m", s("foot reference z, leg frame")));
    }
    if let Some(free) = &g.free {
        rec.put(free.clearance, || (s("body_clearance"), "m", s("body height above the ground plane estimated from the contact points (free gait)")));
        rec.put(free.roll, || (s("posture_roll"), "rad", s("body roll as the free gait knows it (navigation, else desired)")));
        rec.put(free.pitch, || (s("posture_pitch"), "rad", s("body pitch as the free gait knows it (navigation, else desired)")));
        for (l, t) in free.touchdowns.iter().enumerate() {
            rec.put(f64::from(u8::from(*t)), || (format!("touchdown[{l}]"), "1", s("1 when the landing of the leg was detected at t (free gait)")));
        }
        rec.put(f64::from(u8::from(free.deadlock)), || (s("deadlock"), "1", s("1 while the support legs are halted by a deadlock (free gait, Section 7.7.4)")));
        rec.put(free.stability_margin, || (s("stability_margin"), "m", s("normalized energy stability margin of the feet in support as the free gait knows them: the rise of the centre of mass to tip over the weakest edge (< 0: beyond it)")));
    }
}

/// The ground detection experiment's columns (Section 5.6.3): the detector's output per leg and
/// the schedule.
pub fn record_ground_detection(rec: &mut Recorder, g: &GroundExperimentState) {
    let s = |x: &str| x.to_string();
    for (l, d) in g.detections.iter().enumerate() {
        rec.put(d.force, || (format!("F_gnd_est[{l}]"), "N", s("estimated vertical ground force on the foot from the motor current, F_z,gnd = alpha_21 tau_v,gnd (Eq. 5.22)")));
    }
    for (l, d) in g.detections.iter().enumerate() {
        rec.put(f64::from(u8::from(d.detected)), || (format!("gnd_detected[{l}]"), "1", s("1: F_gnd_est at or above the threshold while the foot is lowered (Section 5.6.3)")));
    }
    let (leg, threshold, trial) = g.trial.map_or((-1.0, f64::NAN, -1.0), |(l, f, n)| (l as f64, f, n as f64));
    rec.put(leg, || (s("gd_leg"), "1", s("leg under test in a sawtooth period (-1: none)")));
    rec.put(threshold, || (s("gd_threshold"), "N", s("detection threshold of the current sawtooth period (NaN: none)")));
    rec.put(trial, || (s("gd_trial"), "1", s("trial of the current threshold, from 0 (-1: none)")));
    rec.put(f64::from(u8::from(g.holding)), || (s("gd_hold"), "1", s("1: the tested leg is stopped on a detection")));
    rec.put(f64::from(u8::from(g.stop.is_some())), || (s("gd_stop"), "1", s("1: the tested leg stopped at this instant (a row of Table 5.7: the true force is Fn[gd_leg])")));
}

