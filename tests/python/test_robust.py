"""Robust under abuse (issue 17): Ctrl-C and kill -9 leave nothing behind, long runs are
streamed to disk, names cannot choose a place, a BOM survives storing, settings outside their
ranges and unhealthy runs are reported, and broken inputs give one line naming the file."""

from __future__ import annotations

import json
import math
import os
import random
import re
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest
from click.testing import CliRunner

import hexadyn
from hexadyn import _core, atomic, compare, health, report, runner
from hexadyn.cli import INTERRUPTED, cli
from hexadyn.options import UNHEALTHY

from conftest import shortened, sigint_as_in_a_terminal

HEXADYN = [sys.executable, "-m", "hexadyn.cli"]


def scenario_text(shipped: str, **replace: str) -> str:
    """A shipped scenario with whole lines `key = ...` replaced by `key = value`."""
    text = (hexadyn.SCENARIOS_DIR / f"{shipped}.toml").read_text()
    for key, value in replace.items():
        text, n = re.subn(rf"(?m)^{key} = .*$", lambda _: f"{key} = {value}", text)
        assert n == 1, key
    return text


def invoke(*args: str):
    return CliRunner().invoke(cli, list(args), prog_name="hexadyn")


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.rglob("*") if p.name.endswith((".partial", ".old")))


# ---------------------------------------------------------------------------------------------
# 1. Interruptible: Ctrl-C stops `hexadyn simulate` at once and writes nothing.
# ---------------------------------------------------------------------------------------------


def test_sigint_stops_a_long_run_and_leaves_nothing(tmp_path: Path):
    """SIGINT at a random moment of a run of 1e4 s: exit 130 within 2 s with one line, no
    results folder, no partial file."""
    path = tmp_path / "long.toml"
    path.write_text(scenario_text("stand_six_legs", duration_s="1e4"))
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen([*HEXADYN, "simulate", str(path), "--no-plots"], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, preexec_fn=sigint_as_in_a_terminal)
    # Wait until the run has started (the progress bar), then a random moment more.
    started = b""
    while b"simulated" not in started:
        chunk = proc.stderr.read1(4096)
        assert chunk, f"the run did not start: {started.decode(errors='replace')}"
        started += chunk
    time.sleep(random.uniform(0.0, 1.5))
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    try:
        out, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        raise
    elapsed = time.monotonic() - sent
    assert proc.returncode == INTERRUPTED, err.decode()
    lines = [line for line in (started + err).decode().replace("\r", "\n").splitlines() if line.strip() and "simulated" not in line]
    assert lines == ["Interrupted: nothing was written."], lines
    assert "Traceback" not in err.decode()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["long.toml"] or not any((tmp_path / "results").iterdir())
    assert leftovers(tmp_path) == []
    assert elapsed < 2.0, f"exit {elapsed:.2f} s after SIGINT"


def test_progress_callback_and_signals_are_polled_by_wall_clock(tmp_path: Path):
    """A Python exception raised while the engine runs (here by the chunk sink) stops the run
    and propagates as it was."""

    class Stop(Exception):
        pass

    def sink(columns, units):
        raise Stop()

    with pytest.raises(Stop):
        _core.run_scenario(str(shortened("stand_six_legs", tmp_path, 1.0)), chunk=sink)


# ---------------------------------------------------------------------------------------------
# 2. Streaming: the series goes to disk in chunks; runs too large are refused up front.
# ---------------------------------------------------------------------------------------------


def test_chunks_are_bit_identical_to_the_whole_series(tmp_path: Path):
    path = str(shortened("leg_sine", tmp_path, 0.5))
    whole = _core.run_scenario(path)
    chunks = []

    def keep(columns, units):
        assert units == whole["units"]  # raised here, it would stop the run and propagate
        chunks.append(columns)

    raw = _core.run_scenario(path, chunk=keep, chunk_rows=9)
    assert raw["columns"] == {} and list(raw["units"]) == list(whole["columns"])
    assert [len(c["t"]) for c in chunks][:3] == [1, 9, 9]
    for name, values in whole["columns"].items():
        np.testing.assert_array_equal(np.concatenate([c[name] for c in chunks]), values)


