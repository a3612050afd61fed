"""The 3D scene of a run in a viser scene: terrain, paths and footholds (drawn once) and the
robot, its feet and the ground forces (moved to each frame).

Every part of the robot is placed at the world pose the engine's kinematics gives its body
(:meth:`hexadyn.view.data.Run.frame`), sized from the robot description, so another robot
description shows as itself:

- AMRU5's pantograph legs: the main body, the six leg chassis and the four pantograph links of
  each leg (pantograph lengths, leg angles, R_rot, the chassis offsets);
- serial legs: the main body as a plate over the legs' mounts, each leg's links as boxes from
  each joint's origin to the next and from the last joint to the foot (one batched node per
  joint, named after the robot's joint, e.g. ``/legs/femur``), the foot spheres at the
  description's radius.

The sizes of what has no size in the description (link widths, force arrows, the camera's
distance, marks on the ground) are AMRU5's, scaled to the robot by :func:`robot_scale`.
"""

from __future__ import annotations

import numpy as np
import viser
from viser import transforms as tf

import functools

from hexadyn.view.data import LEGS, Frame, Run, decimation
from hexadyn.vocabulary import FAILED, LANDING, SUPPORT, SWING, TAKEOFF

#: Colours (RGB 0-255).
BODY_COLOUR = (70, 90, 120)
CHASSIS_COLOUR = (120, 130, 145)
LINK_COLOURS = ((205, 160, 60), (150, 150, 150), (150, 150, 150), (215, 120, 40))
#: The links of a serial leg, from the body to the foot.
SERIAL_LINK_COLOURS = ((205, 160, 60), (215, 120, 40), (225, 170, 70))
#: Foot colour per phase code (support, takeoff, swing, landing, a failed leg held up by the free
#: gait) and without a gait (-1).
PHASE_COLOURS = {SUPPORT: (30, 30, 30), TAKEOFF: (240, 170, 0), SWING: (230, 60, 40), LANDING: (40, 150, 230), FAILED: (160, 160, 160), -1: (30, 30, 30)}
PATH_COLOUR = (20, 50, 200)
GRID_COLOUR = (150, 150, 150)
TERRAIN_COLOUR = (185, 170, 140)
REFERENCE_COLOUR = (130, 210, 130)
FOOTHOLD_COLOUR = (120, 60, 160)
FORCE_COLOUR = (220, 30, 120)

#: Sizes at the scale of AMRU5 (the shipped robots/amru5.toml), multiplied by
#: :func:`robot_scale` for another robot.
#: Ground force arrows: metres per newton (the weight, 340 N, on three feet: about 0.17 m each);
#: another robot's weight on three feet gives arrows as long relative to its size.
FORCE_SCALE_M_PER_N = 1.5e-3
#: Link cross-section (m) and foot sphere radius (m; a serial robot's feet are drawn at the
#: description's foot radius).
LINK_WIDTH = 0.014
FOOT_RADIUS = 0.012
FOOTHOLD_RADIUS = 0.012
#: Initial camera: offset from the body's start (m), looking at it.
CAMERA_OFFSET = np.array([-0.9, -1.4, 0.8])
#: Ground marks: a cross of GRID_CROSS (m) every GRID_STEP (m).
GRID_STEP = 0.5
GRID_CROSS = 0.08
#: Main body plate thickness (m), body axes length and radius (m).
PLATE_THICKNESS = 0.05
AXES_LENGTH = 0.12
AXES_RADIUS = 0.004
#: Widths of the body path and of the reference path (m).
PATH_WIDTH = 0.01
REFERENCE_WIDTH = 0.04
MARK_WIDTH = 0.004
#: Force arrows: shaft and head radii, head length (m).
ARROW_SHAFT = 0.006
ARROW_HEAD = 0.013
ARROW_HEAD_LENGTH = 0.03


