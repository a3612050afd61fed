"""Design studies (issue 40): the Sobol' indices of the Ishigami function, Morris' effects of a
linear one, a grid study of the validation walk equal to hexadyn.simulate run by run, reruns
identical, a study killed midway resumed without losing or duplicating a run, and study files
validated with one-line errors."""

from __future__ import annotations

import json
import math
import os
import re
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
from conftest import assert_one_line_error, sigint_as_in_a_terminal

import hexadyn
from hexadyn import health
from hexadyn.cli import cli
from hexadyn.montecarlo import Campaign, FrictionDistributions, study_tables
from hexadyn.montecarlo.execution import SERIES_FIGURES, simulate_run
from hexadyn.montecarlo.storage import DATABASE_FILE
from hexadyn.options import UNHEALTHY
from hexadyn.study import Study, parse_study, read_study
from hexadyn.study.spec import run_count
from hexadyn.study.study import RUNS_FILE, STUDY_FILE

STUDIES = Path(hexadyn.__file__).parent / "studies"
HELD_CAMPAIGN = Path(__file__).parent / "held_campaign"

# ----------------------------------------------------------------------------------------------
# The machinery on analytic functions
# ----------------------------------------------------------------------------------------------

ISHIGAMI_A, ISHIGAMI_B = 7.0, 0.1


def ishigami(x):
    """The Ishigami function (a = 7, b = 0.1) of x1, x2, x3 uniform on [-pi, pi]."""
    return {"y": math.sin(x["x1"]) + ISHIGAMI_A * math.sin(x["x2"]) ** 2 + ISHIGAMI_B * x["x3"] ** 4 * math.sin(x["x1"])}


def ishigami_indices() -> tuple[list[float], list[float]]:
    """The exact first-order and total indices (Ishigami and Homma 1990; Sobol' and Levitan 1999)."""
    a, b, pi = ISHIGAMI_A, ISHIGAMI_B, math.pi
    v1 = 0.5 * (1 + b * pi**4 / 5) ** 2
    v2 = a**2 / 8
    v13 = b**2 * pi**8 * (1 / 18 - 1 / 50)
    v = v1 + v2 + v13
    return [v1 / v, v2 / v, 0.0], [(v1 + v13) / v, v2 / v, v13 / v]


def uniform_study(method: str, outputs: list[str], names: tuple[str, ...], bounds: tuple[float, float], **design) -> dict:
    return {"study": {"outputs": outputs, "seed": 1}, "design": {"method": method, **design}, "parameters": {k: {"range": list(bounds)} for k in names}}


def test_ishigami_sobol_indices_within_0_02(tmp_path):
    s1, st = ishigami_indices()
    assert [round(x, 3) for x in s1] == [0.314, 0.442, 0.0] and [round(x, 3) for x in st] == [0.558, 0.442, 0.244]
    study = Study.create(parse_study(uniform_study("sobol", ["y"], ("x1", "x2", "x3"), (-math.pi, math.pi), samples=2048)), model=ishigami)
    results = study.run(tmp_path / "ishigami", workers=2, progress=False)
    # One stored row per run of Saltelli's scheme, N (D + 2), with its parameters and output.
    runs = results.runs
    assert len(runs) == 2048 * 5 and list(runs["run_index"]) == list(range(2048 * 5))
    row = runs.iloc[1234]
    assert row["y"] == ishigami({k: row[k] for k in ("x1", "x2", "x3")})["y"]
    indices = results.indices.set_index("parameter")
    assert np.abs(indices["S1"].to_numpy() - s1).max() < 0.02, indices
    assert np.abs(indices["ST"].to_numpy() - st).max() < 0.02, indices
    # The exact values lie in the confidence intervals.
    assert (np.abs(indices["ST"].to_numpy() - st) < indices["ST_conf"].to_numpy()).all()
    written = pd.read_csv(tmp_path / "ishigami" / "indices.csv")
    pd.testing.assert_frame_equal(written, results.indices)
    assert {"sobol_y.png", "response_y.png", "runs.parquet", RUNS_FILE} <= {p.name for p in (tmp_path / "ishigami").iterdir()}


