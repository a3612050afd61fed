//! URDF import: a [`SerialHexapod`] from a URDF robot description, parsed by the maintained
//! `urdf-rs` crate (openrr; serde on quick-xml, the parser of the Rust robotics stack), so that
//! hexadyn reads the files ROS, Pinocchio and MuJoCo users already have.
//!
//! What is read:
//! - the tree of links and joints from the one root link (the base); fixed joints are merged
//!   into their parent (masses, centres of mass and inertias combined, [`Link::merged`]), so a
//!   mounting frame or a foot link costs nothing;
//! - the legs: the six chains of actuated joints that leave the base, each exactly three
//!   revolute or prismatic joints in a row, numbered the thesis way (0, 2, 4 on the left, y > 0,
//!   from front to rear; 1, 3, 5 on the right);
//! - each foot: the one sphere `<collision>` of the last link (or of a link fixed to it), its
//!   centre and radius.
//!
//! What is refused, with one line naming the file, the element and what is allowed: malformed
//! XML, a link that is the child of two joints (a closed loop) or not reachable from the root,
//! continuous, floating, planar and spherical joints, mimic joints, a leg that is not a chain of
//! three actuated joints, a body (link with its fixed children) whose mass is not positive or
//! whose inertia is not a physical tensor, a joint without a finite range, a foot without a
//! sphere, legs whose joint kinds differ.

use std::collections::HashMap;

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use crate::hexapod::{JointKind, Link, SerialHexapod, SerialJoint, SerialLeg, LEG_COUNT};
use crate::spatial::{yaw_pitch_roll, Htm};

/// Why a URDF file cannot be imported: `{file}: {element}: {problem}; allowed: {allowed}`.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}: {element}: {problem}; allowed: {allowed}")]
pub struct UrdfError {
    pub file: String,
    /// The URDF element, e.g. `joint "l1_coxa_joint"`, `link "base_link"`, `robot`.
    pub element: String,
    pub problem: String,
    pub allowed: String,
}

impl UrdfError {
    /// The error with every control character of the file's text (a name with a line break)
    /// escaped, so that it stays one line.
    fn new(file: &str, element: impl Into<String>, problem: impl Into<String>, allowed: impl Into<String>) -> Self {
        let line = |s: String| if s.chars().any(char::is_control) { s.chars().flat_map(|c| if c.is_control() { c.escape_default().collect::<Vec<_>>() } else { vec![c] }).collect() } else { s };
        UrdfError { file: line(file.to_string()), element: line(element.into()), problem: line(problem.into()), allowed: allowed.into() }
    }
}

/// The pose of a URDF `<origin xyz rpy>`: R = R_z(yaw) R_y(pitch) R_x(roll) (Eq. 3.52's order).
fn pose(p: &urdf_rs::Pose) -> Htm {
    let [roll, pitch, yaw] = p.rpy.0;
    Htm { rotation: yaw_pitch_roll(yaw, pitch, roll), translation: Vector3::from(p.xyz.0) }
}

/// A link's own inertial: the centre of mass at the inertial origin, the tensor turned from the
/// inertial frame into the link frame.
fn own_inertia(l: &urdf_rs::Link) -> Link {
    let i = &l.inertial.inertia;
    let tensor = Matrix3::new(i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz);
    let frame = pose(&l.inertial.origin);
    Link { mass: l.inertial.mass.value, com: frame.translation, inertia: frame.rotation * tensor * frame.rotation.transpose() }
}

/// A link with the links fixed to it (a rigid body of the model).
struct Cluster<'a> {
    link: &'a str,
    inertia: Link,
    /// Actuated joints leaving the cluster, with their origin in the cluster link's frame.
    exits: Vec<(&'a urdf_rs::Joint, Htm)>,
    /// Sphere collisions of the cluster: centre in the cluster link's frame, radius.
    spheres: Vec<(Vector3<f64>, f64)>,
}

struct Reader<'a> {
    file: &'a str,
    links: HashMap<&'a str, &'a urdf_rs::Link>,
    children: HashMap<&'a str, Vec<&'a urdf_rs::Joint>>,
}

impl<'a> Reader<'a> {
    fn err(&self, element: impl Into<String>, problem: impl Into<String>, allowed: impl Into<String>) -> UrdfError {
        UrdfError::new(self.file, element, problem, allowed)
    }

