//! `hexadyn._core.monte_carlo_distributions`: the friction distributions of the Monte Carlo runs
//! of Section 6.5 (Table 6.7, and Table 5.5 for the load coefficients) read from a robot
//! description, keyed by the scenario fields they are written to (`[model.joint_friction]`).

use hexadyn::scenario::DEFAULT_ROBOT;
use hexadyn::description::{Gaussian, RobotDescription};
use hexadyn::hexapod::PantographJoint;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The physical sign of a friction parameter, which is also the rejection rule of the draws
/// (Section 6.5: "omitted if they are non-physical"): a dry friction opposes the motion (plus
/// sense >= 0, minus sense <= 0), the load coefficients of Eq. 5.12 increase it in magnitude
/// (a_*^+ >= 0, a_*^- <= 0), a viscous slope is never negative. Returned as the interval of
/// physical values.
fn physical_bounds(parameter: &str) -> (f64, f64) {
    if parameter.starts_with("f_v_") || parameter.ends_with("_plus") {
        (0.0, f64::INFINITY)
    } else {
        (f64::NEG_INFINITY, 0.0)
    }
}

fn field(joint: PantographJoint, parameter: &str) -> String {
    format!("model.joint_friction.{}.{parameter}", joint.symbol())
}

/// Returns the Monte Carlo set-up of a robot description (`"amru5"`, the embedded AMRU5, or the
/// path of a description file) as a dict:
///
/// - "robot": `"amru5"` or the path as given;
/// - "runs_per_velocity", "truncation_sigmas", "velocities_m_per_s": `[monte_carlo]`;
/// - "gaussians": scenario field -> (mu, sigma) of the drawn parameters, in a fixed order:
///   Table 6.7 for q_r and q_v (tau_f_d^+, f_v^+, tau_f_d^-, f_v^-) and q_h (tau_f_d^+-), then
///   the Eq. 5.12 coefficients of q_h (a_2^+, a_1^+, a_2^-, a_1^-; mean and n-1 standard
///   deviation over the legs of Table 5.5 without the excluded legs). A coefficient without
///   data (the a_1^- row missing from Table 5.5) is left out: the description's
///   `friction.missing_a1_minus` rule then applies;
/// - "load_parameters": the fields of "gaussians" that only act with the load influence;
/// - "physical_bounds": scenario field -> (low, high), the physical values (the rejection rule);
/// - "fixed": scenario field -> value of the parameters not drawn: the horizontal viscous
///   slopes, neglected in Section 6.5 (0).
///
/// Raises ValueError for an unreadable or invalid description.
#[pyfunction]
#[pyo3(signature = (robot = DEFAULT_ROBOT))]
pub fn monte_carlo_distributions<'py>(py: Python<'py>, robot: &str) -> PyResult<Bound<'py, PyDict>> {
    let description = if robot == DEFAULT_ROBOT {
        RobotDescription::amru5()
    } else {
        RobotDescription::from_file(robot).map_err(|e| PyValueError::new_err(e.to_string()))?
    };
    let m = &description.monte_carlo;

    let gaussians = PyDict::new(py);
    let bounds = PyDict::new(py);
    let fixed = PyDict::new(py);
    let draw = |name: String, g: Gaussian, parameter: &str| -> PyResult<()> {
        gaussians.set_item(&name, (g.mu, g.sigma))?;
        bounds.set_item(&name, physical_bounds(parameter))
    };
    for joint in PantographJoint::ALL {
        let (dry_plus, viscous_plus, dry_minus, viscous_minus) = description.monte_carlo_distribution(joint);
        for (parameter, g) in [("tau_f_d_plus", Some(dry_plus)), ("f_v_plus", viscous_plus), ("tau_f_d_minus", Some(dry_minus)), ("f_v_minus", viscous_minus)] {
            match g {
                Some(g) => draw(field(joint, parameter), g, parameter)?,
                None => fixed.set_item(field(joint, parameter), 0.0)?,
            }
        }
    }
    let load = m.load_dependence_distribution(&description.friction.q_h.load_dependence);
    let mut load_parameters = Vec::new();
    for (parameter, g) in [("a_2_plus", load.a_2_plus), ("a_1_plus", load.a_1_plus), ("a_2_minus", load.a_2_minus), ("a_1_minus", load.a_1_minus)] {
        if let Some(g) = g {
            let name = field(PantographJoint::Horizontal, parameter);
            draw(name.clone(), g, parameter)?;
            load_parameters.push(name);
        }
    }

    let d = PyDict::new(py);
    d.set_item("robot", robot)?;
    d.set_item("runs_per_velocity", m.runs_per_velocity)?;
    d.set_item("truncation_sigmas", m.truncation_sigmas)?;
    d.set_item("velocities_m_per_s", m.velocities_m_per_s.clone())?;
    d.set_item("gaussians", gaussians)?;
    d.set_item("load_parameters", load_parameters)?;
    d.set_item("physical_bounds", bounds)?;
    d.set_item("fixed", fixed)?;
    Ok(d)
}