def test_saved_runs_stream_to_parquet_and_load_lazily(tmp_path: Path):
    path = shortened("leg_sine", tmp_path, 0.5)
    memory = hexadyn.simulate(path, progress=False)
    saved = hexadyn.simulate(path, tmp_path / "out", progress=False)
    assert saved.path == tmp_path / "out"
    assert saved.shape == memory.timeseries.shape
    loaded = hexadyn.Results.load(tmp_path / "out")
    assert loaded._timeseries is None and loaded.shape == memory.timeseries.shape  # read on first access
    np.testing.assert_array_equal(loaded.timeseries.to_numpy(), memory.timeseries.to_numpy())
    assert list(loaded.timeseries.columns) == list(memory.timeseries.columns) and loaded.timeseries.index.name == "t"
    assert loaded.read_columns(["Z"])["Z"].equals(memory.timeseries["Z"])
    assert loaded.summary["warnings"] == [] and loaded.metadata["model"] == {"friction": "lugre", "load_dependence": False, "inductance": False}
    assert json.loads(pq.read_schema(tmp_path / "out" / "timeseries.parquet").metadata[b"hexadyn"])["units"]["Z"] == "m"


def test_a_series_too_long_for_memory_skips_the_in_memory_analysis(tmp_path: Path, monkeypatch):
    monkeypatch.setattr(report, "IN_MEMORY_LIMIT_BYTES", 1000)
    path = shortened("leg_sine", tmp_path, 0.3)
    r = hexadyn.simulate(path, tmp_path / "out", progress=False, plots=True)
    files = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert files == ["energy.csv", "metadata.json", "summary.json", "timeseries.parquet"]
    assert "too long" in r.summary["analysis_skipped"]
    # The energy figures come from the first and last row groups.
    reference = hexadyn.simulate(path, progress=False)
    assert r.summary["average_power_w"] == pytest.approx(reference.summary["average_power_w"], rel=1e-12)


#: A child process: a standing run streamed to a results folder with row groups of 4 MiB (1859
#: instants: a row group is written with every chunk of 2000 from the engine) and without the
#: in-memory analysis; prints its peak resident memory (MB).
STREAMED_RUN = """
import resource, sys
import hexadyn
from hexadyn import report, results
results.ROW_GROUP_BYTES = 4 * 2**20
report.IN_MEMORY_LIMIT_BYTES = 0
hexadyn.simulate(sys.argv[1], sys.argv[2], progress=False)
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
"""


def test_the_memory_of_a_streamed_run_does_not_grow_with_its_duration(tmp_path: Path):
    peaks = {}
    for duration in (10.0, 100.0):
        folder = tmp_path / f"{duration:g}"
        folder.mkdir()
        done = subprocess.run([sys.executable, "-c", STREAMED_RUN, str(shortened("stand_six_legs", folder, duration)), str(folder / "out")], capture_output=True, text=True, check=True)
        peaks[duration] = float(done.stdout.split()[-1])
    file = pq.ParquetFile(tmp_path / "100" / "out" / "timeseries.parquet")
    rows, columns = file.metadata.num_rows, file.metadata.num_columns
    assert rows == 10_001 and file.num_row_groups == 5
    np.testing.assert_allclose(file.read(columns=["t"]).column("t").to_numpy(), np.arange(rows) * 0.01, atol=1e-9)
    # The first and the last instants, read a few columns at a time, are those of the whole file.
    whole = file.read().to_pandas()
    pd.testing.assert_frame_equal(hexadyn.Results.load(tmp_path / "100" / "out").endpoints(), whole.iloc[[0, -1]])
    # Held in memory, the 9000 instants more would take 8 x 9000 x columns bytes (22 MB; the peak
    # grows by 30 MB then); streamed, only the footer grows: 0.9 kB per column and row group
    # (1 MB here; the peak grows by about 5 MB).
    held = 8 * 9000 * columns / 2**20
    assert peaks[100.0] - peaks[10.0] < 0.5 * held, f"peak memory {peaks} MB: grew by more than half the {held:.0f} MB of the longer series"


