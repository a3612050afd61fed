"""Monte Carlo over the joint friction on serial legs (Section 6.5 on the PhantomX Mark II): the
scenario's ``[model.joint_friction.<joint>]`` changes the drive friction the model uses, the
draws follow the truncated Gaussians of the robot's ``[monte_carlo]`` table, a small campaign
gives the specific resistance per velocity under the robot's joint names, and bad input is
refused in one line."""

from __future__ import annotations

import json
import math
import re
import sqlite3
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from scipy import stats
from conftest import shortened

import hexadyn
from hexadyn import _core
from hexadyn.cli import cli
from hexadyn.montecarlo import DEFAULT_SCENARIOS, Campaign, FrictionDistributions, RunKey, draw_friction
from hexadyn.montecarlo.storage import DATABASE_FILE, per_joint_columns
from hexadyn.montecarlo.tables import TABLE_COLUMNS, TABLE_FILE

ROOT = Path(__file__).resolve().parents[2]
JOINTS = ("coxa", "femur", "tibia")
TAU_F_D = 0.590  # N m, robots/phantomx/phantomx.toml: the AX-12A's fitted gear friction
SEED = 2010
G = 9.81  # Eq. 6.6, as in the engine's summary
# A small campaign: the PhantomX walk cut to 3 s (three cycles), 2 runs x 2 velocities.
RUNS = 2
VELOCITIES = (0.03, 0.05)


def friction(value: float, joints=JOINTS) -> dict[str, float]:
    return {f"model.joint_friction.{j}.tau_f_d": value for j in joints}


@pytest.fixture(scope="module")
def distributions() -> FrictionDistributions:
    return FrictionDistributions.of_robot("phantomx")


@pytest.fixture(scope="module")
def walk_file(tmp_path_factory) -> Path:
    """The PhantomX tripod cut to 2 s: two cycles, every leg swings twice."""
    return shortened("phantomx_tripod", tmp_path_factory.mktemp("px_walk"), 2.0)


@pytest.fixture(scope="module")
def walks(walk_file):
    """The short walk with the robot's friction, the femur's doubled and none at all."""
    return {
        name: hexadyn.simulate(walk_file, progress=False, overrides=overrides)
        for name, overrides in {"nominal": {}, "femur_doubled": friction(2 * TAU_F_D, ["femur"]), "none": friction(0.0)}.items()
    }


def final(results, quantity: str, joint: str) -> float:
    """The quantity's last value summed over the six legs (E_fric_femur[0..5] at the end)."""
    return float(sum(results.timeseries[f"{quantity}_{joint}[{leg}]"].iloc[-1] for leg in range(6)))


def peak(results, quantity: str, joint: str) -> float:
    return float(max(results.timeseries[f"{quantity}_{joint}[{leg}]"].abs().max() for leg in range(6)))


# ----------------------------------------------------------------------------------------------
# [model.joint_friction.<joint>] drives the model
# ----------------------------------------------------------------------------------------------


def test_the_override_is_the_friction_the_model_applies(walks):
    # Eq. 6.1 with f_v = 0: |tau_f| <= tau_f_d, reached while the joint slides.
    nominal, doubled = walks["nominal"], walks["femur_doubled"]
    for joint in JOINTS:
        assert TAU_F_D * 0.95 < peak(nominal, "tau_f", joint) <= TAU_F_D * (1 + 1e-9), joint
    assert 2 * TAU_F_D * 0.95 < peak(doubled, "tau_f", "femur") <= 2 * TAU_F_D * (1 + 1e-9)
    for joint in ("coxa", "tibia"):
        assert peak(doubled, "tau_f", joint) <= TAU_F_D * (1 + 1e-9), joint


def test_doubling_the_femur_friction_raises_its_losses(walks):
    nominal, doubled = walks["nominal"], walks["femur_doubled"]
    e_nominal, e_doubled = final(nominal, "E_fric", "femur"), final(doubled, "E_fric", "femur")
    assert e_nominal > 0.5, e_nominal
    assert e_doubled > 1.2 * e_nominal, (e_nominal, e_doubled)
    # The per-joint losses add up to the summary's friction loss.
    for w in (nominal, doubled):
        total = sum(final(w, "E_fric", j) for j in JOINTS)
        assert total == pytest.approx(w.summary["energy_friction_j"], rel=1e-9)
    assert doubled.summary["energy_friction_j"] > nominal.summary["energy_friction_j"]
    assert doubled.summary["energy_electrical_femur_j"] > nominal.summary["energy_electrical_femur_j"]


def test_zero_friction_loses_nothing_to_friction(walks):
    none = walks["none"]
    assert none.summary["energy_friction_j"] == 0.0
    for joint in JOINTS:
        assert final(none, "E_fric", joint) == 0.0 and peak(none, "tau_f", joint) == 0.0
    # Without the gear friction the servos track better: the robot walks farther on less energy.
    assert none.summary["distance_walked_m"] > walks["nominal"].summary["distance_walked_m"]
    assert none.summary["energy_electrical_j"] < walks["nominal"].summary["energy_electrical_j"]