def linear(x):
    """3 x1 + x2 (x3 inert): Morris' elementary effects are the coefficients, everywhere."""
    return {"y": 3 * x["x1"] + x["x2"]}


def test_morris_effects_of_a_linear_function(tmp_path):
    spec = parse_study(uniform_study("morris", ["y"], ("x1", "x2", "x3"), (0.0, 1.0), samples=10))
    results = Study.create(spec, model=linear).run(tmp_path / "morris", workers=1, progress=False)
    assert len(results.runs) == 10 * 4
    indices = results.indices.set_index("parameter")
    np.testing.assert_allclose(indices["mu_star"], [3.0, 1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(indices["sigma"], [0.0, 0.0, 0.0], atol=1e-12)
    assert (tmp_path / "morris" / "morris_y.png").is_file()


def test_grid_and_latin_hypercube_runs():
    grid = parse_study({"study": {"outputs": ["y"]}, "design": {"method": "grid", "levels": 3}, "parameters": {"a": {"range": [0.0, 1.0]}, "b": {"values": [5.0, 7.0]}}})
    study = Study.create(grid, model=linear)
    assert run_count(grid) == 6
    np.testing.assert_array_equal(study.samples, [[0, 5], [0, 7], [0.5, 5], [0.5, 7], [1, 5], [1, 7]])
    latin = parse_study(uniform_study("latin", ["y"], ("x1", "x2"), (2.0, 4.0), samples=20))
    x = Study.create(latin, model=linear).samples
    assert x.shape == (20, 2) and ((x >= 2) & (x <= 4)).all()
    # One sample in each of the 20 strata of each parameter.
    assert all(sorted(np.floor((x[:, j] - 2) / 2 * 20).astype(int)) == list(range(20)) for j in range(2))


# ----------------------------------------------------------------------------------------------
# A study of the validation walk
# ----------------------------------------------------------------------------------------------

WALK_STUDY = """\
[study]
name = "walk_grid"
scenario = "validation_tripod_1_5cm"
outputs = ["specific_resistance", "tracking_error_xy_max_m", "friction_share"]

[fixed]
"scenario.duration_s" = 3.0

[design]
method = "grid"

[parameters."gait.period_s"]
values = [8.0, 12.0]

[parameters."gait.clearance_m"]
values = [0.06, 0.1]
"""


@pytest.fixture(scope="module")
def walk_study(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("walk_study") / "walk_grid.toml"
    path.write_text(WALK_STUDY)
    return path


@pytest.fixture(scope="module")
def walk_reference(walk_study, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("walk") / "reference"
    Study.create(walk_study).run(out, workers=2, progress=False)
    return out


def stored_runs(folder: Path) -> pd.DataFrame:
    with sqlite3.connect(folder / DATABASE_FILE) as db:
        return pd.read_sql_query("SELECT * FROM runs ORDER BY run_index", db)


def test_walk_study_rows_equal_hexadyn_simulate(walk_reference):
    runs = pd.read_csv(walk_reference / RUNS_FILE)
    assert len(runs) == 4 and (runs["status"] == "ok").all()
    assert list(zip(runs["gait.period_s"], runs["gait.clearance_m"])) == [(8.0, 0.06), (8.0, 0.1), (12.0, 0.06), (12.0, 0.1)]
    for _, row in runs.iterrows():
        overrides = {"scenario.duration_s": 3.0, "gait.period_s": row["gait.period_s"], "gait.clearance_m": row["gait.clearance_m"]}
        summary = hexadyn.simulate("validation_tripod_1_5cm", progress=False, overrides=overrides).summary
        for output in ("specific_resistance", "tracking_error_xy_max_m", "friction_share"):
            assert row[output] == summary[output], (output, row[output], summary[output])
    # The outputs of the engine's summary alone (no series) are hexadyn.simulate's too.
    fast = simulate_run(str(hexadyn.resolve_scenario("validation_tripod_1_5cm")), overrides, ("specific_resistance",))
    assert fast["summary"]["specific_resistance"] == summary["specific_resistance"]
    # The figures only the series gives are the ones simulate adds to the engine's summary.
    engine = hexadyn._core.run_scenario(str(hexadyn.resolve_scenario("validation_tripod_1_5cm")), None, overrides, timeseries=False)["summary"]
    assert set(summary) - set(engine) - {"warnings"} == set(SERIES_FIGURES)


def test_walk_study_rerun_is_identical(walk_reference, walk_study, tmp_path):
    again = Study.create(walk_study).run(tmp_path / "again", workers=1, progress=False, plots=False)
    assert stored_runs(tmp_path / "again").equals(stored_runs(walk_reference))
    assert (tmp_path / "again" / RUNS_FILE).read_bytes() == (walk_reference / RUNS_FILE).read_bytes()
    # Resuming the finished study simulates nothing and gives the same table.
    resumed = Study.create(walk_study).run(walk_reference, workers=1, progress=False)
    assert resumed.runs.equals(again.runs)


def test_killed_study_resumes_without_loss_or_duplicate(walk_reference, walk_study, tmp_path):
    """The command is killed (SIGKILL) once a run is stored, each of its two workers holding its
    next walk (tests/python/held_campaign); the same command then finishes the study."""
    out = tmp_path / "killed"
    command = [sys.executable, "-m", "hexadyn.cli", "study", str(walk_study), "--out", str(out), "--workers", "2", "--no-progress", "--no-plots"]
    held = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(HELD_CAMPAIGN), os.environ.get("PYTHONPATH")]))}
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=held, preexec_fn=sigint_as_in_a_terminal)
    try:
        for _ in range(12000):
            if (out / DATABASE_FILE).exists() and _count(out) >= 1:
                break
            assert process.poll() is None, process.communicate()
            time.sleep(0.01)
        process.send_signal(signal.SIGKILL)
        process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == -signal.SIGKILL
    assert 1 <= len(stored_runs(out)) <= 2 and not (out / RUNS_FILE).exists()
    resumed = subprocess.run(command, capture_output=True, text=True, timeout=600)
    assert resumed.returncode == 0, resumed.stderr
    assert "Study walk_grid: grid design, 4 runs of 2 parameters" in resumed.stdout
    assert stored_runs(out).equals(stored_runs(walk_reference))  # the primary key forbids duplicates
    assert (out / RUNS_FILE).read_bytes() == (walk_reference / RUNS_FILE).read_bytes()


