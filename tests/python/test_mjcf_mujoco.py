"""The MJCF export of a serial hexapod against MuJoCo (``mujoco`` from PyPI): MuJoCo loads the
exported file and, on random states of random robots, its feet (sites), mass matrix and gravity
forces are hexadyn's to 1e-9 relative, once MuJoCo's free-joint velocities (linear in the world
frame, angular in the body frame) are written with hexadyn's (X', Y', Z', yaw', pitch', roll')
of Eq. 3.52."""

from __future__ import annotations

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from hexadyn._core import UrdfHexapod
from urdf_hexapods import random_hexapod


def rates_to_body(pitch: float, roll: float) -> np.ndarray:
    """E with ω_body = E (yaw', pitch', roll') for R = R_z(yaw) R_y(pitch) R_x(roll)."""
    sp, cp, sr, cr = np.sin(pitch), np.cos(pitch), np.sin(roll), np.cos(roll)
    return np.array([[-sp, 0.0, 1.0], [cp * sr, cr, 0.0], [cp * cr, -sr, 0.0]])


def record_errors(model, data, ours, q: np.ndarray, g: np.ndarray, worst: dict) -> None:
    """Raises `worst` to the relative errors of hexadyn's feet, mass matrix and gravity forces
    at q against MuJoCo's at `data` (after mj_forward, qvel = 0), reduced to hexadyn's
    coordinates through MuJoCo's qvel = G q': M = Gᵀ M_MuJoCo G, g = −Gᵀ bias."""
    m = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, m)
    feet = np.array([data.site(f"foot{leg}").xpos for leg in range(6)])
    for key, theirs, mine in (
        ("feet", feet, ours.feet(q)),
        ("M", g.T @ m @ g, ours.mass_matrix(q)),
        ("g", -g.T @ data.qfrc_bias, ours.gravity_forces(q)),
    ):
        worst[key] = max(worst[key], np.abs(mine - theirs).max() / np.abs(theirs).max())


def test_the_exported_robot_is_the_same_in_mujoco():
    rng = np.random.default_rng(21)
    worst = {"feet": 0.0, "M": 0.0, "g": 0.0, "mass": 0.0}
    for seed in range(5):
        ours = UrdfHexapod(random_hexapod(200 + seed, prismatic_tibia=seed == 4), "r.urdf")
        model = mujoco.MjModel.from_xml_string(ours.to_mjcf())
        data = mujoco.MjData(model)
        assert (model.nq, model.nv) == (25, 24)
        assert [model.joint(k + 1).name for k in range(18)] == ours.joint_names
        total = ours.mass_matrix(np.zeros(24))[0, 0]
        worst["mass"] = max(worst["mass"], abs(model.body_mass.sum() - total) / total)
        for _ in range(40):
            q = np.concatenate([rng.uniform(-0.3, 0.3, 3), rng.uniform(-np.pi, np.pi, 3), rng.uniform(-0.6, 0.6, 18) * (0.05 if seed == 4 else 1.0)])
            yaw, pitch, roll = q[3:6]
            w, x, y, z = np.roll(Rotation.from_euler("ZYX", [yaw, pitch, roll]).as_quat(), 1)
            data.qpos[:] = np.concatenate([q[:3], [w, x, y, z], q[6:]])
            data.qvel[:] = 0.0
            mujoco.mj_forward(model, data)
            # v_mujoco = T q' with T = blockdiag(I, E, I).
            t = np.eye(24)
            t[3:6, 3:6] = rates_to_body(pitch, roll)
            record_errors(model, data, ours, q, t, worst)
    assert max(worst.values()) < 1e-9, worst


