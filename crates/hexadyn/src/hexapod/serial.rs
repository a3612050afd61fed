//! Serial legs: a chain of three actuated joints given the URDF way (a joint's origin in its
//! parent link's frame, its axis, revolute or prismatic, its limits), links with mass, centre of
//! mass and inertia tensor, and a foot (the centre of a contact sphere on the last link). The
//! thesis' conclusion: its tools adapt "on any other leg mechanism classically encountered in
//! walking machines" directly; here the multibody model of Section 3.3.3 is assembled for such
//! legs with the same elementary transformations as the pantograph (Eq. 3.18-3.22): per link,
//! T_{parent, link} = T_origin T^R(axis, q) (or T^d(axis, q)) T^d(com).
//!
//! The main body is the free body of Eq. 3.52 at the origin of the base link, so that (X, Y, Z)
//! is the base link's origin and (Φ, Θ, Ψ) its yaw, pitch and roll, as a URDF user reads them.

use nalgebra::{Matrix3, Vector3};

use super::joints::JointKind;
use super::{joint_index, DOF, LEG_COUNT};
use crate::mbs::{BodyId, BodySpec, Elementary, Model, ModelBuilder, ModelError, Var};
use crate::spatial::Htm;

/// A rigid link: mass, centre of mass and central inertia tensor, both in the link frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Link {
    pub mass: f64,
    pub com: Vector3<f64>,
    /// Inertia tensor about the centre of mass, in the axes of the link frame (kg m²).
    pub inertia: Matrix3<f64>,
}

impl Link {
    /// The link that carries `self` and `other` rigidly, `other`'s frame placed at `pose` in
    /// `self`'s (a fixed joint merged): masses add, the centre of mass is the mass-weighted
    /// mean, and each tensor moves to it by the parallel-axis theorem.
    pub fn merged(&self, other: &Link, pose: &Htm) -> Link {
        let mass = self.mass + other.mass;
        let other_com = pose.apply(&other.com);
        let com = if mass > 0.0 { (self.com * self.mass + other_com * other.mass) / mass } else { self.com };
        let shift = |m: f64, d: Vector3<f64>| m * (Matrix3::identity() * d.norm_squared() - d * d.transpose());
        let other_inertia = pose.rotation * other.inertia * pose.rotation.transpose();
        Link { mass, com, inertia: self.inertia + shift(self.mass, self.com - com) + other_inertia + shift(other.mass, other_com - com) }
    }
}

/// One actuated joint of a serial leg.
#[derive(Clone, Debug, PartialEq)]
pub struct SerialJoint {
    /// The joint's name in the robot's source (URDF), e.g. `l1_coxa_joint`.
    pub name: String,
    /// The joint frame in the parent link's frame at q = 0 (URDF `<origin>`).
    pub origin: Htm,
    /// Unit axis in the joint frame (URDF `<axis>`).
    pub axis: Vector3<f64>,
    pub kind: JointKind,
    /// Joint range (rad or m).
    pub lower: f64,
    pub upper: f64,
}

/// A serial leg: three joints, the link each one moves, and the foot.
#[derive(Clone, Debug, PartialEq)]
pub struct SerialLeg {
    /// `joints[0].origin` is in the base link's frame, `joints[k].origin` in link k − 1's.
    pub joints: [SerialJoint; 3],
    pub links: [Link; 3],
    /// Centre of the foot's contact sphere in the last link's frame.
    pub foot: Vector3<f64>,
    pub foot_radius: f64,
}

/// A hexapod with serial legs: the base link and six legs, in the leg numbering of the thesis
/// (0, 2, 4 on the left from front to rear, 1, 3, 5 on the right).
#[derive(Clone, Debug, PartialEq)]
pub struct SerialHexapod {
    pub name: String,
    pub base: Link,
    pub legs: [SerialLeg; LEG_COUNT],
}

/// A motor rotor turning at n q about its joint's axis, on the link that carries the motor
/// (Eq. 3.69-3.71 for AMRU5's rotors): `inertia` about its axis (kg m²), `ratio` n.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rotor {
    pub inertia: f64,
    pub ratio: f64,
}

impl Rotor {
    /// No rotor (the URDF's links alone).
    pub const NONE: Rotor = Rotor { inertia: 0.0, ratio: 0.0 };

    /// The rotor's inertia tensor in its frame, the axis `a` its spin axis. INTERPRETATION: the
    /// equatorial moments are half the axial one (a thin disc); they enter only through the
    /// links' rotations, small beside n² times the axial one.
    fn tensor(&self, a: &Vector3<f64>) -> Matrix3<f64> {
        let axial = a * a.transpose();
        self.inertia * axial + 0.5 * self.inertia * (Matrix3::identity() - axial)
    }
}

