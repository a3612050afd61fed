"""The logs the identification reads: hexadyn results folders and CSV files from a real robot.

A log is a time series of joint positions and motor currents (and, optionally, voltages) with
the robot description it was recorded on and the load hung at each foot (Fig. 5.6). Columns
are named as in a results folder (``crates/hexadyn/src/robot/columns.rs``) after the robot's
joints (``[joints] names``: ``q_r``, ``q_v``, ``q_h`` on AMRU5, ``coxa``, ``femur``, ``tibia``
on the PhantomX): ``t``, ``q_v[2]``, ``i_q_v[2]``, ``u_q_v[2]``. A measured current column
``i_meas_q_v[2]`` (the current sensor of Section 2.3.2 with its 30 Hz analog filter) is used
instead of the true current ``i_q_v[2]`` when the log has it.

CSV layout of a real-robot log (docs/identification.md): a header line, then one row per
sample; columns ``t`` (s, strictly increasing), for each joint that moved its position
``q_r[i]`` (rad) / ``q_v[i]``, ``q_h[i]`` (m) and its current ``i_q_r[i]``... (A), optionally the
voltage ``u_q_r[i]``... (V) and ``foot_load_kg[i]`` (the foot load of the loaded experiments,
constant). Lines starting with ``#`` are comments. The robot description is the one given to
:func:`load_log` (default: the embedded AMRU5), which names the columns.
"""

from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np
import pandas as pd

from hexadyn.vocabulary import Joints

__all__ = ["IdentifyError", "Log", "load_log", "column", "robot_joints"]

LEGS = range(6)


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
            raise IdentifyError(f"{self.source}: missing column `{name}` ({what}); the log has {_some(self.frame.columns)}")
        return self.frame[name]


def load_log(path: str | os.PathLike, robot_text: str | None = None) -> Log:
    """Reads a results folder or a CSV file (see the module docs) and checks it: a time column
    strictly increasing, finite values. `robot_text` is the robot description of a CSV log
    (default: the embedded AMRU5); a results folder carries its own.

    Raises:
        IdentifyError: naming the file and what is missing or wrong.
    """
    path = Path(path)
    if path.is_dir():
        log = _results_log(path)
    elif path.is_file():
        log = _csv_log(path, robot_text)
    else:
        raise IdentifyError(f"{path}: no such results folder or CSV file")
    _check(log)
    return log


def _results_log(folder: Path) -> Log:
    from hexadyn.results import Results

    try:
        results = Results.load(folder)
    except (OSError, ValueError) as exc:
        raise IdentifyError(f"{folder}: cannot read the results folder: {exc}") from exc
    scenario = tomllib.loads(results.metadata.get("scenario") or "")
    model = scenario.get("model", {})
    loads = tuple(float(x) for x in model.get("foot_load_kg", [0.0] * 6))
    motions = {(m["joint"], int(m["leg"])): m["kind"] for m in scenario.get("control", {}).get("motion", [])}
    return Log(str(folder), results.timeseries, results.metadata["robot"], loads, motions)


def _csv_log(path: Path, robot_text: str | None) -> Log:
    try:
        frame = pd.read_csv(path, comment="#", skipinitialspace=True)
    except (OSError, ValueError) as exc:
        raise IdentifyError(f"{path}: cannot read the CSV file: {exc}") from exc
    frame.columns = [str(c).strip() for c in frame.columns]
    if "t" not in frame:
        raise IdentifyError(f"{path}: missing column `t` (time, s); the CSV layout is in docs/identification.md; the file has {_some(frame.columns)}")
    loads = [0.0] * 6
    for leg in LEGS:
        name = f"foot_load_kg[{leg}]"
        if name in frame:
            loads[leg] = float(frame[name].iloc[0])
    frame = frame.set_index("t")
    return Log(str(path), frame, robot_text, tuple(loads), None)


def _check(log: Log) -> None:
    t = log.t
    if len(t) < 2:
        raise IdentifyError(f"{log.source}: {len(t)} samples; a log needs at least 2")
    if not np.all(np.isfinite(t)):
        k = int(np.flatnonzero(~np.isfinite(t))[0])
        raise IdentifyError(f"{log.source}: time t is not finite at row {k}")
    steps = np.diff(t)
    if np.any(steps <= 0):
        k = int(np.flatnonzero(steps <= 0)[0])
        raise IdentifyError(f"{log.source}: time is not strictly increasing: t[{k}] = {t[k]} s, t[{k + 1}] = {t[k + 1]} s")
    try:
        names = log.joints.names
    except ValueError as exc:
        raise IdentifyError(f"{log.source}: {exc}") from None
    if not any(log.has(j, leg) for j in names for leg in LEGS):
        j = names[1]
        raise IdentifyError(f"{log.source}: no joint with both a position (`{j}[2]`...) and a current (`i_{j}[2]` or `i_meas_{j}[2]`) column of the robot's joints {', '.join(names)}; the log has {_some(log.frame.columns)}")
    for name in log.frame.columns:
        values = log.frame[name]
        if values.dtype.kind == "f" and not np.all(np.isfinite(values.to_numpy())):
            k = int(np.flatnonzero(~np.isfinite(values.to_numpy()))[0])
            raise IdentifyError(f"{log.source}: column `{name}` is not finite at t = {t[k]} s")


def _some(columns) -> str:
    names = [str(c) for c in columns]
    shown = ", ".join(f"`{n}`" for n in names[:8])
    return f"{len(names)} columns ({shown}{', ...' if len(names) > 8 else ''})"