def test_the_exported_pantograph_robot_is_the_same_in_mujoco():
    """AMRU5's 49 bodies in MuJoCo, the pantograph loops closed by equality constraints and the
    rotors coupled to their joints: at random states, with hexadyn's dependent parameters
    (Eq. 3.62-3.63) giving MuJoCo's 66 coordinates, the loops close, the feet are hexadyn's and
    the mass matrix and gravity forces reduced to the 24 coordinates (Gᵀ M G, Gᵀ g with
    MuJoCo's qvel = G q') are hexadyn's to 1e-9 relative."""
    from hexadyn._core import PantographHexapod, shipped_robot_text

    ours = PantographHexapod(shipped_robot_text("amru5"), "amru5")
    model = mujoco.MjModel.from_xml_string(ours.to_mjcf())
    data = mujoco.MjData(model)
    assert (model.nbody - 1, model.nv, model.neq) == (49, 66, 30)
    names = {model.joint(k).name for k in range(model.njnt)}
    assert {f"{j}[{leg}]" for leg in range(6) for j in ("q_r", "q_v", "q_h")} <= names
    standing = np.concatenate([np.zeros(6), np.tile([0.0, 0.06, 0.035], 6)])
    total = ours.mass_matrix(standing)[0, 0]
    assert abs(model.body_mass.sum() - total) < 1e-12 * total
    rng = np.random.default_rng(5)
    worst = {"loops": 0.0, "feet": 0.0, "M": 0.0, "g": 0.0}
    for _ in range(40):
        legs = np.concatenate([[rng.uniform(-0.3, 0.3), rng.uniform(0.03, 0.09), rng.uniform(0.02, 0.05)] for _ in range(6)])
        q = np.concatenate([rng.uniform(-0.3, 0.3, 3), rng.uniform(-np.pi, np.pi, 3) * [1.0, 0.2, 0.2], legs])
        qpos, g = ours.mujoco_state(q)
        data.qpos[:] = qpos
        data.qvel[:] = 0.0
        mujoco.mj_forward(model, data)
        equality = data.efc_type[: data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        worst["loops"] = max(worst["loops"], np.abs(data.efc_pos[: data.nefc][equality]).max())
        record_errors(model, data, ours, q, g, worst)
    assert worst["loops"] < 1e-12 and max(worst["feet"], worst["M"], worst["g"]) < 1e-9, worst


def test_export_mjcf_writes_either_leg_mechanism(tmp_path):
    """`hexadyn export-mjcf`: the shipped robots load in MuJoCo with hexadyn's mass (the
    PhantomX as its URDF's mechanism, AMRU5 with its loops), a second write needs --overwrite,
    a broken description is one line."""
    from click.testing import CliRunner

    from hexadyn._core import PantographHexapod, UrdfHexapod, robot_urdf, shipped_robot_text
    from hexadyn.cli import cli

    standing = np.concatenate([np.zeros(6), np.tile([0.0, 0.06, 0.035], 6)])
    masses = {
        "amru5": PantographHexapod(shipped_robot_text("amru5")).mass_matrix(standing)[0, 0],
        "phantomx": UrdfHexapod(robot_urdf(shipped_robot_text("phantomx"))).mass_matrix(np.zeros(24))[0, 0],
    }
    for robot, mass in masses.items():
        out = tmp_path / f"{robot}.xml"
        result = CliRunner().invoke(cli, ["export-mjcf", robot, "-o", str(out)])
        assert result.exit_code == 0, result.output
        model = mujoco.MjModel.from_xml_path(str(out))
        assert abs(model.body_mass.sum() - mass) < 1e-9 * mass, robot
        again = CliRunner().invoke(cli, ["export-mjcf", robot, "-o", str(out)])
        assert again.exit_code != 0 and "--overwrite" in again.output and len(again.output.strip().splitlines()) == 1
    broken = tmp_path / "broken.toml"
    broken.write_text(shipped_robot_text("amru5").replace("[geometry", "[geometry_", 1))
    bad = CliRunner().invoke(cli, ["export-mjcf", str(broken), "--out", str(tmp_path / "broken.xml")])
    assert bad.exit_code != 0 and "broken.toml" in bad.output and len(bad.output.strip().splitlines()) == 1, bad.output
    assert not (tmp_path / "broken.xml").exists()
