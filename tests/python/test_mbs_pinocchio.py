"""The mbs equations of motion against an independent oracle: Pinocchio (``pin`` from PyPI).

For a serial chain and a 24-DOF floating-base tree with six 3-DOF legs, the mass matrix M(q)
(Eq. 3.39), the centrifugal/Coriolis vector h(q, q') (Eq. 3.40) and the gravity forces
(Eq. 3.41) of hexadyn agree with Pinocchio's CRBA and RNEA to 1e-9 relative.
"""

import numpy as np
import pinocchio as pin
import pytest

from hexadyn._core import Multibody

JOINTS = {
    "rx": pin.JointModelRX, "ry": pin.JointModelRY, "rz": pin.JointModelRZ,
    "tx": pin.JointModelPX, "ty": pin.JointModelPY, "tz": pin.JointModelPZ,
}


def rotation(axis, angle):
    return pin.exp3(np.asarray(axis, dtype=float) * angle)


def to_pinocchio(coordinates, bodies):
    """Builds the same tree in Pinocchio: one 1-DOF joint per variable element, fixed elements
    folded into the next joint placement, each body's inertia expressed in its last joint frame.
    Returns the model and, for each hexadyn coordinate, its index in Pinocchio's q."""
    model = pin.Model()
    body_joint, body_frame = [], []
    coordinate_of_joint = {}
    for body in bodies:
        if body["parent"] is None:
            joint, frame = 0, pin.SE3.Identity()
        else:
            joint, frame = body_joint[body["parent"]], body_frame[body["parent"]]
        for element in body["joint"]:
            kind = element[0]
            if kind == "offset":
                frame = frame * pin.SE3(np.eye(3), np.asarray(element[1], dtype=float))
            elif kind == "rotation":
                frame = frame * pin.SE3(rotation(element[1], element[2]), np.zeros(3))
            else:
                assert len(element) == 2, "the oracle supports unit-scale joints only"
                joint = model.addJoint(joint, JOINTS[kind](), frame, f"{body['name']}.{kind}{element[1]}")
                coordinate_of_joint[joint] = element[1]
                frame = pin.SE3.Identity()
        body_joint.append(joint)
        body_frame.append(frame)
        inertia = frame.rotation @ np.asarray(body["inertia"]) @ frame.rotation.T
        model.appendBodyToJoint(joint, pin.Inertia(body["mass"], frame.translation, inertia), pin.SE3.Identity())
    permutation = np.empty(coordinates, dtype=int)
    for joint, coordinate in coordinate_of_joint.items():
        permutation[coordinate] = model.joints[joint].idx_q
    assert sorted(permutation) == list(range(coordinates))
    return model, permutation


def random_inertia(rng):
    principal = rng.uniform(0.01, 0.1, 3)
    principal[2] = min(principal[2], principal[0] + principal[1] - 1e-3)
    axis = rng.normal(size=3)
    r = rotation(axis / np.linalg.norm(axis), rng.uniform(-1, 1))
    return (r @ np.diag(principal) @ r.T).tolist()


def serial_chain(rng, n=7):
    bodies = []
    kinds = ["rz", "ry", "tx", "rx", "tz", "ry", "rz"]
    for i in range(n):
        axis = rng.normal(size=3)
        bodies.append({
            "name": f"link{i}",
            "parent": None if i == 0 else i - 1,
            "joint": [
                ("offset", rng.uniform(-0.3, 0.3, 3).tolist()),
                ("rotation", (axis / np.linalg.norm(axis)).tolist(), float(rng.uniform(-1, 1))),
                (kinds[i % len(kinds)], i),
                ("offset", rng.uniform(-0.2, 0.2, 3).tolist()),
            ],
            "mass": float(rng.uniform(0.5, 3.0)),
            "inertia": random_inertia(rng),
        })
    return n, bodies


