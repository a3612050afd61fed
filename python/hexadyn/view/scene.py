"""The 3D scene of a run in a viser scene: terrain, paths and footholds (drawn once) and the
robot, its feet and the ground forces (moved to each frame).

Every part of the robot is placed at the world pose the engine's kinematics gives its body
(:meth:`hexadyn.view.data.Run.frame`): the main body, the six leg chassis and the four
pantograph links of each leg, sized from the robot description (pantograph lengths, leg angles,
R_rot, the chassis offsets), so another robot description shows as itself.
"""

from __future__ import annotations

import numpy as np
import viser
from viser import transforms as tf

from hexadyn.view.data import LEGS, Frame, Run, decimation
from hexadyn.vocabulary import FAILED, LANDING, SUPPORT, SWING, TAKEOFF

#: Colours (RGB 0-255).
BODY_COLOUR = (70, 90, 120)
CHASSIS_COLOUR = (120, 130, 145)
LINK_COLOURS = ((205, 160, 60), (150, 150, 150), (150, 150, 150), (215, 120, 40))
#: Foot colour per phase code (support, takeoff, swing, landing, a failed leg held up by the free
#: gait) and without a gait (-1).
PHASE_COLOURS = {SUPPORT: (30, 30, 30), TAKEOFF: (240, 170, 0), SWING: (230, 60, 40), LANDING: (40, 150, 230), FAILED: (160, 160, 160), -1: (30, 30, 30)}
PATH_COLOUR = (20, 50, 200)
GRID_COLOUR = (150, 150, 150)
TERRAIN_COLOUR = (185, 170, 140)
REFERENCE_COLOUR = (130, 210, 130)
FOOTHOLD_COLOUR = (120, 60, 160)
FORCE_COLOUR = (220, 30, 120)