def test_runs_that_do_not_fit_are_refused_before_running(tmp_path: Path, monkeypatch):
    # The engine's columns of this scenario ("t" included), from a run of one control period.
    (tmp_path / "short").mkdir()
    columns = len(_core.run_scenario(str(shortened("stand_six_legs", tmp_path / "short", 0.01)))["units"])
    path = shortened("stand_six_legs", tmp_path, 1e5)
    monkeypatch.setattr(runner.shutil, "disk_usage", lambda p: type("Usage", (), {"free": 10_000_000})())
    rows = 10_000_001  # 1e5 s at the 10 ms control period, both ends included
    estimate = f"about {8 * rows * columns / 1e9:.1f} GB ({rows} instants x {columns} columns x 8 bytes), more than the free space of the disk of {tmp_path / 'out'} (10.0 MB)"
    with pytest.raises(ValueError, match=re.escape(estimate)):
        hexadyn.simulate(path, tmp_path / "out", progress=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["short", "stand_six_legs.toml"]
    with pytest.raises(ValueError, match="more than memory .* pass out="):
        hexadyn.simulate(path, progress=False)


# ---------------------------------------------------------------------------------------------
# 3. Ranges and health.
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "override, field",
    [
        ({"integrator.tolerance": 1e6}, "integrator.tolerance"),
        ({"integrator.h_max_s": 1e-9}, "integrator.h_max_s"),
        ({"model.supply_voltage_v": 1e6}, "model.supply_voltage_v"),
        ({"model.mu": 1e9}, "model.mu"),
        ({"model.k_gnd": 1e15}, "model.k_gnd"),
    ],
)
def test_numerical_settings_out_of_range_name_the_field(override, field):
    with pytest.raises(ValueError, match=re.escape(f"`{field}`")):
        _core.load_scenario(str(hexadyn.SCENARIOS_DIR / "stand_six_legs.toml"), override)


def test_health_checks_flag_meaningless_runs():
    healthy = {
        "energy_balance_error_relative": 0.001, "max_penetration_m": 0.002, "static_penetration_m": 0.0023, "initial_body_height_m": 0.4,
        "body_height_change_m": -0.01, "tracking_error_xy_max_m": 0.01, "reference_distance_m": 0.9, "distance_walked_m": 0.89,
    }  # fmt: skip
    assert health.check(healthy) == []
    for change, words in [
        ({"energy_balance_error_relative": -0.128}, "energy balance error 12.80 %"),
        ({"max_penetration_m": 0.05}, "50.0 mm into the ground, more than 3 x the 2.3 mm"),
        ({"body_height_change_m": -0.3}, "the body fell by 300 mm"),
        ({"tracking_error_xy_max_m": 1.0}, "strayed 1.000 m"),
        ({"distance_walked_m": 282.0}, "walked 282.000 m for a 0.900 m reference path"),
        ({"energy_electrical_j": float("nan")}, "non-finite figures: energy_electrical_j"),
        ({"min_stability_margin_m": -0.004, "min_stability_margin_t_s": 12.5}, "stability margin fell to -4.0 mm at t = 12.50 s"),
        ({"min_stability_margin_m": float("-inf"), "min_stability_margin_t_s": 3.0}, "fewer than three feet were in support at t = 3.00 s"),
        ({"foot_left_terrain": 2, "foot_left_terrain_t_s": 41.5}, "foot 2 went beyond the border of the terrain mesh at t = 41.50 s"),
        # The desired pose halted with the walk (issue 37): the commanded path is the measure.
        ({"commanded_path_length_m": 1.0, "distance_walked_m": 0.29, "reference_distance_m": 0.3}, "walked 0.290 m for a 1.000 m commanded path"),
    ]:
        warnings = health.check({**healthy, **change})
        assert len(warnings) == 1 and words in warnings[0], (change, warnings)
    # Without electrical energy (unpowered) the shares of it are 0/0: not applicable.
    unpowered = {**healthy, "energy_electrical_j": 0.0, "friction_share": float("nan"), "joule_share": float("nan"), "specific_resistance": float("nan")}
    assert health.check(unpowered) == []
    assert health.check({**healthy, "min_stability_margin_m": 0.003, "min_stability_margin_t_s": 1.0}) == []
    # A walk's episodes and its clamped references and cuts, with when they happened.
    free = {**healthy, "gait_pattern": "free", "clamped_ik_references": 0, "limit_switch_cuts": 0, "deadlocked_at_end": False}
    assert health.check(free) == []
    for change, words in [
        ({"longest_deadlock_s": 25.0, "longest_deadlock_t_s": 100.0}, "deadlocked for 25.00 s from t = 100.00 s (allowed 20 s)"),
        ({"longest_deadlock_s": 3.0, "longest_deadlock_t_s": 197.0, "deadlocked_at_end": True}, "still deadlocked at the end (its longest deadlock began at t = 197.00 s)"),
        ({"longest_support_loss_s": 0.5, "longest_support_loss_t_s": 12.0}, "fewer than three feet carried the robot for 0.50 s from t = 12.00 s"),
        ({"longest_airborne_load_s": 2.0, "longest_airborne_load_t_s": 3.5}, "a foot in takeoff or swing carried load for 2.00 s from t = 3.50 s"),
        ({"longest_airborne_load_s": 0.4, "longest_airborne_load_t_s": 56.1, "longest_airborne_load_leg": 3}, "a foot in takeoff or swing carried load (leg 3) for 0.40 s from t = 56.10 s"),
        ({"clamped_ik_references": 1712, "last_clamped_ik_reference_t_s": 339.17}, "1712 foot references were beyond the leg's reach and clamped into the joint ranges, the last at t = 339.17 s"),
        ({"limit_switch_cuts": 546}, "the limit switches cut a motor 546 times"),
    ]:
        warnings = health.check({**free, **change})
        assert len(warnings) == 1 and words in warnings[0], (change, warnings)
    # Short episodes are healthy; the periodic gaits' episodes are the thesis' own cases (Section 7.6).
    assert health.check({**free, "longest_support_loss_s": 0.2, "longest_support_loss_t_s": 1.0, "longest_airborne_load_s": 0.3, "longest_airborne_load_t_s": 1.0}) == []
    assert health.check({**free, "gait_pattern": "tripod", "longest_airborne_load_s": 1.34, "longest_airborne_load_t_s": 4.66}) == []
    # The identification campaigns drive the joints to their switches on purpose.
    assert health.check({**healthy, "limit_switch_cuts": 968}) == []