# ----------------------------------------------------------------------------------------------
# Draws
# ----------------------------------------------------------------------------------------------


def test_distributions_are_the_robots_monte_carlo_table(distributions):
    d = distributions
    assert d.robot == "phantomx" and d.joints == JOINTS
    assert d.gaussians == {f"model.joint_friction.{j}.tau_f_d": (TAU_F_D, 0.248) for j in JOINTS}
    assert d.physical_bounds == {f: (0.0, math.inf) for f in d.gaussians}
    assert d.load_parameters == () and d.fixed == {}
    assert (d.runs_per_velocity, d.truncation_sigmas, d.velocities_m_per_s) == (1000, 3.0, (0.02, 0.03, 0.04, 0.05))
    # The INTERPRETATION written next to sigma: AMRU5's relative spread of the q_r dry friction
    # (Table 6.7), both senses averaged, times the fitted mean.
    amru5 = FrictionDistributions.of_robot("amru5")
    relative = [abs(s / m) for m, s in (amru5.gaussians[f"model.joint_friction.q_r.{k}"] for k in ("tau_f_d_plus", "tau_f_d_minus"))]
    assert TAU_F_D * np.mean(relative) == pytest.approx(0.248, abs=5e-4)
    assert amru5.joints == ("q_r", "q_v", "q_h")


def test_draws_follow_the_truncated_normal(distributions):
    n = 4000
    draws = [draw_friction(distributions, SEED, 0, ri) for ri in range(n)]
    for field, (mu, sigma) in distributions.gaussians.items():
        x = np.array([d[field] for d in draws])
        lo, hi = distributions.accepted_interval(field)
        assert (lo, hi) == pytest.approx((0.0, mu + 3 * sigma))  # mu - 3 sigma < 0: the sign bounds it
        assert ((x >= 0.0) & (np.abs(x - mu) <= 3 * sigma)).all(), field
        theory = stats.truncnorm((lo - mu) / sigma, (hi - mu) / sigma, loc=mu, scale=sigma)
        # 5 standard errors: deterministic draws, so this either always passes or never does.
        assert abs(x.mean() - theory.mean()) < 5 * theory.std() / math.sqrt(n), field
        assert abs(x.std(ddof=1) - theory.std()) < 5 * theory.std() / math.sqrt(n / 2), field
        assert stats.kstest(x, theory.cdf).pvalue > 1e-3, field
    # Independent joints: the three draws of a run are uncorrelated.
    matrix = np.array([[d[f] for f in distributions.gaussians] for d in draws])
    corr = np.corrcoef(matrix.T)
    assert np.abs(corr[np.triu_indices(3, 1)]).max() < 5 / math.sqrt(n)


# ----------------------------------------------------------------------------------------------
# A campaign
# ----------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def scenario(tmp_path_factory) -> Path:
    return shortened("phantomx_montecarlo", tmp_path_factory.mktemp("px_mc_scenario"), duration=3.0)


@pytest.fixture(scope="module")
def campaign(scenario) -> Campaign:
    return Campaign.create(scenario, velocities=VELOCITIES, runs_per_velocity=RUNS, seed=SEED)