/// The multibody model of a serial hexapod: 1 + 18 bodies on the 24 coordinates of Eq. 3.51,
/// and a massless rotor body per joint with a rotor inertia.
#[derive(Clone, Debug)]
pub struct SerialMechanics {
    pub model: Model,
    pub body: BodyId,
    /// The three link bodies of each leg.
    pub links: [[BodyId; 3]; LEG_COUNT],
    /// Each foot: the body of the last link and the sphere centre in that body's frame (which
    /// sits at the link's centre of mass).
    pub feet: [(BodyId, Vector3<f64>); LEG_COUNT],
}

impl SerialHexapod {
    /// Assembles the multibody model (Section 3.3.3): the base link as the free main body of
    /// Eq. 3.52, each link as a body on its joint's coordinate.
    pub fn mechanics(&self) -> Result<SerialMechanics, ModelError> {
        self.mechanics_with(&[Rotor::NONE; 3])
    }

    /// [`Self::mechanics`] with the motor rotor of each joint of a leg: a body on the joint's
    /// parent link, at the joint's frame, turning at n q about its axis (a configuration
    /// parameter of Section 3.3.4, like AMRU5's rotors); its mass is in the link's.
    pub fn mechanics_with(&self, rotors: &[Rotor; 3]) -> Result<SerialMechanics, ModelError> {
        let mut b = ModelBuilder::new(DOF);
        let mut base_joint = Elementary::free_body(0);
        base_joint.push(Elementary::offset(self.base.com.x, self.base.com.y, self.base.com.z));
        let body = b.add_body(BodySpec { name: "base".into(), parent: None, joint: base_joint, mass: self.base.mass, inertia: self.base.inertia })?;
        let mut links = [[body; 3]; LEG_COUNT];
        let mut feet = [(body, Vector3::zeros()); LEG_COUNT];
        for (leg, l) in self.legs.iter().enumerate() {
            let (mut parent, mut parent_com) = (body, self.base.com);
            for (k, (joint, link)) in l.joints.iter().zip(&l.links).enumerate() {
                let var = Var::q(joint_index(leg, k));
                let motion = match joint.kind {
                    JointKind::Revolute => Elementary::Rotation { axis: joint.axis, var },
                    JointKind::Prismatic => Elementary::Translation { axis: joint.axis, var },
                };
                let back = -parent_com;
                let rotor = &rotors[k];
                if rotor.inertia > 0.0 {
                    let spin = Var::q(joint_index(leg, k)).scaled(rotor.ratio);
                    b.add_body(BodySpec {
                        name: format!("leg{leg}.{}.rotor", joint.name),
                        parent: Some(parent),
                        joint: vec![Elementary::offset(back.x, back.y, back.z), Elementary::Fixed(joint.origin), Elementary::Rotation { axis: joint.axis, var: spin }],
                        mass: 0.0,
                        inertia: rotor.tensor(&joint.axis),
                    })?;
                }
                let spec = BodySpec {
                    name: format!("leg{leg}.{}", joint.name),
                    parent: Some(parent),
                    joint: vec![
                        Elementary::offset(back.x, back.y, back.z),
                        Elementary::Fixed(joint.origin),
                        motion,
                        Elementary::offset(link.com.x, link.com.y, link.com.z),
                    ],
                    mass: link.mass,
                    inertia: link.inertia,
                };
                parent = b.add_body(spec)?;
                parent_com = link.com;
                links[leg][k] = parent;
            }
            feet[leg] = (parent, l.foot - parent_com);
        }
        Ok(SerialMechanics { model: b.build(), body, links, feet })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mbs::{kinematics, mass_matrix, Data};
    use crate::spatial::rotation_about;
    use approx::assert_relative_eq;
    use nalgebra::DMatrix;

    fn link(mass: f64, com: [f64; 3], moments: [f64; 3]) -> Link {
        Link { mass, com: Vector3::from(com), inertia: Matrix3::from_diagonal(&Vector3::from(moments)) }
    }

    /// A planar two-link arm and a point foot, as the textbook writes it.
    fn planar_leg() -> SerialLeg {
        let joint = |name: &str, x: f64, axis: Vector3<f64>| SerialJoint { name: name.into(), origin: Htm::displacement(x, 0.0, 0.0), axis, kind: JointKind::Revolute, lower: -1.0, upper: 1.0 };
        SerialLeg {
            joints: [joint("coxa", 0.1, Vector3::z()), joint("femur", 0.05, Vector3::y()), joint("tibia", 0.2, Vector3::y())],
            links: [link(0.1, [0.025, 0.0, 0.0], [1e-5; 3]), link(0.2, [0.1, 0.0, 0.0], [0.0, 0.0, 0.0]), link(0.3, [0.15, 0.0, 0.0], [0.0, 0.0, 0.0])],
            foot: Vector3::new(0.3, 0.0, 0.0),
            foot_radius: 0.01,
        }
    }

    fn hexapod() -> SerialHexapod {
        SerialHexapod { name: "planar".into(), base: link(2.0, [0.01, 0.0, -0.01], [0.01, 0.02, 0.025]), legs: std::array::from_fn(|_| planar_leg()) }
    }

    /// With the coxa at zero, femur and tibia are the planar double pendulum: the foot is at
    /// (0.1 + 0.05 + 0.2 cos q1 + 0.3 cos(q1 + q2), −(0.2 sin q1 + 0.3 sin(q1 + q2))) (a positive
    /// rotation about y lowers x into −z), and the femur-tibia block of M is the textbook
    /// M11 = I1 + I2 + m1 a1² + m2 (l1² + a2² + 2 l1 a2 cos q2), M12 = I2 + m2 (a2² + l1 a2 cos q2),
    /// M22 = I2 + m2 a2² for point masses at a1 = 0.1, a2 = 0.15 (I = 0 about y).
    #[test]
    fn a_planar_leg_is_the_double_pendulum() {
        let m = hexapod().mechanics().unwrap();
        assert_eq!((m.model.body_count(), m.model.coordinate_count()), (19, 24));
        let mut data = Data::new(&m.model);
        let (q1, q2) = (0.4, -0.7);
        let mut q = vec![0.0; DOF];
        q[joint_index(0, 1)] = q1;
        q[joint_index(0, 2)] = q2;
        kinematics(&m.model, &mut data, &q, &[0.0; DOF]);
        let (foot_body, foot) = m.feet[0];
        let p = data.point(foot_body, &foot);
        let (l1, l2) = (0.2, 0.3);
        assert_relative_eq!(p, Vector3::new(0.15 + l1 * q1.cos() + l2 * (q1 + q2).cos(), 0.0, -(l1 * q1.sin() + l2 * (q1 + q2).sin())), epsilon = 1e-14);
        let mut mm = DMatrix::zeros(DOF, DOF);
        mass_matrix(&m.model, &data, &mut mm);
        let (m1, m2, a1, a2) = (0.2, 0.3, 0.1, 0.15);
        let (f, t) = (joint_index(0, 1), joint_index(0, 2));
        assert_relative_eq!(mm[(f, f)], m1 * a1 * a1 + m2 * (l1 * l1 + a2 * a2 + 2.0 * l1 * a2 * q2.cos()), epsilon = 1e-14);
        assert_relative_eq!(mm[(f, t)], m2 * (a2 * a2 + l1 * a2 * q2.cos()), epsilon = 1e-14);
        assert_relative_eq!(mm[(t, t)], m2 * a2 * a2, epsilon = 1e-14);
        assert_relative_eq!(m.model.total_mass(), 2.0 + 6.0 * 0.6, epsilon = 1e-12);
    }

    /// Merging a link fixed to another keeps the mass, the centre of mass and the inertia about
    /// any point: the merged link's inertia about the origin equals the sum of the two.
    #[test]
    fn merged_links_keep_mass_centre_and_inertia() {
        let a = Link { mass: 1.5, com: Vector3::new(0.1, -0.2, 0.05), inertia: Matrix3::new(0.02, 0.001, 0.0, 0.001, 0.03, 0.002, 0.0, 0.002, 0.025) };
        let b = link(0.7, [0.0, 0.03, -0.1], [0.004, 0.005, 0.006]);
        let pose = Htm { rotation: rotation_about(&Vector3::new(1.0, 2.0, -1.0).normalize(), 0.8), translation: Vector3::new(0.3, 0.1, -0.2) };
        let m = a.merged(&b, &pose);
        assert_relative_eq!(m.mass, 2.2);
        let about_origin = |l: &Link, r: &Matrix3<f64>, c: Vector3<f64>| r * l.inertia * r.transpose() + l.mass * (Matrix3::identity() * c.norm_squared() - c * c.transpose());
        let expected = about_origin(&a, &Matrix3::identity(), a.com) + about_origin(&b, &pose.rotation, pose.apply(&b.com));
        assert_relative_eq!(about_origin(&m, &Matrix3::identity(), m.com), expected, epsilon = 1e-14);
        assert_relative_eq!(m.com * m.mass, a.com * a.mass + pose.apply(&b.com) * b.mass, epsilon = 1e-14);
    }
}
