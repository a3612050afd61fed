"""`hexadyn import-urdf`: a robot description written from a URDF file is the robot the URDF
describes, with the drives it was given: the shipped PhantomX imported again from its URDF
simulates bit for bit as the shipped description, a random URDF hexapod imported stands under
its servos, and what cannot be imported is refused in one line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import hexadyn
import hexadyn.urdf
from hexadyn._core import shipped_robot_text
from hexadyn.cli import cli
from urdf_hexapods import random_hexapod

ROOT = Path(__file__).resolve().parents[2]
PHANTOMX_URDF = ROOT / "robots" / "phantomx" / "phantomx.urdf"


def _stand(robot: Path, tmp_path: Path, duration: float = 1.0) -> hexadyn.Results:
    scenario = tmp_path / "stand.toml"
    text = (ROOT / "python/hexadyn/scenarios/phantomx_stand.toml").read_text()
    scenario.write_text(text.replace('robot = "phantomx"', f'robot = "{robot}"').replace("duration_s = 5.0", f"duration_s = {duration}"))
    return hexadyn.simulate(scenario, progress=False)


def test_the_phantomx_imported_from_its_urdf_is_the_shipped_robot(tmp_path):
    out = tmp_path / "phantomx.toml"
    result = CliRunner().invoke(cli, ["import-urdf", str(PHANTOMX_URDF), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "Robot description" in result.output
    # The drives default to the shipped PhantomX's: the imported robot is the shipped one.
    imported = _stand(out, tmp_path)
    shipped = hexadyn.simulate("phantomx_stand", progress=False, overrides={"scenario.duration_s": 1.0})
    a, b = imported.timeseries, shipped.timeseries
    assert list(a.columns) == list(b.columns)
    np.testing.assert_array_equal(a.to_numpy(), b.to_numpy())


def test_an_imported_random_hexapod_stands_under_its_servos(tmp_path):
    urdf = tmp_path / "random.urdf"
    urdf.write_text(random_hexapod(1))
    out = hexadyn.urdf.import_urdf(urdf, tmp_path / "random.toml", ("hip", "thigh", "shank"))
    r = _stand(out, tmp_path)
    assert {"hip[0]", "thigh[5]", "shank[3]"} <= set(r.timeseries.columns)
    s = r.summary
    # The servos' compliance lets it sag (the AX-12A's slope: 9.4 degrees to full torque, for a
    # robot heavier than the PhantomX), to a standstill well above the ground.
    ts = r.timeseries
    assert abs(s["body_height_change_m"]) < 0.25 * s["initial_body_height_m"], (s["body_height_change_m"], s["initial_body_height_m"])
    assert abs(ts["Z_dot"].iloc[-1]) < 1e-3 and abs(ts["pitch"].iloc[-1]) < 0.05 and abs(ts["roll"].iloc[-1]) < 0.05
    assert abs(s["energy_balance_error_relative"]) < 1e-3 or s["energy_electrical_j"] == 0.0


def test_what_cannot_be_imported_is_refused_in_one_line(tmp_path):
    out = tmp_path / "r.toml"
    out.write_text("taken")
    runner = CliRunner()
    cases = [
        (["import-urdf", str(PHANTOMX_URDF), "--out", str(out)], "exists"),
        (["import-urdf", str(PHANTOMX_URDF), "--out", str(tmp_path / "a.toml"), "--joint-names", "coxa,femur"], "three names"),
        (["import-urdf", str(PHANTOMX_URDF), "--out", str(tmp_path / "b.toml"), "--joint-names", "coxa,coxa,tibia"], "joint names"),
        (["import-urdf", str(PHANTOMX_URDF), "--out", str(tmp_path / "c.toml"), "--drives", str(ROOT / "robots" / "amru5.toml")], "serial robot description"),
        (["import-urdf", str(tmp_path / "missing.urdf"), "--out", str(tmp_path / "d.toml")], "missing.urdf"),
    ]
    for args, expected in cases:
        result = runner.invoke(cli, args)
        assert result.exit_code != 0, args
        lines = [line for line in result.output.splitlines() if line.strip()]
        assert len(lines) == 1 and expected in lines[0] and "Traceback" not in result.output, (args, result.output)
    assert out.read_text() == "taken"
    assert not any((tmp_path / n).exists() for n in ("a.toml", "b.toml", "c.toml", "d.toml"))


def test_shipped_robots_are_named():
    assert 'leg_mechanism = "serial"' in shipped_robot_text("phantomx")
    with pytest.raises(ValueError, match='"amru5", "phantomx"'):
        shipped_robot_text("nope")


def test_the_exported_urdf_is_the_same_mechanism(tmp_path):
    """phantomx -> URDF -> hexadyn: the mass matrix and feet of the shipped URDF's mechanism."""
    from hexadyn._core import UrdfHexapod

    out = tmp_path / "phantomx.urdf"
    result = CliRunner().invoke(cli, ["export-urdf", "phantomx", "--out", str(out)])
    assert result.exit_code == 0, result.output
    exported, original = UrdfHexapod.from_file(str(out)), UrdfHexapod.from_file(str(PHANTOMX_URDF))
    q = np.random.default_rng(1).uniform(-0.5, 0.5, 24)
    np.testing.assert_allclose(exported.mass_matrix(q), original.mass_matrix(q), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(exported.feet(q), original.feet(q), rtol=1e-12, atol=1e-15)
    bad = CliRunner().invoke(cli, ["export-urdf", "amru5", "--out", str(tmp_path / "amru5.urdf")])
    assert bad.exit_code != 0 and "pantograph legs" in bad.output and len(bad.output.strip().splitlines()) == 1
