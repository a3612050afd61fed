"""Exports of a results folder for other tools (``hexadyn export``)::

    from hexadyn import export
    export.export(results, "walk.mcap", "mcap")     # Foxglove Studio, the ROS tools
    export.export(results, "walk.csv", "csv")       # a spreadsheet

- ``csv``: the whole time series, one row per control instant, the column ``t`` (s) first, the
  columns of the results under their own names (units in ``metadata.json``), every value
  written so that it reads back exactly.
- ``mcap``: an MCAP file (https://mcap.dev) of JSON messages with JSON schemas, one message per
  control instant and channel, logged at the instant's time ``t`` (log and publish time, ns from
  the start of the run; each message also carries it as ``timestamp``, ``{sec, nsec}``):

  ============== =========================== ==================================================
  topic          schema                      message
  ============== =========================== ==================================================
  /body_pose     foxglove.PoseInFrame        the body centre (X, Y, Z, m) and orientation (the
                                             quaternion of R_z(yaw) R_y(pitch) R_x(roll),
                                             Eq. 3.52), frame ``world``
  /joint_states  hexadyn.JointStates         ``joints``: per actuator, by the robot's own joint
                                             names (``q_v[2]``, ``femur[2]``): ``name``,
                                             ``leg``, ``joint``, ``position`` (rad or m),
                                             ``velocity`` (rad/s or m/s), ``effort`` (the motor
                                             torque at the joint, Nm or N)
  /foot_forces   hexadyn.FootForces          ``feet``: per leg, the ground force on the foot in
                                             the world frame ``x``, ``y``, ``z`` and its normal
                                             component ``normal`` (N)
  /motor_currents hexadyn.MotorCurrents      ``motors``: per actuator ``name``, ``current`` (A)
                                             and ``voltage`` (V)
  ============== =========================== ==================================================

  A channel whose columns the results do not hold (the body pose of a run on the robot, which
  has no navigation system) is left out. The file's metadata record ``hexadyn`` holds the
  version, the scenario name and the units of the columns the channels read. In Foxglove
  Studio, open the file and plot e.g. ``/joint_states.joints[4].position`` or show
  ``/body_pose`` in a 3D panel.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping, Sequence

from hexadyn import atomic
from hexadyn.results import Results
from hexadyn.vocabulary import LEGS, actuator_column, leg_column

__all__ = ["CHANNELS", "FORMATS", "Channel", "channels", "export"]

#: The export formats, and the file suffix of each.
FORMATS = {"csv": ".csv", "mcap": ".mcap"}
#: Instants read from the time series at a time (bounded memory whatever the duration).
CHUNK_ROWS = 10_000

#: ``{sec, nsec}``, the time of Foxglove's schemas.
_TIME = {"type": "object", "title": "time", "properties": {"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}}}


def _vector(title: str, names: Sequence[str]) -> dict[str, Any]:
    return {"type": "object", "title": title, "properties": {n: {"type": "number"} for n in names}}


def _array_of(description: str, properties: Mapping[str, str]) -> dict[str, Any]:
    kinds = {"string": {"type": "string"}, "integer": {"type": "integer"}, "number": {"type": ["number", "null"]}}
    return {"type": "array", "description": description, "items": {"type": "object", "properties": {k: kinds[v] for k, v in properties.items()}}}


def _schema(title: str, description: str, **properties: Any) -> dict[str, Any]:
    return {"title": title, "description": description, "type": "object", "properties": {"timestamp": _TIME, **properties}}


@dataclass(frozen=True)
class Channel:
    """One MCAP channel: its topic, its JSON schema, the columns it reads and how a message is
    made of one instant's values (``row``: column name -> value)."""

    topic: str
    schema: dict[str, Any]
    columns: Callable[[Results], list[str]]
    message: Callable[[Results, Mapping[str, float]], dict[str, Any]]


def _finite(value: float) -> float | None:
    """JSON has no NaN nor infinity: null."""
    return float(value) if math.isfinite(value) else None


# -- /body_pose ------------------------------------------------------------------------------