def _count(folder: Path) -> int:
    with sqlite3.connect(folder / DATABASE_FILE, timeout=30) as db:
        if db.execute("SELECT count(*) FROM sqlite_master WHERE name = 'runs'").fetchone()[0] == 0:
            return 0
        return db.execute("SELECT count(*) FROM runs").fetchone()[0]


def test_another_study_in_the_folder_names_the_field(walk_reference, walk_study, tmp_path):
    other = tmp_path / "other.toml"
    other.write_text(WALK_STUDY.replace("values = [8.0, 12.0]", "values = [8.0, 10.0]"))
    result = CliRunner().invoke(cli, ["study", str(other), "--out", str(walk_reference), "--no-progress"])
    assert_one_line_error(result, f"{walk_reference}: the study there has another study", "rerun with its configuration to resume it")


def test_failed_runs_are_stored_and_named(walk_study, tmp_path):
    """A period too long for the workspace at 1.5 cm/s: its runs fail, the others are kept."""
    path = tmp_path / "failing.toml"
    path.write_text(WALK_STUDY.replace("values = [8.0, 12.0]", "values = [8.0, 12.0, 40.0]").replace('"scenario.duration_s" = 3.0', '"scenario.duration_s" = 1.0'))
    result = CliRunner().invoke(cli, ["study", str(path), "--out", str(tmp_path / "out"), "--workers", "1", "--no-progress", "--no-plots"])
    assert_one_line_error(result, "Error: 2 of 6 runs failed (run 4, 5); the first (run 4): ", "gait.period_s", "not retried")
    runs = pd.read_csv(tmp_path / "out" / RUNS_FILE)
    assert list(runs["status"]) == ["ok"] * 4 + ["failed"] * 2


