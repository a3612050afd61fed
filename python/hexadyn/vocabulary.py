"""The vocabulary of the engine's time-series columns: a robot's joints, legs, foot phase codes
and the column names built from them.

The number of legs and the phase codes are the engine's (``_core.LEG_COUNT``,
``_core.PHASE_CODES``), not a copy. The joints are the robot's: each robot description names
its legs' three joints (``[joints] names``; AMRU5's are the thesis' ``q_r``, ``q_v``, ``q_h``, a
serial leg's could be ``coxa``, ``femur``, ``tibia``), and :class:`Joints` reads them as the
engine does (``Joints.of(results)``, also ``results.joints``). Column names follow the engine's
recorder: a per-leg quantity is ``name[leg]`` (``phase[2]``, ``foot_x[2]``, ``q_v_ref[2]``), an
actuator is named after its joint and leg (``q_v[2]``, its position) and its other quantities
prefix that name (``u_q_v[2]``, ``i_q_v[2]``, ``E_el_q_v[2]``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping, Protocol, Sequence

from hexadyn import _core

__all__ = [
    "FAILED",
    "Joints",
    "LANDING",
    "LEGS",
    "PHASE_CODES",
    "SUPPORT",
    "SWING",
    "TAKEOFF",
    "actuator",
    "actuator_column",
    "leg_column",
    "phase_codes",
]

#: The legs, 0..5.
LEGS: tuple[int, ...] = tuple(range(_core.LEG_COUNT))
#: Foot phase name -> code of the ``phase[l]`` columns.
PHASE_CODES: dict[str, int] = dict(_core.PHASE_CODES)
SUPPORT, TAKEOFF, SWING, LANDING = (PHASE_CODES[name] for name in ("support", "takeoff", "swing", "landing"))
#: Code of a failed leg, held up by the free gait on five legs (beyond the thesis).
FAILED = PHASE_CODES["failed"]


def phase_codes(values: Any, columns: Sequence[str], t: Any) -> Any:
    """The ``phase[l]`` columns' `values` (rows at the times `t`, one column each of `columns`)
    as integer codes; ValueError naming the column, the time and the value that is no code of
    :data:`PHASE_CODES` (a damaged time series)."""
    import numpy as np

    known = np.isin(values, list(PHASE_CODES.values()))
    if not known.all():
        row, column = np.argwhere(~known)[0]
        raise ValueError(f"column `{columns[column]}` = {float(values[row, column]):g} at t = {float(t[row]):g} s: not a foot phase; allowed: the codes {sorted(PHASE_CODES.values())} ({', '.join(PHASE_CODES)})")
    return values.astype(np.int8)


def leg_column(quantity: str, leg: int) -> str:
    """Column of a per-leg quantity: ``leg_column("phase", 2) == "phase[2]"``."""
    return f"{quantity}[{leg}]"


def actuator(joint: str, leg: int) -> str:
    """Name of an actuator, its position column: ``actuator("q_v", 2) == "q_v[2]"``."""
    return leg_column(joint, leg)


def actuator_column(quantity: str, name: str) -> str:
    """Column of an actuator quantity: ``actuator_column("E_el", "q_v[2]") == "E_el_q_v[2]"``."""
    return f"{quantity}_{name}"


#: The kind of a joint whose position is an angle (rad, its effort in Nm).
REVOLUTE = "revolute"
#: The kind of a joint whose position is a length (m, its effort in N).
PRISMATIC = "prismatic"


class _WithMetadata(Protocol):
    """What :meth:`Joints.of` reads: results (:class:`hexadyn.results.Results`) with their
    ``metadata``, which holds the robot description text."""

    @property
    def metadata(self) -> Mapping[str, Any]: ...


@dataclass(frozen=True)
class Joints:
    """The names and kinds (``"revolute"`` or ``"prismatic"``) of a leg's three joints, in the
    order of q (Eq. 3.51): the columns and tables of the results of one robot."""

    names: tuple[str, ...]
    kinds: tuple[str, ...]

    @classmethod
    def of_robot(cls, robot_text: str, origin: str = "robot description") -> Joints:
        """The joints of a robot description text, as the engine reads it (ValueError naming
        `origin` and the field for an invalid description)."""
        pairs = _core.robot_properties(robot_text, origin)["joints"]
        return cls(tuple(name for name, _ in pairs), tuple(kind for _, kind in pairs))

    @classmethod
    def of(cls, results: _WithMetadata) -> Joints:
        """The joints of the robot description stored with `results`."""
        return cls.of_robot(results.metadata.get("robot", ""), "the robot description stored with these results")

    @property
    def actuators(self) -> tuple[str, ...]:
        """Every actuator, leg by leg in the joint order: ``q_r[0]``, ``q_v[0]``, ``q_h[0]``,
        ``q_r[1]``, ... on AMRU5."""
        return tuple(actuator(j, leg) for leg in LEGS for j in self.names)

    def kind(self, joint: str) -> str:
        """The kind of joint `joint` (ValueError naming the allowed joints if there is none)."""
        return self.kinds[self.index(joint)]

    def index(self, joint: str) -> int:
        """Position of joint `joint` in a leg (0..2)."""
        if joint not in self.names:
            raise ValueError(f"joint = {joint!r}; allowed: {', '.join(self.names)}")
        return self.names.index(joint)
