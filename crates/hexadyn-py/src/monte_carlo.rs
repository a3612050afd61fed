//! `hexadyn._core.monte_carlo_distributions`: the friction distributions of the Monte Carlo runs
//! of Section 6.5 (Table 6.7, and Table 5.5 for the load coefficients) read from a robot
//! description, keyed by the scenario fields they are written to (`[model.joint_friction]`).

use hexadyn::description::{Gaussian, Robot, RobotDescription, SerialRobot, SHIPPED_ROBOTS};
use hexadyn::hexapod::PantographJoint;
use hexadyn::scenario::{physical_bounds, DEFAULT_ROBOT};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The physical values of a drawn parameter, which are also the rejection rule of the draws
/// (Section 6.5: "omitted if they are non-physical"): the sign the scenario's
/// `[model.joint_friction]` check requires (a dry friction opposes the motion: plus sense >= 0,
/// minus sense <= 0; the load coefficients of Eq. 5.12 increase it in magnitude; a viscous
/// slope is never negative).
fn bounds_of(parameter: &str) -> (f64, f64) {
    physical_bounds(parameter).expect("a [model.joint_friction] parameter")
}

fn field(joint: &str, parameter: &str) -> String {
    format!("model.joint_friction.{joint}.{parameter}")
}

/// Returns the Monte Carlo set-up of a robot description (a shipped robot, `"amru5"` or
/// `"phantomx"`, or the path of a description file of either leg mechanism) as a dict:
///
/// - "robot": the name or the path as given;
/// - "joints": the names of a leg's joints, which key the scenario fields;
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
/// For a serial robot the Gaussians are its `[monte_carlo.friction.<joint>]` tables, keyed
/// `model.joint_friction.<joint>.<field>` in the order of the joints then of the fields
/// (tau_f_d, f_v); it has no load parameters and nothing fixed.
///
/// Raises ValueError for an unreadable or invalid description, or a serial one without a
/// `[monte_carlo]` table.
#[pyfunction]
#[pyo3(signature = (robot = DEFAULT_ROBOT))]
pub fn monte_carlo_distributions<'py>(py: Python<'py>, robot: &str) -> PyResult<Bound<'py, PyDict>> {
    let invalid = |e: hexadyn::description::DescriptionError| PyValueError::new_err(e.to_string());
    let description = if robot == DEFAULT_ROBOT {
        Robot::Pantograph(RobotDescription::amru5())
    } else if let Some((_, text, origin)) = SHIPPED_ROBOTS.iter().find(|(name, _, _)| *name == robot) {
        Robot::from_str(text, origin).map_err(invalid)?
    } else {
        Robot::from_file(robot).map_err(invalid)?
    };
    let d = match &description {
        Robot::Pantograph(p) => pantograph(py, p)?,
        Robot::Serial(s) => serial(py, s)?,
    };
    d.set_item("robot", robot)?;
    d.set_item("joints", description.joints().names().collect::<Vec<_>>())?;
    Ok(d)
}

/// The dict of a pantograph description: Table 6.7 and the load coefficients.
fn pantograph<'py>(py: Python<'py>, description: &RobotDescription) -> PyResult<Bound<'py, PyDict>> {
    let m = &description.monte_carlo;
    let gaussians = PyDict::new(py);
    let bounds = PyDict::new(py);
    let fixed = PyDict::new(py);
    let draw = |name: String, g: Gaussian, parameter: &str| -> PyResult<()> {
        gaussians.set_item(&name, (g.mu, g.sigma))?;
        bounds.set_item(&name, bounds_of(parameter))
    };
    for joint in PantographJoint::ALL {
        let (dry_plus, viscous_plus, dry_minus, viscous_minus) = description.monte_carlo_distribution(joint);
        for (parameter, g) in [("tau_f_d_plus", Some(dry_plus)), ("f_v_plus", viscous_plus), ("tau_f_d_minus", Some(dry_minus)), ("f_v_minus", viscous_minus)] {
            match g {
                Some(g) => draw(field(joint.symbol(), parameter), g, parameter)?,
                None => fixed.set_item(field(joint.symbol(), parameter), 0.0)?,
            }
        }
    }
    let load = m.load_dependence_distribution(&description.friction.q_h.load_dependence);
    let mut load_parameters = Vec::new();
    for (parameter, g) in [("a_2_plus", load.a_2_plus), ("a_1_plus", load.a_1_plus), ("a_2_minus", load.a_2_minus), ("a_1_minus", load.a_1_minus)] {
        if let Some(g) = g {
            let name = field(PantographJoint::Horizontal.symbol(), parameter);
            draw(name.clone(), g, parameter)?;
            load_parameters.push(name);
        }
    }
    set_up(py, m.runs_per_velocity, m.truncation_sigmas, &m.velocities_m_per_s, gaussians, load_parameters, bounds, fixed)
}

/// The dict of a serial description: its `[monte_carlo]` table.
fn serial<'py>(py: Python<'py>, robot: &SerialRobot) -> PyResult<Bound<'py, PyDict>> {
    let m = robot.monte_carlo.as_ref().ok_or_else(|| {
        PyValueError::new_err(format!("{}: no [monte_carlo] table: a Monte Carlo campaign draws the drive friction from its Gaussians (docs/robot-format.md, [monte_carlo])", robot.origin))
    })?;
    let gaussians = PyDict::new(py);
    let bounds = PyDict::new(py);
    for (name, table) in robot.joints.names().zip(&m.friction) {
        for (parameter, g) in table.drawn() {
            gaussians.set_item(field(name, parameter), (g.mu, g.sigma))?;
            bounds.set_item(field(name, parameter), bounds_of(parameter))?;
        }
    }
    set_up(py, m.runs_per_velocity, m.truncation_sigmas, &m.velocities_m_per_s, gaussians, Vec::new(), bounds, PyDict::new(py))
}

#[allow(clippy::too_many_arguments)]
fn set_up<'py>(
    py: Python<'py>,
    runs_per_velocity: u32,
    truncation_sigmas: f64,
    velocities: &[f64],
    gaussians: Bound<'py, PyDict>,
    load_parameters: Vec<String>,
    bounds: Bound<'py, PyDict>,
    fixed: Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("runs_per_velocity", runs_per_velocity)?;
    d.set_item("truncation_sigmas", truncation_sigmas)?;
    d.set_item("velocities_m_per_s", velocities.to_vec())?;
    d.set_item("gaussians", gaussians)?;
    d.set_item("load_parameters", load_parameters)?;
    d.set_item("physical_bounds", bounds)?;
    d.set_item("fixed", fixed)?;
    Ok(d)
}