def test_unhealthy_runs_are_named_and_strict_exits_3(walk_study, tmp_path, monkeypatch):
    """Every run's health checks (`hexadyn.health.check`, as `hexadyn simulate`'s) are kept in
    the runs' warnings column; the runs that failed one are named on one WARNING line, and
    --strict makes them exit status 3."""
    args = ["study", str(walk_study), "--workers", "1", "--no-progress", "--no-plots"]
    healthy = CliRunner().invoke(cli, [*args, "--strict", "--out", str(tmp_path / "healthy")])
    assert healthy.exit_code == 0 and "WARNING" not in healthy.stderr, healthy.output
    assert (pd.read_csv(tmp_path / "healthy" / RUNS_FILE)["warnings"] == "[]").all()
    monkeypatch.setattr(health, "MAX_PENETRATION_RATIO", 0.0)  # every foot "too deep" (the workers are forked)
    for strict, status in [([], 0), (["--strict"], UNHEALTHY)]:
        out = tmp_path / f"unhealthy{len(strict)}"
        result = CliRunner().invoke(cli, [*args, *strict, "--out", str(out)])
        assert result.exit_code == status, result.output
        pattern = r"WARNING: 4 of 4 runs failed a health check \(run 0, 1, 2, 3\); the first \(run 0\): a foot went [^\n]* into the ground[^\n]* \(column warnings of [^\n]*runs.csv\)\n"
        assert re.fullmatch(pattern, result.stderr), result.stderr
        warnings = [json.loads(w) for w in pd.read_csv(out / RUNS_FILE)["warnings"]]
        assert all(len(w) == 1 and "into the ground" in w[0] for w in warnings)


WALK_PARAMETERS = ["gait.period_s", "gait.overlap", "gait.clearance_m", "gait.body_height_m"]
#: The AMRU5 study's walk parameters: the PhantomX's and the spread of the footholds.
AMRU5_WALK = WALK_PARAMETERS + ["gait.foothold_offset_m"]


@pytest.mark.parametrize(
    "file, robot, samples, walk, lower, upper",
    [
        ("specific_resistance_1_5cm.toml", "amru5", 512, AMRU5_WALK, [8.0, 0.02, 0.04, 0.40, -0.03], [16.0, 0.10, 0.10, 0.48, 0.03]),
        ("phantomx_gait.toml", "phantomx", 256, WALK_PARAMETERS, [0.6, 0.02, 0.02, 0.09], [1.6, 0.10, 0.045, 0.14]),
    ],
)
def test_shipped_study_is_valid(file, robot, samples, walk, lower, upper):
    """Its fields and outputs pass the engine (Study.create's run at the nominal values), its
    runs stay within the walk's ranges docs/studies.md states, and its friction is the robot's
    Monte Carlo campaign's (the [monte_carlo] table of its description, ``study_tables``)."""
    spec = read_study(STUDIES / file)
    tables = study_tables(FrictionDistributions.of_robot(robot))
    dimension = len(walk) + len(tables["parameters"])
    assert spec.design.method == "sobol" and spec.design.samples == samples and run_count(spec) == samples * (dimension + 2)
    assert [p.key for p in spec.parameters] == walk + list(tables["parameters"])
    assert spec.fixed == tables["fixed"]
    for p in spec.parameters[len(walk):]:
        expected = tables["parameters"][p.key]
        assert p.distribution == expected["distribution"] and (p.mean, p.std) == (expected["mean"], expected["std"])
        np.testing.assert_allclose(p.range, expected["range"], rtol=1e-9, atol=1e-9)
    x = Study.create(spec).samples
    assert x.shape == (samples * (dimension + 2), dimension)
    assert (x[:, : len(walk)].min(axis=0) >= lower).all() and (x[:, : len(walk)].max(axis=0) <= upper).all()


