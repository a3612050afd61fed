"""Monte Carlo campaigns refuse what they cannot do honestly, before drawing or allocating
(issue 39): friction statistics a draw is too rarely kept from, more runs than a campaign
holds, a device as statistics file, a corrupt runs.sqlite; they start no more workers than
runs, end with a failure status naming the failed runs, and write their table and figures as
one set."""

from __future__ import annotations

import json
import os
import shutil
import sqlite3
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from conftest import assert_one_line_error, shortened
from scipy import stats

from hexadyn import atomic, health
from hexadyn.cli import cli
from hexadyn.montecarlo import Campaign, FrictionDistributions, draw_friction
from hexadyn.montecarlo import execution
from hexadyn.montecarlo.campaign import MAX_SIMULATIONS
from hexadyn.montecarlo.execution import ProcessPool, Ray
from hexadyn.montecarlo.sampling import MIN_ACCEPTANCE
from hexadyn.montecarlo.storage import DATABASE_FILE
from hexadyn.montecarlo.tables import FIGURE_FILES, TABLE_FILE
from hexadyn.options import UNHEALTHY

FIELD = "model.joint_friction.q_v.tau_f_d_plus"  # physical values >= 0


@pytest.fixture(scope="module")
def scenario(tmp_path_factory) -> Path:
    """The validation walk cut to 2 s: a run takes about a second."""
    return shortened("validation_tripod_1_5cm", tmp_path_factory.mktemp("mc_checks"), duration=2.0)


@pytest.fixture(scope="module")
def finished(scenario, tmp_path_factory) -> Path:
    """A finished campaign of two runs (one velocity, one variant)."""
    out = tmp_path_factory.mktemp("finished") / "mc"
    Campaign.create(scenario, velocities=[0.01], runs_per_velocity=2, variants=["dry_viscous"]).run(out, workers=2, progress=False)
    return out


def invoke(*args: str):
    return CliRunner().invoke(cli, ["montecarlo", *args])


def stats_file(folder: Path, entries: str) -> Path:
    path = folder / "friction_stats.toml"
    path.write_text(f"[friction_stats]\n{entries}\n")
    return path


# ---------------------------------------------------------------------------------------------
# Draws: the probability of keeping one, computed before drawing
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("mu, sigma", [(311.4, 62.3), (3.0, 10.0), (-2.0, 1.0), (-2.9, 1.0), (5.0, 0.0)])
def test_the_acceptance_is_the_truncated_normal_mass(mu, sigma):
    d = FrictionDistributions.of_robot("amru5").with_stats({FIELD: (mu, sigma)}, "test")
    lo, hi = d.accepted_interval(FIELD)
    expected = 1.0 if sigma == 0 else stats.norm.cdf(hi, mu, sigma) - stats.norm.cdf(lo, mu, sigma)
    assert d.acceptance(FIELD) == pytest.approx(expected, rel=1e-9)


def test_a_nearly_empty_accepted_interval_is_refused_before_drawing(scenario, tmp_path):
    """N(-2.9999999999, 1) kept at or above 0: 4.4e-13 of the draws, forever in practice."""
    path = stats_file(tmp_path, f'"{FIELD}" = {{ mu = -2.9999999999, sigma = 1.0 }}')
    out = tmp_path / "mc"
    line = assert_one_line_error(invoke(str(scenario), "--out", str(out), "--friction-stats", str(path)), f"{path}: {FIELD} ~ N(-2.9999999999, 1.0^2) keeps a draw with probability 4.43e-13")
    assert f"allowed: a probability of at least {MIN_ACCEPTANCE:g}" in line
    assert not out.exists()


