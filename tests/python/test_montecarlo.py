"""Monte Carlo over the friction uncertainty (Section 6.5): truncated Gaussian draws, campaign
storage that survives interruptions, identical results on a process pool and on Ray, and the
specific resistance of Eq. 6.6."""

from __future__ import annotations

import json
import math
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from scipy import stats
from conftest import shortened, sigint_as_in_a_terminal

from hexadyn import _core
from hexadyn.cli import cli
from hexadyn.montecarlo import Campaign, CampaignStore, FrictionDistributions, RunKey, draw_friction
from hexadyn.montecarlo.execution import simulate_run
from hexadyn.montecarlo.storage import CAMPAIGN_FILE, DATABASE_FILE
from hexadyn.montecarlo.tables import FIGURE_FILES, TABLE_COLUMNS, TABLE_FILE

# A small campaign: the validation walk shortened to one step (12 s), 2 runs x 2 velocities x
# 2 variants = 8 simulations.
RUNS = 2
VELOCITIES = (0.01, 0.02)
SEED = 2010
G = 9.81  # Eq. 6.6, as in the engine's summary


@pytest.fixture(scope="module")
def scenario(tmp_path_factory) -> Path:
    return shortened("validation_tripod_1_5cm", tmp_path_factory.mktemp("mc_scenario"), duration=12.0)


@pytest.fixture(scope="module")
def campaign(scenario) -> Campaign:
    return Campaign.create(scenario, velocities=VELOCITIES, runs_per_velocity=RUNS, seed=SEED)


@pytest.fixture(scope="module")
def reference(campaign, tmp_path_factory) -> Path:
    """The small campaign run uninterrupted on two local processes."""
    out = tmp_path_factory.mktemp("mc") / "reference"
    campaign.run(out, workers=2, progress=False)
    return out


@pytest.fixture(scope="module")
def distributions() -> FrictionDistributions:
    return FrictionDistributions.of_robot("amru5")


def stored_runs(folder: Path) -> pd.DataFrame:
    with sqlite3.connect(folder / DATABASE_FILE) as db:
        return pd.read_sql_query("SELECT * FROM runs ORDER BY variant, velocity_index, run_index", db)


def stored_count(folder: Path) -> int:
    """The runs stored so far by a campaign that may still be creating its database."""
    if not (folder / DATABASE_FILE).exists():
        return 0
    with sqlite3.connect(folder / DATABASE_FILE, timeout=30) as db:
        if db.execute("SELECT count(*) FROM sqlite_master WHERE name = 'runs'").fetchone()[0] == 0:
            return 0  # the file exists, its schema is not written yet
        return db.execute("SELECT count(*) FROM runs").fetchone()[0]


def cli_command(scenario: Path, out: Path, runs: int = RUNS) -> list[str]:
    velocities = ",".join(f"{v * 100:g}" for v in VELOCITIES)  # cm/s on the command line
    return [sys.executable, "-m", "hexadyn.cli", "montecarlo", str(scenario), "--out", str(out), "--runs", str(runs), "--velocities", velocities, "--seed", str(SEED), "--workers", "2", "--no-progress"]


# ----------------------------------------------------------------------------------------------
# Draws
# ----------------------------------------------------------------------------------------------


def test_distributions_are_table_6_7_and_the_load_coefficients(distributions):
    d = distributions
    assert d.gaussians["model.joint_friction.q_r.tau_f_d_plus"] == (8.04, 3.58)
    assert d.gaussians["model.joint_friction.q_r.tau_f_d_minus"] == (-8.97, 3.56)  # NOTES.md: not 356
    assert d.gaussians["model.joint_friction.q_h.tau_f_d_minus"] == (-452.9, 76.0)
    assert d.fixed == {"model.joint_friction.q_h.f_v_plus": 0.0, "model.joint_friction.q_h.f_v_minus": 0.0}
    # a_1^- is missing from Table 5.5: not drawn, the robot's missing_a1_minus rule applies.
    assert d.load_parameters == tuple(f"model.joint_friction.q_h.{a}" for a in ("a_2_plus", "a_1_plus", "a_2_minus"))
    assert d.physical_bounds["model.joint_friction.q_v.f_v_minus"] == (0.0, math.inf)
    assert d.physical_bounds["model.joint_friction.q_h.a_2_minus"] == (-math.inf, 0.0)
    assert (d.runs_per_velocity, d.truncation_sigmas, d.velocities_m_per_s) == (1000, 3.0, (0.01, 0.015, 0.02, 0.025))


