"""The logs the identification reads (:mod:`hexadyn.identify.reading`: hexadyn results folders
and CSV files from a real robot).

A log is a time series of joint positions and motor currents (and, optionally, voltages) with
the robot description it was recorded on and the load hung at each foot (Fig. 5.6). Columns
are named as in a results folder (``crates/hexadyn/src/robot/columns.rs``) after the robot's
joints (``[joints] names``: ``q_r``, ``q_v``, ``q_h`` on AMRU5, ``coxa``, ``femur``, ``tibia``
on the PhantomX): ``t``, ``q_v[2]``, ``i_q_v[2]``, ``u_q_v[2]``. A measured current column
``i_meas_q_v[2]`` (the current sensor of Section 2.3.2 with its 30 Hz analog filter) is used
instead of the true current ``i_q_v[2]`` when the log has it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
import pandas as pd

from hexadyn.vocabulary import Joints

__all__ = ["IdentifyError", "LEGS", "Log", "UNITS", "column", "robot_joints", "some_columns"]

LEGS = range(6)
#: Units of the dry friction and the viscous slope per joint kind (Table 5.3: Nm, Nms for q_r).
UNITS = {"revolute": ("Nm", "Nms"), "prismatic": ("N", "Ns/m")}


class IdentifyError(ValueError):
    """A log that cannot be identified: one line naming the file and what is wrong."""


def column(kind: str, joint: str, leg: int) -> str:
    """The results column of a joint quantity: ``column("i", "q_v", 2) == "i_q_v[2]"``,
    ``column("q", "q_v", 2) == "q_v[2]"``."""
    return f"{joint}[{leg}]" if kind == "q" else f"{kind}_{joint}[{leg}]"


@lru_cache(maxsize=8)
def robot_joints(robot_text: str | None) -> tuple[Joints, str]:
    """The joints of a robot description (None: the embedded AMRU5), in the order of a leg's
    coordinates (Eq. 3.51), and its leg mechanism ("pantograph" or "serial")."""
    from hexadyn import _core

    text, origin = robot_text or _core.shipped_robot_text("amru5"), "robot description of the log"
    return Joints.of_robot(text, origin), _core.robot_properties(text, origin)["leg_mechanism"]


@dataclass
class Log:
    """One experiment log.

    Attributes:
        source: the file or folder it was read from (named in every error).
        frame: the samples, indexed by ``t`` (s).
        robot_text: the robot description (TOML) the log was recorded on; None for the
            embedded AMRU5.
        foot_load_kg: load at each foot (kg, Fig. 5.6), 0 without.
        motions: (joint type, leg) -> the motion kind of the scenario (``"sawtooth"``,
            ``"voltage_ramp"``...) for a results folder; None for a CSV log, whose joints are
            told apart by their records (:func:`hexadyn.identify.identification.experiment_of`).
    """

    source: str
    frame: pd.DataFrame
    robot_text: str | None
    foot_load_kg: tuple[float, ...] = (0.0,) * 6
    motions: dict[tuple[str, int], str] | None = field(default=None)

    @property
    def joints(self) -> Joints:
        """The names and kinds of a leg's joints of the log's robot."""
        return robot_joints(self.robot_text)[0]

    @property
    def leg_mechanism(self) -> str:
        return robot_joints(self.robot_text)[1]

    @property
    def t(self) -> np.ndarray:
        return self.frame.index.to_numpy(dtype=float)

    def position(self, joint: str, leg: int) -> np.ndarray:
        return self._required(column("q", joint, leg), "joint position").to_numpy(dtype=float)

    def current(self, joint: str, leg: int) -> np.ndarray:
        """The measured current if the log has it (``i_meas_...``), else the motor current."""
        measured = column("i_meas", joint, leg)
        if measured in self.frame:
            return self.frame[measured].to_numpy(dtype=float)
        return self._required(column("i", joint, leg), f"motor current (or {measured})").to_numpy(dtype=float)

    def measured_current(self, joint: str, leg: int) -> bool:
        """Whether the current of the joint is a measured one (a sensor's, filtered): a CSV log
        or an ``i_meas_...`` column; else the simulated motor current sampled at the control
        instants."""
        return self.motions is None or column("i_meas", joint, leg) in self.frame

    def has(self, joint: str, leg: int) -> bool:
        """Whether the log holds the position and a current of the joint."""
        f = self.frame
        return column("q", joint, leg) in f and (column("i", joint, leg) in f or column("i_meas", joint, leg) in f)

    def _required(self, name: str, what: str) -> pd.Series:
        if name not in self.frame:
            raise IdentifyError(f"{self.source}: missing column `{name}` ({what}); the log has {some_columns(self.frame.columns)}")
        return self.frame[name]


def some_columns(columns) -> str:
    """A short list of a log's columns for an error message."""
    names = [str(c) for c in columns]
    shown = ", ".join(f"`{n}`" for n in names[:8])
    return f"{len(names)} columns ({shown}{', ...' if len(names) > 8 else ''})"