_POSE = ("X", "Y", "Z", "yaw", "pitch", "roll")


def _pose(results: Results, row: Mapping[str, float]) -> dict[str, Any]:
    # R = R_z(yaw) R_y(pitch) R_x(roll) (Eq. 3.52): the product of the three half-angle
    # quaternions in that order.
    cy, sy = math.cos(row["yaw"] / 2), math.sin(row["yaw"] / 2)
    cp, sp = math.cos(row["pitch"] / 2), math.sin(row["pitch"] / 2)
    cr, sr = math.cos(row["roll"] / 2), math.sin(row["roll"] / 2)
    orientation = {"x": sr * cp * cy - cr * sp * sy, "y": cr * sp * cy + sr * cp * sy, "z": cr * cp * sy - sr * sp * cy, "w": cr * cp * cy + sr * sp * sy}
    position = {"x": _finite(row["X"]), "y": _finite(row["Y"]), "z": _finite(row["Z"])}
    return {"frame_id": "world", "pose": {"position": position, "orientation": {k: _finite(v) for k, v in orientation.items()}}}


_POSE_SCHEMA = _schema(
    "foxglove.PoseInFrame",
    "The body centre and orientation (yaw-pitch-roll, Eq. 3.52) in the world frame.",
    frame_id={"type": "string"},
    pose={"type": "object", "title": "foxglove.Pose", "properties": {"position": _vector("foxglove.Vector3", "xyz"), "orientation": _vector("foxglove.Quaternion", "xyzw")}},
)

# -- /joint_states ---------------------------------------------------------------------------


def _joint_columns(results: Results) -> list[str]:
    names = results.joints.names
    return [c for leg in LEGS for j in names for c in (leg_column(j, leg), leg_column(f"{j}_dot", leg), actuator_column("tau_m", leg_column(j, leg)))]


def _joint_states(results: Results, row: Mapping[str, float]) -> dict[str, Any]:
    joints = []
    for leg in LEGS:
        for j in results.joints.names:
            name = leg_column(j, leg)
            joints.append({"name": name, "leg": leg, "joint": j, "position": _finite(row[name]), "velocity": _finite(row[leg_column(f"{j}_dot", leg)]), "effort": _finite(row[actuator_column("tau_m", name)])})
    return {"joints": joints}


_JOINT_SCHEMA = _schema(
    "hexadyn.JointStates",
    "Per actuator (leg by leg, in the robot's joint order): position (rad or m), velocity (rad/s or m/s) and effort, the motor torque at the joint (Nm or N).",
    joints=_array_of("one entry per actuator", {"name": "string", "leg": "integer", "joint": "string", "position": "number", "velocity": "number", "effort": "number"}),
)

# -- /foot_forces ----------------------------------------------------------------------------

_FORCES = {"x": "Fx", "y": "Fy", "z": "Fz", "normal": "Fn"}


def _force_columns(results: Results) -> list[str]:
    return [leg_column(q, leg) for leg in LEGS for q in _FORCES.values()]


def _foot_forces(results: Results, row: Mapping[str, float]) -> dict[str, Any]:
    return {"feet": [{"leg": leg, **{k: _finite(row[leg_column(q, leg)]) for k, q in _FORCES.items()}} for leg in LEGS]}


_FORCE_SCHEMA = _schema(
    "hexadyn.FootForces",
    "Per leg, the ground force on the foot in the world frame (x, y, z) and its normal component (N).",
    feet=_array_of("one entry per leg", {"leg": "integer", "x": "number", "y": "number", "z": "number", "normal": "number"}),
)

# -- /motor_currents -------------------------------------------------------------------------


def _motor_columns(results: Results) -> list[str]:
    return [actuator_column(q, a) for a in results.joints.actuators for q in ("i", "u")]


def _motor_currents(results: Results, row: Mapping[str, float]) -> dict[str, Any]:
    return {"motors": [{"name": a, "current": _finite(row[actuator_column("i", a)]), "voltage": _finite(row[actuator_column("u", a)])} for a in results.joints.actuators]}


