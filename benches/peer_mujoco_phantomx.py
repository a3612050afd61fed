"""Side-by-side benchmark against MuJoCo on the second shipped robot: the PhantomX Mark II's
20 s tripod walk (``phantomx_tripod``), both engines on the same URDF.

hexadyn runs its full model of the shipped scenario: the 18-joint serial multibody with the
AX-12A rotors turning at 254 q, Hertz-Hunt-Crossley contact at the foot spheres with
regularised Coulomb friction, dry/viscous joint friction, 18 DC motors driven by the servos'
compliance loops, the gait controller at 100 Hz. MuJoCo loads the robot hexadyn exports from
``robots/phantomx/phantomx.urdf`` (``UrdfHexapod.to_mjcf``: the same bodies, joints, ranges,
inertias and foot spheres) on a plane, with per joint:
- a position actuator with the servo law's linear part and the motor: kp = n k_t G / R
  (G the duty-per-radian gain of the compliance slope, times the supply), kv = (n k_t)^2 / R
  (the back-EMF), force-limited to the stall torque n k_t L V / R;
- the rotor as armature J_r n^2 and the dry friction as frictionloss,
and replays hexadyn's servo goals (the joint references plus the master's friction
feed-forward, columns ``<joint>_goal[i]``) held over each 10 ms
control period at dt = 1 ms, implicitfast. Both are timed in the same run, in `--repeats`
interleaved pairs; the medians are printed with each one's distance walked.

    .venv/bin/python benches/peer_mujoco_phantomx.py     # or: make bench-peer
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

try:
    import mujoco
except ImportError:  # a benchmark-only dependency
    sys.exit("benches/peer_mujoco_phantomx.py needs MuJoCo: pip install -c requirements/lock.txt -e '.[bench]'")

from hexadyn import _core
from peer_mujoco import hexadyn_walk, ypr_quaternion  # the AMRU5 peer benchmark's, same folder

ROOT = Path(__file__).resolve().parent.parent
SCENARIO = ROOT / "python/hexadyn/scenarios/phantomx_tripod.toml"
ROBOT = ROOT / "robots/phantomx/phantomx.toml"
URDF = ROOT / "robots/phantomx/phantomx.urdf"
DT = 1e-3
JOINTS = ("coxa", "femur", "tibia")


def phantomx_mjcf() -> str:
    """The exported MJCF with a floor, the drives as position actuators, armature and
    frictionloss (see the module doc)."""
    robot = tomllib.loads(ROBOT.read_text())
    supply = robot["controller"]["supply_voltage_v"]
    xml = _core.UrdfHexapod.from_file(str(URDF)).to_mjcf()
    actuators, defaults = [], {}
    for name in JOINTS:
        d = robot["drives"][name]
        m, s, f = d["motor"], d["servo"], d["friction"]
        k = d["gear_ratio"] * m["torque_constant_nm_per_a"]
        gain = (s["torque_limit"] - s["punch"]) / math.radians(s["compliance_slope_deg"]) * supply
        defaults[name] = {
            "kp": k * gain / m["resistance_ohm"],
            "kv": k * k / m["resistance_ohm"],
            "force": k * s["torque_limit"] * supply / m["resistance_ohm"],
            "armature": m["rotor_inertia_kg_m2"] * d["gear_ratio"] ** 2,
            "friction": f["tau_f_d"],
        }
    model = mujoco.MjModel.from_xml_string(xml)
    for j in range(1, model.njnt):  # joint 0 is the free joint
        jname = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
        p = defaults[JOINTS[(j - 1) % 3]]
        xml = xml.replace(f'<joint name="{jname}" ', f'<joint name="{jname}" armature="{p["armature"]:.9g}" frictionloss="{p["friction"]:.9g}" limited="true" ', 1)
        actuators.append(f'<position joint="{jname}" kp="{p["kp"]:.9g}" kv="{p["kv"]:.9g}" forcelimited="true" forcerange="{-p["force"]:.9g} {p["force"]:.9g}"/>')
    mu = robot["ground"]["mu"]
    floor = f'<geom name="ground" type="plane" size="50 50 0.1" friction="{mu} 0.005 0.0001"/>'
    xml = xml.replace("<worldbody>", f"<worldbody>\n    {floor}", 1)
    xml = xml.replace("</mujoco>", f"  <actuator>{''.join(actuators)}</actuator>\n</mujoco>", 1)
    return xml.replace("<option ", f'<option timestep="{DT}" integrator="implicitfast" ', 1)


def mujoco_walk(model, c: dict, ctrl: np.ndarray, settle_s: float = 1.0):
    """From hexadyn's initial pose and joints, settles under the first targets (not timed),
    then replays the targets with a zero-order hold over each control period. Returns
    (X at each control instant, wall s, CPU s)."""
    data = mujoco.MjData(model)
    data.qpos[:3] = [c["X"][0], c["Y"][0], c["Z"][0] + 0.002]
    data.qpos[3:7] = ypr_quaternion(c["yaw"][0], c["pitch"][0], c["roll"][0])
    data.qpos[7:] = ctrl[0]
    data.ctrl[:] = ctrl[0]
    mujoco.mj_step(model, data, nstep=int(round(settle_s / DT)))
    per_period = int(round((c["t"][1] - c["t"][0]) / DT))
    x = np.empty(len(ctrl))
    x0 = data.qpos[0]
    wall, cpu = time.perf_counter(), time.process_time()
    for i, u in enumerate(ctrl):
        x[i] = data.qpos[0] - x0
        if i + 1 < len(ctrl):
            data.ctrl[:] = u
            mujoco.mj_step(model, data, nstep=per_period)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    return x, wall, cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--xml", type=Path, help="also write the generated MJCF to this file")
    parser.add_argument("--repeats", type=int, default=5, help="timed pairs of walks, interleaved; the medians are printed (default 5)")
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error(f"--repeats {args.repeats}: must be at least 1")
    c, hx_wall, hx_cpu = hexadyn_walk(SCENARIO)
    xml = phantomx_mjcf()
    if args.xml:
        args.xml.write_text(xml)
    model = mujoco.MjModel.from_xml_string(xml)
    # The goals the servos received: the references plus the master's friction feed-forward.
    ctrl = np.stack([c[f"{j}_goal[{leg}]"] for leg in range(6) for j in JOINTS], axis=1)
    x, mj_wall, mj_cpu = mujoco_walk(model, c, ctrl)
    pairs = [(hx_wall, hx_cpu, mj_wall, mj_cpu)]
    for _ in range(args.repeats - 1):
        _, hw, hc = hexadyn_walk(SCENARIO)
        _, mw, mc = mujoco_walk(model, c, ctrl)
        pairs.append((hw, hc, mw, mc))
    hx_wall, hx_cpu, mj_wall, mj_cpu = (float(np.median(column)) for column in zip(*pairs))
    ratios = [mc / hc for _, hc, _, mc in pairs]
    duration = float(c["t"][-1] - c["t"][0])
    walked_hx, walked_mj = float(c["X"][-1] - c["X"][0]), float(x[-1])
    print(f"PhantomX Mark II, 20 s tripod walk (T = 1 s, 5 cm/s), one core; load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"MuJoCo {mujoco.__version__}, {model.nbody - 1} bodies, {model.nv} DOF, {model.nu} position actuators, dt = {DT * 1e3:g} ms; medians of {args.repeats} interleaved pairs")
    print(f"{'':<10} {'wall s':>8} {'CPU s':>8} {'RTF(CPU)':>9} {'walked m':>9}")
    for name, (w, p, walked) in (("hexadyn", (hx_wall, hx_cpu, walked_hx)), ("MuJoCo", (mj_wall, mj_cpu, walked_mj))):
        print(f"{name:<10} {w:>8.3f} {p:>8.3f} {duration / p:>9.0f} {walked:>9.3f}")
    print(f"ratio MuJoCo / hexadyn: {float(np.median(ratios)):.2f} (median of the pairs' CPU ratios; {min(ratios):.2f}-{max(ratios):.2f}); walked distances differ by {abs(walked_mj / walked_hx - 1) * 100:.1f} %")


if __name__ == "__main__":
    main()
