"""The vocabulary of the engine's time-series columns: joint types, legs, foot phase codes and
the column names built from them.

The joint names, the number of legs and the phase codes are the engine's
(``_core.JOINT_NAMES``, ``_core.LEG_COUNT``, ``_core.PHASE_CODES``), not a copy. Column names
follow the engine's recorder: a per-leg quantity is ``name[leg]`` (``phase[2]``, ``foot_x[2]``,
``q_v_ref[2]``), an actuator is named after its joint and leg (``q_v[2]``, its position) and its
other quantities prefix that name (``u_q_v[2]``, ``i_q_v[2]``, ``E_el_q_v[2]``).
"""

from __future__ import annotations

from hexadyn import _core

__all__ = [
    "ACTUATORS",
    "FAILED",
    "JOINT_TYPES",
    "LANDING",
    "LEGS",
    "PHASE_CODES",
    "SUPPORT",
    "SWING",
    "TAKEOFF",
    "actuator",
    "actuator_column",
    "leg_column",
]

#: Joint types in the thesis order (Eq. 3.51, and the columns of Tables 6.3-6.6): rotation,
#: vertical, horizontal.
JOINT_TYPES: tuple[str, ...] = tuple(_core.JOINT_NAMES)
#: The legs, 0..5.
LEGS: tuple[int, ...] = tuple(range(_core.LEG_COUNT))
#: Foot phase name -> code of the ``phase[l]`` columns.
PHASE_CODES: dict[str, int] = dict(_core.PHASE_CODES)
SUPPORT, TAKEOFF, SWING, LANDING = (PHASE_CODES[name] for name in ("support", "takeoff", "swing", "landing"))
#: Code of a failed leg, held up by the free gait on five legs (beyond the thesis).
FAILED = PHASE_CODES["failed"]


def leg_column(quantity: str, leg: int) -> str:
    """Column of a per-leg quantity: ``leg_column("phase", 2) == "phase[2]"``."""
    return f"{quantity}[{leg}]"


def actuator(joint: str, leg: int) -> str:
    """Name of an actuator, its position column: ``actuator("q_v", 2) == "q_v[2]"``."""
    return leg_column(joint, leg)


def actuator_column(quantity: str, name: str) -> str:
    """Column of an actuator quantity: ``actuator_column("E_el", "q_v[2]") == "E_el_q_v[2]"``."""
    return f"{quantity}_{name}"


#: Every actuator, leg by leg in the joint order: ``q_r[0]``, ``q_v[0]``, ``q_h[0]``, ``q_r[1]``, ...
ACTUATORS: tuple[str, ...] = tuple(actuator(j, leg) for leg in LEGS for j in JOINT_TYPES)