def test_draws_are_within_3_sigma_and_physical(distributions):
    d = distributions
    for vi in range(4):
        for ri in range(500):
            drawn = draw_friction(d, SEED, vi, ri)
            assert list(drawn) == list(d.gaussians)
            for field, x in drawn.items():
                mu, sigma = d.gaussians[field]
                low, high = d.physical_bounds[field]
                assert abs(x - mu) <= 3 * sigma and low <= x <= high, (field, x)


@pytest.mark.parametrize("field", ["model.joint_friction.q_r.f_v_plus", "model.joint_friction.q_v.tau_f_d_plus", "model.joint_friction.q_h.a_1_plus"])
def test_draws_follow_the_truncated_normal(distributions, field):
    n = 4000
    x = np.array([draw_friction(distributions, SEED, 0, ri)[field] for ri in range(n)])
    mu, sigma = distributions.gaussians[field]
    lo, hi = distributions.accepted_interval(field)
    theory = stats.truncnorm((lo - mu) / sigma, (hi - mu) / sigma, loc=mu, scale=sigma)
    # 5 standard errors: deterministic draws, so this either always passes or never does.
    assert abs(x.mean() - theory.mean()) < 5 * theory.std() / math.sqrt(n)
    assert abs(x.std(ddof=1) - theory.std()) < 5 * theory.std() / math.sqrt(n / 2)
    assert stats.kstest(x, theory.cdf).pvalue > 1e-3


def test_a_draw_depends_only_on_seed_velocity_and_run(distributions):
    keys = [(vi, ri) for vi in range(3) for ri in range(20)]
    forward = {k: draw_friction(distributions, SEED, *k) for k in keys}
    backward = {k: draw_friction(distributions, SEED, *k) for k in reversed(keys)}
    assert forward == backward
    assert len({tuple(v.values()) for v in forward.values()}) == len(keys)
    assert draw_friction(distributions, SEED + 1, 0, 0) != forward[(0, 0)]


def test_both_variants_share_the_draw(campaign, distributions):
    plain = campaign.friction(RunKey("dry_viscous", 1, 1))
    load = campaign.friction(RunKey("dry_viscous_load", 1, 1))
    assert set(load) - set(plain) == set(distributions.load_parameters)
    assert all(load[k] == v for k, v in plain.items())
    o = campaign.overrides(RunKey("dry_viscous_load", 1, 1))
    assert o["gait.heading.vx_m_s"] == VELOCITIES[1] and o["model.friction"] == "dry_viscous" and o["model.load_dependence"] is True


# ----------------------------------------------------------------------------------------------
# A campaign
# ----------------------------------------------------------------------------------------------


def test_campaign_stores_every_run_with_eq_6_6(reference, campaign):
    runs = stored_runs(reference)
    assert len(runs) == len(campaign.keys()) == RUNS * len(VELOCITIES) * 2
    assert (runs["status"] == "ok").all()
    for row in runs.itertuples():
        assert row.distance_walked_m > 0
        assert row.specific_resistance == pytest.approx(row.energy_electrical_j / (row.robot_mass_kg * G * row.distance_walked_m), rel=1e-12)
        assert row.energy_electrical_j == pytest.approx(row.energy_electrical_q_r_j + row.energy_electrical_q_v_j + row.energy_electrical_q_h_j, rel=1e-9)
        assert json.loads(row.parameters) == campaign.friction(RunKey(row.variant, row.velocity_index, row.run_index))
    config = json.loads((reference / CAMPAIGN_FILE).read_text())["configuration"]
    assert config["seed"] == SEED and config["velocities_m_per_s"] == list(VELOCITIES)


