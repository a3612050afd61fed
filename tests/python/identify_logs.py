"""Synthetic real-robot logs for the identification tests: a sawtooth campaign written as the CSV
layout of docs/identification.md, whose currents are those of the robot's own friction (its
description, `_core.LegModel.joint`) plus the leg's gravity, exactly; no simulation needed."""

from __future__ import annotations

import numpy as np
import pandas as pd

from hexadyn.identify.torques import leg_model

#: AMRU5's joints, in a leg's order.
JOINTS = ("q_r", "q_v", "q_h")


def sawtooth_frame(joint: str = "q_v", legs=(2,), speeds_fraction=(0.1, 0.2, 0.3, 0.4), dt: float = 0.01) -> pd.DataFrame:
    """Columns t, `joint[leg]` and `i_joint[leg]` of a sawtooth over the middle 80 % of the
    joint's stroke, one back-and-forth cycle per speed (fractions of the stroke per second), at
    rest at the end; the other joints of the leg held mid-range (as the identification assumes
    for joints without a position column)."""
    model = leg_model(None)
    k = JOINTS.index(joint)
    first = dict(model.joint(legs[0], joint))
    stroke = first["upper"] - first["lower"]
    lo, hi = first["lower"] + 0.1 * stroke, first["upper"] - 0.1 * stroke
    pieces = [np.array([lo])]
    for fraction in speeds_fraction:
        samples = int(round((hi - lo) / (fraction * stroke) / dt))
        ramp = np.linspace(lo, hi, samples + 1)[1:]
        pieces += [ramp, ramp[::-1][1:], [lo]]
    position = np.concatenate([*pieces, np.full(100, lo)])
    velocity = np.gradient(position, dt)
    columns = {"t": np.arange(len(position)) * dt}
    for leg in legs:
        c = dict(model.joint(leg, joint))
        q = np.array([[0.5 * (dict(model.joint(leg, j))["lower"] + dict(model.joint(leg, j))["upper"]) for j in JOINTS]] * len(position))
        q[:, k] = position
        gravity = model.joint_torques(leg, q, np.zeros_like(q), np.zeros_like(q))[:, k]
        friction = np.where(velocity > 0, c["tau_f_d_plus"] + c["f_v_plus"] * velocity, np.where(velocity < 0, c["tau_f_d_minus"] + c["f_v_minus"] * velocity, 0.0))
        columns[f"{joint}[{leg}]"] = position
        columns[f"i_{joint}[{leg}]"] = (friction + gravity) / c["torque_per_ampere"]
    return pd.DataFrame(columns)
