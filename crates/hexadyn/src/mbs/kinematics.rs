//! Recursive kinematics with direct partial velocities (thesis Eq. 3.23-3.34, Section 3.3.4).
//!
//! Each body is described from its reference body (relative motion): pose, velocity,
//! convective acceleration and the partial velocities d_ij, δ_ij are carried through the
//! elementary transforms of the body's joint. A translation by s along unit axis e (global
//! direction) at offset r adds d_j += δ_j × r + e ∂s/∂q_j; a rotation adds δ_j += e ∂s/∂q_j.
//! Only the columns of the joint's own variables change along the joint: the reference body's
//! partial velocities ride along rigidly, so they are kept relative to it (and summed into the
//! full d_ij, δ_ij only when asked for, e.g. for the mass matrix).

use nalgebra::{DMatrix, Vector3};

use super::data::Data;
use super::dependent;
use super::model::{Angle, CompiledElementary, CompiledVar, Model, Source, Var};
use crate::spatial::Htm;

/// Value, rate, convective second derivative and gradient (per compiled column) of a variable.
struct VarState {
    value: f64,
    rate: f64,
    bias: f64,
}

fn var_state(v: &Var, q: &[f64], qd: &[f64], dependents: &[super::DependentValue]) -> VarState {
    match v.source {
        Source::Coordinate(j) => VarState { value: v.scale * q[j] + v.offset, rate: v.scale * qd[j], bias: 0.0 },
        Source::Dependent(k) => {
            let p = &dependents[k];
            VarState { value: v.scale * p.value + v.offset, rate: v.scale * p.rate, bias: v.scale * p.bias }
        }
    }
}

/// (sin, cos) of the joint angle scale p + o: from (sin p, cos p) when the dependent parameter p
/// has them and scale = ±1, sin(±p + o) = ±sin p cos o + cos p sin o and
/// cos(±p + o) = cos p cos o ∓ sin p sin o with (sin o, cos o) kept in the [`Angle`]; otherwise
/// `sin_cos` of the angle (the pantograph's angles come from their arc cosines: 12 of the 21 angles of the
/// hexapod, 12 of the 21 evaluations of `sin_cos` per kinematics, each about 200 instructions).
fn angle_sin_cos(angle: &Angle, q: &[f64], qd: &[f64], dependents: &[super::DependentValue]) -> (f64, f64) {
    let var = &angle.var;
    if let (Source::Dependent(k), true) = (var.source, var.scale.abs() == 1.0) {
        if let Some((s, c)) = dependents[k].sin_cos {
            let ((so, co), s) = (angle.offset_sin_cos, var.scale * s);
            return (s * co + c * so, c * co - s * so);
        }
    }
    var_state(var, q, qd, dependents).value.sin_cos()
}

/// Adds `e * scale * ∂source/∂q` to the columns of `target`.
fn add_gradient(var: &CompiledVar, dependents: &[super::DependentValue], e: &Vector3<f64>, target: &mut [Vector3<f64>]) {
    let v = &var.var;
    match v.source {
        Source::Coordinate(_) => target[var.columns[0]] += e * v.scale,
        Source::Dependent(k) => {
            for (g, &col) in dependents[k].gradient.iter().zip(&var.columns) {
                target[col] += e * (v.scale * g);
            }
        }
    }
}

/// Velocity, convective acceleration and relative partial velocities carried across a
/// displacement r of the frame (rigid transport, Eq. 3.24-3.27).
fn offset_motion(r: &Vector3<f64>, omega: &Vector3<f64>, alpha: &Vector3<f64>, vel: &mut Vector3<f64>, acc: &mut Vector3<f64>, d: &mut [Vector3<f64>], delta: &[Vector3<f64>]) {
    *vel += omega.cross(r);
    *acc += alpha.cross(r) + omega.cross(&omega.cross(r));
    for (dk, deltak) in d.iter_mut().zip(delta) {
        *dk += deltak.cross(r);
    }
}

