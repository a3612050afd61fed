//! The engine's schema for the Python front end, so that Python never restates it: the number
//! of legs of the column names, a robot's joint names and kinds (`robot_properties`), the foot phase codes of the `phase[l]`
//! columns, the robot's mass and motor inductance as the engine reads its description, and the
//! specific resistance of Eq. 6.6.

use hexadyn::control::gait::pattern::FootPhase;
use hexadyn::control::gait::schedule::FAILED_LEG_CODE;
use hexadyn::description::Robot;
use hexadyn::hexapod::LEG_COUNT;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

/// Adds `LEG_COUNT` (6) and `PHASE_CODES` (foot phase name -> code of the `phase[l]` columns:
/// support 0, takeoff 1, swing 2, landing 3, and 4 for a failed leg held up by the free gait)
/// and the functions of this module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("LEG_COUNT", LEG_COUNT)?;
    let phases = PyDict::new(py);
    for phase in FootPhase::ALL {
        // The codes are small integers stored as floats in the time series.
        phases.set_item(phase.name(), phase.code() as u8)?;
    }
    phases.set_item("failed", FAILED_LEG_CODE as u8)?;
    m.add("PHASE_CODES", phases)?;
    m.add_function(wrap_pyfunction!(robot_properties, m)?)?;
    m.add_function(wrap_pyfunction!(specific_resistance, m)?)?;
    Ok(())
}

/// Reads a robot description text (`origin` names it in errors) and returns a dict:
///
/// - "mass_kg": m_0 + 6 m_leg (Table B.2), the mass the engine simulates and reports as the
///   summary's `robot_mass_kg`;
/// - "stated_mass_kg": `inertia.total_mass_kg`, the total mass as printed in Table B.2
///   ("about 34 kg", checked against m_0 + 6 m_leg within 5 %); a serial robot's total mass;
/// - "inductance_h": the motor inductance L (H) of Eq. 3.91 of each joint of a leg;
/// - "leg_mechanism": "pantograph" or "serial";
/// - "joints": the names and kinds of a leg's three joints in the order of q, a tuple of
///   `(name, kind)` pairs, kind `"revolute"` or `"prismatic"` (AMRU5: `("q_r", "revolute")`,
///   `("q_v", "prismatic")`, `("q_h", "prismatic")`): the names of the results columns.
///
/// Raises ValueError (one line naming `origin` and the field) for an invalid description.
#[pyfunction]
#[pyo3(signature = (text, origin = "robot description"))]
pub fn robot_properties<'py>(py: Python<'py>, text: &str, origin: &str) -> PyResult<Bound<'py, PyDict>> {
    let robot = Robot::from_str(text, origin).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let d = PyDict::new(py);
    d.set_item("mass_kg", robot.total_mass_kg())?;
    d.set_item("leg_mechanism", robot.leg_mechanism())?;
    match &robot {
        Robot::Pantograph(p) => {
            d.set_item("stated_mass_kg", p.inertia.total_mass_kg)?;
            d.set_item("inductance_h", PyTuple::new(py, [p.motor.inductance_h(); 3])?)?;
        }
        Robot::Serial(s) => {
            d.set_item("stated_mass_kg", s.total_mass_kg())?;
            d.set_item("inductance_h", PyTuple::new(py, s.drives.iter().map(|drive| drive.motor.inductance_mh * 1e-3))?)?;
        }
    }
    let joints = robot.joints();
    d.set_item("joints", PyTuple::new(py, (0..3).map(|j| (joints.name(j), joints.kind(j).name())))?)?;
    Ok(d)
}

/// Specific resistance ξ = E / (m g l) (Eq. 6.6), g the engine's standard gravity: the formula
/// of the summary's `specific_resistance`. NaN when the distance is not positive.
#[pyfunction]
pub fn specific_resistance(energy_j: f64, mass_kg: f64, distance_m: f64) -> f64 {
    hexadyn::scenario::specific_resistance(energy_j, mass_kg, distance_m)
}

/// The pantograph description of a robot description text, for the tools written for AMRU5's
/// legs (`what`, e.g. "friction identification"): ValueError (one line) for an invalid description or a
/// serial one.
pub fn pantograph_description(text: &str, origin: &str, what: &str) -> PyResult<hexadyn::description::RobotDescription> {
    match Robot::from_str(text, origin).map_err(|e| PyValueError::new_err(e.to_string()))? {
        Robot::Pantograph(d) => Ok(d),
        Robot::Serial(s) => Err(PyValueError::new_err(format!("{origin}: robot {:?} has serial legs; allowed: a pantograph robot (AMRU5's legs): {what} is not available on serial legs yet", s.name))),
    }
}
