"""What the viewer reads from a results folder, and the robot's kinematics over it.

:class:`Run` reads only the columns the scene needs from ``timeseries.parquet`` (a 1000 s walk is
10^5 rows of about 300 columns: the plotted signals are read on demand, column by column) and the
scenario and robot texts from ``metadata.json``. The robot, AMRU5's pantograph legs or a serial
robot's, is drawn from the recorded joint coordinates through the engine's own multibody
kinematics (:class:`hexadyn._core.Kinematics`), frame by frame, so the page never holds the
whole run.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hexadyn import vocabulary
from hexadyn.results import FORMAT, METADATA_FILE, TIMESERIES_FILE

#: The number of legs is the engine's (:mod:`hexadyn.vocabulary`); the joint names are the
#: robot's (``Run.joints``).
LEGS = len(vocabulary.LEGS)
POSE_COLUMNS = ["X", "Y", "Z", "yaw", "pitch", "roll"]


def q_columns(joints: vocabulary.Joints) -> list[str]:
    """Generalized coordinates in the engine's order (Eq. 3.51): body pose, then the robot's
    three joints per leg (q_r, q_v, q_h on AMRU5)."""
    return POSE_COLUMNS + [f"{j}[{leg}]" for leg in range(LEGS) for j in joints.names]


class ViewError(ValueError):
    """A folder or file the viewer cannot show; the message names it."""


def _xyz(prefix: tuple[str, str, str]) -> list[str]:
    return [f"{c}[{f}]" for f in range(LEGS) for c in prefix]


FOOT_COLUMNS = _xyz(("foot_x", "foot_y", "foot_z"))
FORCE_COLUMNS = _xyz(("Fx", "Fy", "Fz"))
PHASE_COLUMNS = [f"phase[{leg}]" for leg in range(LEGS)]
REFERENCE_COLUMNS = ["X_ref", "Y_ref"]


@dataclass(frozen=True)
class Frame:
    """The state of the robot at one recorded instant, in the world frame (m, N)."""

    index: int
    t: float
    #: Body position (3,) and rotation matrix (3, 3), body to world.
    body_position: np.ndarray
    body_rotation: np.ndarray
    #: All bodies: names as in :attr:`Run.body_names`, positions (B, 3), rotations (B, 3, 3).
    positions: np.ndarray
    rotations: np.ndarray
    #: Per leg the points named by :attr:`Run.leg_point_names` (6, P, 3): AMRU5's 8 pantograph
    #: points, or a serial leg's joint origins and foot; feet = ``[:, -1]``.
    leg_points: np.ndarray
    #: Ground force on each foot (6, 3) and foot phase (6,), -1 where not recorded.
    forces: np.ndarray
    phases: np.ndarray

    @property
    def feet(self) -> np.ndarray:
        """Foot positions (6, 3) from the kinematics of the recorded q."""
        return self.leg_points[:, -1]


class Run:
    """A results folder as the viewer sees it.

    Raises :class:`ViewError` naming the folder, file or column when the folder is not a hexadyn
    results folder or lacks a column the scene needs.
    """

    def __init__(self, folder: str | Path):
        import pyarrow.parquet as pq

        from hexadyn import _core

        self.folder = Path(folder)
        meta_path = self.folder / METADATA_FILE
        table_path = self.folder / TIMESERIES_FILE
        if not self.folder.is_dir():
            raise ViewError(f"{self.folder}: no such results folder")
        if not meta_path.is_file() or not table_path.is_file():
            raise ViewError(f"{self.folder}: not a hexadyn results folder (needs {METADATA_FILE} and {TIMESERIES_FILE})")
        try:
            self.metadata = json.loads(meta_path.read_text(encoding="utf-8"))
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise ViewError(f"{meta_path}: not JSON ({exc})") from exc
        if not isinstance(self.metadata, dict) or self.metadata.get("format") != FORMAT:
            found = self.metadata.get("format") if isinstance(self.metadata, dict) else f"a JSON {type(self.metadata).__name__}"
            raise ViewError(f"{meta_path}: not hexadyn results metadata (format {found!r}, expected {FORMAT!r})")
        if not self.metadata.get("robot"):
            raise ViewError(f"{meta_path}: no robot description (key 'robot')")
        try:
            self.joints = vocabulary.Joints.of_robot(self.metadata["robot"], f"{meta_path} (robot)")
        except ValueError as exc:
            raise ViewError(str(exc)) from exc
        q_names = q_columns(self.joints)
        self._parquet = pq.ParquetFile(table_path)
        self.columns: list[str] = list(self._parquet.schema_arrow.names)
        missing = [c for c in ["t", *q_names, *FOOT_COLUMNS, *FORCE_COLUMNS] if c not in self.columns]
        if missing:
            raise ViewError(f"{table_path}: missing column{'s' if len(missing) > 1 else ''} {', '.join(missing)}")
        self.name: str = self.metadata.get("scenario_name") or self.folder.name
        wanted = ["t", *q_names, *FOOT_COLUMNS, *FORCE_COLUMNS]
        self.has_phases = all(c in self.columns for c in PHASE_COLUMNS)
        self.has_reference = all(c in self.columns for c in REFERENCE_COLUMNS)
        wanted += PHASE_COLUMNS if self.has_phases else []
        wanted += REFERENCE_COLUMNS if self.has_reference else []
        data = self.read(wanted)
        self.t = data["t"]
        if self.t.size < 1:
            raise ViewError(f"{table_path}: no rows")
        self.q = np.column_stack([data[c] for c in q_names])
        self.recorded_feet = np.column_stack([data[c] for c in FOOT_COLUMNS]).reshape(-1, LEGS, 3)
        self.forces = np.column_stack([data[c] for c in FORCE_COLUMNS]).reshape(-1, LEGS, 3)
        self.phases = np.column_stack([data[c] for c in PHASE_COLUMNS]).astype(np.int8) if self.has_phases else np.full((self.t.size, LEGS), -1, np.int8)
        self.reference_xy = np.column_stack([data["X_ref"], data["Y_ref"]]) if self.has_reference else None
        try:
            self.kinematics = _core.Kinematics(self.metadata["robot"], f"{meta_path} (robot)")
        except ValueError as exc:
            raise ViewError(str(exc)) from exc
        self.body_names: list[str] = self.kinematics.body_names
        self.leg_point_names: list[str] = self.kinematics.leg_point_names
        self.geometry: dict = self.kinematics.geometry

    def read(self, columns: list[str]) -> dict[str, np.ndarray]:
        """The given columns as float arrays, read from the Parquet file (not kept)."""
        missing = [c for c in columns if c not in self.columns]
        if missing:
            raise ViewError(f"{self.folder / TIMESERIES_FILE}: missing column{'s' if len(missing) > 1 else ''} {', '.join(missing)}")
        table = self._parquet.read(columns=columns)
        return {c: table.column(c).to_numpy().astype(np.float64) for c in columns}

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])

    def index_at(self, t: float) -> int:
        """The recorded instant nearest to time `t` (clamped to the run)."""
        i = int(np.searchsorted(self.t, t))
        if i >= self.t.size:
            return self.t.size - 1
        if i > 0 and t - self.t[i - 1] <= self.t[i] - t:
            return i - 1
        return i

    def frame(self, index: int) -> Frame:
        """The kinematics of recorded instant `index`."""
        q = self.q[index : index + 1]
        positions, rotations = self.kinematics.poses(q)
        leg_points = self.kinematics.leg_points(q)[0]
        return Frame(
            index=index,
            t=float(self.t[index]),
            body_position=positions[0, 0],
            body_rotation=rotations[0, 0],
            positions=positions[0],
            rotations=rotations[0],
            leg_points=leg_points,
            forces=self.forces[index],
            phases=self.phases[index],
        )

    def body_path(self) -> np.ndarray:
        """The body position (N, 3) of every recorded instant."""
        return self.q[:, :3]

    def terrain(self, centre: np.ndarray, half_width: float) -> tuple[np.ndarray, np.ndarray] | None:
        """The ground of the run's scenario file (``scenario_path``) as vertices (float32) and
        faces, when it is not flat: None for flat ground, or when the file is gone or invalid
        (the flat marks are drawn then). Planes and steps are cut to the square around
        ``centre`` (x, y) of half side ``half_width``."""
        from hexadyn import _core

        path = self.metadata.get("scenario_path")
        if not path or not Path(path).is_file():
            return None
        try:
            vertices, faces = _core.terrain_triangles(str(path), half_width_m=float(half_width), centre_x_m=float(centre[0]), centre_y_m=float(centre[1]))
        except ValueError:
            return None
        if np.ptp(vertices[:, 2]) == 0.0:
            return None
        return vertices.astype(np.float32), faces

    def footholds(self) -> np.ndarray:
        """Where the feet touched down (K, 3): the recorded foot positions at each start of a
        support phase (phase 0), or of a contact (F_z > 0) in runs without a gait."""
        if self.has_phases:
            down = self.phases == 0
        else:
            down = self.forces[:, :, 2] > 0.0
        starts = down.copy()
        starts[1:] &= ~down[:-1]
        rows, legs = np.nonzero(starts)
        return self.recorded_feet[rows, legs]


def decimation(count: int, budget: int) -> np.ndarray:
    """Indices of at most `budget` evenly spread rows of `count`, first and last included."""
    if count <= budget:
        return np.arange(count)
    return np.unique(np.linspace(0, count - 1, budget).round().astype(np.int64))
