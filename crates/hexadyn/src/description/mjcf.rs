//! MJCF export of a serial hexapod, so that a MuJoCo user loads the robot hexadyn simulates:
//! the base link as a free body, each link a body at its joint's origin (URDF `<origin>`: the
//! link frame at q = 0) with a hinge or slide joint on its axis and range, its mass, centre of
//! mass and full inertia tensor as hexadyn has them (fixed links merged), and each foot a
//! contact sphere with a site `foot{leg}` at its centre. Legs and joints are written in the
//! order of q (Eq. 3.51), so MuJoCo's joint order is hexadyn's.

use std::fmt::Write;

use nalgebra::{Rotation3, UnitQuaternion, Vector3};

use crate::hexapod::{JointKind, Link, SerialHexapod};
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