# ----------------------------------------------------------------------------------------------
# A study of the Monte Carlo campaign's friction against the campaign itself
# ----------------------------------------------------------------------------------------------

#: Runs of each side: the standard error of the mean specific resistance is then about 2 % of its
#: standard deviation (0.25 at 1.5 cm/s).
FRICTION_RUNS = 128


def test_friction_study_reproduces_the_monte_carlo_campaign(tmp_path):
    """Issue 40: a Latin hypercube study over the Table 6.7 friction (``study_tables``: each drawn
    field a truncated normal on the campaign's accepted interval) gives the specific resistance
    at 1.5 cm/s the campaign's mean and standard deviation, each difference within the combined
    standard error of the two estimates (measured 2026-11-28: 3.3238 / 0.2546 for the campaign,
    3.3221 / 0.2483 for the study, 0.05 and 0.28 standard errors apart). Independent samples of
    the same distributions: a wrong truncation, a lost sign or a field the study does not set
    moves the mean by several standard errors."""
    distributions = FrictionDistributions.of_robot("amru5")
    campaign = Campaign.create("validation_tripod_1_5cm", velocities=[0.015], runs_per_velocity=FRICTION_RUNS, variants=["dry_viscous"])
    table = campaign.run(tmp_path / "campaign", workers=2, progress=False)
    tables = study_tables(distributions)
    assert set(tables["parameters"]) == set(distributions.gaussians) - set(distributions.load_parameters)
    assert all(tables["parameters"][f]["range"] == list(distributions.accepted_interval(f)) for f in tables["parameters"])
    spec = parse_study(
        {
            "study": {"scenario": "validation_tripod_1_5cm", "outputs": ["specific_resistance"], "seed": 1},
            "fixed": {**tables["fixed"], "gait.heading.vx_m_s": 0.015},
            "design": {"method": "latin", "samples": FRICTION_RUNS},
            "parameters": tables["parameters"],
        }
    )
    study = Study.create(spec).run(tmp_path / "study", workers=2, progress=False, plots=False)
    assert (study.runs["status"] == "ok").all() and table["failed"][0] == 0
    xi = study.runs["specific_resistance"]
    mean_mc, std_mc = float(table["specific_resistance_mean"][0]), float(table["specific_resistance_std"][0])
    mean_study, std_study = float(xi.mean()), float(xi.std(ddof=1))
    n = FRICTION_RUNS
    se_mean = math.hypot(std_mc, std_study) / math.sqrt(n)
    se_std = math.hypot(std_mc, std_study) / math.sqrt(2 * (n - 1))
    assert abs(mean_mc - mean_study) <= se_mean, (mean_mc, mean_study, se_mean)
    assert abs(std_mc - std_study) <= se_std, (std_mc, std_study, se_std)


def test_shipped_efficiency_study_sets_the_efficiency_law_beside_the_load_dependence(tmp_path: Path):
    """docs/studies.md, efficiency against load-dependent friction, on one step (12 s) of its
    walk: the grid holds the robot's efficiency, the specific resistance falls as the horizontal
    screws' forward efficiency rises, and at the robot's efficiency it stays below the
    load-dependent friction's (Section 6.4.4) and above the dry/viscous one's."""
    spec = read_study(STUDIES / "efficiency_vs_load_dependent.toml")
    key = "model.joint_friction.q_h.eta_forward"
    assert spec.design.method == "grid" and [p.key for p in spec.parameters] == [key] and 0.638 in spec.parameters[0].values
    step = {"scenario.duration_s": 12.0}
    runs = Study.create(spec, fixed=step).run(tmp_path / "study", workers=1, progress=False, plots=False).runs
    assert (runs["status"] == "ok").all()
    xi = runs.set_index(key)["specific_resistance"]
    assert (np.diff(xi.to_numpy()) < 0).all(), xi
    walk = "validation_tripod_1_5cm"
    load = hexadyn.simulate(walk, progress=False, overrides={**step, "model.friction": "dry_viscous", "model.load_dependence": True}).summary["specific_resistance"]
    dry = hexadyn.simulate(walk, progress=False, overrides={**step, "model.friction": "dry_viscous"}).summary["specific_resistance"]
    assert dry < xi[0.638] < load, (dry, xi[0.638], load)


