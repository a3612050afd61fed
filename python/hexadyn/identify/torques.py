"""Joint torques from a log: the motor torque of the measured current (Eq. 3.90 through the
reduction, tau_m = n k_t i, Eq. 5.17; on a position servo the current of its motor) minus what
the leg itself needs, computed by the leg model of the engine (Eq. 3.37 on a single leg of
either mechanism, ``hexadyn._core.LegModel``): its gravity and the foot load of the loaded experiments (Fig. 5.6). What remains is the friction torque at
constant velocity (Eq. 5.7, Coriolis and centrifugal terms negligible).

What is left of the velocity transient in an averaging window is removed as the leg's inertia
at the window's mean acceleration. A simulated motor current ``i_q_v[2]`` is the value at the
end of each control period, under the voltage held over it: within a period the joint velocity
relaxes towards its new value with the mechanical time constant tau = M / (n k_t)^2 * R
(16 ms for q_v on AMRU5, beside the 10 ms period), so the end-of-period acceleration is the
period's mean acceleration times phi = x e^-x / (1 - e^-x), x = period / tau (0.72 for q_v).
A measured current (``i_meas_...``, CSV logs) has been through the sensor's analog low-pass
filter, which averages it over the period: phi = 1 (:func:`sampling_factor`).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from hexadyn.identify.logs import Log

__all__ = ["leg_model", "friction_torque", "joint_constants"]

#: Samples between two evaluations of the leg model (0.1 s at 100 Hz: q_v moves at most 0.8 mm).
STRIDE = 10
#: Weight of one kilogram at the foot (N/kg): Section 5.3 uses 9.81 m/s^2.
LOAD_GRAVITY = 9.81


@lru_cache(maxsize=8)
def leg_model(robot_text: str | None):
    """The engine's leg model of a robot description (None: the embedded AMRU5)."""
    from hexadyn import _core

    return _core.LegModel(robot_text, "robot description of the log")


def joint_constants(log: Log, joint: str, leg: int) -> dict[str, float]:
    """n k_t, the encoder resolution and the friction the description gives the joint."""
    return dict(leg_model(log.robot_text).joint(leg, joint))


def sampling_factor(log: Log, joint: str, leg: int, q: np.ndarray) -> float:
    """phi of the module docs for the joint's current column at the leg configuration q (3,)."""
    if log.measured_current(joint, leg):
        return 1.0
    k = log.joints.index(joint)
    c = joint_constants(log, joint, leg)
    unit = np.zeros((1, 3))
    unit[0, k] = 1.0
    model = leg_model(log.robot_text)
    rows = np.vstack([q, q])
    torques = model.joint_torques(leg, rows, np.zeros((2, 3)), np.vstack([unit, np.zeros((1, 3))]))
    inertia = float(torques[0, k] - torques[1, k])
    tau_m = inertia * c["resistance"] / c["torque_per_ampere"] ** 2
    x = float(np.median(np.diff(log.t))) / tau_m
    return x * np.exp(-x) / -np.expm1(-x)


def friction_torque(log: Log, joint: str, leg: int, rows: slice | np.ndarray = slice(None), velocity: float = 0.0, acceleration: float = 0.0) -> np.ndarray:
    """tau_m - tau_grav - tau_iner - tau_load of the joint over `rows` of the log (Eq. 5.7 and
    5.14): the leg model at the logged positions, the joint at `velocity` and `acceleration`
    (a section's means), the other joints of the leg still."""
    k = log.joints.index(joint)
    i = log.current(joint, leg)[rows]
    q = np.column_stack([log.position(j, leg)[rows] if _has_position(log, j, leg) else np.full(len(i), _mid_range(log, j, leg)) for j in log.joints.names])
    qd, qdd = np.zeros_like(q), np.zeros_like(q)
    qd[:, k] = velocity
    if acceleration:
        qdd[:, k] = acceleration * sampling_factor(log, joint, leg, q[len(q) // 2])
    force = (0.0, 0.0, LOAD_GRAVITY * log.foot_load_kg[leg])
    # The leg model at every STRIDE-th sample and the last one, interpolated in between: the
    # torques are smooth functions of the slowly moving positions.
    nodes = np.unique(np.concatenate([np.arange(0, len(q), STRIDE), [len(q) - 1]]))
    at_nodes = leg_model(log.robot_text).joint_torques(leg, q[nodes], qd[nodes], qdd[nodes], force)[:, k]
    needed = np.interp(np.arange(len(q)), nodes, at_nodes)
    return joint_constants(log, joint, leg)["torque_per_ampere"] * i - needed


def _has_position(log: Log, joint: str, leg: int) -> bool:
    return f"{joint}[{leg}]" in log.frame


def _mid_range(log: Log, joint: str, leg: int) -> float:
    # A joint whose position the log lacks: the middle of its range (on AMRU5 the strokes of
    # Table 5.2). Only the gravity of the leg depends on it, below 5 % of the currents on
    # AMRU5 (Section 5.2.1); a serial leg's gravity depends on every joint, so its logs should
    # hold the three positions of the leg.
    c = joint_constants(log, joint, leg)
    return 0.5 * (c["lower"] + c["upper"])
