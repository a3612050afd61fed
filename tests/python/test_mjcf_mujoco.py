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
            # v_mujoco = T q' with T = blockdiag(I, E, I): M_ours = Tᵀ M T, g_ours = −Tᵀ bias.
            t = np.eye(24)
            t[3:6, 3:6] = rates_to_body(pitch, roll)
            m = np.zeros((24, 24))
            mujoco.mj_fullM(model, data, m)
            feet = np.array([data.site(f"foot{leg}").xpos for leg in range(6)])
            for key, theirs, mine in (
                ("feet", feet, ours.feet(q)),
                ("M", t.T @ m @ t, ours.mass_matrix(q)),
                ("g", -t.T @ data.qfrc_bias, ours.gravity_forces(q)),
            ):
                worst[key] = max(worst[key], np.abs(mine - theirs).max() / np.abs(theirs).max())
    assert max(worst.values()) < 1e-9, worst
