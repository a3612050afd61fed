"""What the viewer reads from a results folder, and the robot's kinematics over it.

:class:`Run` reads only the columns the scene needs from ``timeseries.parquet`` (a 1000 s walk is
10^5 rows of about 300 columns: the plotted signals are read on demand, column by column), a
row group at a time, keeping at most :data:`MAX_FRAMES` instants evenly spread over the run, so
that the memory of the viewer does not grow with the duration. The scenario and robot texts
come from ``metadata.json`` (:func:`hexadyn.results.read_metadata`). The robot, AMRU5's
pantograph legs or a serial robot's, is drawn from the recorded joint coordinates through the
engine's own multibody kinematics (:class:`hexadyn._core.Kinematics`), frame by frame, so the
page never holds the whole run.

Any results folder the project writes is shown with what it has: a simulation's body pose, feet
and ground forces; a run on the robot (``hexadyn robot run``) has no measured body pose, foot
positions or forces, so its body follows the controller's reference pose (``X_ref`` ...
``roll_ref``, the master's estimate of where the body is), or stands still at the origin
without a gait, its feet come from the kinematics and no force is drawn.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hexadyn import vocabulary
from hexadyn.results import METADATA_FILE, TIMESERIES_FILE, open_series, read_metadata

#: The number of legs is the engine's (:mod:`hexadyn.vocabulary`); the joint names are the
#: robot's (``Run.joints``).
LEGS = len(vocabulary.LEGS)
POSE_COLUMNS = ["X", "Y", "Z", "yaw", "pitch", "roll"]
#: The controller's reference body pose: the body of a run on the robot (no measured pose).
REFERENCE_POSE_COLUMNS = [f"{c}_ref" for c in POSE_COLUMNS]
#: The most recorded instants a :class:`Run` holds (a 500 s run at 100 Hz whole; a 2e4 s run one
#: instant in 40): about 30 MB of poses, feet, forces and phases.
MAX_FRAMES = 50_000


#: The most bytes of a row group decoded at a time (a block of its columns).
READ_BYTES = 16 * 2**20


def joint_columns(joints: vocabulary.Joints) -> list[str]:
    """The robot's three joints per leg, leg by leg (q_r, q_v, q_h on AMRU5): the generalized
    coordinates after the body pose, in the engine's order (Eq. 3.51)."""
    return [f"{j}[{leg}]" for leg in range(LEGS) for j in joints.names]


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
    """A results folder as the viewer sees it: at most `max_frames` recorded instants, evenly
    spread over the run, first and last included (:func:`decimation`).

    Raises :class:`ViewError` naming the folder, file or column when the folder is not a hexadyn
    results folder or lacks a column the scene needs.
    """

    def __init__(self, folder: str | Path, max_frames: int = MAX_FRAMES):
        from hexadyn import _core

        self.folder = Path(folder)
        meta_path = self.folder / METADATA_FILE
        table_path = self.folder / TIMESERIES_FILE
        if not self.folder.is_dir():
            raise ViewError(f"{self.folder}: no such results folder")
        if not meta_path.exists() or not table_path.exists():
            raise ViewError(f"{self.folder}: not a hexadyn results folder (needs {METADATA_FILE} and {TIMESERIES_FILE})")
        try:
            self.metadata = read_metadata(self.folder)
            with open_series(table_path) as file:
                self.columns: list[str] = list(file.schema_arrow.names)
                self._group_rows = [file.metadata.row_group(g).num_rows for g in range(file.num_row_groups)]
        except ValueError as exc:
            raise ViewError(str(exc)) from exc
        if not self.metadata.get("robot"):
            raise ViewError(f"{meta_path}: no robot description (key 'robot')")
        try:
            self.joints = vocabulary.Joints.of_robot(self.metadata["robot"], f"{meta_path} (robot)")
            self.kinematics = _core.Kinematics(self.metadata["robot"], f"{meta_path} (robot)")
        except ValueError as exc:
            raise ViewError(str(exc)) from exc
        self.body_names: list[str] = self.kinematics.body_names
        self.leg_point_names: list[str] = self.kinematics.leg_point_names
        self.geometry: dict = self.kinematics.geometry
        self.name: str = self.metadata.get("scenario_name") or self.folder.name
        #: The instants of the file, and the rows of it held (indices into the file).
        self.instants = sum(self._group_rows)
        if self.instants < 1:
            raise ViewError(f"{table_path}: no rows")
        self.rows = decimation(self.instants, max_frames)

        # Where the body pose comes from (`body_source`): "recorded", "reference" (the
        # controller's, a run on the robot) or "still" (neither).
        if self._present(POSE_COLUMNS):
            pose, self.body_source = POSE_COLUMNS, "recorded"
        elif all(c in self.columns for c in REFERENCE_POSE_COLUMNS):
            pose, self.body_source = REFERENCE_POSE_COLUMNS, "reference"
        else:
            pose, self.body_source = [], "still"
        self.has_feet = self._present(FOOT_COLUMNS)
        self.has_forces = self._present(FORCE_COLUMNS)
        self.has_phases = self._present(PHASE_COLUMNS)
        self.has_reference = self._present(REFERENCE_COLUMNS)
        joints = joint_columns(self.joints)
        wanted = ["t", *pose, *joints]
        wanted += FOOT_COLUMNS if self.has_feet else []
        wanted += FORCE_COLUMNS if self.has_forces else []
        wanted += PHASE_COLUMNS if self.has_phases else []
        wanted += REFERENCE_COLUMNS if self.has_reference else []
        data = self.read(wanted)
        self.t = data["t"]
        self.q = _held(np.column_stack([data[c] for c in [*pose, *joints]]))
        if not pose:
            self.q = np.column_stack([np.zeros((self.t.size, len(POSE_COLUMNS))), self.q])
            self.q[:, 2] = -self.kinematics.leg_points(self.q[:1])[0, :, -1, 2].min()  # the feet on the ground
        n = self.t.size
        self.recorded_feet = np.column_stack([data[c] for c in FOOT_COLUMNS]).reshape(-1, LEGS, 3) if self.has_feet else None
        self.forces = np.column_stack([data[c] for c in FORCE_COLUMNS]).reshape(-1, LEGS, 3) if self.has_forces else np.zeros((n, LEGS, 3))
        if self.has_phases:
            try:
                self.phases = vocabulary.phase_codes(np.column_stack([data[c] for c in PHASE_COLUMNS]), PHASE_COLUMNS, self.t)
            except ValueError as exc:
                raise ViewError(f"{self.folder / TIMESERIES_FILE}: {exc}") from None
        else:
            self.phases = np.full((n, LEGS), -1, np.int8)
        self.reference_xy = np.column_stack([data["X_ref"], data["Y_ref"]]) if self.has_reference else None

    def _present(self, columns: list[str]) -> bool:
        """Whether the optional `columns` are recorded: all (True) or none (False); ViewError
        naming the missing ones otherwise."""
        missing = [c for c in columns if c not in self.columns]
        if len(missing) < len(columns):
            self._refuse_missing(missing)
        return not missing

    def _refuse_missing(self, missing: list[str]) -> None:
        """ViewError naming the `missing` columns, if any."""
        if missing:
            raise ViewError(f"{self.folder / TIMESERIES_FILE}: missing column{'s' if len(missing) > 1 else ''} {', '.join(missing)}")

    def read(self, columns: list[str]) -> dict[str, np.ndarray]:
        """The given columns at the held rows (:attr:`rows`) as float arrays, read from the
        Parquet file a row group and a block of at most :data:`READ_BYTES` at a time (not kept)."""
        self._refuse_missing([c for c in columns if c not in self.columns])
        out = {c: np.empty(self.rows.size) for c in columns}
        try:
            with open_series(self.folder / TIMESERIES_FILE) as file:
                start = done = 0
                for group, count in enumerate(self._group_rows):
                    end = int(np.searchsorted(self.rows, start + count))
                    if end > done:
                        local = self.rows[done:end] - start
                        step = max(1, READ_BYTES // (8 * count))
                        for k in range(0, len(columns), step):
                            block = file.read_row_group(group, columns=columns[k : k + step], use_threads=False)
                            for c in block.column_names:
                                out[c][done:end] = block.column(c).to_numpy()[local]
                        done = end
                    start += count
        except ValueError as exc:
            raise ViewError(str(exc)) from exc
        return out

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
        """Where the feet touched down (K, 3): the foot positions (recorded, else from the
        kinematics) at each start of a support phase (phase 0), or of a contact (F_z > 0) in
        runs without a gait; none in a run with neither."""
        if self.has_phases:
            down = self.phases == 0
        elif self.has_forces:
            down = self.forces[:, :, 2] > 0.0
        else:
            return np.zeros((0, 3))
        starts = down.copy()
        starts[1:] &= ~down[:-1]
        rows, legs = np.nonzero(starts)
        if self.recorded_feet is not None:
            return self.recorded_feet[rows, legs]
        return self.kinematics.leg_points(self.q[rows])[np.arange(rows.size), legs, -1]


def _held(values: np.ndarray) -> np.ndarray:
    """`values` (N, K) with each row holding a NaN (a period a run on the robot missed) replaced
    by the last row without (the first complete row before any)."""
    complete = ~np.isnan(values).any(axis=1)
    if complete.all() or not complete.any():
        return values
    last = np.maximum.accumulate(np.where(complete, np.arange(len(values)), -1))
    return values[np.where(last < 0, np.argmax(complete), last)]


def decimation(count: int, budget: int) -> np.ndarray:
    """Indices of at most `budget` evenly spread rows of `count`, first and last included."""
    if count <= budget:
        return np.arange(count)
    return np.unique(np.linspace(0, count - 1, budget).round().astype(np.int64))