def test_health_sees_a_five_legged_walk_halted_for_good():
    """Issue 37: with leg 4 failed the shipped five-legged walk halted for good at about 30 s
    (a deadlock the five-leg rules did not clear); its warnings said nothing. Now the longest
    deadlock, its start and that it was still on at the end are in the summary, and warned. The
    five-leg footholds clear that deadlock now; a stability margin of 30 cm, which no lift on
    five legs keeps, halts the walk for good instead."""
    r = hexadyn.simulate("free_gait_five_legs", progress=False, overrides={"gait.free.failed_leg": 4, "gait.free.stability_margin_m": 0.3})
    s = r.summary
    assert s["deadlocked_at_end"] is True and s["longest_deadlock_s"] > 100.0
    assert s["longest_deadlock_t_s"] + s["longest_deadlock_s"] == pytest.approx(s["duration_s"], abs=0.02)
    deadlock = r.timeseries["deadlock"].to_numpy()
    assert deadlock[-1] == 1.0 and deadlock[r.timeseries.index.get_indexer([s["longest_deadlock_t_s"]], method="nearest")[0]] == 1.0
    assert any(w.startswith(f"the free gait was deadlocked for {s['longest_deadlock_s']:.2f} s") for w in s["warnings"]), s["warnings"]
    # 200 s at 0.5 cm/s commanded; the body's net advance is about 0.15 m (the sway of the deadlock).
    assert s["commanded_path_length_m"] == pytest.approx(1.0, rel=1e-3) and s["net_displacement_m"] < 0.3
    assert any("m commanded path" in w for w in s["warnings"]), s["warnings"]
    # The shipped walk (leg 3 failed) is healthy.
    assert hexadyn.simulate("free_gait_five_legs", progress=False).summary["warnings"] == []