def test_table_6_8_and_fig_6_20(reference):
    table = pd.read_csv(reference / TABLE_FILE)
    assert tuple(table.columns) == TABLE_COLUMNS
    assert list(table["variant"]) == ["dry_viscous"] * 2 + ["dry_viscous_load"] * 2
    assert list(table["velocity_m_s"]) == list(VELOCITIES) * 2
    assert (table["runs"] == RUNS).all() and (table["failed"] == 0).all()
    runs = stored_runs(reference)
    first = runs[(runs["variant"] == "dry_viscous") & (runs["velocity_index"] == 0)]["specific_resistance"]
    assert table["specific_resistance_mean"][0] == pytest.approx(first.mean(), rel=1e-15)
    assert table["specific_resistance_std"][0] == pytest.approx(first.std(ddof=1), rel=1e-12)
    # Section 6.5: "the load influence on the horizontal joint clearly penalizes the robot
    # specific resistance".
    plain, load = table[table.variant == "dry_viscous"], table[table.variant == "dry_viscous_load"]
    assert (load["specific_resistance_mean"].to_numpy() > plain["specific_resistance_mean"].to_numpy()).all()
    for name in FIGURE_FILES:
        assert (reference / name).stat().st_size > 1000
    assert not [p for p in reference.iterdir() if p.name.startswith(".")], "no temporary file left"


def test_reruns_are_bit_identical(reference, campaign, scenario):
    key = RunKey("dry_viscous_load", 1, 0)
    overrides = campaign.overrides(key)
    a = _core.run_scenario(str(scenario), None, overrides, timeseries=False)["summary"]
    b = _core.run_scenario(str(scenario), None, overrides, timeseries=False)["summary"]
    del a["wall_time_s"], b["wall_time_s"]
    assert a == b
    # ... and equal to the run simulated in a worker process of the campaign.
    row = stored_runs(reference).set_index(["variant", "velocity_index", "run_index"]).loc[tuple(key)]
    assert row["specific_resistance"] == a["specific_resistance"]
    assert row["energy_electrical_j"] == a["energy_electrical_j"]


def test_interrupted_campaign_resumes_without_loss_or_duplicate(reference, campaign, tmp_path):
    out = tmp_path / "interrupted"
    stop_after = 3

    def interrupt(done: int, total: int) -> None:
        if done == stop_after:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        campaign.run(out, workers=2, progress=interrupt)
    assert len(stored_runs(out)) == stop_after
    assert not (out / TABLE_FILE).exists()
    table = campaign.run(out, workers=1, progress=False)
    runs = stored_runs(out)
    assert len(runs) == len(campaign.keys())  # the primary key forbids duplicates
    pd.testing.assert_frame_equal(table, pd.read_csv(reference / TABLE_FILE), check_exact=True)
    assert (out / TABLE_FILE).read_bytes() == (reference / TABLE_FILE).read_bytes()
    ref = stored_runs(reference)
    assert runs.drop(columns="wall_time_s").equals(ref.drop(columns="wall_time_s"))


# The killed command runs with tests/python/held_campaign on its PYTHONPATH: each of its 2 workers
# stores one run and then holds its next walk, so the signal, sent once the first run is stored,
# finds the campaign unfinished however fast the machine is.
HELD_CAMPAIGN = Path(__file__).parent / "held_campaign"


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGKILL], ids=["SIGINT", "SIGKILL"])
def test_killed_command_resumes(reference, scenario, tmp_path, sig):
    out = tmp_path / "killed"
    command = cli_command(scenario, out)
    total = RUNS * len(VELOCITIES) * 2
    held = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(HELD_CAMPAIGN), os.environ.get("PYTHONPATH")]))}
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=held, preexec_fn=sigint_as_in_a_terminal)
    try:
        # Wait for the first stored run (bounded, so that a broken campaign cannot hang the tests).
        for _ in range(12000):
            if stored_count(out) >= 1:
                break
            assert process.poll() is None, process.communicate()
            time.sleep(0.01)
        process.send_signal(sig)
        _, err = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            process.kill()
    if sig == signal.SIGINT:
        assert process.returncode == 130, err
        assert "run the same command again to resume" in err and "Traceback" not in err
    else:
        assert process.returncode == -signal.SIGKILL
    assert 1 <= len(stored_runs(out)) <= 2  # one per worker
    assert not (out / TABLE_FILE).exists()
    resumed = subprocess.run(command, capture_output=True, text=True, timeout=600)
    assert resumed.returncode == 0, resumed.stderr
    assert "Table 6.8" in resumed.stdout
    runs = stored_runs(out)
    assert len(runs) == total  # the primary key forbids duplicates
    assert runs.drop(columns="wall_time_s").equals(stored_runs(reference).drop(columns="wall_time_s"))
    assert (out / TABLE_FILE).read_bytes() == (reference / TABLE_FILE).read_bytes()


