//! The hexapod's vocabulary and geometry, below both the controller and the simulated robot:
//! the legs and their three actuated joints (Eq. 3.51), the pantograph linkage of a leg
//! (Section 3.4.1, Eq. 3.57-3.63), the multibody assembly of the whole hexapod (Eq. 3.51-3.71),
//! the leg kinematics (Section 7.3) and the leg workspace (Section 7.1.1).
//!
//! Nothing here reads a file: the parameter sets ([`MechanicsParameters`], [`JointLimits`]) are
//! plain SI numbers; `crate::description` builds them from a robot description.
//!
//! ```
//! use hexadyn::hexapod::{joint_index, Joint, DOF, JOINTS, LEG_COUNT};
//! assert_eq!(JOINTS, LEG_COUNT * Joint::ALL.len());
//! assert_eq!(joint_index(5, 2), DOF - 1);
//! ```

pub mod leg_dynamics;
pub mod leg_kinematics;
pub mod mechanics;
pub mod pantograph;
pub mod workspace;

pub use leg_dynamics::{joint_torques, leg_joint_torques, StillBody};
pub use leg_kinematics::{Clamping, IkOptions, IkOutcome, IkSolution, JointLimits, LegKinematics, LegKinematicsError, Limit};
pub use mechanics::{Inertia, LegBodies, Mechanics, MechanicsParameters};
pub use pantograph::PantographGeometry;
pub use workspace::Workspace;

/// Number of legs of a hexapod; every per-leg array has this length.
pub const LEG_COUNT: usize = 6;

/// Number of actuated joints of a hexapod with 3-DOF legs.
pub const JOINTS: usize = 3 * LEG_COUNT;

/// Number of configuration parameters: (X, Y, Z, Φ, Θ, Ψ) then (q_r, q_v, q_h) per leg (Eq. 3.51).
pub const DOF: usize = 6 + JOINTS;

/// Index of coordinate `joint` (0 = q_r, 1 = q_v, 2 = q_h) of `leg` in q (Eq. 3.51).
pub const fn joint_index(leg: usize, joint: usize) -> usize {
    6 + 3 * leg + joint
}

/// The three actuated joints of a leg (Eq. 3.51): q_r the rotation of the leg chassis about
/// the vertical axis, q_v the vertical and q_h the horizontal ball-screw nut positions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Joint {
    /// q_r, rad (joint torques in Nm).
    Rotation,
    /// q_v, m (joint "torques" are forces in N).
    Vertical,
    /// q_h, m (joint "torques" are forces in N).
    Horizontal,
}

impl Joint {
    /// The three joints in the thesis order (q_r, q_v, q_h).
    pub const ALL: [Joint; 3] = [Joint::Rotation, Joint::Vertical, Joint::Horizontal];

    /// Thesis symbol: `q_r`, `q_v` or `q_h` (also the TOML table names).
    pub fn symbol(self) -> &'static str {
        match self {
            Joint::Rotation => "q_r",
            Joint::Vertical => "q_v",
            Joint::Horizontal => "q_h",
        }
    }

    /// True for q_r (radians and Nm), false for the translational joints (metres and N).
    pub fn is_rotational(self) -> bool {
        matches!(self, Joint::Rotation)
    }
}

impl std::fmt::Display for Joint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.symbol())
    }
}