#: The robots of the "AMRU5 bis" studies, each set for every run as the study files say (--set).
BIS_ROBOTS = ("amru5", "amru5_backdrivable", "amru5_series_elastic")


def test_shipped_bis_studies_compare_the_drives(tmp_path: Path):
    """docs/studies.md, AMRU5 bis: the walk study at Table 6.2's velocities on one step (12 s) of
    its walk and the unpowered stand study in full, once per robot. The backdrivable drives
    cost less than AMRU5 at every velocity, the series springs' deflection shows in the q_v
    tracking; unpowered, AMRU5 stands, the backdrivable robot keeps sinking (farther at 10 s
    than at 3 s) and the series-elastic one sinks by its springs' deflection and stands (the
    same height at 3 s and 10 s)."""
    walk, stand = read_study(STUDIES / "amru5_bis.toml"), read_study(STUDIES / "amru5_bis_unpowered.toml")
    assert (walk.scenario, walk.design.method, [p.key for p in walk.parameters]) == ("validation_tripod_1_5cm", "grid", ["gait.heading.vx_m_s"])
    assert walk.parameters[0].values == (0.01, 0.015, 0.02, 0.025)
    assert (stand.scenario, [p.key for p in stand.parameters]) == ("unpowered_lugre", ["initial.q_v_m", "scenario.duration_s"])
    walks, stands = {}, {}
    for robot in BIS_ROBOTS:
        runs = Study.create(walk, fixed={"scenario.robot": robot, "scenario.duration_s": 12.0}).run(tmp_path / "walk" / robot, workers=2, progress=False, plots=False).runs
        assert (runs["status"] == "ok").all(), runs
        walks[robot] = runs.set_index("gait.heading.vx_m_s")
        runs = Study.create(stand, fixed={"scenario.robot": robot}).run(tmp_path / "stand" / robot, workers=2, progress=False, plots=False).runs
        assert (runs["status"] == "ok").all(), runs
        stands[robot] = runs.pivot(index="initial.q_v_m", columns="scenario.duration_s", values="body_height_change_m")
    xi = {robot: walks[robot]["specific_resistance"] for robot in BIS_ROBOTS}
    assert (xi["amru5_backdrivable"] < 0.5 * xi["amru5"]).all(), xi
    tracking = {robot: walks[robot]["max_tracking_error_q_v_m"] for robot in BIS_ROBOTS}
    assert (tracking["amru5_series_elastic"] > tracking["amru5"] + 0.5e-3).all(), tracking
    assert (stands["amru5"].abs() < 0.02e-3).all(axis=None), stands["amru5"]
    backdrivable, springs = stands["amru5_backdrivable"], stands["amru5_series_elastic"]
    assert (backdrivable[10.0] < 2 * backdrivable[3.0]).all() and (backdrivable[3.0] < -1e-3).all(), backdrivable
    assert ((springs[10.0] - springs[3.0]).abs() < 1e-6).all() and (springs[10.0] < -4e-3).all(), springs


