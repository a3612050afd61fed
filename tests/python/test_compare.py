"""The friction-model comparison (hexadyn.compare, `hexadyn compare-friction`): Tables 6.3-6.6
and Fig. 6.19 on a short walk at two velocities."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from hexadyn import compare
from hexadyn.cli import cli

from conftest import assert_drawn, shortened

MODELS = ["none", "dry_viscous", "lugre", "dry_viscous_load", "efficiency"]


@pytest.fixture(scope="module")
def short_walk(tmp_path_factory) -> Path:
    """The validation walk cut to 6 s: the first half step (tripod 1-2-5 swings)."""
    return shortened("validation_tripod_1_5cm", tmp_path_factory.mktemp("compare"), 6.0)


def test_cli_compare_friction(short_walk: Path, tmp_path: Path):
    out = tmp_path / "cmp"
    result = CliRunner().invoke(cli, ["compare-friction", str(short_walk), "--velocities", "1,2", "--out", str(out), "--workers", "2", "--no-progress"], prog_name="hexadyn")
    assert result.exit_code == 0, result.output
    for text in ["averaged power of the q_r actuators (W), V_x = 1 cm/s", "q_h actuators", "dry_viscous_load", "specific_resistance", "alpha_w"]:
        assert text in result.output, text
    assert sorted(p.name for p in out.iterdir()) == ["fit.csv", "plots", "power_by_model.csv", "robot_power.csv"]
    assert sorted(p.name for p in (out / "plots").iterdir()) == ["power_by_model.png", "power_velocity.png", "specific_resistance.png"]
    series = [compare.MODEL_COLOURS[m] for m in MODELS]  # one per model
    assert_drawn(out / "plots" / "power_by_model.png", series)
    for stem in ["power_velocity", "specific_resistance"]:
        assert_drawn(out / "plots" / f"{stem}.png", series, width_in=5.0)
    assert [p.name for p in tmp_path.iterdir()] == ["cmp"]

    robot = pd.read_csv(out / "robot_power.csv", index_col=["velocity_m_s", "model"])
    assert list(robot.index) == [(v, m) for v in (0.01, 0.02) for m in MODELS]
    p = robot["average_power_w"]
    for v in (0.01, 0.02):
        # Friction dominates the power (Section 6.6); LuGre and dry/viscous draw about the same
        # (Section 6.4.5); the load dependence of the horizontal joints adds power (6.4.4).
        assert p[(v, "none")] < 0.3 * p[(v, "dry_viscous")]
        assert p[(v, "lugre")] == pytest.approx(p[(v, "dry_viscous")], rel=0.25)
        assert p[(v, "dry_viscous_load")] > p[(v, "dry_viscous")]
        # The efficiency law adds a loss to Eq. 6.1 wherever a transmission carries a load.
        assert p[(v, "efficiency")] > p[(v, "dry_viscous")]
        assert robot.loc[(v, "none"), "friction_share"] == 0 and robot.loc[(v, "none"), "friction_power_share"] == pytest.approx(0, abs=1e-12)
        assert robot.loc[(v, "dry_viscous"), "friction_power_share"] == pytest.approx(1 - p[(v, "none")] / p[(v, "dry_viscous")], rel=1e-6)
    assert (robot.xs(0.02, level="velocity_m_s")["distance_m"] > 1.5 * robot.xs(0.01, level="velocity_m_s")["distance_m"]).all()
    xi = robot["specific_resistance"]
    np.testing.assert_allclose(xi, robot["energy_electrical_j"] / (robot["mass_kg"] * 9.81 * robot["distance_m"]), rtol=1e-6)

    # Two velocities: the fit of Eq. 6.8 goes through both points.
    fit = pd.read_csv(out / "fit.csv", index_col="model")
    assert list(fit.index) == MODELS
    for m in MODELS:
        f = fit.loc[m]
        for v in (0.01, 0.02):
            assert f.alpha_w + f.beta_n * v == pytest.approx(p[(v, m)], rel=1e-6)
        assert f.xi_asymptote == pytest.approx(f.beta_n / (f.mass_kg * 9.81), rel=1e-6)

    # Tables 6.3-6.6: per leg and joint type, for every velocity and model; totals add up.
    power = pd.read_csv(out / "power_by_model.csv", index_col=["velocity_m_s", "model", "leg"])
    assert list(power.columns) == ["q_r", "q_v", "q_h", "total"]
    for (v, m), block in power.groupby(level=["velocity_m_s", "model"]):
        legs = block.drop(index="total", level="leg")
        assert len(legs) == 6
        np.testing.assert_allclose(block.xs("total", level="leg").to_numpy()[0], legs.sum().to_numpy(), rtol=1e-6)
        assert block.xs("total", level="leg")["total"].iloc[0] == pytest.approx(p[(v, m)], rel=1e-6)

    # An existing folder is refused before running.
    result = CliRunner().invoke(cli, ["compare-friction", str(short_walk), "--velocities", "1,2", "--out", str(out)], prog_name="hexadyn")
    assert result.exit_code == 1 and "exists" in result.output


def test_bad_input_is_refused_before_running(short_walk: Path, tmp_path: Path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    runner = CliRunner()
    for args, message in [
        (["--velocities", "1,10"], "V_x = 0.1 m/s"),
        (["--velocities", "-1"], "allowed: positive velocities"),
        (["--velocities", "1,x"], "comma-separated velocities in cm/s"),
        (["--models", "lugre,coulomb"], "allowed: none, dry_viscous, lugre, dry_viscous_load, efficiency"),
    ]:
        result = runner.invoke(cli, ["compare-friction", str(short_walk), "--no-progress", *args], prog_name="hexadyn")
        assert result.exit_code != 0 and message in result.output and "Traceback" not in result.output, (args, result.output)
    result = runner.invoke(cli, ["compare-friction", "leg_sine", "--no-progress"], prog_name="hexadyn")
    assert result.exit_code == 1 and "needs a walking scenario" in result.output, result.output
    assert list(tmp_path.iterdir()) == [], "nothing is written"
    with pytest.raises(ValueError, match="gait.heading"):
        compare.compare_friction(short_walk, [0.01, 0.2], progress=False)
