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

#: Colours (RGB 0-255).
BODY_COLOUR = (70, 90, 120)
CHASSIS_COLOUR = (120, 130, 145)
LINK_COLOURS = ((205, 160, 60), (150, 150, 150), (150, 150, 150), (215, 120, 40))
#: Foot colour per phase code (0 support, 1 takeoff, 2 swing, 3 landing) and without a gait.
PHASE_COLOURS = {0: (30, 30, 30), 1: (240, 170, 0), 2: (230, 60, 40), 3: (40, 150, 230), -1: (30, 30, 30)}
PATH_COLOUR = (30, 100, 220)
REFERENCE_COLOUR = (40, 170, 60)
FOOTHOLD_COLOUR = (120, 60, 160)
FORCE_COLOUR = (220, 30, 120)

#: Ground force arrows: metres per newton (the weight, 340 N, on three feet: about 0.17 m each).
FORCE_SCALE_M_PER_N = 1.5e-3
#: Link cross-section (m) and foot sphere radius (m).
LINK_WIDTH = 0.014
FOOT_RADIUS = 0.012
#: Initial camera: offset from the body's start (m), looking at it.
CAMERA_OFFSET = np.array([-0.9, -1.4, 0.8])
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
        """Terrain, the reference and actual body paths and the footholds."""
        run = self.run
        path = run.body_path()
        keep = decimation(len(path), PATH_POINTS)
        ground = path[keep].copy()
        ground[:, 2] = 0.004
        holds = run.footholds()
        extent = np.vstack([path[:, :2], holds[:, :2]]) if len(holds) else path[:, :2]
        lo, hi = extent.min(axis=0) - 1.0, extent.max(axis=0) + 1.0
        centre = (lo + hi) / 2
        size = np.ceil(hi - lo)
        # Terrain: the flat ground z = 0 of the contact model.
        scene.add_grid("/terrain", width=float(size[0]), height=float(size[1]), plane="xy", cell_size=0.1, section_size=1.0, plane_color=(235, 232, 225), plane_opacity=1.0, position=(float(centre[0]), float(centre[1]), 0.0))
        if len(ground) > 1:
            scene.add_line_segments("/paths/body", np.stack([ground[:-1], ground[1:]], axis=1), colors=PATH_COLOUR, thickness=2.0, thickness_units="screen")
        if run.reference_xy is not None:
            ref = run.reference_xy[keep]
            ref3 = np.column_stack([ref, np.full(len(ref), 0.002)])
            if len(ref3) > 1:
                scene.add_line_segments("/paths/reference", np.stack([ref3[:-1], ref3[1:]], axis=1), colors=REFERENCE_COLOUR, thickness=6.0, thickness_units="screen")
        if len(holds):
            marks = holds.copy()
            marks[:, 2] = np.maximum(marks[:, 2], 0.0) + 0.001
            scene.add_point_cloud("/footholds", points=marks.astype(np.float32), colors=FOOTHOLD_COLOUR, point_size=0.02, point_shape="circle")

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