def test_an_interval_at_the_bound_is_drawn_from(scenario, tmp_path):
    """Just above MIN_ACCEPTANCE the campaign is accepted, and its draws are in the interval."""
    # Kept: [0, mu + 3 sigma], of mass Phi(3) - Phi(-mu) for sigma = 1.
    mu = -stats.norm.ppf(stats.norm.cdf(3.0) - 1.2 * MIN_ACCEPTANCE)
    d = FrictionDistributions.of_robot("amru5").with_stats({FIELD: (mu, 1.0)}, "test")
    assert MIN_ACCEPTANCE < d.acceptance(FIELD) < 1.5 * MIN_ACCEPTANCE
    d.check("test")
    lo, hi = d.accepted_interval(FIELD)
    assert all(lo <= draw_friction(d, 0, 0, r)[FIELD] <= hi for r in range(50))


@pytest.mark.parametrize("name", ["/dev/zero", "fifo"])
def test_a_device_as_friction_statistics_fails_at_once(scenario, tmp_path, name):
    path = Path(name) if name.startswith("/") else tmp_path / name
    if not path.exists():
        os.mkfifo(path)
    assert_one_line_error(invoke(str(scenario), "--out", str(tmp_path / "mc"), "--friction-stats", str(path)), f"{path}: " + ("a device" if name.startswith("/") else "a named pipe (FIFO)") + ", not a regular file")


# ---------------------------------------------------------------------------------------------
# Size of a campaign
# ---------------------------------------------------------------------------------------------


def test_runs_are_bounded_before_anything_is_allocated(scenario, tmp_path):
    out = tmp_path / "mc"
    assert_one_line_error(
        invoke(str(scenario), "--out", str(out), "--runs", "999999999999"),
        "runs per velocity = 999999999999: need at most 125000 with 4 velocities and 2 variants",
        f"at most {MAX_SIMULATIONS} simulations",
    )
    assert not out.exists()
    assert Campaign.create(scenario, runs_per_velocity=MAX_SIMULATIONS // 8).runs_per_velocity == 125000


def test_workers_are_capped_at_the_runs(scenario, tmp_path, monkeypatch):
    """--workers 200 for 2 runs starts 2 processes."""
    started = []

    class Recorded(execution.ProcessPoolExecutor):
        def __init__(self, max_workers, **kwargs):
            started.append(max_workers)
            super().__init__(max_workers, **kwargs)

    monkeypatch.setattr(execution, "ProcessPoolExecutor", Recorded)
    Campaign.create(scenario, velocities=[0.01], runs_per_velocity=2, variants=["dry_viscous"]).run(tmp_path / "mc", workers=200, progress=False)
    assert started == [2]
    assert ProcessPool(200).capped(2).workers == 2 and ProcessPool(1).capped(5).workers == 1
    assert Ray("local", 200).capped(3).workers == 3 and Ray("ray://head:10001", 200).capped(3).workers == 200


@pytest.mark.parametrize("workers", ["0", "-3"])
def test_bad_workers_are_one_line_and_create_nothing(scenario, tmp_path, workers):
    """A usage error (exit status 2), as in every command taking --workers (test_cli_grammar.py);
    the API refuses them too."""
    out = tmp_path / "mc"
    result = invoke(str(scenario), "--out", str(out), "--workers", workers)
    assert result.exit_code == 2 and result.stderr.count("\n") == 1, result.stderr
    assert result.stderr.startswith(f"Error: Invalid value for '--workers': {workers} is not in the range x>=1. (see '") and "montecarlo --help')" in result.stderr
    assert not out.exists()
    with pytest.raises(ValueError, match=f"workers = {workers}: need an integer >= 1"):
        Campaign.create(scenario, velocities=[0.01], runs_per_velocity=1, variants=["dry_viscous"]).run(out, workers=int(workers), progress=False)
    assert not out.exists()


# ---------------------------------------------------------------------------------------------
# Failed runs
# ---------------------------------------------------------------------------------------------


def test_failed_runs_end_with_a_failure_status_naming_them(scenario, tmp_path):
    """10 m/s cannot fit the workspace: its runs fail; the table is written, the exit status is
    1 and one line names the failed runs and the first error."""
    out = tmp_path / "mc"
    result = invoke(str(scenario), "--out", str(out), "--runs", "2", "--velocities", "1,1000", "--variants", "dry_viscous", "--workers", "2", "--no-progress")
    line = assert_one_line_error(result, "Error: 2 of 4 simulations failed: dry_viscous at V_x = 10 m/s (2: run 0, 1); the first (dry_viscous, V_x = 10 m/s, run 0): ", "workspace", f"kept as failed in {out / DATABASE_FILE} (not retried)")
    assert "Specific resistance xi" in result.stdout
    assert list(pd.read_csv(out / TABLE_FILE)["failed"]) == [0, 2]
    # Resumed: nothing is rerun, the same status and line.
    again = invoke(str(scenario), "--out", str(out), "--runs", "2", "--velocities", "1,1000", "--variants", "dry_viscous", "--no-progress")
    assert assert_one_line_error(again) == line


def failing_run(scenario, overrides):
    """A walk the engine rejects (the campaign's per-run function, replaced in the workers)."""
    return {"status": "failed", "error": "the engine rejected the walk"}


def test_a_campaign_whose_every_run_fails_exits_non_zero(scenario, tmp_path, monkeypatch):
    monkeypatch.setattr(execution, "simulate_run", failing_run)  # the pool's workers are forked
    out = tmp_path / "mc"
    result = invoke(str(scenario), "--out", str(out), "--runs", "1", "--velocities", "1", "--no-progress")
    assert_one_line_error(result, "Error: 2 of 2 simulations failed: dry_viscous at V_x = 0.01 m/s (1: run 0); dry_viscous_load at V_x = 0.01 m/s (1: run 0)", "the engine rejected the walk")
    assert list(pd.read_csv(out / TABLE_FILE)["runs"]) == [0, 0]


# ---------------------------------------------------------------------------------------------
# The campaign folder: a corrupt database, the outputs as one set
# ---------------------------------------------------------------------------------------------


def corrupt_half(path: Path) -> None:
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])


