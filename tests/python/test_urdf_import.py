"""URDF import: the legs and bodies hexadyn finds in a URDF file, and the one-line errors for
what it cannot model (closed loops, joints without a range, mimic joints, bodies without mass
or with an impossible inertia, legs that are not six chains of three actuated joints, feet
without a sphere)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from hexadyn._core import UrdfHexapod
from urdf_hexapods import random_hexapod


def test_legs_are_numbered_left_even_right_odd_from_the_front():
    robot = UrdfHexapod(random_hexapod(2), "r.urdf")
    assert robot.joint_names[::3] == [f"{side}{row}_coxa_joint" for row in (1, 2, 3) for side in ("l", "r")]
    assert robot.joint_names[:3] == ["l1_coxa_joint", "l1_femur_joint", "l1_tibia_joint"]
    feet = robot.feet(np.zeros(24))
    assert (feet[0::2, 1] > 0).all() and (feet[1::2, 1] < 0).all()
    assert (np.diff(feet[0::2, 0]) < 0).all() and (np.diff(feet[1::2, 0]) < 0).all()
    assert robot.foot_radii == [0.01] * 6


def test_fixed_links_merge_into_their_parent():
    """Moving a link's mass into a fixed child link at the same place changes nothing."""
    urdf = random_hexapod(4)
    ours = UrdfHexapod(urdf, "r.urdf")
    inertial = re.search(r'<link name="l1_foot">(<inertial>.*?</inertial>)', urdf).group(1)
    moved = urdf.replace(f'<link name="l1_foot">{inertial}', '<link name="l1_foot">')
    joint = re.search(r'<joint name="l1_foot_joint".*?</joint>', moved).group(0)
    moved = moved.replace(joint, joint + joint.replace("l1_foot_joint", "l1_extra_joint").replace('<child link="l1_foot"/>', '<child link="l1_extra"/>') + f'<link name="l1_extra">{inertial}</link>')
    theirs = UrdfHexapod(moved, "moved.urdf")
    q = np.random.default_rng(0).uniform(-0.5, 0.5, 24)
    np.testing.assert_allclose(theirs.mass_matrix(q), ours.mass_matrix(q), rtol=1e-12, atol=1e-15)


def _swap(urdf: str, old: str, new: str) -> str:
    assert old in urdf, old
    return urdf.replace(old, new, 1)


def _drop(urdf: str, pattern: str) -> str:
    edited, n = re.subn(pattern, "", urdf, count=1, flags=re.S)
    assert n == 1, pattern
    return edited


