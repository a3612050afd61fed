//! MJCF export of a hexapod, so that a MuJoCo user loads the robot hexadyn simulates.
//!
//! A serial hexapod ([`serial_hexapod_to_mjcf`]):
//! the base link as a free body, each link a body at its joint's origin (URDF `<origin>`: the
//! link frame at q = 0) with a hinge or slide joint on its axis and range, its mass, centre of
//! mass and full inertia tensor as hexadyn has them (fixed links merged), and each foot a
//! contact sphere with a site `foot{leg}` at its centre. Legs and joints are written in the
//! order of q (Eq. 3.51), so MuJoCo's joint order is hexadyn's.

//!
//! A pantograph hexapod ([`pantograph_hexapod_to_mjcf`]): its closed linkages written as
//! MuJoCo's equality constraints, with the map from hexadyn's minimal coordinates to MuJoCo's
//! ([`pantograph_mujoco_state`]).

use std::fmt::Write;

use nalgebra::{DMatrix, Rotation3, UnitQuaternion, Vector3};

use crate::hexapod::{joint_index, JointKind, LegJoints, Link, MechanicsParameters, SerialHexapod, DOF};
use crate::mbs::{evaluate_jets, DependentValue};
use crate::spatial::Htm;

fn vec3(v: &Vector3<f64>) -> String {
    format!("{:?} {:?} {:?}", v.x, v.y, v.z)
}

/// MuJoCo's `quat` (w x y z) of a rotation matrix.
fn quat(h: &Htm) -> String {
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(h.rotation));
    format!("{:?} {:?} {:?} {:?}", q.w, q.i, q.j, q.k)
}

/// `<inertial>` of a link: mass, centre of mass and the tensor about it in the link frame.
fn inertial(l: &Link) -> String {
    let i = &l.inertia;
    format!(
        "<inertial pos=\"{}\" mass=\"{:?}\" fullinertia=\"{:?} {:?} {:?} {:?} {:?} {:?}\"/>",
        vec3(&l.com),
        l.mass,
        i[(0, 0)],
        i[(1, 1)],
        i[(2, 2)],
        i[(0, 1)],
        i[(0, 2)],
        i[(1, 2)]
    )
}

/// The MJCF text of `robot`, gravity −`gravity` along z (m/s²).
pub fn serial_hexapod_to_mjcf(robot: &SerialHexapod, gravity: f64) -> String {
    let name = |s: &str| quick_xml::escape::escape(s).into_owned();
    let mut x = String::new();
    let _ = writeln!(x, "<mujoco model=\"{}\">", name(&robot.name));
    let _ = writeln!(x, "  <!-- Written by hexadyn from its model of the robot: links with their fixed children merged. -->");
    let _ = writeln!(x, "  <compiler angle=\"radian\" autolimits=\"true\"/>");
    let _ = writeln!(x, "  <option gravity=\"0 0 {:?}\"/>", -gravity);
    let _ = writeln!(x, "  <worldbody>");
    let _ = writeln!(x, "    <body name=\"base\">");
    let _ = writeln!(x, "      <freejoint name=\"base\"/>");
    let _ = writeln!(x, "      {}", inertial(&robot.base));
    for (leg, l) in robot.legs.iter().enumerate() {
        let mut indent = String::from("      ");
        for (k, (joint, link)) in l.joints.iter().zip(&l.links).enumerate() {
            let kind = match joint.kind {
                JointKind::Revolute => "hinge",
                JointKind::Prismatic => "slide",
            };
            let _ = writeln!(x, "{indent}<body name=\"leg{leg}_link{k}\" pos=\"{}\" quat=\"{}\">", vec3(&joint.origin.translation), quat(&joint.origin));
            indent.push_str("  ");
            let _ = writeln!(x, "{indent}<joint name=\"{}\" type=\"{kind}\" axis=\"{}\" range=\"{:?} {:?}\"/>", name(&joint.name), vec3(&joint.axis), joint.lower, joint.upper);
            let _ = writeln!(x, "{indent}{}", inertial(link));
        }
        let _ = writeln!(x, "{indent}<geom name=\"foot{leg}\" type=\"sphere\" size=\"{:?}\" pos=\"{}\" mass=\"0\"/>", l.foot_radius, vec3(&l.foot));
        let _ = writeln!(x, "{indent}<site name=\"foot{leg}\" pos=\"{}\"/>", vec3(&l.foot));
        for _ in 0..3 {
            indent.truncate(indent.len() - 2);
            let _ = writeln!(x, "{indent}</body>");
        }
    }
    let _ = writeln!(x, "    </body>");
    let _ = writeln!(x, "  </worldbody>");
    let _ = writeln!(x, "</mujoco>");
    x
}