_MOTOR_SCHEMA = _schema(
    "hexadyn.MotorCurrents",
    "Per actuator (leg by leg, in the robot's joint order): the motor current (A) and the voltage across motor and H-bridge (V).",
    motors=_array_of("one entry per actuator", {"name": "string", "current": "number", "voltage": "number"}),
)

#: The channels of an MCAP export, in the order they are registered.
CHANNELS = (
    Channel("/body_pose", _POSE_SCHEMA, lambda results: list(_POSE), _pose),
    Channel("/joint_states", _JOINT_SCHEMA, _joint_columns, _joint_states),
    Channel("/foot_forces", _FORCE_SCHEMA, _force_columns, _foot_forces),
    Channel("/motor_currents", _MOTOR_SCHEMA, _motor_columns, _motor_currents),
)


def channels(results: Results) -> list[Channel]:
    """The channels of :data:`CHANNELS` whose columns the results hold."""
    return [c for c in CHANNELS if set(c.columns(results)) <= set(results.units)]


# -- Writing ---------------------------------------------------------------------------------


def export(results: Results, path: str | os.PathLike, format: str, *, overwrite: bool = False) -> Path:
    """Writes the results as `format` (``csv`` or ``mcap``, see the module docs) to the file
    `path`, atomically; returns the path. FileExistsError if it exists and not `overwrite`;
    ValueError for another format or results without a time series."""
    if format not in FORMATS:
        raise ValueError(f"export format = {format!r}; allowed: {', '.join(FORMATS)}")
    target = Path(path)
    if not overwrite:
        atomic.refuse_existing(target, "export file")
    write = _write_csv if format == "csv" else _write_mcap
    atomic.write_file(target, lambda tmp: write(results, tmp))
    return target


def _write_csv(results: Results, path: Path) -> None:
    columns = [c for c in results.units if c != "t"]
    with open(path, "w", encoding="utf-8", newline="") as f:
        for k, chunk in enumerate(results.iter_chunks(columns, CHUNK_ROWS)):
            chunk.to_csv(f, header=k == 0)


def _write_mcap(results: Results, path: Path) -> None:
    from mcap.writer import Writer

    from hexadyn import __version__

    chosen = channels(results)
    if not chosen:
        raise ValueError(f"{results.path or 'these results'}: none of the MCAP channels' columns ({', '.join(c.topic for c in CHANNELS)}) in the time series")
    needed = list(dict.fromkeys(col for c in chosen for col in c.columns(results)))
    with open(path, "wb") as f:
        writer = Writer(f)
        writer.start(profile="", library=f"hexadyn {__version__}")
        ids = []
        for c in chosen:
            schema = writer.register_schema(name=c.schema["title"], encoding="jsonschema", data=json.dumps(c.schema).encode())
            ids.append(writer.register_channel(topic=c.topic, message_encoding="json", schema_id=schema))
        sequence = 0
        for t, row in _rows(results, needed):
            ns = round(t * 1e9)
            stamp = {"sec": ns // 1_000_000_000, "nsec": ns % 1_000_000_000}
            for c, channel_id in zip(chosen, ids):
                data = json.dumps({"timestamp": stamp, **c.message(results, row)}, allow_nan=False).encode()
                writer.add_message(channel_id=channel_id, log_time=ns, publish_time=ns, data=data, sequence=sequence)
            sequence += 1
        units = {col: results.units.get(col, "") for col in ["t", *needed]}
        writer.add_metadata("hexadyn", {"hexadyn_version": __version__, "scenario": str(results.metadata.get("scenario_name")), "units": json.dumps(units)})
        writer.finish()


def _rows(results: Results, columns: list[str]) -> Iterator[tuple[float, dict[str, float]]]:
    """(t, column -> value) of every instant, read :data:`CHUNK_ROWS` instants at a time."""
    for chunk in results.iter_chunks(columns, CHUNK_ROWS):
        values = {c: chunk[c].to_numpy(dtype=float).tolist() for c in columns}
        for i, t in enumerate(chunk.index.to_numpy(dtype=float).tolist()):
            yield t, {c: values[c][i] for c in columns}
