"""Reading the logs of the identification: hexadyn results folders and CSV files from a real
robot, checked (:mod:`hexadyn.identify.checks`) into :class:`~hexadyn.identify.logs.Log`.

CSV layout of a real-robot log (docs/identification.md): a header line, then one row per
sample; columns ``t`` (s, strictly increasing by a constant step), for each joint that moved its position
``q_r[i]`` (rad) / ``q_v[i]``, ``q_h[i]`` (m) and its current ``i_q_r[i]``... (A), optionally the
voltage ``u_q_r[i]``... (V) and ``foot_load_kg[i]`` (the foot load of the loaded experiments,
constant). Lines starting with ``#`` are comments. The robot description is the one given to
:func:`load_log` (default: the embedded AMRU5), which names the columns. A CSV log is read only
from a regular file of at most :data:`MAX_LOG_BYTES` (:func:`hexadyn.inputs.open_input`).
"""

from __future__ import annotations

import dataclasses
import math
import os
import tomllib
from pathlib import Path

import pandas as pd

from hexadyn import inputs
from hexadyn.identify.checks import check_log
from hexadyn.identify.logs import LEGS, IdentifyError, Log, some_columns

__all__ = ["MAX_LOG_BYTES", "load_log"]

#: The largest CSV log read: 1 GB, about 10^7 samples of a six-leg campaign (a day at 100 Hz),
#: which pandas holds in about as much memory again.
MAX_LOG_BYTES = 1 << 30


def load_log(path: str | os.PathLike, robot_text: str | None = None) -> Log:
    """Reads a results folder or a CSV file (see the module docs) and checks it
    (:func:`hexadyn.identify.checks.check_log`: numbers, a constant time step, every leg of a
    campaign, physical magnitudes). `robot_text` is the robot description of a CSV log
    (default: the embedded AMRU5); a results folder carries its own.

    Raises:
        IdentifyError: naming the file and what is missing or wrong.
    """
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
        with inputs.open_input(path, MAX_LOG_BYTES) as source:
            frame = pd.read_csv(source, comment="#", skipinitialspace=True)
    except (OSError, ValueError) as exc:
        raise IdentifyError(f"{path}: cannot read the CSV file: {' '.join(str(exc).split())}") from exc
    frame.columns = [str(c).strip() for c in frame.columns]
    if "t" not in frame:
        raise IdentifyError(f"{path}: missing column `t` (time, s); the CSV layout is in docs/identification.md; the file has {some_columns(frame.columns)}")
    return Log(str(path), frame.set_index("t"), robot_text, (0.0,) * len(LEGS), None)