#: Ground force arrows: metres per newton (the weight, 340 N, on three feet: about 0.17 m each).
FORCE_SCALE_M_PER_N = 1.5e-3
#: Link cross-section (m) and foot sphere radius (m).
LINK_WIDTH = 0.014
FOOT_RADIUS = 0.012
FOOTHOLD_RADIUS = 0.012
#: Initial camera: offset from the body's start (m), looking at it.
CAMERA_OFFSET = np.array([-0.9, -1.4, 0.8])
#: Ground marks: a cross of GRID_CROSS (m) every GRID_STEP (m).
GRID_STEP = 0.5
GRID_CROSS = 0.08
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
        start = run.q[0, :3]
        server.initial_camera.position = tuple(start + CAMERA_OFFSET)
        server.initial_camera.look_at = tuple(start)
        server.initial_camera.up = (0.0, 0.0, 1.0)
        # Shadows and image-based lighting cost tens of milliseconds a frame in software WebGL.
        scene.configure_default_lights(cast_shadow=False)
        scene.configure_environment_map(hdri=None)
        scene.add_light_hemisphere("/light", sky_color=(255, 255, 255), ground_color=(140, 130, 120), intensity=2.5)
        g = run.geometry
        names = run.body_names
        self._chassis = [names.index(f"leg{leg}.chassis") for leg in range(LEGS)]
        self._links = [names.index(f"leg{leg}.link{k}") for k in range(4) for leg in range(LEGS)]
        lengths = [g["l0"], g["l1"], g["l2"], g["l3"]]
        # Each link is a box from its first joint (A, B, D, C: at -cog along its x axis) over its length.
        self._link_start = np.repeat(-np.asarray(g["link_cog"]), LEGS)
        link_scales = np.array([[lengths[k], LINK_WIDTH, LINK_WIDTH] for k in range(4) for _ in range(LEGS)], dtype=np.float32)
        link_colours = np.array([LINK_COLOURS[k] for k in range(4) for _ in range(LEGS)], dtype=np.uint8)

        self._add_static(scene)
        first = run.frame(0)
        angles = np.asarray(g["leg_angles"])
        order = np.argsort(angles)
        hexagon = 1.08 * g["r_rot"] * np.column_stack([np.cos(angles[order]), np.sin(angles[order])])
        self.body = scene.add_frame("/robot", show_axes=False)
        scene.add_mesh_simple("/robot/plate", *_prism(hexagon, -0.025, 0.025), color=BODY_COLOUR)
        scene.add_frame("/robot/axes", axes_length=0.12, axes_radius=0.004)
        hip, crossing = -np.asarray(g["chassis_cog"]), np.asarray(g["crossing_point"])
        chassis_box = _box(hip[0], crossing[0] + 0.015, -0.02, 0.02, crossing[2] - 0.015, hip[2] + 0.01)
        identity = np.tile([1.0, 0.0, 0.0, 0.0], (LEGS, 1))
        self.chassis = scene.add_batched_meshes_simple("/legs/chassis", *chassis_box, batched_wxyzs=identity, batched_positions=np.zeros((LEGS, 3)), batched_colors=CHASSIS_COLOUR)
        unit = _box(0.0, 1.0, -0.5, 0.5, -0.5, 0.5)
        count = 4 * LEGS
        self.links = scene.add_batched_meshes_simple(
            "/legs/links", *unit, batched_wxyzs=np.tile([1.0, 0.0, 0.0, 0.0], (count, 1)), batched_positions=np.zeros((count, 3)), batched_scales=link_scales, batched_colors=link_colours
        )
        sphere = _icosphere(FOOT_RADIUS)
        self.feet = scene.add_batched_meshes_simple("/legs/feet", *sphere, batched_wxyzs=identity, batched_positions=np.zeros((LEGS, 3)), batched_colors=np.array([PHASE_COLOURS[0]] * LEGS, dtype=np.uint8))
        self.forces = scene.add_arrows("/forces", points=np.zeros((LEGS, 2, 3)), colors=FORCE_COLOUR, shaft_radius=0.006, head_radius=0.013, head_length=0.03)
        self.show(first)

    def _add_static(self, scene: viser.SceneApi) -> None:
        """Terrain, the reference and actual body paths and the footholds. Plain meshes: viser's
        grid and line primitives cost several times more per frame in software WebGL."""
        run = self.run
        path = run.body_path()
        keep = decimation(len(path), PATH_POINTS)
        holds = run.footholds()
        extent = np.vstack([path[:, :2], holds[:, :2]]) if len(holds) else path[:, :2]
        lo, hi = np.floor(extent.min(axis=0) - 1.0), np.ceil(extent.max(axis=0) + 1.0)
        # Terrain: the flat ground z = 0 of the contact model, marked with a cross every 0.5 m
        # (a lit ground plane or grid lines across the view cost half the frame rate in
        # software WebGL).
        xs, ys = np.meshgrid(np.arange(lo[0], hi[0] + 1e-9, GRID_STEP), np.arange(lo[1], hi[1] + 1e-9, GRID_STEP))
        arm = np.array([GRID_CROSS / 2, 0.0])
        crosses = [np.array([c - arm, c + arm]) for c in np.column_stack([xs.ravel(), ys.ravel()])]
        crosses += [np.array([c - arm[::-1], c + arm[::-1]]) for c in np.column_stack([xs.ravel(), ys.ravel()])]
        scene.add_mesh_simple("/terrain", *_ribbons(crosses, 0.004, 0.0), color=GRID_COLOUR, cast_shadow=False, side="double")
        # A ground that is not flat (a step, a slope, a mesh): its triangles, under the marks,
        # shaded per face so that a step's riser and a slope stand out from the level ground.
        surface = run.terrain((lo + hi) / 2, float(np.max(hi - lo)) / 2)
        if surface is not None:
            scene.add_mesh_simple("/terrain/surface", *surface, color=TERRAIN_COLOUR, flat_shading=True, cast_shadow=False, side="double")
        if len(keep) > 1:
            scene.add_mesh_simple("/paths/body", *_ribbons([path[keep, :2]], 0.01, 0.003), color=PATH_COLOUR, cast_shadow=False, side="double")
        if run.reference_xy is not None and len(keep) > 1:
            scene.add_mesh_simple("/paths/reference", *_ribbons([run.reference_xy[keep]], 0.04, 0.002), color=REFERENCE_COLOUR, cast_shadow=False, side="double")
        if len(holds):
            scene.add_mesh_simple("/footholds", *_discs(holds[:, :2], FOOTHOLD_RADIUS, 0.001), color=FOOTHOLD_COLOUR, cast_shadow=False, side="double")

    def show(self, frame: Frame) -> None:
        """Moves the robot, its feet and the force arrows to `frame`."""
        self.body.position = frame.body_position
        self.body.wxyz = _wxyz(frame.body_rotation)
        self.chassis.batched_positions = frame.positions[self._chassis]
        self.chassis.batched_wxyzs = _wxyz(frame.rotations[self._chassis])
        rotations = frame.rotations[self._links]
        self.links.batched_positions = frame.positions[self._links] + rotations[:, :, 0] * self._link_start[:, None]
        self.links.batched_wxyzs = _wxyz(rotations)
        feet = frame.feet
        self.feet.batched_positions = feet
        self.feet.batched_colors = np.array([PHASE_COLOURS.get(int(p), PHASE_COLOURS[-1]) for p in frame.phases], dtype=np.uint8)
        self.forces.points = np.stack([feet, feet + FORCE_SCALE_M_PER_N * frame.forces], axis=1)


def _icosphere(radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of a once-subdivided icosahedron of the given radius."""
    import trimesh

    mesh = trimesh.creation.icosphere(subdivisions=1, radius=radius)
    return mesh.vertices.astype(np.float32), mesh.faces.astype(np.uint32)