@functools.cache
def _reference_mass() -> float:
    """The mass (kg) of AMRU5, the robot the sizes above are drawn for."""
    from hexadyn import _core

    return float(_core.Kinematics(_core.shipped_robot_text("amru5"), "robots/amru5.toml").geometry["mass_kg"])


def robot_scale(geometry: dict) -> float:
    """The robot's size relative to AMRU5's: the cube root of the ratio of their masses (bodies of
    one density; 1 for AMRU5, about 0.38 for the 1.8 kg PhantomX)."""
    return float(np.cbrt(geometry["mass_kg"] / _reference_mass()))


def force_scale(geometry: dict) -> float:
    """Metres of arrow per newton of ground force: FORCE_SCALE_M_PER_N at AMRU5's size and
    weight, so that the robot's weight on three feet draws arrows as long relative to it."""
    return FORCE_SCALE_M_PER_N * robot_scale(geometry) * _reference_mass() / geometry["mass_kg"]
#: Most points drawn for a path (decimated beyond).
PATH_POINTS = 500


def _wxyz(rotations: np.ndarray) -> np.ndarray:
    """Unit quaternions (w, x, y, z) of rotation matrices (..., 3, 3)."""
    return np.asarray(tf.SO3.from_matrix(rotations).wxyz)


def _box(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and outward triangles of an axis-aligned box."""
    v = np.array([[x, y, z] for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)], dtype=np.float32)
    faces = np.array(
        [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]],
        dtype=np.uint32,
    )
    return v, faces


def _prism(polygon: np.ndarray, z0: float, z1: float) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of a convex polygon (K, 2), counter-clockwise, extruded in z."""
    k = len(polygon)
    bottom = np.column_stack([polygon, np.full(k, z0)])
    top = np.column_stack([polygon, np.full(k, z1)])
    centres = np.array([[*polygon.mean(axis=0), z0], [*polygon.mean(axis=0), z1]])
    vertices = np.vstack([bottom, top, centres]).astype(np.float32)
    cb, ct = 2 * k, 2 * k + 1
    faces = []
    for i in range(k):
        j = (i + 1) % k
        faces += [[cb, j, i], [ct, k + i, k + j], [i, j, k + j], [i, k + j, k + i]]
    return vertices, np.array(faces, dtype=np.uint32)


def _ribbons(polylines: list[np.ndarray], width: float, z: float) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of flat strips `width` wide at height `z` along polylines (K, 2):
    one quad per segment."""
    quads = []
    for points in polylines:
        a, b = points[:-1], points[1:]
        d = b - a
        length = np.linalg.norm(d, axis=1)
        a, b, d, length = a[length > 0], b[length > 0], d[length > 0], length[length > 0]
        side = np.column_stack([-d[:, 1], d[:, 0]]) * (width / 2 / length)[:, None]
        quads.append(np.stack([a + side, a - side, b - side, b + side], axis=1))
    corners = np.concatenate(quads)
    vertices = np.column_stack([corners.reshape(-1, 2), np.full(corners.shape[0] * 4, z)]).astype(np.float32)
    base = 4 * np.arange(corners.shape[0], dtype=np.uint32)[:, None]
    faces = np.concatenate([base + np.array([0, 1, 2], dtype=np.uint32), base + np.array([0, 2, 3], dtype=np.uint32)])
    return vertices, faces


def _discs(centres: np.ndarray, radius: float, z: float, sides: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of flat polygonal discs at height `z` around centres (K, 2)."""
    angles = np.linspace(0.0, 2 * np.pi, sides, endpoint=False)
    ring = radius * np.column_stack([np.cos(angles), np.sin(angles)])
    points = (centres[:, None, :] + ring[None]).reshape(-1, 2)
    vertices = np.column_stack([points, np.full(len(points), z)]).astype(np.float32)
    fan = np.array([[0, i, i + 1] for i in range(1, sides - 1)], dtype=np.uint32)
    faces = (sides * np.arange(len(centres), dtype=np.uint32)[:, None, None] + fan[None]).reshape(-1, 3)
    return vertices, faces


class RobotScene:
    """The scene of one run, with the initial camera on the robot; :meth:`show` moves the robot
    to a frame."""

    def __init__(self, server: viser.ViserServer, run: Run):
        self.run = run
        scene = server.scene
        scene.set_up_direction("+z")
        g = run.geometry
        self.scale = robot_scale(g)
        self.force_scale = force_scale(g)
        self.serial = g["leg_mechanism"] == "serial"
        start = run.q[0, :3]
        server.initial_camera.position = tuple(start + self.scale * CAMERA_OFFSET)
        server.initial_camera.look_at = tuple(start)
        server.initial_camera.up = (0.0, 0.0, 1.0)
        # Shadows and image-based lighting cost tens of milliseconds a frame in software WebGL.
        scene.configure_default_lights(cast_shadow=False)
        scene.configure_environment_map(hdri=None)
        scene.add_light_hemisphere("/light", sky_color=(255, 255, 255), ground_color=(140, 130, 120), intensity=2.5)

        self._add_static(scene)
        first = run.frame(0)
        self.body = scene.add_frame("/robot", show_axes=False)
        if self.serial:
            self._add_serial_legs(scene)
        else:
            self._add_pantograph_legs(scene)
        scene.add_frame("/robot/axes", axes_length=self.scale * AXES_LENGTH, axes_radius=self.scale * AXES_RADIUS)
        identity = np.tile([1.0, 0.0, 0.0, 0.0], (LEGS, 1))
        foot_radius = g["foot_radius"] if self.serial and g["foot_radius"] > 0.0 else self.scale * FOOT_RADIUS
        sphere = _icosphere(foot_radius)
        self.feet = scene.add_batched_meshes_simple("/legs/feet", *sphere, batched_wxyzs=identity, batched_positions=np.zeros((LEGS, 3)), batched_colors=np.array([PHASE_COLOURS[0]] * LEGS, dtype=np.uint8))
        s = self.scale
        self.forces = scene.add_arrows("/forces", points=np.zeros((LEGS, 2, 3)), colors=FORCE_COLOUR, shaft_radius=s * ARROW_SHAFT, head_radius=s * ARROW_HEAD, head_length=s * ARROW_HEAD_LENGTH)
        self.show(first)

    def _add_pantograph_legs(self, scene: viser.SceneApi) -> None:
        """AMRU5's legs: the hexagonal body, the six chassis and the four pantograph links of
        each leg."""
        g = self.run.geometry
        names = self.run.body_names
        width = self.scale * LINK_WIDTH
        self._chassis = [names.index(f"leg{leg}.chassis") for leg in range(LEGS)]
        self._links = [names.index(f"leg{leg}.link{k}") for k in range(4) for leg in range(LEGS)]
        lengths = [g["l0"], g["l1"], g["l2"], g["l3"]]
        # Each link is a box from its first joint (A, B, D, C: at -cog along its x axis) over its length.
        self._link_start = np.repeat(-np.asarray(g["link_cog"]), LEGS)
        link_scales = np.array([[lengths[k], width, width] for k in range(4) for _ in range(LEGS)], dtype=np.float32)
        link_colours = np.array([LINK_COLOURS[k] for k in range(4) for _ in range(LEGS)], dtype=np.uint8)
        angles = np.asarray(g["leg_angles"])
        order = np.argsort(angles)
        hexagon = 1.08 * g["r_rot"] * np.column_stack([np.cos(angles[order]), np.sin(angles[order])])
        half = self.scale * PLATE_THICKNESS / 2
        scene.add_mesh_simple("/robot/plate", *_prism(hexagon, -half, half), color=BODY_COLOUR)
        hip, crossing = -np.asarray(g["chassis_cog"]), np.asarray(g["crossing_point"])
        chassis_box = _box(hip[0], crossing[0] + 0.015, -0.02, 0.02, crossing[2] - 0.015, hip[2] + 0.01)
        identity = np.tile([1.0, 0.0, 0.0, 0.0], (LEGS, 1))
        self.chassis = scene.add_batched_meshes_simple("/legs/chassis", *chassis_box, batched_wxyzs=identity, batched_positions=np.zeros((LEGS, 3)), batched_colors=CHASSIS_COLOUR)
        unit = _box(0.0, 1.0, -0.5, 0.5, -0.5, 0.5)
        count = 4 * LEGS
        self.links = scene.add_batched_meshes_simple(
            "/legs/links", *unit, batched_wxyzs=np.tile([1.0, 0.0, 0.0, 0.0], (count, 1)), batched_positions=np.zeros((count, 3)), batched_scales=link_scales, batched_colors=link_colours
        )

    def _add_serial_legs(self, scene: viser.SceneApi) -> None:
        """Serial legs: a plate over the legs' mounts, and per joint one batched node of the six
        legs' links (``/legs/<joint>``), each a box from the joint's origin to the next joint's
        (the last: to the foot)."""
        g = self.run.geometry
        names = self.run.body_names
        mounts = np.asarray(g["mounts"])
        centre = mounts[:, :2].mean(axis=0)
        order = np.argsort(np.arctan2(mounts[:, 1] - centre[1], mounts[:, 0] - centre[0]))
        half = self.scale * PLATE_THICKNESS / 2
        z = float(mounts[:, 2].mean())
        scene.add_mesh_simple("/robot/plate", *_prism(mounts[order, :2], z - half, z + half), color=BODY_COLOUR)
        joints = self.run.joints.names
        # The body of the link each joint moves (for the boxes' roll about their axis).
        self._serial_links = np.array([[names.index(f"leg{leg}.{g['leg_joint_names'][leg][k]}") for leg in range(LEGS)] for k in range(3)])
        self._link_width = self.scale * LINK_WIDTH
        unit = _box(0.0, 1.0, -0.5, 0.5, -0.5, 0.5)
        identity = np.tile([1.0, 0.0, 0.0, 0.0], (LEGS, 1))
        self.serial_links = [
            scene.add_batched_meshes_simple(
                f"/legs/{joint}", *unit, batched_wxyzs=identity, batched_positions=np.zeros((LEGS, 3)), batched_scales=np.ones((LEGS, 3), dtype=np.float32), batched_colors=SERIAL_LINK_COLOURS[k]
            )
            for k, joint in enumerate(joints)
        ]

    def _add_static(self, scene: viser.SceneApi) -> None:
        """Terrain, the reference and actual body paths and the footholds. Plain meshes: viser's
        grid and line primitives cost several times more per frame in software WebGL."""
        run = self.run
        s = self.scale
        path = run.body_path()
        keep = decimation(len(path), PATH_POINTS)
        holds = run.footholds()
        extent = np.vstack([path[:, :2], holds[:, :2]]) if len(holds) else path[:, :2]
        lo, hi = np.floor(extent.min(axis=0) - 1.0), np.ceil(extent.max(axis=0) + 1.0)
        # Terrain: the flat ground z = 0 of the contact model, marked with a cross every 0.5 m
        # at AMRU5's scale (a lit ground plane or grid lines across the view cost half the
        # frame rate in software WebGL).
        step = s * GRID_STEP
        xs, ys = np.meshgrid(np.arange(lo[0], hi[0] + 1e-9, step), np.arange(lo[1], hi[1] + 1e-9, step))
        arm = np.array([s * GRID_CROSS / 2, 0.0])
        crosses = [np.array([c - arm, c + arm]) for c in np.column_stack([xs.ravel(), ys.ravel()])]
        crosses += [np.array([c - arm[::-1], c + arm[::-1]]) for c in np.column_stack([xs.ravel(), ys.ravel()])]
        scene.add_mesh_simple("/terrain", *_ribbons(crosses, s * MARK_WIDTH, 0.0), color=GRID_COLOUR, cast_shadow=False, side="double")
        # A ground that is not flat (a step, a slope, a mesh): its triangles, under the marks,
        # shaded per face so that a step's riser and a slope stand out from the level ground.
        surface = run.terrain((lo + hi) / 2, float(np.max(hi - lo)) / 2)
        if surface is not None:
            scene.add_mesh_simple("/terrain/surface", *surface, color=TERRAIN_COLOUR, flat_shading=True, cast_shadow=False, side="double")
        if len(keep) > 1:
            scene.add_mesh_simple("/paths/body", *_ribbons([path[keep, :2]], s * PATH_WIDTH, 0.003 * s), color=PATH_COLOUR, cast_shadow=False, side="double")
        if run.reference_xy is not None and len(keep) > 1:
            scene.add_mesh_simple("/paths/reference", *_ribbons([run.reference_xy[keep]], s * REFERENCE_WIDTH, 0.002 * s), color=REFERENCE_COLOUR, cast_shadow=False, side="double")
        if len(holds):
            scene.add_mesh_simple("/footholds", *_discs(holds[:, :2], s * FOOTHOLD_RADIUS, 0.001 * s), color=FOOTHOLD_COLOUR, cast_shadow=False, side="double")

    def show(self, frame: Frame) -> None:
        """Moves the robot, its feet and the force arrows to `frame`."""
        self.body.position = frame.body_position
        self.body.wxyz = _wxyz(frame.body_rotation)
        if self.serial:
            self._show_serial(frame)
        else:
            self.chassis.batched_positions = frame.positions[self._chassis]
            self.chassis.batched_wxyzs = _wxyz(frame.rotations[self._chassis])
            rotations = frame.rotations[self._links]
            self.links.batched_positions = frame.positions[self._links] + rotations[:, :, 0] * self._link_start[:, None]
            self.links.batched_wxyzs = _wxyz(rotations)
        feet = frame.feet
        self.feet.batched_positions = feet
        self.feet.batched_colors = np.array([PHASE_COLOURS.get(int(p), PHASE_COLOURS[-1]) for p in frame.phases], dtype=np.uint8)
        self.forces.points = np.stack([feet, feet + self.force_scale * frame.forces], axis=1)

    def _show_serial(self, frame: Frame) -> None:
        """Each link of a serial leg: a box from its joint's origin to the next point of the leg
        (the next joint's origin, or the foot), turned about that line as the link's body."""
        points = frame.leg_points  # (6, 4, 3): the joints' origins, then the foot
        for k, node in enumerate(self.serial_links):
            start, end = points[:, k], points[:, k + 1]
            rotations, lengths = _segment_frames(start, end, frame.rotations[self._serial_links[k]])
            node.batched_positions = start
            node.batched_wxyzs = _wxyz(rotations)
            node.batched_scales = np.column_stack([np.maximum(lengths, 1e-6), np.full(LEGS, self._link_width), np.full(LEGS, self._link_width)]).astype(np.float32)


def _segment_frames(start: np.ndarray, end: np.ndarray, body: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotations (K, 3, 3) whose x axis points from `start` to `end` (K, 3) and whose y axis is
    the body's (K, 3, 3) y axis, or its z axis when that lies along the segment, made
    perpendicular; and the segments' lengths. A zero-length segment keeps the body's rotation."""
    d = end - start
    lengths = np.linalg.norm(d, axis=1)
    frames = body.copy()
    for i in np.nonzero(lengths > 1e-12)[0]:
        x = d[i] / lengths[i]
        for guess in (body[i][:, 1], body[i][:, 2], body[i][:, 0]):
            y = guess - (guess @ x) * x
            if np.linalg.norm(y) > 1e-6:
                break
        y = y / np.linalg.norm(y)
        frames[i] = np.column_stack([x, y, np.cross(x, y)])
    return frames, lengths


def _icosphere(radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of a once-subdivided icosahedron of the given radius."""
    import trimesh

    mesh = trimesh.creation.icosphere(subdivisions=1, radius=radius)
    return mesh.vertices.astype(np.float32), mesh.faces.astype(np.uint32)