# ----------------------------------------------------------------------------------------------
# Validation: one line naming the file, the field, the value and what is allowed
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "edit, words",
    [
        (("method = \"grid\"", "method = \"factorial\""), ["field `design.method` = \"factorial\": allowed: one of grid, latin, sobol, morris"]),
        (("method = \"grid\"", "method = \"sobol\"\nsamples = 100"), ["field `design.samples` = 100: allowed: a power of two"]),
        (("method = \"grid\"", "method = \"grid\"\nseed = 3"), ["field `design.seed` = 3: allowed: the keys method, levels of [design]"]),
        (("values = [8.0, 12.0]", "range = [12.0, 8.0]\nlevels = 3"), ["field `parameters.\"gait.period_s\".range` = [12.0, 8.0]: allowed: [low, high]"]),
        (("values = [8.0, 12.0]", "values = [8.0, 12.0]\ndistribution = \"normal\""), ["field `parameters.\"gait.period_s\".distribution` = \"normal\": allowed: uniform"]),
        (("[parameters.\"gait.period_s\"]", "[parameters.\"gait.period s\"]"), ["field `parameters.\"gait.period s\"` = \"gait.period s\": allowed: a dotted key"]),
        (("gait.period_s\"]", "gait.stride_s\"]"), ["validation_tripod_1_5cm.toml (with overrides): field `gait.stride_s`", "unknown field"]),
        (("values = [8.0, 12.0]", "values = [8.0, \"long\"]"), ["field `parameters.\"gait.period_s\".values` = [8.0, \"long\"]: allowed: a list of distinct finite numbers"]),
        (("\"friction_share\"]", "\"friction_share\", \"gait_pattern\"]"), ["field `study.outputs` = \"gait_pattern\": not a figure of the summary of validation_tripod_1_5cm", "allowed: ", "specific_resistance"]),
        (("scenario = \"validation_tripod_1_5cm\"", "scenario = \"no_such_walk\""), ["field `study.scenario` = \"no_such_walk\": no such scenario file"]),
        (("[design]", "[design]\n[design]"), ["not a TOML study file"]),
        (("outputs = [", "outputz = ["), ["field `study.outputz`", "allowed: the keys name, description, scenario, outputs, seed of [study]"]),
    ],
    ids=["method", "sobol-samples", "key-of-another-method", "range", "grid-distribution", "key", "scenario-field", "values", "output", "scenario", "toml", "study-key"],
)
def test_bad_study_files_are_one_line(tmp_path, edit, words):
    path = tmp_path / "bad.toml"
    old, new = edit
    assert old in WALK_STUDY
    path.write_text(WALK_STUDY.replace(old, new, 1))
    out = tmp_path / "out"
    result = CliRunner().invoke(cli, ["study", str(path), "--out", str(out), "--no-progress"])
    assert_one_line_error(result, f"Error: {path}", *words)
    assert not out.exists()


def test_bad_settings_and_missing_files_are_one_line(tmp_path, walk_study):
    assert_one_line_error(CliRunner().invoke(cli, ["study", str(tmp_path / "none.toml")]), "none.toml: No such file or directory")
    result = CliRunner().invoke(cli, ["study", str(walk_study), "--set", "gait.period_s=9", "--out", str(tmp_path / "o")])
    assert_one_line_error(result, "--set gait.period_s: the study varies this field")
    result = CliRunner().invoke(cli, ["study", str(walk_study), "--set", "noequals"])
    assert result.exit_code == 2 and "KEY=VALUE" in result.stderr


def test_a_fixed_field_of_a_toml_date_is_refused_in_one_line(tmp_path):
    """Found by test_fuzz_cli.py: a `[fixed]` value TOML reads as a date reached the engine,
    which has no dates: a TypeError traceback."""
    study = tmp_path / "study.toml"
    study.write_text('[study]\nscenario = "stand_six_legs"\noutputs = ["energy_electrical_j"]\n\n[fixed]\n"scenario.duration_s" = 1979-05-27\n\n[design]\nmethod = "grid"\nlevels = 2\n\n[parameters."model.mu"]\nrange = [0.3, 0.6]\n')
    result = CliRunner().invoke(cli, ["study", str(study), "--no-plots", "--no-progress", "--out", str(tmp_path / "out")])
    assert_one_line_error(result, f'{study}: field `fixed."scenario.duration_s"` = "1979-05-27": allowed: a value a scenario field holds')