/// Radius of the foot sphere written for a point foot (AMRU5's, Eq. 3.72): MuJoCo's contacts need
/// a volume. INTERPRETATION: 5 mm, a tenth of the smallest step a walk of Chapter 7 climbs; the
/// sphere is centred at F.
const POINT_FOOT_RADIUS: f64 = 0.005;

/// MuJoCo joints per pantograph leg: q_r and its rotor, link 0 on q_v and −p0, links 1 and 3
/// at π − p1, link 2 on q_h and −p0, the rotors of q_v and q_h (MuJoCo's depth-first order
/// through the bodies [`pantograph_hexapod_to_mjcf`] writes).
const LEG_JOINTS: usize = 10;

/// The value of each of a leg's [`LEG_JOINTS`] joints and its gradient in (q_r, q_v, q_h), from the joints and
/// the dependent parameters p0, p1 (Eq. 3.62-3.63) with their gradients in (q_v, q_h).
fn leg_joint_values(p: &MechanicsParameters, q: [f64; 3], p0: (f64, [f64; 2]), p1: (f64, [f64; 2])) -> [(f64, [f64; 3]); LEG_JOINTS] {
    let [n_r, n_v, n_h] = p.reductions;
    let minus_p0 = (-p0.0, [0.0, -p0.1[0], -p0.1[1]]);
    let pi_minus_p1 = (std::f64::consts::PI - p1.0, [0.0, -p1.1[0], -p1.1[1]]);
    [
        (q[0], [1.0, 0.0, 0.0]),
        (n_r * q[0], [n_r, 0.0, 0.0]),
        (q[1], [0.0, 1.0, 0.0]),
        minus_p0,
        pi_minus_p1,
        pi_minus_p1,
        (q[2], [0.0, 0.0, 1.0]),
        minus_p0,
        (n_v * q[1], [0.0, n_v, 0.0]),
        (n_h * q[2], [0.0, 0.0, n_h]),
    ]
}

fn diagonal_inertial(pos: &Vector3<f64>, mass: f64, moments: &Vector3<f64>) -> String {
    format!("<inertial pos=\"{}\" mass=\"{mass:?}\" diaginertia=\"{}\"/>", vec3(pos), vec3(moments))
}

