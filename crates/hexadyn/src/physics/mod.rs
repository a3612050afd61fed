//! Physical elements of the robot model (thesis Section 3.4.2-3.4.4, Chapter 5, Section 6.1):
//! the terrain and the ground contact, joint friction, DC motors and their current sensors, the
//! springs of series-elastic transmissions.
//!
//! Each element is a set of small pure functions returning its value with the exact partial
//! derivatives with respect to each argument, from which the assembler of the global residual
//! f(q, q', q'', t) = 0 fills the blocks M = ∂f/∂q'', CT = ∂f/∂q' and KT = ∂f/∂q (Eq. 3.12).

mod contact;
mod current_sensor;
mod friction;
mod motor;
mod series_elastic;
pub mod terrain;

pub use contact::{ContactForce, GroundContact};
pub use terrain::{Extent, FlatGround, Heightfield, MeshTerrain, Proximity, Slope, Step, Terrain, Triangles, Vicinity};
pub use current_sensor::{AnalogLowPass, CurrentSensing, CurrentSensors, ANALOG_CURRENT_CUTOFF_HZ};
pub use friction::{
    BristleResidual, DryViscous, Efficiency, FrictionElement, FrictionError, FrictionTorque, JointFriction, LoadDependence, LuGre, SteadyState,
    LOAD_GRAVITY,
};
pub use motor::{limit_switch, saturate, Current, CurrentResidual, DcMotor};
pub use series_elastic::SeriesSpring;