def test_strict_turns_warnings_into_an_exit_status(tmp_path: Path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = shortened("stand_six_legs", tmp_path, 0.05)
    result = invoke("simulate", str(path), "--no-progress", "--no-plots", "--strict")
    assert result.exit_code == 0, result.output
    monkeypatch.setattr(health, "MAX_PENETRATION_RATIO", 0.0)
    for strict, status in [([], 0), (["--strict"], UNHEALTHY)]:
        result = invoke("simulate", str(path), "--no-progress", "--no-plots", *strict)
        assert result.exit_code == status and "WARNING: a foot went" in result.output, result.output
    saved = json.loads(next((tmp_path / "results").glob("stand_six_legs-2")).joinpath("summary.json").read_text())
    assert saved["warnings"] and "into the ground" in saved["warnings"][0]


# ---------------------------------------------------------------------------------------------
# 4. One text, one parser: a BOM survives the results folder.
# ---------------------------------------------------------------------------------------------


def test_a_scenario_with_a_byte_order_mark_is_stored_and_reloaded(tmp_path: Path):
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + scenario_text("stand_six_legs", duration_s="0.05", inductance="true").encode())
    r = hexadyn.simulate(path, tmp_path / "out", progress=False)
    loaded = hexadyn.Results.load(tmp_path / "out")
    assert loaded.metadata["scenario"].startswith("\ufeff") and loaded.metadata["model"]["inductance"] is True
    assert (report.energy.energy_breakdown(loaded)["magnetic_j"] != 0).any()
    # Results saved before the flags were stored: the engine reads them from the stored text.
    loaded.metadata.pop("model")
    np.testing.assert_array_equal(report.energy.energy_breakdown(loaded)["magnetic_j"], report.energy.energy_breakdown(r)["magnetic_j"])


def test_compare_reads_the_velocity_through_the_engine(tmp_path: Path):
    path = tmp_path / "walk.toml"
    path.write_bytes(b"\xef\xbb\xbf" + (hexadyn.SCENARIOS_DIR / "validation_tripod_2cm.toml").read_bytes())
    assert compare._scenario_velocity(path, {}) == 0.02
    assert compare._scenario_velocity(hexadyn.SCENARIOS_DIR / "path_spline.toml", {}) is None


def test_compare_friction_with_one_velocity_skips_the_fit(tmp_path: Path):
    path = shortened("validation_tripod_1_5cm", tmp_path, 0.5)
    result = invoke("compare-friction", str(path), "--velocities", "1.5", "--models", "none", "--out", str(tmp_path / "cmp"), "--no-progress", "--workers", "1")
    assert result.exit_code == 0, result.output
    assert "averaged power of the q_r actuators" in result.output and "skipped: it needs at least two velocities" in result.output
    assert (tmp_path / "cmp" / "fit.csv").read_text().strip() == "model,alpha_w,beta_n,xi_asymptote,mass_kg"


# ---------------------------------------------------------------------------------------------
# 5. Names are folder names, not paths.
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name, folder", [("/tmp/x", "_tmp_x"), ("../../../x", "_.._.._x"), ("..", "scenario"), ("a b\nc", "a_b_c"), ("stand", "stand")])
def test_a_scenario_name_is_made_a_folder_name(tmp_path: Path, monkeypatch, name: str, folder: str):
    monkeypatch.chdir(tmp_path)
    assert runner.safe_folder_name(name) == folder
    path = tmp_path / "s.toml"
    path.write_text(scenario_text("stand_six_legs", duration_s="0.02", name=json.dumps(name)))
    result = invoke("simulate", str(path), "--no-progress", "--no-plots")
    assert result.exit_code == 0, result.output
    assert [p.name for p in (tmp_path / "results").iterdir()] == [folder]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results", "s.toml"]


# ---------------------------------------------------------------------------------------------
# 6. Stale partials of killed runs are removed by the next run in the same place.
# ---------------------------------------------------------------------------------------------


