"""Serial hexapods read from URDF against an independent oracle: Pinocchio (``pin`` from PyPI)
loads the same URDF file with, as its root joint, the free body of Eq. 3.52 (translations X, Y,
Z, then rotations about z, y, x: hexadyn's (X, Y, Z, yaw, pitch, roll)), so that both use the
same q and q'. On random states of random robots (mounting frames, inertial frames turned by
rpy, tilted joint axes, fixed foot links, a prismatic joint), the mass matrix (Eq. 3.39), the
centrifugal and Coriolis terms (Eq. 3.40), the gravity forces (Eq. 3.41), the feet and their
Jacobians agree to 1e-9 relative: the URDF conventions (rpy, axes, inertial origins, fixed
joints merged) are read as Pinocchio reads them."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from hexadyn._core import UrdfHexapod
from urdf_hexapods import random_hexapod

STATES = 1000


def root_joint() -> pin.JointModelComposite:
    """Eq. 3.52: T^d(X, Y, Z) T^Rz(Φ) T^Ry(Θ) T^Rx(Ψ)."""
    root = pin.JointModelComposite()
    for joint in (pin.JointModelPX(), pin.JointModelPY(), pin.JointModelPZ(), pin.JointModelRZ(), pin.JointModelRY(), pin.JointModelRX()):
        root.addJoint(joint)
    return root


def oracle(urdf: str, ours: UrdfHexapod):
    """Pinocchio's model of the URDF, the index in its q of each of hexadyn's coordinates, and
    a frame at each foot sphere's centre."""
    model = pin.buildModelFromXML(urdf, root_joint())
    perm = list(range(6)) + [model.joints[model.getJointId(name)].idx_q for name in ours.joint_names]
    assert sorted(perm) == list(range(model.nq)) and model.nq == model.nv == 24
    geometry = pin.buildGeomFromUrdfString(model, urdf, pin.GeometryType.COLLISION)
    spheres = [g for g in geometry.geometryObjects if isinstance(g.geometry, pin.hppfcl.Sphere if hasattr(pin, "hppfcl") else pin.coal.Sphere)]
    feet = []
    for leg in range(6):
        tibia = model.getJointId(ours.joint_names[3 * leg + 2])
        (sphere,) = [g for g in spheres if g.parentJoint == tibia]
        feet.append(model.addFrame(pin.Frame(f"foot{leg}", tibia, sphere.parentFrame, sphere.placement, pin.FrameType.OP_FRAME)))
    return model, np.array(perm), feet


@pytest.mark.parametrize("prismatic", [False, True], ids=["coxa-femur-tibia", "prismatic tibia"])
def test_dynamics_feet_and_jacobians_match_pinocchio(prismatic):
    rng = np.random.default_rng(11 + prismatic)
    worst = dict.fromkeys(["M", "h", "g", "feet", "J"], 0.0)
    for robot in range(10):
        urdf = random_hexapod(100 * prismatic + robot, prismatic_tibia=prismatic)
        ours = UrdfHexapod(urdf, f"random_hexapod_{robot}.urdf")
        model, perm, feet = oracle(urdf, ours)
        model.gravity.linear = np.array([0.0, 0.0, -9.81])
        data = model.createData()
        for _ in range(STATES // 10):
            q = np.concatenate([rng.uniform(-0.3, 0.3, 3), rng.uniform(-np.pi, np.pi, 3), rng.uniform(-1.0, 1.0, 18) * (0.03 if prismatic else 1.0)])
            qd = rng.uniform(-2.0, 2.0, 24)
            q_pin, v_pin = np.empty(24), np.empty(24)
            q_pin[perm], v_pin[perm] = q, qd

            m_pin = pin.crba(model, data, q_pin)
            m_pin = (np.triu(m_pin) + np.triu(m_pin, 1).T)[np.ix_(perm, perm)]
            g_pin = pin.computeGeneralizedGravity(model, data, q_pin)[perm]
            h_pin = pin.nonLinearEffects(model, data, q_pin, v_pin)[perm] - g_pin
            pin.computeJointJacobians(model, data, q_pin)
            pin.updateFramePlacements(model, data)
            feet_pin = np.array([data.oMf[f].translation for f in feet])
            j_pin = np.array([pin.getFrameJacobian(model, data, f, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)[:3, perm] for f in feet])

            for key, ours_value, theirs in (
                ("M", ours.mass_matrix(q), m_pin),
                ("h", ours.nonlinear_effects(q, qd), h_pin),
                ("g", ours.gravity_forces(q), -g_pin),
                ("feet", ours.feet(q), feet_pin),
                ("J", ours.foot_jacobians(q), j_pin),
            ):
                error = np.abs(ours_value - theirs).max() / np.abs(theirs).max()
                worst[key] = max(worst[key], error)
    assert max(worst.values()) < 1e-9, worst


def test_a_foot_jacobian_is_the_feet_velocity():
    """The Jacobian gives the feet's velocity: central differences of feet(q) along q'."""
    ours = UrdfHexapod(random_hexapod(3), "r.urdf")
    rng = np.random.default_rng(5)
    q, qd = rng.uniform(-0.5, 0.5, 24), rng.uniform(-1.0, 1.0, 24)
    eps = 1e-6
    numeric = (ours.feet(q + eps * qd) - ours.feet(q - eps * qd)) / (2 * eps)
    np.testing.assert_allclose(ours.foot_jacobians(q) @ qd, numeric, atol=1e-8)