/// Evaluates dependent parameters, then poses, velocities, convective accelerations and
/// partial velocities of all bodies at (q, q̇): [`relative_kinematics`] then
/// [`partial_velocities`].
pub fn kinematics(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) {
    relative_kinematics(model, data, q, qd);
    partial_velocities(model, data);
}

/// Evaluates dependent parameters, then poses, velocities and convective accelerations of all
/// bodies at (q, q̇), and the partial velocities of each body relative to its reference body
/// over the columns of its own joint: all that [`super::residual`] needs. The partial velocities
/// of the bodies themselves (the mass matrix, [`Data::partial_velocities`]) follow from
/// [`partial_velocities`].
pub fn relative_kinematics(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) {
    debug_assert_eq!(q.len(), model.coordinates);
    for g in &model.dependents {
        let (x, xd) = &mut data.input_work;
        x.clear();
        xd.clear();
        x.extend(g.inputs.iter().map(|&i| q[i]));
        xd.extend(g.inputs.iter().map(|&i| qd[i]));
        let no = g.function.output_count();
        let out = &mut data.dependents[g.first_output..g.first_output + no];
        dependent::evaluate(g.function.as_ref(), x, xd, out, &mut data.dual_work);
    }
    data.complete = false;
    // Sine and cosine of each distinct joint angle, once (links moving in parallel, e.g. the
    // pantograph's, turn by the same dependent parameter).
    for (sc, angle) in data.angles.iter_mut().zip(&model.angles) {
        *sc = angle_sin_cos(angle, q, qd, &data.dependents);
    }
    // The relative partial velocities are accumulated below: zeroed once for all bodies (one
    // fill rather than a small one per body).
    data.d_rel.fill(Vector3::zeros());
    data.delta_rel.fill(Vector3::zeros());
    for (i, body) in model.bodies.iter().enumerate() {
        let (mut pose, mut omega, mut vel, mut alpha, mut acc) = match body.parent {
            Some(p) => (data.pose[p], data.omega[p], data.velocity[p], data.alpha_bias[p], data.accel_bias[p]),
            None => (Htm::identity(), Vector3::zeros(), Vector3::zeros(), Vector3::zeros(), Vector3::zeros()),
        };
        // The reference body's partial velocities are carried rigidly (see `partial_velocities`):
        // only the own columns of the joint are propagated here.
        let n = body.own.len();
        let d = &mut data.d_rel[body.own_offset..body.own_offset + n];
        let delta = &mut data.delta_rel[body.own_offset..body.own_offset + n];
        // Displacements are carried rigidly with ω, α and δ of the frame, which only a rotation
        // changes: those up to the next rotation are summed and carried once (Eq. 3.24-3.27
        // are linear in the displacement), and only when there are some. The relative δ are
        // zero up to the joint's first rotation: none to carry into d before it.
        let mut displacement = Vector3::zeros();
        // `with_delta`: the own columns whose relative δ may be non-zero (all after a rotation).
        let (mut moved, mut with_delta) = (false, 0);
        for e in &body.joint {
            match e {
                CompiledElementary::Fixed(h) => {
                    displacement += pose.rotation * h.translation;
                    pose.rotation *= h.rotation;
                    moved = true;
                }
                CompiledElementary::Offset(t) => {
                    displacement += pose.rotation * t;
                    moved = true;
                }
                CompiledElementary::Rotation { axis, var, angle } => {
                    if moved {
                        offset_motion(&displacement, &omega, &alpha, &mut vel, &mut acc, &mut d[..with_delta], &delta[..with_delta]);
                        pose.translation += displacement;
                        (displacement, moved) = (Vector3::zeros(), false);
                    }
                    let s = var_state(&var.var, q, qd, &data.dependents);
                    let e = axis.in_frame(&pose.rotation);
                    alpha += omega.cross(&e) * s.rate + e * s.bias;
                    omega += e * s.rate;
                    add_gradient(var, &data.dependents, &e, delta);
                    with_delta = n;
                    match angle {
                        Some(k) => axis.rotate(&mut pose.rotation, data.angles[*k]),
                        None => data.spin[i] = Some((*axis, s.value)),
                    }
                }
                CompiledElementary::Translation { axis, var } => {
                    let s = var_state(&var.var, q, qd, &data.dependents);
                    let e = axis.in_frame(&pose.rotation);
                    displacement += e * s.value;
                    vel += e * s.rate;
                    acc += omega.cross(&e) * (2.0 * s.rate) + e * s.bias;
                    add_gradient(var, &data.dependents, &e, d);
                    moved = true;
                }
            }
        }
        if moved {
            offset_motion(&displacement, &omega, &alpha, &mut vel, &mut acc, &mut d[..with_delta], &delta[..with_delta]);
            pose.translation += displacement;
        }
        data.pose[i] = pose;
        data.omega[i] = omega;
        data.velocity[i] = vel;
        data.alpha_bias[i] = alpha;
        data.accel_bias[i] = acc;
    }
}