@pytest.fixture(scope="module")
def reference(campaign, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("px_mc") / "reference"
    campaign.run(out, workers=2, progress=False)
    return out


def stored_runs(folder: Path) -> pd.DataFrame:
    with sqlite3.connect(folder / DATABASE_FILE) as db:
        return pd.read_sql_query("SELECT * FROM runs ORDER BY variant, velocity_index, run_index", db)


def test_the_campaign_draws_the_servo_friction(campaign):
    assert campaign.variants == ("dry_viscous",)
    o = campaign.overrides(RunKey("dry_viscous", 1, 0))
    assert o["gait.heading.vx_m_s"] == VELOCITIES[1] and o["model.friction"] == "dry_viscous" and o["model.load_dependence"] is False
    assert {k for k in o if k.startswith("model.joint_friction.")} == {f"model.joint_friction.{j}.tau_f_d" for j in JOINTS}


def test_a_small_campaign_gives_the_specific_resistance(reference, campaign):
    table = pd.read_csv(reference / TABLE_FILE)
    assert tuple(table.columns) == TABLE_COLUMNS
    assert list(table["variant"]) == ["dry_viscous"] * 2 and list(table["velocity_m_s"]) == list(VELOCITIES)
    assert (table["runs"] == RUNS).all() and (table["failed"] == 0).all()
    for column in ("specific_resistance_mean", "specific_resistance_std", "average_power_w_mean"):
        assert np.isfinite(table[column]).all(), column
    assert (table["specific_resistance_mean"] > 0).all() and (table["specific_resistance_std"] > 0).all()
    assert (table["average_power_w_mean"] > 0).all()
    runs = stored_runs(reference)
    assert len(runs) == len(campaign.keys()) == RUNS * len(VELOCITIES)
    # The split of E per joint under the robot's joint names, and Eq. 6.6.
    columns = per_joint_columns(JOINTS)
    assert set(columns) <= set(runs.columns) and "energy_electrical_q_r_j" not in runs.columns
    for row in runs.itertuples():
        assert row.status == "ok" and row.distance_walked_m > 0
        assert row.specific_resistance == pytest.approx(row.energy_electrical_j / (row.robot_mass_kg * G * row.distance_walked_m), rel=1e-12)
        assert row.energy_electrical_j == pytest.approx(sum(getattr(row, c) for c in columns), rel=1e-9)
        assert json.loads(row.parameters) == campaign.friction(RunKey(row.variant, row.velocity_index, row.run_index))
    # A run of the campaign is the scenario run with its overrides.
    key = RunKey("dry_viscous", 0, 1)
    summary = _core.run_scenario(str(campaign.scenario), None, campaign.overrides(key), timeseries=False)["summary"]
    row = runs.set_index(["variant", "velocity_index", "run_index"]).loc[tuple(key)]
    assert row["specific_resistance"] == summary["specific_resistance"]


def test_the_cli_runs_the_phantomx_campaign(tmp_path):
    out = tmp_path / "mc"
    result = CliRunner().invoke(cli, ["montecarlo", "--robot", "phantomx", "--out", str(out), "--runs", "1", "--velocities", "5", "--workers", "1", "--no-progress", "--seed", str(SEED)])
    assert result.exit_code == 0, result.output
    assert "phantomx_montecarlo" in result.output and "dry_viscous" in result.output
    table = pd.read_csv(out / TABLE_FILE)
    assert list(table["runs"]) == [1] and table["specific_resistance_mean"].iloc[0] > 0
    assert json.loads((out / "campaign.json").read_text())["configuration"]["robot"] == "phantomx"
    assert DEFAULT_SCENARIOS["phantomx"] == "phantomx_montecarlo"


# ----------------------------------------------------------------------------------------------
# Bad input
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("overrides", "field", "allowed"),
    [
        ({"model.joint_friction.knee.tau_f_d": 1.0}, "model.joint_friction.knee", "[model.joint_friction.coxa], [model.joint_friction.femur], [model.joint_friction.tibia]"),
        ({"model.joint_friction.femur.tau_f_d_plus": 1.0}, "model.joint_friction.femur.tau_f_d_plus", "one of tau_f_d, f_v, sigma_0, sigma_1, v_d"),
        ({"model.joint_friction.femur.tau_f_d": -0.2}, "model.joint_friction.femur.tau_f_d", ">= 0"),
        ({"model.joint_friction.tibia.f_v": "high"}, "model.joint_friction.tibia.f_v", ">= 0"),
    ],
)
def test_bad_overrides_are_one_line(walk_file, overrides, field, allowed):
    with pytest.raises(ValueError) as error:
        _core.load_scenario(str(walk_file), overrides)
    message = str(error.value)
    assert "\n" not in message and str(walk_file) in message and f"field `{field}`" in message and allowed in message, message


def test_a_load_variant_is_refused_on_serial_legs(scenario):
    with pytest.raises(ValueError, match=r"variants = \['dry_viscous_load'\]: need distinct variants among dry_viscous, efficiency \(no load influence"):
        Campaign.create(scenario, variants=["dry_viscous_load"])


def test_the_cli_refuses_a_robot_and_a_scenario(tmp_path, scenario):
    result = CliRunner().invoke(cli, ["montecarlo", str(scenario), "--robot", "phantomx", "--out", str(tmp_path / "mc")])
    assert result.exit_code == 2 and "--robot" in result.output and "Traceback" not in result.output
    assert not (tmp_path / "mc").exists()


def without_monte_carlo(text: str) -> str:
    start = text.index("# ---------------------------------------------------------------------------------------------\n# Monte Carlo")
    return text[:start]


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (without_monte_carlo, r"^\S*robot\.toml: no \[monte_carlo\] table"),
        (lambda t: t.replace("[monte_carlo.friction.tibia]", "[monte_carlo.friction.knee]"), r"field `monte_carlo\.friction\.knee`.*no such joint.*coxa, femur, tibia"),
        (lambda t: t.replace("tau_f_d = { mu = 0.590, sigma = 0.248 }", "tau_f_d = { mu = 0.590, sigma = -0.1 }", 1), r"field `monte_carlo\.friction\.coxa\.tau_f_d"),
        (lambda t: re.sub(r"(?m)^tau_f_d = \{ mu.*$", "", t), r"field `monte_carlo\.friction`.*nothing to draw"),
    ],
    ids=["no table", "unknown joint", "negative sigma", "nothing drawn"],
)
def test_bad_monte_carlo_tables_are_one_line(tmp_path, edit, message):
    path = tmp_path / "robot.toml"
    path.write_text(edit((ROOT / "robots" / "phantomx" / "phantomx.toml").read_text()))
    with pytest.raises(ValueError) as error:
        FrictionDistributions.of_robot(str(path))
    text = str(error.value)
    assert "\n" not in text and str(path) in text, text
    assert re.search(message, text), text
