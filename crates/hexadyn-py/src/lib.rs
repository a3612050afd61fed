//! Thin PyO3 bindings of the hexadyn engine: numpy arrays in and out.

use pyo3::prelude::*;

mod leg;
mod link;
mod mbs;
mod monte_carlo;
mod pantograph;
mod scenario;
mod schema;
mod urdf;
mod view;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("STANDARD_GRAVITY", hexadyn::mbs::STANDARD_GRAVITY)?;
    // The names `scenario.robot` takes for the embedded robot descriptions.
    m.add("SHIPPED_ROBOTS", hexadyn::description::SHIPPED_ROBOTS.map(|(name, _, _)| name).to_vec())?;
    m.add_class::<mbs::PyMultibody>()?;
    m.add_class::<urdf::PyUrdfHexapod>()?;
    m.add_class::<pantograph::PyPantographHexapod>()?;
    m.add_function(wrap_pyfunction!(pantograph::robot_mjcf, m)?)?;
    m.add_function(wrap_pyfunction!(urdf::shipped_robot_text, m)?)?;
    m.add_function(wrap_pyfunction!(urdf::robot_urdf, m)?)?;
    m.add_function(wrap_pyfunction!(scenario::run_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(scenario::load_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(scenario::scenario_model, m)?)?;
    m.add_function(wrap_pyfunction!(scenario::terrain_triangles, m)?)?;
    m.add_function(wrap_pyfunction!(monte_carlo::monte_carlo_distributions, m)?)?;
    schema::register(m)?;
    m.add_class::<view::PyKinematics>()?;
    m.add_class::<leg::PyLegModel>()?;
    m.add_function(wrap_pyfunction!(link::encode_command, m)?)?;
    m.add_function(wrap_pyfunction!(link::decode_command, m)?)?;
    m.add_function(wrap_pyfunction!(link::encode_reply, m)?)?;
    m.add_function(wrap_pyfunction!(link::decode_reply, m)?)?;
    m.add_function(wrap_pyfunction!(link::robot_run, m)?)?;
    m.add_function(wrap_pyfunction!(link::robot_emulate, m)?)?;
    Ok(())
}