BASE = random_hexapod(7)
CASES = {
    "not XML": (BASE[: len(BASE) // 2], r"robot: not a URDF robot \(.*\); allowed: a <robot>"),
    "closed loop": (
        _swap(BASE, "</robot>", '<joint name="loop" type="fixed"><parent link="r1_tibia"/><child link="l1_femur"/></joint></robot>'),
        r'joint "loop": link "l1_femur" is already the child of joint "l1_femur_joint" \(a closed loop\); allowed: a tree',
    ),
    "continuous joint": (_swap(BASE, 'name="r2_femur_joint" type="revolute"', 'name="r2_femur_joint" type="continuous"'), r'joint "r2_femur_joint": type continuous; allowed: revolute and prismatic'),
    "floating joint": (_swap(BASE, 'name="l3_tibia_joint" type="revolute"', 'name="l3_tibia_joint" type="floating"'), r'joint "l3_tibia_joint": type floating'),
    "planar joint": (_swap(BASE, 'name="l2_coxa_joint" type="revolute"', 'name="l2_coxa_joint" type="planar"'), r'joint "l2_coxa_joint": type planar'),
    "mimic joint": (_swap(BASE, '<child link="r3_femur"/>', '<child link="r3_femur"/><mimic joint="r3_coxa_joint"/>'), r'joint "r3_femur_joint": mimics joint "r3_coxa_joint"; allowed: independent joints'),
    "missing inertial": (_drop(BASE, r'(?<=<link name="r1_coxa">)<inertial>.*?</inertial>'), r'link "r1_coxa" \(with the links fixed to it\): mass 0 kg \(a missing <inertial> is a zero mass\); allowed: a positive mass'),
    "zero mass": (re.sub(r'(<link name="l2_femur"><inertial>.*?<mass value=")[^"]*', r"\g<1>0.0", BASE, count=1, flags=re.S), r'link "l2_femur" .*: mass 0 kg'),
    "impossible inertia": (re.sub(r'(<link name="l2_tibia"><inertial>.*?izz=")[^"]*', r"\g<1>-1.0", BASE, count=1, flags=re.S), r'link "l2_tibia" .*: inertia with principal moments .*; allowed: a positive definite tensor'),
    "two-joint leg": (_swap(BASE, 'name="l1_coxa_joint" type="revolute"', 'name="l1_coxa_joint" type="fixed"'), r'the leg of joint "l1_femur_joint" ends after 2 actuated joint\(s\); allowed: a chain of three'),
    "seventh leg": (
        _swap(BASE, "</robot>", '<link name="tail"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link><joint name="tail_joint" type="revolute"><parent link="base_link"/><child link="tail"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'),
        r'link "base_link" \(the base, with the links fixed to it\): 7 actuated joints leave it; allowed: six',
    ),
    "no range": (re.sub(r'(name="r2_coxa_joint".*?<limit lower=")[^"]*', r"\g<1>2.0", BASE, count=1, flags=re.S), r'joint "r2_coxa_joint": limits \[2, .*\]; allowed: a <limit> with finite lower < upper'),
    "foot without sphere": (re.sub(r'(<link name="l3_foot"><inertial>.*?</inertial>)<collision>.*?</collision>', r"\1", BASE, count=1, flags=re.S), r'link "l3_tibia": 0 sphere <collision> on the last link of the leg of joint "l3_coxa_joint"'),
    "two roots": (_swap(BASE, "</robot>", '<link name="stray"/></robot>'), r"robot: 2 root links \(base_link, stray\); allowed: one root link"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_what_cannot_be_modelled_is_refused_in_one_line(case):
    urdf, message = CASES[case]
    with pytest.raises(ValueError) as error:
        UrdfHexapod(urdf, "robots/my.urdf")
    text = str(error.value)
    assert "\n" not in text and text.startswith("robots/my.urdf: "), text
    assert re.search(message, text), text


def test_inspect_reports_legs_masses_and_reachable_workspaces(tmp_path):
    from hexadyn.urdf import inspect, standing_height

    path = tmp_path / "robot.urdf"
    path.write_text(random_hexapod(2))
    robot = UrdfHexapod.from_file(str(path))
    table = inspect(path, lift=0.02)
    assert list(table.index) == list(range(6)) and table.attrs["height_m"] == pytest.approx(standing_height(robot))
    assert table.attrs["mass_kg"] == pytest.approx(robot.base_mass + sum(sum(d["link_masses"]) for d in robot.legs))
    # Mass of the whole model: the multibody's M(q) block of the body translation is m I.
    assert robot.mass_matrix(np.zeros(24))[0, 0] == pytest.approx(table.attrs["mass_kg"], rel=1e-12)
    for leg, row in table.iterrows():
        if row["workspace"]:
            continue
        # The cylinder's centre, at the ground and at the lift, is reached from mid-range.
        z = -table.attrs["height_m"] - robot.legs[leg]["body_from_leg"][2, 3]
        for height in (z, z + 0.02):
            _, reached, distance = robot.inverse(leg, [row["workspace_x_m"], row["workspace_y_m"], height])
            assert reached and distance == 0.0, (leg, height)
    assert table["workspace"].eq("").sum() >= 4, table["workspace"]


def test_the_urdf_command_prints_one_line_per_leg_or_one_error(tmp_path):
    from click.testing import CliRunner

    from hexadyn.cli import cli

    path = tmp_path / "robot.urdf"
    path.write_text(random_hexapod(2))
    result = CliRunner().invoke(cli, ["urdf", str(path), "--lift", "0.01"], prog_name="hexadyn")
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert lines[0].startswith("random_hexapod_2: ") and "six legs of three joints" in lines[0]
    assert sum(line.split()[0] in "012345" for line in lines[2:]) == 6 and "l1_coxa_joint" in result.output
    for args, message in (
        ([str(tmp_path)], "a directory, not a file"),
        ([str(tmp_path / "none.urdf")], "none.urdf"),
        ([str(path), "--height", "nan"], "height = nan: allowed a finite body height > 0"),
        ([str(path), "--lift", "-1"], "lift = -1.0: allowed a finite length >= 0"),
    ):
        result = CliRunner().invoke(cli, ["urdf", *args], prog_name="hexadyn")
        assert result.exit_code == 1 and "Traceback" not in result.output, result.output
        assert result.output.startswith("Error: ") and message in result.output and result.output.count("\n") == 1, result.output


def test_the_urdf_command_writes_an_mjcf_file_mujoco_loads(tmp_path):
    import mujoco
    from click.testing import CliRunner

    from hexadyn.cli import cli

    path = tmp_path / "robot.urdf"
    path.write_text(random_hexapod(6))
    out = tmp_path / "robot.xml"
    result = CliRunner().invoke(cli, ["urdf", str(path), "--mjcf", str(out)], prog_name="hexadyn")
    assert result.exit_code == 0 and f"MJCF: {out}" in result.output, result.output
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.body_mass.sum() == pytest.approx(UrdfHexapod.from_file(str(path)).mass_matrix(np.zeros(24))[0, 0], rel=1e-12)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["robot.urdf", "robot.xml"], "no temporary left"