def other_schema(path: Path) -> None:
    path.unlink()
    with sqlite3.connect(path) as db:
        db.execute("CREATE TABLE runs (x INTEGER)")


@pytest.mark.parametrize(
    "damage, words",
    [
        (corrupt_half, "database disk image is malformed"),
        (lambda p: p.write_bytes(b"not sqlite" * 500), "file is not a database"),
        (other_schema, "no such column: variant"),
    ],
    ids=["truncated-to-half", "not-a-database", "another-table"],
)
def test_a_corrupt_database_is_one_line(finished, scenario, tmp_path, damage, words):
    out = tmp_path / "mc"
    shutil.copytree(finished, out)
    damage(out / DATABASE_FILE)
    result = invoke(str(scenario), "--out", str(out), "--runs", "2", "--velocities", "1", "--variants", "dry_viscous", "--no-progress")
    assert_one_line_error(result, f"{out / DATABASE_FILE}: not a readable campaign database (", words, "move it away to start the campaign again")


def test_the_outputs_appear_as_one_set_csv_last(finished, tmp_path, monkeypatch):
    """The figures are renamed into place before the table: a specific_resistance.csv is never
    there without its figures; no temporary is left."""
    table = pd.read_csv(finished / TABLE_FILE)
    folder = tmp_path / "fresh"
    folder.mkdir()
    seen = []
    replace = os.replace

    def recorded(src, dst):
        seen.append((Path(dst).name, sorted(p.name for p in folder.iterdir() if not p.name.startswith("."))))
        replace(src, dst)

    monkeypatch.setattr(atomic.os, "replace", recorded)
    from hexadyn.montecarlo.tables import write_results

    write_results(table, folder)
    assert [name for name, _ in seen] == [*FIGURE_FILES, TABLE_FILE]
    assert all(TABLE_FILE not in present for _, present in seen)
    assert sorted(p.name for p in folder.iterdir()) == sorted([*FIGURE_FILES, TABLE_FILE])


