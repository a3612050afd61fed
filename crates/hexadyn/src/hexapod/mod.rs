//! The hexapod's vocabulary and geometry, below both the controller and the simulated robot:
//! the legs and the names and kinds of their three actuated joints (Eq. 3.51, [`LegJoints`]),
//! serial legs given the URDF way ([`SerialHexapod`]), the pantograph linkage of a leg
//! (Section 3.4.1, Eq. 3.57-3.63), the multibody assembly of the whole hexapod (Eq. 3.51-3.71),
//! the leg kinematics (Section 7.3) and the leg workspace (Section 7.1.1).
//!
//! Nothing here reads a file: the parameter sets ([`MechanicsParameters`], [`JointLimits`]) are
//! plain SI numbers; `crate::description` builds them from a robot description.
//!
//! ```
//! use hexadyn::hexapod::{joint_index, DOF, JOINTS, LEG_COUNT};
//! assert_eq!(JOINTS, LEG_COUNT * 3);
//! assert_eq!(joint_index(5, 2), DOF - 1);
//! ```

pub mod joints;
pub mod leg_dynamics;
pub mod leg_kinematics;
pub mod mechanics;
pub mod pantograph;
pub mod serial;
pub mod workspace;

pub use joints::{JointKind, JointNameError, LegJoints};
pub use leg_dynamics::{LegDynamics, StillBody};
pub use leg_kinematics::{Clamping, IkOptions, IkOutcome, IkSolution, JointLimits, Leg, LegChain, LegKinematics, LegKinematicsError, Limit, SerialLegKinematics, default_serial_height};
pub use mechanics::{Inertia, LegBodies, Mechanics, MechanicsParameters};
pub use pantograph::{PantographGeometry, PantographJoint};
pub use serial::{Link, Rotor, SerialHexapod, SerialJoint, SerialLeg, SerialMechanics};
pub use workspace::Workspace;

/// Number of legs of a hexapod; every per-leg array has this length.
pub const LEG_COUNT: usize = 6;

/// Number of actuated joints of a hexapod with 3-DOF legs.
pub const JOINTS: usize = 3 * LEG_COUNT;

/// Number of configuration parameters: (X, Y, Z, Φ, Θ, Ψ) then the three joints of each leg
/// (Eq. 3.51; (q_r, q_v, q_h) on AMRU5).
pub const DOF: usize = 6 + JOINTS;

/// Index of joint `joint` (0..3, in the order of the robot's [`LegJoints`]) of `leg` in q
/// (Eq. 3.51).
pub const fn joint_index(leg: usize, joint: usize) -> usize {
    6 + 3 * leg + joint
}