/// The MJCF text of a pantograph hexapod (AMRU5's mechanics, Eq. 3.51-3.71) with the joint names
/// `joints`, gravity −`gravity` along z (m/s²): the same 49 bodies with their masses and
/// inertias, each pantograph link on its own hinge and the two loops of the linkage closed by
/// `connect` equality constraints (link 1's end on D, link 2's end on link 3's E), the rotors on
/// hinges coupled to their joints by `joint` equality constraints (n q, Table 3.1). The
/// actuated joints are named as hexadyn's columns (`q_r[0]` ...); a point foot is a
/// [`POINT_FOOT_RADIUS`] sphere with a site `foot{leg}` at F. [`pantograph_mujoco_state`] maps
/// hexadyn's 24 coordinates to MuJoCo's.
pub fn pantograph_hexapod_to_mjcf(p: &MechanicsParameters, joints: &LegJoints, name: &str, foot_radius: f64, gravity: f64) -> String {
    let pg = &p.pantograph;
    let c_star = p.chassis_cog + p.crossing_point;
    let [ag0, bg1, dg2, cg3] = p.link_cog;
    let rotor = |axis: usize| {
        let mut m = Vector3::repeat(p.rotor_equatorial);
        m[axis] = p.rotor_axial;
        diagonal_inertial(&Vector3::zeros(), p.rotor_mass, &m)
    };
    let radius = if foot_radius > 0.0 { foot_radius } else { POINT_FOOT_RADIUS };
    let mut x = String::new();
    let _ = writeln!(x, "<mujoco model=\"{}\">", quick_xml::escape::escape(name));
    let _ = writeln!(x, "  <!-- Written by hexadyn from its model of the robot: the pantograph loops as equality constraints, the rotors coupled to their joints. -->");
    let _ = writeln!(x, "  <compiler angle=\"radian\" autolimits=\"true\"/>");
    let _ = writeln!(x, "  <option gravity=\"0 0 {:?}\"/>", -gravity);
    let _ = writeln!(x, "  <worldbody>");
    let _ = writeln!(x, "    <body name=\"body\">");
    let _ = writeln!(x, "      <freejoint name=\"body\"/>");
    let _ = writeln!(x, "      {}", diagonal_inertial(&Vector3::zeros(), p.body.mass, &p.body.moments));
    let mut equalities = String::new();
    for (leg, &alpha) in p.leg_angles.iter().enumerate() {
        let joint = |k: usize| quick_xml::escape::escape(joints.column("", 3 * leg + k, "")).into_owned();
        let own = |part: &str| format!("leg{leg}_{part}");
        let o_l = Vector3::new(p.r_rot * alpha.cos(), p.r_rot * alpha.sin(), 0.0);
        let (s, c) = (0.5 * alpha).sin_cos();
        // Eq. 3.64: the chassis frame at O_l, turned by α, then by −q_r.
        let _ = writeln!(x, "      <body name=\"{}\" pos=\"{}\" quat=\"{c:?} 0 0 {s:?}\">", own("chassis"), vec3(&o_l));
        let _ = writeln!(x, "        <joint name=\"{}\" type=\"hinge\" axis=\"0 0 -1\"/>", joint(0));
        let _ = writeln!(x, "        {}", diagonal_inertial(&p.chassis_cog, p.chassis.mass, &p.chassis.moments));
        let _ = writeln!(x, "        <body name=\"{}\" pos=\"{:?} 0 0\"><joint name=\"{}\" type=\"hinge\" axis=\"0 0 1\"/>{}</body>", own("rotor_r"), p.rotor_r_radius - p.r_rot, own("rotor_r"), rotor(2));
        // Eq. 3.65-3.66, 3.68: link 0 from A on q_v, turned by −p0; links 1 (from B) and 3 (from C).
        let _ = writeln!(x, "        <body name=\"{}\" pos=\"{}\">", own("link0"), vec3(&c_star));
        let _ = writeln!(x, "          <joint name=\"{}\" type=\"slide\" axis=\"0 0 1\"/>", joint(1));
        let _ = writeln!(x, "          <joint name=\"{}\" type=\"hinge\" axis=\"0 1 0\"/>", own("link0"));
        let _ = writeln!(x, "          {}", diagonal_inertial(&Vector3::new(ag0, 0.0, 0.0), p.links[0].mass, &p.links[0].moments));
        let _ = writeln!(x, "          <body name=\"{}\" pos=\"{:?} 0 0\"><joint name=\"{}\" type=\"hinge\" axis=\"0 1 0\"/>{}<site name=\"{}\" pos=\"{:?} 0 0\"/></body>", own("link1"), pg.c, own("link1"), diagonal_inertial(&Vector3::new(bg1, 0.0, 0.0), p.links[1].mass, &p.links[1].moments), own("D1"), pg.l1);
        let _ = writeln!(x, "          <body name=\"{}\" pos=\"{:?} 0 0\">", own("link3"), pg.l0);
        let _ = writeln!(x, "            <joint name=\"{}\" type=\"hinge\" axis=\"0 1 0\"/>", own("link3"));
        let _ = writeln!(x, "            {}", diagonal_inertial(&Vector3::new(cg3, 0.0, 0.0), p.links[3].mass, &p.links[3].moments));
        let _ = writeln!(x, "            <site name=\"{}\" pos=\"{:?} 0 0\"/>", own("E3"), pg.l1);
        let _ = writeln!(x, "            <geom name=\"foot{leg}\" type=\"sphere\" size=\"{radius:?}\" pos=\"{:?} 0 0\" mass=\"0\"/>", pg.l3);
        let _ = writeln!(x, "            <site name=\"foot{leg}\" pos=\"{:?} 0 0\"/>", pg.l3);
        let _ = writeln!(x, "          </body>");
        let _ = writeln!(x, "        </body>");
        // Eq. 3.67: link 2 from D on q_h, parallel to link 0 (its end E at C − B from D).
        let _ = writeln!(x, "        <body name=\"{}\" pos=\"{}\">", own("link2"), vec3(&c_star));
        let _ = writeln!(x, "          <joint name=\"{}\" type=\"slide\" axis=\"1 0 0\"/>", joint(2));
        let _ = writeln!(x, "          <joint name=\"{}\" type=\"hinge\" axis=\"0 1 0\"/>", own("link2"));
        let _ = writeln!(x, "          {}", diagonal_inertial(&Vector3::new(dg2, 0.0, 0.0), p.links[2].mass, &p.links[2].moments));
        let _ = writeln!(x, "          <site name=\"{}\"/><site name=\"{}\" pos=\"{:?} 0 0\"/>", own("D2"), own("E2"), pg.l0 - pg.c);
        let _ = writeln!(x, "        </body>");
        // Eq. 3.69-3.71: the nut rotors.
        let _ = writeln!(x, "        <body name=\"{}\" pos=\"{}\"><joint name=\"{}\" type=\"hinge\" axis=\"0 0 1\"/>{}</body>", own("rotor_v"), vec3(&(c_star + p.rotor_v)), own("rotor_v"), rotor(2));
        let _ = writeln!(x, "        <body name=\"{}\" pos=\"{}\"><joint name=\"{}\" type=\"hinge\" axis=\"1 0 0\"/>{}</body>", own("rotor_h"), vec3(&(c_star + p.rotor_h)), own("rotor_h"), rotor(0));
        let _ = writeln!(x, "      </body>");
        let _ = writeln!(equalities, "    <connect site1=\"{}\" site2=\"{}\"/>", own("D1"), own("D2"));
        let _ = writeln!(equalities, "    <connect site1=\"{}\" site2=\"{}\"/>", own("E3"), own("E2"));
        for (rotor, k) in [("rotor_r", 0), ("rotor_v", 1), ("rotor_h", 2)] {
            let _ = writeln!(equalities, "    <joint joint1=\"{}\" joint2=\"{}\" polycoef=\"0 {:?} 0 0 0\"/>", own(rotor), joint(k), p.reductions[k]);
        }
    }
    let _ = writeln!(x, "    </body>");
    let _ = writeln!(x, "  </worldbody>");
    let _ = writeln!(x, "  <equality>\n{equalities}  </equality>");
    let _ = writeln!(x, "</mujoco>");
    x
}