def test_ray_gives_the_same_table(reference, campaign, tmp_path):
    pytest.importorskip("ray")
    table = campaign.run(tmp_path / "ray", ray="local", workers=2, progress=False)
    pd.testing.assert_frame_equal(table, pd.read_csv(reference / TABLE_FILE), check_exact=True)


def test_failed_simulation_is_stored_and_not_retried(scenario, tmp_path):
    # 10 m/s cannot fit the workspace: the engine rejects the scenario of those runs.
    campaign = Campaign.create(scenario, velocities=[0.01, 10.0], runs_per_velocity=1, variants=["dry_viscous"], seed=SEED)
    out = tmp_path / "failing"
    table = campaign.run(out, workers=2, progress=False)
    assert list(table["runs"]) == [1, 0] and list(table["failed"]) == [0, 1]
    runs = stored_runs(out)
    failed = runs[runs.status == "failed"].iloc[0]
    assert failed.velocity_m_s == 10.0 and "workspace" in failed.error
    assert math.isnan(failed.specific_resistance)
    with CampaignStore.open(out, campaign.configuration()) as store:
        before = store.finished()
    campaign.run(out, workers=2, progress=False)
    assert len(stored_runs(out)) == len(before) == 2


def test_simulate_run_reports_engine_errors(scenario):
    outcome = simulate_run(str(scenario), {"model.friction": "coulomb"})
    assert outcome["status"] == "failed" and "coulomb" in outcome["error"]


# ----------------------------------------------------------------------------------------------
# Bad input
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"runs_per_velocity": -3}, "runs per velocity = -3"),
        ({"runs_per_velocity": 0}, "runs per velocity = 0"),
        ({"variants": ["coulomb"]}, "variants"),
        ({"velocities": [0.01, 0.0]}, "velocities"),
        ({"velocities": [-0.01]}, "velocities"),
        ({"seed": -1}, "seed"),
    ],
)
def test_bad_campaigns_are_rejected(scenario, kwargs, message):
    with pytest.raises(ValueError, match=message):
        Campaign.create(scenario, **kwargs)


def test_a_non_walking_scenario_is_rejected():
    with pytest.raises(ValueError, match="walking scenario"):
        Campaign.create("stand_six_legs")


def test_resuming_another_campaign_names_the_field(reference, scenario):
    other = Campaign.create(scenario, velocities=VELOCITIES, runs_per_velocity=RUNS, seed=SEED + 1)
    with pytest.raises(ValueError, match="another seed"):
        other.run(reference, progress=False)
    other = Campaign.create(scenario, velocities=VELOCITIES, runs_per_velocity=RUNS + 1, seed=SEED)
    with pytest.raises(ValueError, match="another runs_per_velocity"):
        other.run(reference, progress=False)


def test_a_folder_holding_something_else_is_rejected(campaign, tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(ValueError, match="not a Monte Carlo campaign folder"):
        campaign.run(tmp_path, progress=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--runs", "-3"], "runs per velocity = -3"),
        (["--variants", "dry_viscous,coulomb"], "variants"),
        (["--velocities", "0.01,0"], "velocities"),
        (["--velocities", "0.01,fast"], "--velocities"),
    ],
)
def test_cli_bad_input_is_one_line(tmp_path, args, message):
    result = CliRunner().invoke(cli, ["montecarlo", "--out", str(tmp_path / "mc"), *args])
    assert result.exit_code in (1, 2)
    assert message in result.output and "Traceback" not in result.output
    assert not (tmp_path / "mc").exists()