def floating_hexapod(rng):
    bodies = [{
        "name": "body", "parent": None,
        "joint": [("tx", 0), ("ty", 1), ("tz", 2), ("rz", 3), ("ry", 4), ("rx", 5)],
        "mass": 11.2, "inertia": np.diag([0.1063, 0.1198, 0.0843]).tolist(),
    }]
    for leg in range(6):
        j = 6 + 3 * leg
        angle = np.radians(30 + 60 * leg)
        hip = len(bodies)
        bodies.append({"name": f"hip{leg}", "parent": 0, "joint": [
            ("rotation", [0, 0, 1], float(angle)), ("offset", [0.175, 0.0, 0.0]), ("rz", j),
            ("offset", [0.05, -0.017, -0.084])], "mass": 2.9, "inertia": random_inertia(rng)})
        bodies.append({"name": f"thigh{leg}", "parent": hip, "joint": [
            ("offset", [0.06, 0.017, 0.03]), ("ry", j + 1), ("offset", [0.14, 0.0, 0.0])],
            "mass": 0.3, "inertia": random_inertia(rng)})
        bodies.append({"name": f"shank{leg}", "parent": hip + 1, "joint": [
            ("offset", [0.14, 0.0, 0.0]), ("ry", j + 2), ("offset", [0.0, 0.0, -0.2])],
            "mass": 0.56, "inertia": random_inertia(rng)})
    return 24, bodies


@pytest.mark.parametrize("make", [serial_chain, floating_hexapod], ids=["serial chain", "24-DOF floating tree"])
def test_mass_matrix_and_bias_forces_match_pinocchio(make):
    rng = np.random.default_rng(7)
    n, bodies = make(rng)
    ours = Multibody(n, bodies)
    model, perm = to_pinocchio(n, bodies)
    data = model.createData()
    for _ in range(5):
        q = rng.uniform(-1.0, 1.0, n)
        qd = rng.uniform(-2.0, 2.0, n)
        q_pin, v_pin = np.empty(n), np.empty(n)
        q_pin[perm], v_pin[perm] = q, qd

        m_pin = pin.crba(model, data, q_pin)
        m_pin = np.triu(m_pin) + np.triu(m_pin, 1).T
        m = ours.mass_matrix(q)
        np.testing.assert_allclose(m, m_pin[np.ix_(perm, perm)], rtol=1e-9, atol=1e-9 * np.abs(m_pin).max())

        model.gravity.linear = np.zeros(3)
        h_pin = pin.rnea(model, data, q_pin, v_pin, np.zeros(n))[perm]
        model.gravity.linear = np.array([0.0, 0.0, -9.81])
        g_pin = pin.computeGeneralizedGravity(model, data, q_pin)[perm]
        h = ours.nonlinear_effects(q, qd)
        np.testing.assert_allclose(h, h_pin, rtol=1e-9, atol=1e-9 * np.abs(h_pin).max())
        np.testing.assert_allclose(ours.gravity_forces(q), -g_pin, rtol=1e-9, atol=1e-9 * np.abs(g_pin).max())
        # Kinetic energy ½ q'ᵀ M q' (Eq. 3.39) against Pinocchio's.
        assert ours.kinetic_energy(q, qd) == pytest.approx(pin.computeKineticEnergy(model, data, q_pin, v_pin), rel=1e-9)


def test_bad_input_is_named():
    n, bodies = serial_chain(np.random.default_rng(1), 2)
    bodies[1]["joint"].append(("qz", 0))
    with pytest.raises(ValueError, match=r"bodies\[1\]: unknown joint element .qz.; allowed: offset"):
        Multibody(n, bodies)
    ours = Multibody(*serial_chain(np.random.default_rng(1), 2))
    with pytest.raises(ValueError, match=r"q\[1\] = NaN is not finite"):
        ours.mass_matrix(np.array([0.0, np.nan]))
    with pytest.raises(ValueError, match="q has 3 entries; the model has 2 coordinates"):
        ours.mass_matrix(np.zeros(3))