/// The partial velocities d_ij and δ_ij of every body (Eq. 3.24, 3.31) after
/// [`relative_kinematics`]: those of the reference body p carried rigidly to G_i,
/// d_ij = d_pj + δ_pj × (p_i − p_p), δ_ij = δ_pj, plus the relative ones of the body's joint.
/// Does nothing when they are already complete.
pub fn partial_velocities(model: &Model, data: &mut Data) {
    if data.complete {
        return;
    }
    for (i, body) in model.bodies.iter().enumerate() {
        let n = body.columns.len();
        let (head, tail) = data.d.split_at_mut(body.offset);
        let d = &mut tail[..n];
        let (dhead, dtail) = data.delta.split_at_mut(body.offset);
        let delta = &mut dtail[..n];
        d.iter_mut().for_each(|x| *x = Vector3::zeros());
        delta.iter_mut().for_each(|x| *x = Vector3::zeros());
        if let Some(p) = body.parent {
            let parent = &model.bodies[p];
            let r = data.pose[i].translation - data.pose[p].translation;
            for (k, &pos) in body.parent_columns.iter().enumerate() {
                let dp = dhead[parent.offset + k];
                d[pos] = head[parent.offset + k] + dp.cross(&r);
                delta[pos] = dp;
            }
        }
        for (k, &pos) in body.own_columns.iter().enumerate() {
            d[pos] += data.d_rel[body.own_offset + k];
            delta[pos] += data.delta_rel[body.own_offset + k];
        }
    }
    data.complete = true;
}

