"""Random serial hexapods written as URDF, for the tests of the URDF import: six legs of three
actuated joints (coxa, femur, tibia) on a base link, with what real URDF files carry: fixed
mounting links without inertia, inertial frames turned by rpy, joint axes that are not unit
vectors of the frame, a foot link fixed to the tibia with a sphere collision."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

#: Leg mounting yaw angles (deg) and sides: 0, 2, 4 on the left front to rear, 1, 3, 5 on the right.
MOUNT_YAW = (45.0, -45.0, 90.0, -90.0, 135.0, -135.0)


def _vec(v) -> str:
    return " ".join(repr(float(x)) for x in v)


def _inertia(rng, mass: float, size: float) -> str:
    """A physical inertia tensor in random axes, as the attributes of <inertia>: the principal
    moments of a body whose mass has second moments s along its axes, (s_y + s_z, s_x + s_z,
    s_x + s_y), which satisfy the triangle inequality."""
    s = mass * size**2 * rng.uniform(0.01, 0.1, 3)
    principal = np.array([s[1] + s[2], s[0] + s[2], s[0] + s[1]])
    r = Rotation.from_rotvec(rng.normal(size=3)).as_matrix()
    i = r @ np.diag(principal) @ r.T
    return f'ixx="{float(i[0, 0])!r}" ixy="{float(i[0, 1])!r}" ixz="{float(i[0, 2])!r}" iyy="{float(i[1, 1])!r}" iyz="{float(i[1, 2])!r}" izz="{float(i[2, 2])!r}"'


def _inertial(rng, mass: float, size: float, com) -> str:
    rpy = rng.uniform(-0.5, 0.5, 3)
    return (
        f'<inertial><origin xyz="{_vec(com)}" rpy="{_vec(rpy)}"/><mass value="{float(mass)!r}"/>'
        f"<inertia {_inertia(rng, mass, size)}/></inertial>"
    )


def random_hexapod(seed: int, prismatic_tibia: bool = False, tilt: float = 0.15) -> str:
    """A serial hexapod: coxa axis about z (tilted by up to `tilt` rad), femur and tibia axes
    about the leg's y (tilted likewise), random lengths and masses within a real robot's range;
    the tibia slides along its link instead when `prismatic_tibia`."""
    rng = np.random.default_rng(seed)
    parts = [f'<robot name="random_hexapod_{seed}">']
    base_mass = rng.uniform(1.0, 3.0)
    parts.append(f'<link name="base_link">{_inertial(rng, base_mass, 0.15, rng.uniform(-0.02, 0.02, 3))}</link>')
    for leg, yaw in enumerate(MOUNT_YAW):
        side = "l" if leg % 2 == 0 else "r"
        name = f"{side}{leg // 2 + 1}"
        radius = rng.uniform(0.08, 0.14)
        a = np.radians(yaw)
        mount = [radius * np.cos(a), radius * np.sin(a), rng.uniform(-0.01, 0.01)]
        coxa, femur, tibia = rng.uniform(0.03, 0.06), rng.uniform(0.06, 0.12), rng.uniform(0.10, 0.18)

        def axis(nominal):
            v = np.asarray(nominal, float) + rng.uniform(-tilt, tilt, 3)
            return v / np.linalg.norm(v)

        parts.append(f'<link name="{name}_mount"/>')
        parts.append(
            f'<joint name="{name}_mount_joint" type="fixed"><parent link="base_link"/><child link="{name}_mount"/>'
            f'<origin xyz="{_vec(mount)}" rpy="0 0 {float(a)!r}"/></joint>'
        )
        links = [("coxa", coxa, rng.uniform(0.05, 0.15)), ("femur", femur, rng.uniform(0.05, 0.2)), ("tibia", tibia, rng.uniform(0.03, 0.12))]
        parent, origin = f"{name}_mount", [0.0, 0.0, 0.0]
        for k, (part, length, mass) in enumerate(links):
            parts.append(f'<link name="{name}_{part}">{_inertial(rng, mass, length, [length / 2, rng.uniform(-0.005, 0.005), rng.uniform(-0.005, 0.005)])}</link>')
            kind = "prismatic" if (prismatic_tibia and part == "tibia") else "revolute"
            if kind == "prismatic":
                ax, limit = axis([1.0, 0.0, 0.0]), '<limit lower="-0.03" upper="0.03" effort="10" velocity="0.1"/>'
            else:
                ax = axis([0.0, 0.0, 1.0] if part == "coxa" else [0.0, 1.0, 0.0])
                limit = f'<limit lower="{-float(rng.uniform(0.6, 1.2))!r}" upper="{float(rng.uniform(0.6, 1.2))!r}" effort="3" velocity="5"/>'
            rpy = rng.uniform(-0.2, 0.2, 3) if k else [0.0, 0.0, 0.0]
            parts.append(
                f'<joint name="{name}_{part}_joint" type="{kind}"><parent link="{parent}"/><child link="{name}_{part}"/>'
                f'<origin xyz="{_vec(origin)}" rpy="{_vec(rpy)}"/><axis xyz="{_vec(ax)}"/>{limit}</joint>'
            )
            parent, origin = f"{name}_{part}", [length, 0.0, 0.0]
        foot_mass = rng.uniform(0.005, 0.02)
        sphere = [rng.uniform(-0.002, 0.002), 0.0, rng.uniform(-0.002, 0.002)]
        parts.append(
            f'<link name="{name}_foot">{_inertial(rng, foot_mass, 0.01, [0.0, 0.0, 0.0])}'
            f'<collision><origin xyz="{_vec(sphere)}"/><geometry><sphere radius="0.01"/></geometry></collision></link>'
        )
        parts.append(
            f'<joint name="{name}_foot_joint" type="fixed"><parent link="{name}_tibia"/><child link="{name}_foot"/>'
            f'<origin xyz="{_vec(origin)}" rpy="{_vec(rng.uniform(-0.3, 0.3, 3))}"/></joint>'
        )
    parts.append("</robot>")
    return "\n".join(parts)
