"""The PhantomX's AX-12A servos holding its legs in the air (body on a stand, no joint
friction): at rest each motor's torque is the leg's gravity torque as Pinocchio computes it on
the robot's URDF (an independent oracle of the multibody model, the rotors massless), and each
joint's error from its goal is the one the compliance law needs to give that torque (the
servo law of `control::servo`, through the DC motor of Eq. 4.4 at rest: tau = n k_t u / R).
A leg in the air asks its femur and tibia for less than the punch: their errors lie in the
sensor count over which the punch comes in, beyond the margin."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import hexadyn
from hexadyn._core import UrdfHexapod
from test_urdf_pinocchio import oracle

ROOT = Path(__file__).resolve().parents[2]
URDF = ROOT / "robots" / "phantomx" / "phantomx.urdf"
JOINTS = ("coxa", "femur", "tibia")

SCENARIO = """
[scenario]
name = "phantomx_on_a_stand"
duration_s = 3.0
robot = "phantomx"

[model]
friction = "none"
stand = true

[initial]
settle = false
body_height_offset_m = 0.05

[control]
mode = "pi"
"""


def test_the_servos_hold_the_legs_against_gravity_as_the_compliance_law_says(tmp_path):
    path = tmp_path / "stand.toml"
    path.write_text(SCENARIO)
    last = hexadyn.simulate(path, progress=False).timeseries.iloc[-1]
    names = [f"{j}[{leg}]" for leg in range(6) for j in JOINTS]
    assert max(abs(last[f"{j}_dot[{leg}]"]) for leg in range(6) for j in JOINTS) < 1e-6, "the legs are at rest"
    assert (last[[f"Fn[{leg}]" for leg in range(6)]] == 0).all(), "the feet are in the air"

    # Pinocchio's gravity torques at the simulated state: what the motors must hold.
    text = URDF.read_text()
    model, perm, _ = oracle(text, UrdfHexapod(text, "phantomx.urdf"))
    model.gravity.linear = np.array([0.0, 0.0, -hexadyn._core.STANDARD_GRAVITY])
    q = np.concatenate([last[["X", "Y", "Z", "yaw", "pitch", "roll"]].to_numpy(float), last[names].to_numpy(float)])
    q_pin = np.empty(24)
    q_pin[perm] = q
    tau_g = pin.computeGeneralizedGravity(model, model.createData(), q_pin)[perm][6:]
    tau_m = last[[f"tau_m_{n}" for n in names]].to_numpy(float)
    assert np.abs(tau_m - tau_g).max() < 1e-6 * np.abs(tau_g).max(), (tau_m, tau_g)

    # The compliance law inverted at that torque gives the joints' errors.
    robot = tomllib.loads((ROOT / "robots" / "phantomx" / "phantomx.toml").read_text())
    supply = robot["controller"]["supply_voltage_v"]
    checked = 0
    for k, name in enumerate(names):
        d = robot["drives"][JOINTS[k % 3]]
        s, m = d["servo"], d["motor"]
        duty = abs(tau_g[k]) * m["resistance_ohm"] / (d["gear_ratio"] * m["torque_constant_nm_per_a"] * supply)
        if duty < 1e-3 * s["punch"]:
            continue  # a coxa about the vertical: no torque, any error within the margin holds
        count = math.radians(s["sensor_range_deg"]) / s["sensor_counts"]
        beyond = count * duty / s["punch"] if duty < s["punch"] else count + (duty - s["punch"]) * math.radians(s["compliance_slope_deg"]) / (s["torque_limit"] - s["punch"])
        error = math.radians(s["compliance_margin_deg"]) + beyond
        simulated = last[name.replace("[", "_ref[")] - last[name]
        assert math.copysign(error, tau_g[k]) == pytest.approx(simulated, rel=1e-6), (name, error, simulated)
        checked += 1
    assert checked >= 12, "the femur and tibia joints carry their links"