    /// The link `name` and everything fixed to it.
    fn cluster(&self, name: &'a str) -> Result<Cluster<'a>, UrdfError> {
        let mut c = Cluster { link: name, inertia: own_inertia(self.links[name]), exits: Vec::new(), spheres: Vec::new() };
        let mut stack = vec![(name, Htm::identity())];
        let mut first = true;
        while let Some((link, at)) = stack.pop() {
            let l = self.links[link];
            if !std::mem::take(&mut first) {
                c.inertia = c.inertia.merged(&own_inertia(l), &at);
            }
            for collision in &l.collision {
                if let urdf_rs::Geometry::Sphere { radius } = collision.geometry {
                    c.spheres.push((at.apply(&pose(&collision.origin).translation), radius));
                }
            }
            for j in self.children.get(link).into_iter().flatten() {
                let origin = at.compose(&pose(&j.origin));
                match j.joint_type {
                    urdf_rs::JointType::Fixed => stack.push((j.child.link.as_str(), origin)),
                    _ => c.exits.push((j, origin)),
                }
            }
        }
        self.check_body(&c)?;
        Ok(c)
    }

    /// A body's mass is positive and its inertia a physical tensor: symmetric positive definite
    /// principal moments that satisfy the triangle inequality (Section 3.3.3's Φ_G).
    fn check_body(&self, c: &Cluster) -> Result<(), UrdfError> {
        let (m, i) = (c.inertia.mass, &c.inertia.inertia);
        let element = format!("link \"{}\" (with the links fixed to it)", c.link);
        if !(m.is_finite() && m > 0.0) {
            return Err(self.err(element, format!("mass {m} kg (a missing <inertial> is a zero mass)"), "a positive mass in <inertial>"));
        }
        // Bounded iterations: a tensor of overflowing entries gives no decomposition, not a hang.
        let moments = SymmetricEigen::try_new(*i, f64::EPSILON, 1000).map_or(Vector3::repeat(f64::NAN), |e| e.eigenvalues);
        let tol = 1e-9 * moments.abs().max();
        let triangle = (0..3).all(|k| moments[k] <= moments[(k + 1) % 3] + moments[(k + 2) % 3] + tol);
        if !(moments.iter().all(|m| m.is_finite()) && moments.min() > 0.0 && triangle) {
            return Err(self.err(element, format!("inertia with principal moments ({:.4e}, {:.4e}, {:.4e}) kg m²", moments[0], moments[1], moments[2]), "a positive definite tensor whose principal moments satisfy the triangle inequality"));
        }
        Ok(())
    }

    /// An actuated joint of a leg, checked.
    fn joint(&self, j: &urdf_rs::Joint, origin: Htm) -> Result<SerialJoint, UrdfError> {
        let element = format!("joint \"{}\"", j.name);
        let axis = Vector3::from(j.axis.xyz.0);
        if !(axis.iter().all(|x| x.is_finite()) && axis.amax() > 1e-12) {
            return Err(self.err(element, format!("axis ({} {} {})", axis.x, axis.y, axis.z), "a non-zero finite axis"));
        }
        let (lower, upper) = (j.limit.lower, j.limit.upper);
        if !(lower.is_finite() && upper.is_finite() && lower < upper) {
            return Err(self.err(element, format!("limits [{lower}, {upper}]"), "a <limit> with finite lower < upper (the workspace is computed from the ranges)"));
        }
        let kind = if j.joint_type == urdf_rs::JointType::Prismatic { JointKind::Prismatic } else { JointKind::Revolute };
        // Scaled before normalizing, so that an axis of huge components does not overflow.
        let axis = (axis / axis.amax()).normalize();
        Ok(SerialJoint { name: j.name.clone(), origin, axis, kind, lower, upper })
    }

    /// The leg that starts with the actuated joint `first` leaving the base.
    fn leg(&self, first: &'a urdf_rs::Joint, origin: Htm) -> Result<SerialLeg, UrdfError> {
        let chain = "a chain of three revolute or prismatic joints from the base to the foot";
        let mut joints = Vec::with_capacity(3);
        let mut links = Vec::with_capacity(3);
        let mut next = Some((first, origin));
        let mut last = None;
        while let Some((j, origin)) = next {
            if joints.len() == 3 {
                return Err(self.err(format!("joint \"{}\"", j.name), format!("a fourth actuated joint in the leg of joint \"{}\"", first.name), chain));
            }
            joints.push(self.joint(j, origin)?);
            let c = self.cluster(&j.child.link)?;
            if c.exits.len() > 1 {
                return Err(self.err(format!("link \"{}\"", c.link), format!("{} actuated joints leave it (the leg of joint \"{}\" branches)", c.exits.len(), first.name), chain));
            }
            next = c.exits.first().map(|(j, o)| (*j, *o));
            links.push(c.inertia.clone());
            last = Some(c);
        }
        let last = last.expect("the first joint is part of the leg");
        if joints.len() < 3 {
            return Err(self.err(format!("link \"{}\"", last.link), format!("the leg of joint \"{}\" ends after {} actuated joint(s)", first.name, joints.len()), chain));
        }
        let &[(foot, foot_radius)] = last.spheres.as_slice() else {
            return Err(self.err(format!("link \"{}\"", last.link), format!("{} sphere <collision> on the last link of the leg of joint \"{}\" and the links fixed to it", last.spheres.len(), first.name), "exactly one sphere collision: the foot"));
        };
        Ok(SerialLeg {
            joints: joints.try_into().expect("three joints"),
            links: links.try_into().expect("three links"),
            foot,
            foot_radius,
        })
    }
}

/// Reads a serial hexapod from the URDF file `path` (a regular UTF-8 file within the input size
/// limit of [`crate::fields::read_input`]).
pub fn serial_hexapod_from_file(path: impl AsRef<std::path::Path>) -> Result<SerialHexapod, UrdfError> {
    let file = path.as_ref().display().to_string();
    let text = crate::fields::read_input(path.as_ref()).map_err(|reason| UrdfError::new(&file, "file", reason, "a readable URDF text file"))?;
    serial_hexapod_from_urdf(&text, &file)
}

/// Reads a serial hexapod from URDF `text`; `file` names it in errors.
pub fn serial_hexapod_from_urdf(text: &str, file: &str) -> Result<SerialHexapod, UrdfError> {
    let robot = urdf_rs::read_from_string(text).map_err(|e| {
        let reason = e.to_string().split_whitespace().collect::<Vec<_>>().join(" ");
        UrdfError::new(file, "robot", format!("not a URDF robot ({reason})"), "a <robot> of <link> and <joint> elements (URDF)")
    })?;
    let mut r = Reader { file, links: HashMap::new(), children: HashMap::new() };
    for l in &robot.links {
        if r.links.insert(l.name.as_str(), l).is_some() {
            return Err(r.err(format!("link \"{}\"", l.name), "defined twice", "one <link> per name"));
        }
    }
    check_numbers(&r, &robot)?;
    let mut parent_of: HashMap<&str, &str> = HashMap::new();
    for j in &robot.joints {
        let element = format!("joint \"{}\"", j.name);
        for end in [&j.parent.link, &j.child.link] {
            if !r.links.contains_key(end.as_str()) {
                return Err(r.err(element, format!("link \"{end}\" does not exist"), "parent and child among the robot's links"));
            }
        }
        if let Some(other) = parent_of.insert(&j.child.link, &j.name) {
            return Err(r.err(element, format!("link \"{}\" is already the child of joint \"{other}\" (a closed loop)", j.child.link), "a tree: every link the child of at most one joint"));
        }
        use urdf_rs::JointType as T;
        let kind = match j.joint_type {
            T::Revolute | T::Prismatic | T::Fixed => None,
            T::Continuous => Some("continuous"),
            T::Floating => Some("floating"),
            T::Planar => Some("planar"),
            T::Spherical => Some("spherical"),
        };
        if let Some(kind) = kind {
            return Err(r.err(element, format!("type {kind}"), "revolute and prismatic joints with limits, fixed joints"));
        }
        if let Some(m) = &j.mimic {
            return Err(r.err(element, format!("mimics joint \"{}\"", m.joint), "independent joints: each leg joint has its own actuator"));
        }
        r.children.entry(j.parent.link.as_str()).or_default().push(j);
    }
    let roots: Vec<&str> = robot.links.iter().map(|l| l.name.as_str()).filter(|n| !parent_of.contains_key(n)).collect();
    let &[root] = roots.as_slice() else {
        return Err(r.err("robot", format!("{} root links ({})", roots.len(), roots.join(", ")), "one root link, the base, from which every link is reached (no closed loop)"));
    };
    let mut reached = vec![root];
    let mut k = 0;
    while let Some(link) = reached.get(k) {
        reached.extend(r.children.get(link).into_iter().flatten().map(|j| j.child.link.as_str()));
        k += 1;
    }
    if let Some(lost) = robot.links.iter().find(|l| !reached.contains(&l.name.as_str())) {
        return Err(r.err(format!("link \"{}\"", lost.name), format!("not reached from the root link \"{root}\" (its joints form a closed loop)"), "a tree: every link reached from the base"));
    }
    let base = r.cluster(root)?;
    if base.exits.len() != LEG_COUNT {
        return Err(r.err(format!("link \"{root}\" (the base, with the links fixed to it)"), format!("{} actuated joints leave it", base.exits.len()), "six: the first joint of each leg"));
    }
    let legs = base.exits.iter().map(|(j, origin)| r.leg(j, *origin)).collect::<Result<Vec<_>, _>>()?;
    let mut legs: [SerialLeg; LEG_COUNT] = legs.try_into().map_err(|_| r.err("robot", "not six legs", "six legs"))?;
    number_serial_legs(&mut legs).map_err(|problem| r.err("robot", problem, "three legs on each side of the base's x axis"))?;
    for (l, leg) in legs.iter().enumerate() {
        for k in 0..3 {
            let (kind, first) = (leg.joints[k].kind, legs[0].joints[k].kind);
            if kind != first {
                return Err(r.err(format!("joint \"{}\"", leg.joints[k].name), format!("{} where leg 0's joint {k} is {} (leg {l})", kind.name(), first.name()), "the same kind of joint at the same place of every leg"));
            }
        }
    }
    Ok(SerialHexapod { name: robot.name.clone(), base: base.inertia, legs })
}

/// Every number the model uses is finite (and a sphere's radius positive), so that nothing
/// downstream meets a NaN.
fn check_numbers(r: &Reader, robot: &urdf_rs::Robot) -> Result<(), UrdfError> {
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    let pose_ok = |p: &urdf_rs::Pose| finite(&p.xyz.0) && finite(&p.rpy.0);
    for l in &robot.links {
        let element = format!("link \"{}\"", l.name);
        let i = &l.inertial;
        let inertia = [i.mass.value, i.inertia.ixx, i.inertia.ixy, i.inertia.ixz, i.inertia.iyy, i.inertia.iyz, i.inertia.izz];
        if !(pose_ok(&i.origin) && finite(&inertia)) {
            return Err(r.err(element, "a non-finite number in <inertial>", "finite origin, mass and inertia"));
        }
        for c in &l.collision {
            let radius_ok = match c.geometry {
                urdf_rs::Geometry::Sphere { radius } => radius.is_finite() && radius > 0.0,
                _ => true,
            };
            if !(pose_ok(&c.origin) && radius_ok) {
                return Err(r.err(element, "a <collision> with a non-finite origin or a sphere radius that is not positive", "finite origins, spheres of positive radius"));
            }
        }
    }
    for j in &robot.joints {
        if !pose_ok(&j.origin) {
            return Err(r.err(format!("joint \"{}\"", j.name), "a non-finite number in <origin>", "finite xyz and rpy"));
        }
    }
    Ok(())
}

/// Sorts the legs into the thesis numbering: the left ones (y > 0 at the first joint) 0, 2, 4
/// and the right ones 1, 3, 5, each side from front to rear (x decreasing). The problem, when
/// the mounts are not three on each side.
pub(crate) fn number_serial_legs(legs: &mut [SerialLeg; LEG_COUNT]) -> Result<(), String> {
    let mount = |l: &SerialLeg| l.joints[0].origin.translation;
    let (mut left, mut right): (Vec<SerialLeg>, Vec<SerialLeg>) = legs.iter().cloned().partition(|l| mount(l).y > 0.0);
    if left.len() != 3 {
        return Err(format!("{} legs mounted on the left (y > 0 at their first joint), {} on the right", left.len(), right.len()));
    }
    for side in [&mut left, &mut right] {
        side.sort_by(|a, b| mount(b).x.total_cmp(&mount(a).x));
    }
    for (n, (l, r)) in left.into_iter().zip(right).enumerate() {
        legs[2 * n] = l;
        legs[2 * n + 1] = r;
    }
    Ok(())
}