/// Partial velocities estimated by numerical derivation of the positions (central differences
/// on T_{0,i}(q), Eq. 3.24 and 3.30): the slow method of the first rows of Table 3.2, kept as the
/// baseline of the benchmarks and as a test oracle. Returns, per body, J_S and J_ω (3 × n).
pub fn partial_velocities_numerical(model: &Model, data: &mut Data, q: &[f64]) -> Vec<(DMatrix<f64>, DMatrix<f64>)> {
    let n = model.coordinates;
    let zero = vec![0.0; n];
    let mut x = q.to_vec();
    let mut out = vec![(DMatrix::zeros(3, n), DMatrix::zeros(3, n)); model.bodies.len()];
    for j in 0..n {
        let step = 1e-6 * q[j].abs().max(1.0);
        x[j] = q[j] + step;
        let poses = |data: &mut Data, x: &[f64]| {
            kinematics(model, data, x, &zero);
            (0..model.bodies.len()).map(|i| data.pose(super::BodyId(i))).collect::<Vec<_>>()
        };
        let plus = poses(data, &x);
        x[j] = q[j] - step;
        let minus = poses(data, &x);
        x[j] = q[j];
        for (i, (js, jw)) in out.iter_mut().enumerate() {
            let dp = (plus[i].translation - minus[i].translation) / (2.0 * step);
            let dr = (plus[i].rotation - minus[i].rotation) / (2.0 * step);
            let w = dr * ((plus[i].rotation + minus[i].rotation) * 0.5).transpose();
            js.set_column(j, &dp);
            jw.set_column(j, &Vector3::new(w[(2, 1)] - w[(1, 2)], w[(0, 2)] - w[(2, 0)], w[(1, 0)] - w[(0, 1)]).scale(0.5));
        }
    }
    kinematics(model, data, q, &zero);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix3;
    use crate::mbs::{mass_matrix, residual, BodyId, BodySpec, Elementary, ModelBuilder, Var};

    /// A free body carrying a chassis on q6 and a rotor on q7 · 50 about its x axis, whose
    /// equatorial moments are `equatorial` (I_e, I_e for a rotor).
    fn rotor_on_chassis(equatorial: (f64, f64)) -> Model {
        let mut b = ModelBuilder::new(8);
        let base = b.add_body(BodySpec { name: "base".into(), parent: None, joint: Elementary::free_body(0), mass: 3.0, inertia: Matrix3::from_diagonal(&Vector3::new(0.1, 0.2, 0.25)) }).unwrap();
        let chassis = b
            .add_body(BodySpec { name: "chassis".into(), parent: Some(base), joint: vec![Elementary::offset(0.2, 0.1, 0.0), Elementary::rz(Var::q(6)), Elementary::offset(0.05, 0.0, -0.02)], mass: 1.0, inertia: Matrix3::from_diagonal(&Vector3::new(0.01, 0.02, 0.015)) })
            .unwrap();
        b.add_body(BodySpec { name: "rotor".into(), parent: Some(chassis), joint: vec![Elementary::offset(-0.03, 0.01, 0.02), Elementary::rx(Var::q(7).scaled(50.0))], mass: 0.2, inertia: Matrix3::from_diagonal(&Vector3::new(6.5e-6, equatorial.0, equatorial.1)) }).unwrap();
        b.build()
    }

    /// The turn of an axisymmetric leaf rotor about its axis is not carried through the pass (no
    /// sine and cosine of n q), yet the pose, the world inertia, the mass matrix and the residual
    /// are those of the full rotation, which a rotor whose equatorial moments differ by 1e-12
    /// (not symmetric: the fallback) turns through.
    #[test]
    fn the_spin_of_a_rotor_changes_no_dynamic_quantity() {
        let spinning = rotor_on_chassis((1.9e-4, 1.9e-4));
        let full = rotor_on_chassis((1.9e-4, 1.9e-4 * (1.0 + 1e-12)));
        assert_eq!((spinning.angles.len(), full.angles.len()), (4, 5));
        let q = [0.1, -0.2, 0.3, 0.4, -0.3, 0.2, 0.7, 0.9];
        let qd = [0.3, 0.1, -0.2, 0.5, 0.4, -0.6, 1.5, -2.0];
        let qdd = [1.0, -2.0, 0.5, 3.0, -1.0, 2.0, 10.0, 20.0];
        let rotor = BodyId(2);
        let evaluate = |model: &Model| {
            let mut data = Data::new(model);
            kinematics(model, &mut data, &q, &qd);
            let mut m = DMatrix::zeros(8, 8);
            mass_matrix(model, &data, &mut m);
            let mut f = [0.0; 8];
            residual(model, &mut data, &qdd, &mut f);
            (data, m, f)
        };
        let ((a, ma, fa), (b, mb, fb)) = (evaluate(&spinning), evaluate(&full));
        assert!(a.spin[rotor.0].is_some() && b.spin[rotor.0].is_none());
        assert!((a.pose(rotor).rotation - b.pose(rotor).rotation).amax() < 1e-15);
        assert!((a.point(rotor, &Vector3::new(0.0, 0.02, 0.0)) - b.point(rotor, &Vector3::new(0.0, 0.02, 0.0))).amax() < 1e-15);
        let world_inertia = |model: &Model, data: &Data| model.bodies[rotor.0].world_inertia(&data.pose(rotor).rotation);
        assert!((world_inertia(&spinning, &a) - world_inertia(&full, &b)).amax() < 1e-15);
        assert!((&ma - &mb).amax() < 1e-12 * mb.amax(), "{}", (&ma - &mb).amax());
        let scale = fb.iter().fold(0.0_f64, |s, x| s.max(x.abs()));
        assert!(fa.iter().zip(&fb).all(|(x, y)| (x - y).abs() < 1e-12 * scale), "{fa:?} vs {fb:?}");
    }
}