/// MuJoCo's qpos (the free joint's position and quaternion, then the ten joints of each leg of
/// [`pantograph_hexapod_to_mjcf`]) at hexadyn's coordinates `q` (Eq. 3.51-3.52), and the map G
/// from q' to MuJoCo's qvel (the free joint's linear velocity in the world and angular velocity
/// in the body, Eq. 3.52's rates turned into it; each leg joint's gradient through the
/// dependent parameters): v_MuJoCo = G q', so that hexadyn's mass matrix is Gᵀ M G and its
/// generalized gravity Gᵀ of MuJoCo's. None when a leg's linkage does not close.
pub fn pantograph_mujoco_state(p: &MechanicsParameters, q: &[f64; DOF]) -> Option<(Vec<f64>, DMatrix<f64>)> {
    let per_leg = LEG_JOINTS;
    let (mut qpos, mut g) = (Vec::with_capacity(7 + 6 * per_leg), DMatrix::zeros(6 + 6 * per_leg, DOF));
    let (yaw, pitch, roll) = (q[3], q[4], q[5]);
    let r = UnitQuaternion::from_euler_angles(roll, pitch, yaw);
    qpos.extend_from_slice(&[q[0], q[1], q[2], r.w, r.i, r.j, r.k]);
    let (sp, cp, sr, cr) = (pitch.sin(), pitch.cos(), roll.sin(), roll.cos());
    let e = [[-sp, 0.0, 1.0], [cp * sr, cr, 0.0], [cp * cr, -sr, 0.0]];
    for i in 0..3 {
        g[(i, i)] = 1.0;
        for j in 0..3 {
            g[(3 + i, 3 + j)] = e[i][j];
        }
    }
    let mut work = Vec::new();
    for leg in 0..6 {
        let j = joint_index(leg, 0);
        let (q_v, q_h) = (q[j + 1], q[j + 2]);
        if !p.pantograph.closes(q_v, q_h) {
            return None;
        }
        let mut out: [DependentValue; 2] = std::array::from_fn(|_| DependentValue { gradient: vec![0.0; 2], ..Default::default() });
        evaluate_jets(&p.pantograph, &[q_v, q_h], &[0.0, 0.0], &mut out, &mut work);
        let dependent = |d: &DependentValue| (d.value, [d.gradient[0], d.gradient[1]]);
        let values = leg_joint_values(p, [q[j], q_v, q_h], dependent(&out[0]), dependent(&out[1]));
        for (k, (value, gradient)) in values.iter().enumerate() {
            qpos.push(*value);
            for (c, d) in gradient.iter().enumerate() {
                g[(6 + leg * per_leg + k, j + c)] = *d;
            }
        }
    }
    Some((qpos, g))
}
