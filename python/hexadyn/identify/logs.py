"""The logs the identification reads: hexadyn results folders and CSV files from a real robot.

A log is a time series of joint positions and motor currents (and, optionally, voltages) with
the robot description it was recorded on and the load hung at each foot (Fig. 5.6). Columns
are named as in a results folder (``crates/hexadyn/src/robot/columns.rs``) after the robot's
joints (``[joints] names``: ``q_r``, ``q_v``, ``q_h`` on AMRU5, ``coxa``, ``femur``, ``tibia``
on the PhantomX): ``t``, ``q_v[2]``, ``i_q_v[2]``, ``u_q_v[2]``. A measured current column
``i_meas_q_v[2]`` (the current sensor of Section 2.3.2 with its 30 Hz analog filter) is used
instead of the true current ``i_q_v[2]`` when the log has it.

CSV layout of a real-robot log (docs/identification.md): a header line, then one row per
sample; columns ``t`` (s, strictly increasing by a constant step), for each joint that moved its position
``q_r[i]`` (rad) / ``q_v[i]``, ``q_h[i]`` (m) and its current ``i_q_r[i]``... (A), optionally the
voltage ``u_q_r[i]``... (V) and ``foot_load_kg[i]`` (the foot load of the loaded experiments,
constant). Lines starting with ``#`` are comments. The robot description is the one given to
:func:`load_log` (default: the embedded AMRU5), which names the columns.
"""

from __future__ import annotations

import dataclasses
import math
import os
import tomllib
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np
import pandas as pd

from hexadyn.vocabulary import Joints

__all__ = ["IdentifyError", "Log", "load_log", "column", "robot_joints", "some_columns"]

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


def load_log(path: str | os.PathLike, robot_text: str | None = None) -> Log:
    """Reads a results folder or a CSV file (see the module docs) and checks it
    (:func:`hexadyn.identify.checks.check_log`: numbers, a constant time step, every leg of a
    campaign, physical magnitudes). `robot_text` is the robot description of a CSV log
    (default: the embedded AMRU5); a results folder carries its own.

    Raises:
        IdentifyError: naming the file and what is missing or wrong.
    """
    from hexadyn.identify.checks import check_log  # it checks Log objects: imported here, not above

    path = Path(path)
    if path.is_dir():
        return check_log(_results_log(path))
    if path.is_file():
        log = check_log(_csv_log(path, robot_text))
        return dataclasses.replace(log, foot_load_kg=tuple(float(log.frame[f"foot_load_kg[{leg}]"].iloc[0]) if f"foot_load_kg[{leg}]" in log.frame else 0.0 for leg in LEGS))
    raise IdentifyError(f"{path}: no such results folder or CSV file")


def _results_log(folder: Path) -> Log:
    from hexadyn.results import METADATA_FILE, Results

    try:
        results = Results.load(folder)
        frame = results.timeseries
    except (OSError, ValueError) as exc:
        raise IdentifyError(f"{folder}: cannot read the results folder: {' '.join(str(exc).split())}") from exc
    meta = folder / METADATA_FILE
    robot = results.metadata.get("robot")
    if not isinstance(robot, str):
        raise IdentifyError(f"{meta}: no `robot` entry (the robot description the run used); allowed: the metadata `hexadyn simulate` writes")
    try:
        scenario = tomllib.loads(results.metadata.get("scenario") or "")
    except tomllib.TOMLDecodeError as exc:
        raise IdentifyError(f"{meta}: `scenario` is not a scenario text ({exc}); allowed: the metadata `hexadyn simulate` writes") from None
    return Log(str(folder), frame, robot, _foot_loads(scenario, meta), _motions(scenario, meta))


def _foot_loads(scenario: dict, meta: Path) -> tuple[float, ...]:
    """`model.foot_load_kg` of a stored scenario: six finite numbers (kg), zeros without."""
    model = scenario.get("model", {})
    loads = model.get("foot_load_kg", [0.0] * len(LEGS)) if isinstance(model, dict) else None
    ok = isinstance(loads, list) and len(loads) == len(LEGS) and all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in loads)
    if not ok:
        raise IdentifyError(f"{meta}: scenario `model.foot_load_kg` = {loads!r}; allowed: {len(LEGS)} finite loads in kg")
    return tuple(float(x) for x in loads)


def _motions(scenario: dict, meta: Path) -> dict[tuple[str, int], str]:
    """(joint, leg) -> motion kind of the `[[control.motion]]` tables of a stored scenario."""
    control = scenario.get("control", {})
    motions = control.get("motion", []) if isinstance(control, dict) else None
    if not isinstance(motions, list):
        raise IdentifyError(f"{meta}: scenario `control.motion` = {motions!r}; allowed: a list of motion tables")
    out = {}
    for k, m in enumerate(motions):
        fields = {"joint": str, "leg": int, "kind": str}
        for name, kind in fields.items():
            value = m.get(name) if isinstance(m, dict) else None
            if not isinstance(value, kind) or isinstance(value, bool) or (name == "leg" and value not in LEGS):
                allowed = f"a leg {LEGS[0]}..{LEGS[-1]}" if name == "leg" else "a string"
                raise IdentifyError(f"{meta}: scenario `control.motion[{k}].{name}` = {value!r}; allowed: {allowed}")
        out[(m["joint"], m["leg"])] = m["kind"]
    return out


def _csv_log(path: Path, robot_text: str | None) -> Log:
    try:
        frame = pd.read_csv(path, comment="#", skipinitialspace=True)
    except (OSError, ValueError) as exc:
        raise IdentifyError(f"{path}: cannot read the CSV file: {' '.join(str(exc).split())}") from exc
    frame.columns = [str(c).strip() for c in frame.columns]
    if "t" not in frame:
        raise IdentifyError(f"{path}: missing column `t` (time, s); the CSV layout is in docs/identification.md; the file has {some_columns(frame.columns)}")
    return Log(str(path), frame.set_index("t"), robot_text, (0.0,) * len(LEGS), None)


def some_columns(columns) -> str:
    """A short list of a log's columns for an error message."""
    names = [str(c) for c in columns]
    shown = ", ".join(f"`{n}`" for n in names[:8])
    return f"{len(names)} columns ({shown}{', ...' if len(names) > 8 else ''})"
