"""Rigid-body evaluation of a serial hexapod read from URDF: hexadyn against Pinocchio, timed in
the same run on the same file and states.

Each side loads the URDF (hexadyn: `_core.UrdfHexapod`, urdf-rs and its minimal-coordinates
multibody model; Pinocchio: `buildModelFromXML` with the free body of Eq. 3.52 as root joint)
and evaluates, for N random states, the mass matrix M(q) and the nonlinear effects (Coriolis
and gravity) through its Python binding, one call per quantity and state, so both pay the same
kind of binding overhead. The timings are medians of interleaved repeats; the ratio is
Pinocchio's time over hexadyn's (above 1: hexadyn faster). Pinocchio's CRBA and RNEA are
O(n) recursive algorithms in C++; hexadyn's are the projections of Eq. 3.39-3.41 over the
bodies' partial velocities, the formulation its implicit integrator differentiates.

    .venv/bin/python benches/urdf_rigid_body.py [--states 2000] [--repeats 5]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "python"))

import pinocchio as pin  # noqa: E402  (a test dependency)

from hexadyn._core import UrdfHexapod  # noqa: E402
from urdf_hexapods import random_hexapod  # noqa: E402


def root_joint() -> pin.JointModelComposite:
    root = pin.JointModelComposite()
    for joint in (pin.JointModelPX(), pin.JointModelPY(), pin.JointModelPZ(), pin.JointModelRZ(), pin.JointModelRY(), pin.JointModelRX()):
        root.addJoint(joint)
    return root


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=2000)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    urdf = random_hexapod(1)
    rng = np.random.default_rng(0)
    states = [(np.concatenate([rng.uniform(-0.3, 0.3, 6), rng.uniform(-0.8, 0.8, 18)]), rng.uniform(-1, 1, 24)) for _ in range(args.states)]

    def load_ours():
        return UrdfHexapod(urdf, "bench.urdf")

    def load_pin():
        model = pin.buildModelFromXML(urdf, root_joint())
        return model, model.createData()

    ours = load_ours()
    model, data = load_pin()
    perm = np.array(list(range(6)) + [model.joints[model.getJointId(n)].idx_q for n in ours.joint_names])
    pin_states = []
    for q, qd in states:
        q_pin, v_pin = np.empty(24), np.empty(24)
        q_pin[perm], v_pin[perm] = q, qd
        pin_states.append((q_pin, v_pin))

    def run_ours() -> None:
        for q, qd in states:
            ours.mass_matrix(q)
            ours.nonlinear_effects(q, qd)
            ours.gravity_forces(q)

    def run_pin() -> None:
        for q, v in pin_states:
            pin.crba(model, data, q)
            pin.nonLinearEffects(model, data, q, v)

    times: dict[str, list[float]] = {"hexadyn load": [], "Pinocchio load": [], "hexadyn": [], "Pinocchio": []}
    for _ in range(args.repeats):
        for name, f in (("hexadyn load", load_ours), ("Pinocchio load", load_pin), ("hexadyn", run_ours), ("Pinocchio", run_pin)):
            start = time.process_time()
            f()
            times[name].append(time.process_time() - start)
    med = {k: statistics.median(v) for k, v in times.items()}
    per = {k: med[k] / args.states * 1e6 for k in ("hexadyn", "Pinocchio")}
    print(f"serial hexapod from URDF (24 DOF, 19 bodies), {args.states} states, medians of {args.repeats} interleaved repeats (CPU time)")
    print(f"  load:  hexadyn {med['hexadyn load'] * 1e3:.2f} ms, Pinocchio {med['Pinocchio load'] * 1e3:.2f} ms")
    print(f"  M + h per state: hexadyn {per['hexadyn']:.1f} us (M, h and g: three calls), Pinocchio {per['Pinocchio']:.1f} us (crba, nonLinearEffects)")
    print(f"  ratio Pinocchio / hexadyn: {med['Pinocchio'] / med['hexadyn']:.2f}")


if __name__ == "__main__":
    main()