@pytest.mark.parametrize("error", [RuntimeError("PDF backend failed"), KeyboardInterrupt()], ids=["error", "ctrl-c"])
def test_a_failed_pdf_leaves_the_previous_set_and_no_partial(finished, tmp_path, monkeypatch, error):
    from matplotlib.figure import Figure

    from hexadyn.montecarlo.tables import write_results

    out = tmp_path / "mc"
    shutil.copytree(finished, out)
    before = {name: (out / name).read_bytes() for name in (*FIGURE_FILES, TABLE_FILE)}
    savefig = Figure.savefig

    def failing(self, path, *args, format=None, **kwargs):
        if format == "pdf":
            raise error
        return savefig(self, path, *args, format=format, **kwargs)

    monkeypatch.setattr(Figure, "savefig", failing)
    table = pd.read_csv(out / TABLE_FILE).assign(specific_resistance_mean=np.pi)
    with pytest.raises(type(error)):
        write_results(table, out)
    assert {name: (out / name).read_bytes() for name in before} == before
    assert not [p.name for p in out.iterdir() if p.name.startswith(".")]


# ---------------------------------------------------------------------------------------------
# Health checks of the runs: kept in runs.sqlite, one WARNING line, --strict
# ---------------------------------------------------------------------------------------------


def test_the_runs_health_checks_are_kept_and_strict_exits_3(scenario, tmp_path, monkeypatch):
    monkeypatch.setattr(health, "MAX_PENETRATION_RATIO", 0.0)  # every foot "too deep" (the workers are forked)
    out = tmp_path / "mc"
    args = [str(scenario), "--out", str(out), "--runs", "2", "--velocities", "1", "--variants", "dry_viscous", "--workers", "2", "--no-progress"]
    result = invoke(*args, "--strict")
    assert result.exit_code == UNHEALTHY, result.output
    assert "Specific resistance xi" in result.stdout
    line = result.stderr
    assert line.startswith("WARNING: 2 of 2 simulations failed a health check: dry_viscous at V_x = 0.01 m/s (2: run 0, 1); the first (dry_viscous, V_x = 0.01 m/s, run 0): a foot went ")
    assert line.endswith(f"three feet: check model.k_gnd and the integrator settings (column warnings of {out / DATABASE_FILE})\n") and line.count("\n") == 1, line
    with sqlite3.connect(out / DATABASE_FILE) as db:
        stored = [json.loads(w) for (w,) in db.execute("SELECT warnings FROM runs")]
    assert len(stored) == 2 and all(len(w) == 1 and "into the ground" in w[0] for w in stored)
    # Resumed without --strict: nothing is rerun, the same line from the store, status 0.
    again = invoke(*args)
    assert again.exit_code == 0 and again.stderr == line, again.output


def test_a_healthy_campaign_passes_strict(finished, scenario, tmp_path):
    out = tmp_path / "mc"
    shutil.copytree(finished, out)
    result = invoke(str(scenario), "--out", str(out), "--runs", "2", "--velocities", "1", "--variants", "dry_viscous", "--no-progress", "--strict")
    assert result.exit_code == 0 and result.stderr == "", result.output
    with sqlite3.connect(out / DATABASE_FILE) as db:
        assert [json.loads(w) for (w,) in db.execute("SELECT warnings FROM runs")] == [[], []]


def test_a_campaign_stored_without_the_warnings_column_resumes(finished, scenario, tmp_path):
    """A runs.sqlite of a hexadyn that did not record the health checks, its second run not
    finished: the column is added, the stored run holds NULL (not checked), the campaign
    resumes with the run left and records its checks."""
    out = tmp_path / "mc"
    shutil.copytree(finished, out)
    with sqlite3.connect(out / DATABASE_FILE) as db:
        db.execute("ALTER TABLE runs DROP COLUMN warnings")
        db.execute("DELETE FROM runs WHERE run_index = 1")
    result = invoke(str(scenario), "--out", str(out), "--runs", "2", "--velocities", "1", "--variants", "dry_viscous", "--workers", "1", "--no-progress", "--strict")
    assert result.exit_code == 0 and result.stderr == "", result.output
    with sqlite3.connect(out / DATABASE_FILE) as db:
        assert list(db.execute("SELECT run_index, warnings FROM runs ORDER BY run_index")) == [(0, None), (1, "[]")]
