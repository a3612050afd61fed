"""A serial hexapod read from URDF, as hexadyn models it (``hexadyn urdf ROBOT.urdf``): the
legs it finds (six chains of three actuated joints from the base, fixed joints merged,
numbered the thesis way: 0, 2, 4 on the left from front to rear, 1, 3, 5 on the right), their
joints, masses and feet, and each leg's workspace cylinder (Section 7.1.1) for a standing
height. The rigid-body model behind it is :class:`hexadyn._core.UrdfHexapod` (mass matrix,
nonlinear effects, feet and foot Jacobians; checked against Pinocchio on the same file)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from hexadyn import inputs

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["export_mjcf", "export_urdf", "import_urdf", "inspect", "standing_height", "write_mjcf"]


def standing_height(robot) -> float:
    """The default standing height (m): the body height at which the feet, with every joint at
    the middle of its range, touch flat ground, i.e. minus the lowest foot in the body frame
    (the base link's origin) at mid-range."""
    q = np.zeros(robot.coordinates)
    for leg, description in enumerate(robot.legs):
        q[6 + 3 * leg : 9 + 3 * leg] = (np.asarray(description["lower"]) + np.asarray(description["upper"])) / 2
    return float(-robot.feet(q)[:, 2].min())


def inspect(path: str | os.PathLike, height: float | None = None, lift: float = 0.0) -> pd.DataFrame:
    """One row per leg: its joints (URDF names, kinds, ranges), link masses, foot radius, and
    the workspace cylinder for a level body at `height` (m, default :func:`standing_height`)
    with feet lifted up to `lift` (m): centre (x, y) and radius in the leg frame (m), or the
    reason there is none. ValueError (one line) for a file hexadyn cannot model."""
    import pandas as pd

    from hexadyn._core import UrdfHexapod

    if not (lift >= 0 and np.isfinite(lift)):
        raise ValueError(f"lift = {lift!r}: allowed a finite length >= 0 (m)")
    robot = UrdfHexapod.from_file(os.fspath(path))
    h = standing_height(robot) if height is None else float(height)
    if not (h > 0 and np.isfinite(h)):
        raise ValueError(f"height = {height!r}: allowed a finite body height > 0 (m)")
    rows = []
    for leg, d in enumerate(robot.legs):
        row = {"leg": leg, "joints": ", ".join(d["joints"]), "kinds": ", ".join(d["kinds"])}
        row["ranges"] = ", ".join(f"[{lo:.3g}, {hi:.3g}]" for lo, hi in zip(d["lower"], d["upper"]))
        row["mass_kg"] = float(sum(d["link_masses"]))
        row["foot_radius_m"] = d["foot_radius"]
        # The foot on flat ground under a level body at height h is at z = -h in the body
        # frame, -h - z_l in the leg frame whose origin is at height z_l of the body frame.
        z = -h - float(d["body_from_leg"][2, 3])
        try:
            w = robot.workspace(leg, z, z + lift)
            row.update(workspace_x_m=w["centre"][0], workspace_y_m=w["centre"][1], workspace_radius_m=w["radius"], workspace="")
        except ValueError as exc:
            row.update(workspace_x_m=np.nan, workspace_y_m=np.nan, workspace_radius_m=np.nan, workspace=str(exc))
        rows.append(row)
    table = pd.DataFrame(rows).set_index("leg")
    table.attrs.update(name=robot.name, mass_kg=float(robot.base_mass + table["mass_kg"].sum()), height_m=h, lift_m=lift)
    return table


def write_mjcf(urdf: str | os.PathLike, out: str | os.PathLike) -> Path:
    """Writes the robot of a URDF file as MuJoCo MJCF (:meth:`hexadyn._core.UrdfHexapod.to_mjcf`:
    the bodies, joints, ranges and inertias hexadyn simulates, fixed links merged, foot spheres
    and sites ``foot0`` ... ``foot5``) to `out`, atomically; returns `out`."""
    from hexadyn import atomic
    from hexadyn._core import UrdfHexapod

    text = UrdfHexapod.from_file(os.fspath(urdf)).to_mjcf()
    target = Path(out)
    atomic.write_file(target, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    return target


def import_urdf(
    urdf: str | os.PathLike,
    out: str | os.PathLike,
    joint_names: tuple[str, str, str] = ("coxa", "femur", "tibia"),
    drives: str | os.PathLike | None = None,
    overwrite: bool = False,
) -> Path:
    """Writes a hexadyn robot description (``docs/robot-format.md``) of the hexapod of a URDF
    file to `out`, atomically, and returns `out`: the mechanism as hexadyn reads it (the six
    legs numbered the thesis way, fixed links merged, the foot spheres), the per-leg joint
    names `joint_names` (the results' columns), and the drives, controller and ground of the
    serial robot description `drives` (default: the shipped PhantomX's Dynamixel AX-12A,
    ``robots/phantomx/phantomx.toml``), joint by joint in order: replace them with your robot's.
    The written file is read back by the engine before it is kept. ValueError (one line) for a
    file hexadyn cannot model, an existing `out` without `overwrite`, or bad names."""
    from hexadyn import atomic
    from hexadyn._core import UrdfHexapod, shipped_robot_text

    names = list(joint_names)
    if len(names) != 3:
        raise ValueError(f"joint names = {joint_names!r}: allowed three names, one per joint of a leg from the body to the foot")
    target = Path(out)
    if target.exists() and not overwrite:
        raise ValueError(f"{target}: exists; allowed: a new file, or --overwrite")
    if drives is None:
        template, origin = shipped_robot_text("phantomx"), "the shipped PhantomX description (robots/phantomx/phantomx.toml)"
    else:
        origin = os.fspath(drives)
        try:
            template = inputs.read_text(drives)
        except OSError as exc:
            raise ValueError(f"{origin}: cannot read the drives' description: {exc}") from None
    robot = UrdfHexapod.from_file(os.fspath(urdf))
    header = (
        f"# {robot.name}: imported from {Path(urdf).name} by `hexadyn import-urdf`.\n"
        f"# The drives, controller and ground are those of {origin}:\n"
        "# replace them with your robot's (docs/robot-format.md).\n\n"
    )
    text = header + robot.description_toml(names, template, origin)
    atomic.write_file(target, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    return target


def _robot_text(robot: str | os.PathLike, out: str | os.PathLike, overwrite: bool) -> tuple[str, str, Path]:
    """(description text, its name for errors, the output path) of an export: a shipped robot
    name or a description file; ValueError (one line) for an unreadable file or an existing
    `out` without `overwrite`."""
    from hexadyn._core import shipped_robot_text

    target = Path(out)
    if target.exists() and not overwrite:
        raise ValueError(f"{target}: exists; allowed: a new file, or --overwrite")
    name = os.fspath(robot)
    try:
        return shipped_robot_text(name), name, target
    except ValueError:
        try:
            return inputs.read_text(robot), name, target
        except OSError as exc:
            raise ValueError(f"{name}: cannot read the robot description: {exc}") from None


def export_urdf(robot: str | os.PathLike, out: str | os.PathLike, overwrite: bool = False) -> Path:
    """Writes a serial robot (a shipped name such as ``"phantomx"`` or a description file) as
    URDF to `out`, atomically, and returns `out`: ``base_link``, a link per joint with its
    inertial, the joints with their ranges and the drives' stall torque and no-load speed as
    limits, the foot spheres as collisions (``SerialRobot::to_urdf``; the importer reads it back
    as the same mechanism). ValueError (one line) for a pantograph robot, an unreadable file or
    an existing `out` without `overwrite`."""
    from hexadyn import atomic
    from hexadyn._core import robot_urdf

    text, origin, target = _robot_text(robot, out, overwrite)
    urdf = robot_urdf(text, origin)
    atomic.write_file(target, lambda tmp: tmp.write_text(urdf, encoding="utf-8"))
    return target


def export_mjcf(robot: str | os.PathLike, out: str | os.PathLike, overwrite: bool = False) -> Path:
    """Writes a robot of either leg mechanism (a shipped name or a description file) as MuJoCo
    MJCF to `out`, atomically, and returns `out`: a serial robot's links, or a pantograph
    robot's 49 bodies with the linkage loops as ``connect`` equality constraints and the rotors
    coupled to their joints (``description::mjcf``). ValueError (one line) for an invalid or
    unreadable description or an existing `out` without `overwrite`."""
    from hexadyn import atomic
    from hexadyn._core import robot_mjcf

    text, origin, target = _robot_text(robot, out, overwrite)
    mjcf = robot_mjcf(text, origin)
    atomic.write_file(target, lambda tmp: tmp.write_text(mjcf, encoding="utf-8"))
    return target
