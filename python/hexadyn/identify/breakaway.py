"""Breakaway (stiction) torque of the vertical joints, Section 5.3 (Eq. 5.10-5.11, Table 5.4).

The voltage rises slowly (0.05 V/s) with a load at the foot; the current grows with it while
the joint sticks, and the joint breaks away when the motor torque overcomes the breakaway
friction. The friction torque (motor torque minus leg gravity and foot load, the general form
of Eq. 5.10-5.11) just before the joint moves "frankly" is tau_f,s.

INTERPRETATION: "frankly" is taken as the joint velocity reaching ``breakaway_velocity``
(default 1e-4 m/s, the Stribeck velocity of Table 6.1: below it the joint is in the stiction
zone of Eq. 6.4). The velocity is the least-squares slope of the encoder position over
+- ``smoothing_s``; the friction torque is smoothed over the same window (a Savitzky-Golay
line, exact on the linear rise of the current, which also averages the current noise); tau_f,s
is its extreme (largest for the plus sense, smallest for the minus one) up to the breakaway.

A joint that moves before the voltage could have moved it — from the start, or against the
voltage — is reversible under its load: its breakaway is not identified (the "-" of Table
5.4: "joint is reversible"), and the measurement says so instead of giving a number.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from hexadyn.identify.logs import IdentifyError, Log
from hexadyn.identify.torques import friction_torque

__all__ = ["BreakawayOptions", "Breakaway", "breakaway"]


@dataclass(frozen=True)
class BreakawayOptions:
    breakaway_velocity: float = 1e-4
    smoothing_s: float = 0.25


@dataclass(frozen=True)
class Breakaway:
    """One breakaway measurement of a joint: tau_f,s (NaN when not identified, then `reason` says
    why), its direction (the voltage's), the instant and the foot load."""

    source: str
    joint: str
    leg: int
    direction: int
    load_kg: float
    tau_f_s: float
    t_breakaway: float
    reason: str = ""


def breakaway(log: Log, leg: int, options: BreakawayOptions, joint: str = "q_v") -> Breakaway:
    """tau_f,s of one joint driven by a voltage ramp.

    Raises:
        IdentifyError: the joint never moves in the log.
    """
    where = f"{log.source}: {joint}[{leg}]"
    t = log.t
    q = log.position(joint, leg)
    dt = float(np.median(np.diff(t)))
    w = max(2, int(round(options.smoothing_s / dt)))
    length = 2 * w + 1
    if len(t) < length + 2:
        raise IdentifyError(f"{where}: {len(t)} samples; the breakaway needs more than {length + 2} ({2 * options.smoothing_s} s smoothing)")
    velocity = signal.savgol_filter(q, length, 1, deriv=1, delta=dt, mode="interp")
    moving = np.flatnonzero(np.abs(velocity) >= options.breakaway_velocity)
    if len(moving) == 0:
        raise IdentifyError(f"{where}: the joint never reaches {options.breakaway_velocity} (breakaway velocity): no breakaway in the log (a longer ramp?)")
    k = int(moving[0])
    moved = 1 if velocity[k] > 0 else -1
    voltage = f"u_{joint}[{leg}]"
    direction = int(np.sign(log.frame[voltage].iloc[-1])) if voltage in log.frame and log.frame[voltage].iloc[-1] != 0 else moved
    if k < length or moved != direction:
        why = "from the start" if k < length else "against the voltage"
        return Breakaway(log.source, joint, leg, direction, log.foot_load_kg[leg], float("nan"), float(t[k]), f"reversible: moves {why} (t = {t[k]:.2f} s)")
    tau = signal.savgol_filter(friction_torque(log, joint, leg, slice(0, k + 1)), length, 1, mode="interp")
    tau_f_s = float(tau.max() if direction > 0 else tau.min())
    return Breakaway(log.source, joint, leg, direction, log.foot_load_kg[leg], tau_f_s, float(t[k]))
