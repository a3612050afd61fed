//! The `sim` module (thesis Section 3.3.2): systems in residual form f(q, q', q'', t) = 0
//! (Eq. 3.1), their implicit Newmark integration with Newton-Raphson (Eq. 3.7-3.15), static
//! equilibrium and linearization (Eq. 3.16-3.17).

mod bordered;
mod broyden;
mod error;
mod factorization;
mod jacobian;
mod linearize;
mod newmark;
mod newton_test;
mod statics;
mod system;

pub use error::{ResidualRow, SimError};
pub use jacobian::{finite_difference_jacobian, finite_difference_jacobian_with_steps, Jacobian};
pub(crate) use jacobian::zero_matrix;
pub use linearize::{linearize, Linearization, Pole};
pub use newmark::{Newmark, NewmarkOptions, NewmarkStats, State};
pub use statics::{static_equilibrium, StaticOptions};
pub use system::{Layout, Order, System};