def test_a_run_killed_while_saving_leaves_a_partial_the_next_run_removes(tmp_path: Path):
    """SIGKILL while the results folder is written (the series streams into it during the
    whole run): a `.NAME.PID.*.partial` stays; the next run into the same folder removes it."""
    path = tmp_path / "long.toml"
    path.write_text(scenario_text("stand_six_legs", duration_s="1e4"))
    out = tmp_path / "out"
    proc = subprocess.Popen([*HEXADYN, "simulate", str(path), "--out", str(out / "a"), "--no-progress"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        while not any((out.iterdir() if out.is_dir() else [])):
            assert proc.poll() is None, "the run ended before writing"
            time.sleep(0.05)
        time.sleep(random.uniform(0.1, 1.0))
    finally:
        proc.kill()
        proc.wait()
    stale = leftovers(out)
    assert len(stale) == 1 and stale[0].startswith(f".a.{proc.pid}."), stale
    # A live owner's partial is kept.
    live = out / f".c.{os.getpid()}.abcdefgh.partial"
    live.mkdir()
    short = shortened("stand_six_legs", tmp_path, 0.02)
    result = invoke("simulate", str(short), "--out", str(out / "b"), "--no-progress", "--no-plots")
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in out.iterdir()) == [live.name, "b"]


def test_stale_partial_files_are_recognised_by_their_owner():
    assert atomic._owner(".specific_resistance.csv.1234.k2j3h4.partial") == 1234
    assert atomic._owner(".a.b.99.x_y.old") == 99
    for name in ["results", ".hidden", ".a.partial", ".a.xyz.abc.partial", "a.1.b.partial"]:
        assert atomic._owner(name) is None, name


# ---------------------------------------------------------------------------------------------
# 7. Smaller rough edges.
# ---------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def saved(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("saved")
    hexadyn.simulate(shortened("stand_six_legs", folder, 0.05), folder / "run", progress=False)
    return folder / "run"


@pytest.mark.parametrize(
    "file, content, words",
    [
        ("summary.json", "[1, 2]", "summary.json: a JSON array; expected an object"),
        ("summary.json", "{broken", "summary.json: not valid JSON"),
        ("metadata.json", '{"format": "hexadyn-results", "units": [1]}', "metadata.json: `units` = [1]: a JSON array; allowed: a JSON object"),
        ("metadata.json", '{"format": "hexadyn-results", "robot": 5}', "metadata.json: `robot` = 5: a JSON integer; allowed: a JSON string"),
        ("metadata.json", '{"format": "hexadyn-results", "scenario_path": 5}', "metadata.json: `scenario_path` = 5: a JSON integer; allowed: a JSON string or a JSON null"),
        ("metadata.json", '{"format": "hexadyn-results", "units": {"t": 1}}', "metadata.json: `units` holds 1, a JSON integer; allowed: strings as its values"),
        ("metadata.json", "[]", "metadata.json: a JSON array"),
        ("metadata.json", "\xff", "metadata.json: not UTF-8 text (invalid byte at offset 0)"),
    ],
)
def test_broken_results_files_are_named_in_one_line(saved: Path, tmp_path: Path, file: str, content: str, words: str):
    broken = tmp_path / "broken"
    broken.mkdir()
    for p in saved.iterdir():
        if p.is_file():
            (broken / p.name).write_bytes(p.read_bytes())
    (broken / file).write_text(content, encoding="latin-1")
    result = invoke("plot", str(broken))
    assert result.exit_code == 1 and words in result.output and "Traceback" not in result.output, result.output
    assert len(result.output.strip().splitlines()) == 1


def test_a_timeseries_directory_is_not_an_empty_table(saved: Path, tmp_path: Path):
    broken = tmp_path / "broken"
    broken.mkdir()
    for name in ["metadata.json", "summary.json"]:
        (broken / name).write_bytes((saved / name).read_bytes())
    (broken / "timeseries.parquet").mkdir()
    with pytest.raises(ValueError, match="timeseries.parquet: a directory"):
        hexadyn.Results.load(broken)


def test_override_values_that_toml_cannot_hold_name_the_field():
    path = str(hexadyn.SCENARIOS_DIR / "stand_six_legs.toml")
    with pytest.raises(ValueError, match=r"override model\.mu = 1180591620717411303424: out of range"):
        _core.load_scenario(path, {"model.mu": 2**70})
    # A newline in an override is a value like any other.
    assert _core.load_scenario(path, {"scenario.name": "two\nlines"})["name"] == "two\nlines"
    assert _core.load_scenario(path, {"scenario.description": "a\r\nb"})["description"] == "a\r\nb"


def test_a_device_as_robot_file_fails_at_once(tmp_path: Path):
    path = tmp_path / "s.toml"
    path.write_text(scenario_text("stand_six_legs", robot='"/dev/zero"'))
    with pytest.raises(ValueError, match="scenario.robot.*not a regular file"):
        _core.load_scenario(str(path))


# ---------------------------------------------------------------------------------------------
# 5. Every shipped scenario passes its health checks: `hexadyn simulate NAME --strict` exits 0.
# ---------------------------------------------------------------------------------------------

#: The simulated time of a run of the test below: a shipped scenario longer than this (19 of
#: 47, up to 1000 s; in full, about 2.5 minutes of engine time alone on the shared 2-core
#: machine, before streaming and analysing the series) runs its first STRICT_CAP_S seconds only
#: (`--set scenario.duration_s`); the others run in full (the whole test: about 50 s).
STRICT_CAP_S = 120.0
@pytest.mark.parametrize("name", hexadyn.list_scenarios())
def test_every_shipped_scenario_passes_strict(name: str, tmp_path: Path):
    duration = _core.load_scenario(str(hexadyn.resolve_scenario(name)))["duration_s"]
    cut = ["--set", f"scenario.duration_s={STRICT_CAP_S}"] if duration > STRICT_CAP_S else []
    result = invoke("simulate", name, *cut, "--strict", "--no-plots", "--no-progress", "--out", str(tmp_path / "run"))
    assert result.exit_code == 0, result.output
    assert json.loads((tmp_path / "run" / "summary.json").read_text())["warnings"] == []


def copy_of_results(saved: Path, broken: Path) -> Path:
    """A copy of the files of the results folder `saved` in the new folder `broken`, to break."""
    broken.mkdir()
    for p in saved.iterdir():
        if p.is_file():
            (broken / p.name).write_bytes(p.read_bytes())
    return broken


@pytest.mark.parametrize("command", ["plot", "identify", "export"])
def test_a_time_series_holding_a_column_twice_is_named_in_one_line(saved: Path, tmp_path: Path, command: str):
    """Found by test_fuzz_cli.py: a time series with a column renamed to the name of another
    made that column a table, and `hexadyn identify` ended in an AttributeError traceback."""
    import pyarrow.parquet as pq

    broken = copy_of_results(saved, tmp_path / "broken")
    table = pq.read_table(saved / "timeseries.parquet")
    pq.write_table(table.rename_columns([table.column_names[0] if i == 1 else c for i, c in enumerate(table.column_names)]), broken / "timeseries.parquet")
    args = {"plot": ["plot", str(broken)], "identify": ["identify", str(broken), "--out", str(tmp_path / "ident")], "export": ["export", str(broken), "--format", "csv"]}[command]
    result = invoke(*args)
    assert result.exit_code == 1 and "Traceback" not in result.output, (result.output, result.exception)
    assert result.stderr.splitlines() == [f"Error: {'' if command != 'identify' else f'{broken}: cannot read the results folder: '}{broken / 'timeseries.parquet'}: column `{table.column_names[0]}` appears 2 times; allowed: a time series of distinct columns"], result.stderr


@pytest.mark.parametrize("edit, words", [("single", "the time series has a single instant"), ("constant", "the time series' instants do not increase (median step 0 s)")])
def test_plot_refuses_a_time_axis_it_cannot_draw_on_in_one_line(saved: Path, tmp_path: Path, edit: str, words: str):
    """Found by test_fuzz_cli.py: `hexadyn plot` of a time series cut to one instant, or whose
    times were all made equal, drew its figures with matplotlib's warning of a singular axis on
    stderr. The figures are refused first, in one line naming the folder."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    broken = copy_of_results(saved, tmp_path / "broken")
    table = pq.read_table(saved / "timeseries.parquet")
    if edit == "single":
        table = table.slice(0, 1)
    else:
        t = table.column_names.index("t")
        table = table.set_column(t, "t", pa.array([1.0] * table.num_rows))
    pq.write_table(table, broken / "timeseries.parquet")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = invoke("plot", str(broken))
    assert result.exit_code == 1 and result.stderr.startswith(f"Error: {broken}: {words}") and len(result.stderr.splitlines()) == 1, (result.output, result.exception)
    assert not (broken / "plots").exists()


@pytest.mark.parametrize("edit, words", [("drop", "the time series has no column 'q_r[0]'"), ("phase", "column `phase[3]` = nan at t = 0 s: not a foot phase; allowed: the codes")])
def test_plot_names_a_missing_column_or_a_phase_that_is_no_phase(tmp_path: Path, edit: str, words: str):
    """Found by test_fuzz_cli.py: `hexadyn plot` of a time series without a joint's column ended
    in a KeyError traceback; with a foot phase made NaN it drew figures with numpy's cast
    warnings on stderr. Both are refused in one line naming the folder and the column (the
    column dropped from the metadata too: else the folder is refused when loaded, below)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    folder = tmp_path / "walk"
    hexadyn.simulate(shortened("validation_tripod_1_5cm", tmp_path, 0.05), folder, progress=False)
    table = pq.read_table(folder / "timeseries.parquet")
    if edit == "drop":
        table = table.drop_columns(["q_r[0]"])
        metadata = json.loads((folder / "metadata.json").read_text())
        del metadata["units"]["q_r[0]"]
        (folder / "metadata.json").write_text(json.dumps(metadata))
    else:
        table = table.set_column(table.column_names.index("phase[3]"), "phase[3]", pa.array([math.nan] * table.num_rows))
    pq.write_table(table, folder / "timeseries.parquet")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = invoke("plot", str(folder))
    assert result.exit_code == 1 and result.stderr.startswith(f"Error: {folder}: {words}") and len(result.stderr.splitlines()) == 1, (result.output, result.exception)


@pytest.mark.parametrize("command", [["export", "--format", "mcap"], ["export", "--format", "csv"], ["plot"], ["ground-detection"]])
def test_a_time_series_without_a_column_its_metadata_lists_is_refused_when_loaded(saved: Path, tmp_path: Path, command: list[str]):
    """Found by test_fuzz_cli.py: `hexadyn export --format mcap` of a time series that lost a
    motor current its metadata lists ended in a KeyError traceback. The folder is refused when
    loaded, naming the file and the column."""
    import pyarrow.parquet as pq

    broken = tmp_path / "broken"
    broken.mkdir()
    for p in saved.iterdir():
        if p.is_file():
            (broken / p.name).write_bytes(p.read_bytes())
    pq.write_table(pq.read_table(saved / "timeseries.parquet").drop_columns(["i_q_r[4]", "u_q_r[4]"]), broken / "timeseries.parquet")
    result = invoke(command[0], str(broken), *command[1:])
    assert result.exit_code == 1 and "Traceback" not in result.output, (result.output, result.exception)
    assert result.stderr.splitlines() == [f"Error: {broken / 'timeseries.parquet'}: no column `u_q_r[4]` (and 1 more), which metadata.json lists; allowed: a time series of the columns of its metadata"]


def test_an_infinite_duration_is_refused_naming_the_field(tmp_path: Path):
    """Found by test_fuzz_cli.py: `duration_s = inf` passed the check of at least one control
    period, and `hexadyn simulate` ended in an OverflowError traceback (the rows of an infinite
    run)."""
    path = tmp_path / "forever.toml"
    path.write_text(scenario_text("stand_six_legs", duration_s="inf"))
    result = invoke("simulate", str(path), "--no-plots", "--no-progress")
    assert result.exit_code == 1 and "Traceback" not in result.output, (result.output, result.exception)
    assert result.stderr.splitlines() == [f"Error: {path}:10: field `scenario.duration_s` = inf: not a finite number; allowed: a finite duration >= 0.01 s (one control period)"], result.stderr


def test_a_duration_too_long_for_an_integer_count_is_refused_as_too_large(tmp_path: Path):
    """Found by test_fuzz_cli.py: `duration_s = 1e308` made the count of instants infinite:
    an OverflowError traceback before the check of the memory a series takes."""
    path = tmp_path / "long.toml"
    path.write_text(scenario_text("stand_six_legs", duration_s="1e308"))
    result = invoke("simulate", str(path), "--no-plots", "--no-progress", "--out", str(tmp_path / "out"))
    assert result.exit_code == 1 and "Traceback" not in result.output, (result.output, result.exception)
    assert len(result.stderr.splitlines()) == 1 and "Error: the time series would take about inf TB (inf instants x" in result.stderr, result.stderr


def test_a_time_series_column_of_text_is_named_in_one_line(saved: Path, tmp_path: Path):
    """Found by test_fuzz_cli.py: a time series column of strings reached the figures' sums:
    a numpy casting traceback from `hexadyn plot`."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    broken = tmp_path / "broken"
    broken.mkdir()
    for p in saved.iterdir():
        if p.is_file():
            (broken / p.name).write_bytes(p.read_bytes())
    table = pq.read_table(saved / "timeseries.parquet")
    table = table.set_column(table.column_names.index("q_v[2]"), "q_v[2]", pa.array(["x"] * table.num_rows))
    pq.write_table(table, broken / "timeseries.parquet")
    result = invoke("plot", str(broken))
    assert result.exit_code == 1 and result.stderr.splitlines() == [f"Error: {broken / 'timeseries.parquet'}: column `q_v[2]` holds string values; allowed: a time series of numbers"], (result.output, result.exception)
