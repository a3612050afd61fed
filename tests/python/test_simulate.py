"""Scenarios from Python and from the command line: results in pandas with units, atomic
save/load, the shipped scenarios, one-line errors for malformed scenarios."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import hexadyn
from hexadyn import Results, _core, report
from hexadyn import results as results_module
from hexadyn.cli import DEFAULT_SCENARIO, cli

from conftest import shortened

#: The shipped scenarios: every ``*.toml`` of the package's scenario folder, the one list that
#: the Rust tests (``crates/hexadyn/tests/robot_scenario.rs``) enumerate too.
SOURCE_SCENARIOS = Path(__file__).resolve().parents[2] / "python" / "hexadyn" / "scenarios"


@pytest.fixture(scope="module")
def sine_file(tmp_path_factory) -> Path:
    return shortened("leg_sine", tmp_path_factory.mktemp("scenario"))


@pytest.fixture(scope="module")
def sine(sine_file) -> Results:
    return hexadyn.simulate(sine_file, progress=False)


def test_shipped_scenarios_are_listed_and_valid():
    files = hexadyn.scenario_files()
    # The scenarios found are those of the repository (where the Rust tests look), and there are some.
    assert [p.name for p in files] == sorted(p.name for p in SOURCE_SCENARIOS.glob("*.toml"))
    assert hexadyn.list_scenarios() == [p.stem for p in files]
    assert len(files) >= 30 and DEFAULT_SCENARIO in {p.stem for p in files}
    for p in files:
        # Shipped as package data, next to the Python modules.
        assert p.parent == Path(hexadyn.__file__).resolve().parent / "scenarios"
        info = _core.load_scenario(str(p))
        assert info["name"] == p.stem
        assert info["duration_s"] > 0
        assert p.read_text().startswith("#"), "comment header citing the thesis"
    assert hexadyn.resolve_scenario("leg_ramp") == hexadyn.SCENARIOS_DIR / "leg_ramp.toml"
    assert hexadyn.resolve_scenario("leg_ramp.toml") == hexadyn.SCENARIOS_DIR / "leg_ramp.toml"
    with pytest.raises(FileNotFoundError, match="stand_six_legs"):
        hexadyn.resolve_scenario("no_such_scenario")


def test_timeseries_in_pandas_with_units(sine: Results, sine_file: Path):
    df = sine.timeseries
    assert isinstance(df, pd.DataFrame)
    assert df.index.name == "t"
    assert len(df) == 21  # 0.2 s at the 10 ms control period, both ends included
    np.testing.assert_allclose(df.index.to_numpy(), np.arange(21) * 0.01, atol=1e-12)
    expected_units = {
        "t": "s",
        "X": "m",
        "Z": "m",
        "yaw": "rad",
        "q_r[1]": "rad",
        "q_v[1]": "m",
        "q_h[1]": "m",
        "q_v_dot[1]": "m/s",
        "q_v_ref[1]": "m",
        "u_q_v[1]": "V",
        "i_q_v[1]": "A",
        "tau_m_q_r[1]": "Nm",
        "tau_f_q_v[1]": "N",
        "z_q_v[1]": "m",
        "Fz[0]": "N",
        "Fn[0]": "N",
        "penetration[0]": "m",
        "E_el_q_v[1]": "J",
        "E_joule_q_v[1]": "J",
        "E_fric_q_v[1]": "J",
        "E_kin": "J",
        "E_pot": "J",
    }
    for name, unit in expected_units.items():
        assert sine.units[name] == unit, name
        if name != "t":
            assert name in df.columns, name
    assert set(df.columns) | {"t"} == set(sine.units)
    assert all(df.dtypes == np.float64)
    assert np.isfinite(df.to_numpy()).all()
    assert sine.descriptions["i_q_v[1]"]
    # Leg 1 follows its sine references in the air; the tripod 0-3-4 carries the robot.
    assert (df["Fz[1]"] == 0).all()
    assert df["q_v_ref[1]"].iloc[-1] == pytest.approx(0.045 + 0.004 * math.sin(2 * math.pi * 0.25 * 0.2), abs=1e-12)
    assert (df["Fz[0]"] + df["Fz[3]"] + df["Fz[4]"]).iloc[-1] == pytest.approx(34.447 * 9.81, rel=0.02)
    # Summary and metadata.
    s = sine.summary
    assert s["scenario"] == "leg_sine" and s["friction"] == "lugre" and s["control"] == "pi"
    assert s["duration_s"] == pytest.approx(0.2)
    assert s["rows"] == 21 and isinstance(s["integration_steps"], int)
    # A sanity bound on a 0.2 s transient (the leg's drop): its balance error at the robot's
    # integration tolerance is the step sequence's, -0.7 % to +1.0 % over 0.2-2 s; the account
    # closes to 0.1 % when the integration converges (the Rust test
    # walking_energy_account_closes_when_the_integration_converges).
    assert abs(s["energy_balance_error_relative"]) < 0.02
    assert sine.metadata["scenario"] == sine_file.read_text()
    assert 'name = "AMRU5"' in sine.metadata["robot"]
    assert sine.metadata["hexadyn_version"] == hexadyn.__version__
    assert sine.metadata["units"] == sine.units


def test_runs_are_deterministic(sine: Results, sine_file: Path):
    again = hexadyn.simulate(sine_file, progress=False)
    pd.testing.assert_frame_equal(sine.timeseries, again.timeseries, check_exact=True)


def test_progress_callback_and_bar(sine_file: Path, capsys):
    calls = []
    hexadyn.simulate(sine_file, progress=lambda t, d: calls.append((t, d)))
    assert len(calls) >= 2
    assert calls[0][0] == 0.0 and calls[-1][0] == pytest.approx(0.2)
    assert all(d == 0.2 for _, d in calls)
    hexadyn.simulate(sine_file, progress=True)
    assert "s simulated" in capsys.readouterr().err


def test_progress_exception_stops_the_run(sine_file: Path):
    def boom(t, d):
        if t > 0.05:
            raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        _core.run_scenario(str(sine_file), boom)


def test_save_load_round_trip(sine: Results, tmp_path: Path):
    folder = report.save(sine, tmp_path / "nested" / "run")
    assert sorted(p.name for p in folder.iterdir()) == ["energy.csv", "metadata.json", "power.csv", "summary.json", "timeseries.parquet"]
    assert [p.name for p in folder.parent.iterdir()] == ["run"], "no temporary folders left"
    loaded = Results.load(folder)
    pd.testing.assert_frame_equal(loaded.timeseries, sine.timeseries, check_exact=True)
    assert loaded.units == sine.units
    assert loaded.summary == sine.summary
    assert loaded.metadata["scenario"] == sine.metadata["scenario"]
    assert loaded.metadata["robot"] == sine.metadata["robot"]
    assert loaded.metadata["hexadyn_version"] == hexadyn.__version__
    assert loaded.path == folder
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["scenario"] == "leg_sine"
    import pyarrow.parquet as pq

    units = json.loads(pq.read_schema(folder / "timeseries.parquet").metadata[b"hexadyn"])["units"]
    assert units["i_q_v[1]"] == "A"

    with pytest.raises(FileExistsError):
        report.save(sine, folder)
    report.save(sine, folder, overwrite=True)
    assert Results.load(folder).summary == sine.summary
    assert sorted(p.name for p in folder.parent.iterdir()) == ["run"]
    with pytest.raises(ValueError, match="not a hexadyn results folder"):
        Results.load(tmp_path)


def test_atomic_save_leaves_nothing_on_failure(sine: Results, tmp_path: Path, monkeypatch):
    calls = []
    real = results_module._write_json

    def failing(path, value):
        calls.append(path.name)
        if path.name == "summary.json":  # after the Parquet file and metadata.json were written
            raise OSError(28, "No space left on device", str(path))
        real(path, value)

    monkeypatch.setattr(results_module, "_write_json", failing)
    with pytest.raises(OSError, match="No space left"):
        report.save(sine, tmp_path / "new" / "run")
    assert calls == ["metadata.json", "summary.json"]
    assert list(tmp_path.iterdir()) == [], "neither the folder, its new parent nor a temporary folder is left"

    # Overwriting: a failure keeps the previous results intact.
    monkeypatch.setattr(results_module, "_write_json", real)
    folder = report.save(sine, tmp_path / "run")
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    monkeypatch.setattr(results_module, "_write_json", failing)
    with pytest.raises(OSError):
        report.save(sine, folder, overwrite=True)
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before
    assert [p.name for p in tmp_path.iterdir()] == ["run"]


def test_simulate_saves_to_out(sine_file: Path, tmp_path: Path):
    out = tmp_path / "out"
    r = hexadyn.simulate(sine_file, out=out, progress=False)
    assert r.path == out and (out / "timeseries.parquet").is_file()
    with pytest.raises(FileExistsError):
        hexadyn.simulate(sine_file, out=out, progress=False)


def test_unpowered_scenario_columns(tmp_path: Path):
    r = hexadyn.simulate(shortened("unpowered_none", tmp_path, 0.05), progress=False)
    assert "q_v_ref[0]" not in r.timeseries.columns  # no references without control
    assert "z_q_v[0]" not in r.timeseries.columns  # no bristles without LuGre
    assert (r.timeseries["u_q_v[0]"] == 0).all()
    assert r.summary["control"] == "unpowered" and r.summary["friction"] == "none"


def test_walking_scenario(tmp_path: Path):
    """A shortened validation walk (Table 6.2 at 1.5 cm/s): the gait columns in pandas."""
    path = shortened("validation_tripod_1_5cm", tmp_path, 2.0)
    info = _core.load_scenario(str(path))
    assert info["control"] == "gait"
    assert info["gait"] == {
        "pattern": "tripod",
        "period_s": 12.0,
        "duty_factor": 0.5,
        "cycle": "enhanced",
        "heading": "constant",
        "vx_m_s": 0.015,
        "navigation": False,
        "clearance_m": 0.105,
        "body_height_m": pytest.approx(0.414, abs=1e-3),
        "changes": 0,
    }
    assert _core.load_scenario(str(hexadyn.SCENARIOS_DIR / "leg_sine.toml"))["gait"] is None

    r = hexadyn.simulate(path, progress=False)
    df = r.timeseries
    assert len(df) == 201
    for name, unit in {"X_ref": "m", "Y_ref": "m", "yaw_ref": "rad", "X_dot_ref": "m/s", "phase[1]": "1", "foot_ref_z[1]": "m", "duty_factor": "1"}.items():
        assert name in df.columns and r.units[name] == unit, name
    assert df["X_ref"].iloc[-1] == pytest.approx(0.015 * 1.995, abs=1e-9)
    assert (df["Y_ref"] == 0).all()
    assert (df["X"] - df["X_ref"]).abs().max() < 2e-3
    # Tripod {1, 2, 5} lifts off (support, takeoff, swing); {0, 3, 4} stays down.
    assert set(df["phase[1]"].unique()) == {0.0, 1.0, 2.0}
    assert (df["phase[0]"] == 0).all()
    s = r.summary
    assert s["control"] == "gait" and s["gait_pattern"] == "tripod" and s["navigation"] is False
    assert s["tracking_error_xy_max_m"] < 2e-3
    assert s["reference_distance_m"] == pytest.approx(0.015 * 1.995, abs=1e-6)
    assert s["gait_switches"] == 0 and s["clamped_ik_references"] == 0 and s["min_feet_on_ground"] == 3

    result = CliRunner().invoke(cli, ["simulate", str(path), "--out", str(tmp_path / "walk"), "--no-progress"], prog_name="hexadyn")
    assert result.exit_code == 0, result.output
    assert "XY tracking error" in result.output and "gait switches" in result.output


def test_walking_scenario_errors(tmp_path: Path):
    bad = tmp_path / "bad.toml"
    text = (hexadyn.SCENARIOS_DIR / "validation_tripod_1_5cm.toml").read_text()
    bad.write_text(text.replace("vx_m_s = 0.015", "vx_m_s = 0.05"))
    with pytest.raises(ValueError, match=r"bad\.toml:\d+: field `gait\.heading` = .*does not fit the workspace"):
        _core.load_scenario(str(bad))
    bad.write_text(text.replace('pattern = "tripod"', 'pattern = "gallop"'))
    with pytest.raises(ValueError, match=r"gait\.pattern.*gallop.*tripod"):
        hexadyn.simulate(bad, progress=False)


# ---------------------------------------------------------------------------------------------
# Command line
# ---------------------------------------------------------------------------------------------


def test_cli_simulate(sine_file: Path, tmp_path: Path):
    out = tmp_path / "cli-out"
    result = CliRunner().invoke(cli, ["simulate", str(sine_file), "--out", str(out), "--no-progress", "--no-plots"], prog_name="hexadyn")
    assert result.exit_code == 0, result.output
    assert f"Results: {out}" in result.output
    assert "body height" in result.output and "balance error" in result.output
    assert Results.load(out).summary["scenario"] == "leg_sine"
    # An existing --out is refused before running, unless --overwrite.
    result = CliRunner().invoke(cli, ["simulate", str(sine_file), "--out", str(out), "--no-progress", "--no-plots"], prog_name="hexadyn")
    assert result.exit_code == 1 and "exists" in result.output and "Traceback" not in result.output
    result = CliRunner().invoke(cli, ["simulate", str(sine_file), "--out", str(out), "--overwrite", "--no-progress", "--no-plots"], prog_name="hexadyn")
    assert result.exit_code == 0, result.output


def test_cli_default_results_folder(sine_file: Path, tmp_path: Path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for expected in ["results/leg_sine", "results/leg_sine-2"]:
        result = CliRunner().invoke(cli, ["simulate", str(sine_file), "--no-progress", "--no-plots"], prog_name="hexadyn")
        assert result.exit_code == 0, result.output
        assert f"Results: {expected}\n" in result.output
        assert (tmp_path / expected / "summary.json").is_file()


def test_cli_malformed_scenario(tmp_path: Path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("HEXADYN_DEBUG", raising=False)
    bad = tmp_path / "bad.toml"
    bad.write_text((hexadyn.SCENARIOS_DIR / "stand_six_legs.toml").read_text().replace('friction = "lugre"', 'friction = "coulomb"'))
    result = CliRunner().invoke(cli, ["simulate", str(bad)], prog_name="hexadyn")
    assert result.exit_code == 1
    lines = result.output.splitlines()
    assert len(lines) == 1, result.output
    line = lines[0]
    assert line.startswith(f"Error: {bad}:")
    for part in ["model.friction", "coulomb", "none", "dry_viscous", "lugre"]:
        assert part in line, line
    assert "Traceback" not in result.output
    assert list(tmp_path.iterdir()) == [bad], "no results folder is created"

    # Motion out of the stroke, and a missing file: one line each, exit status 1.
    bad.write_text((hexadyn.SCENARIOS_DIR / "leg_sine.toml").read_text().replace("amplitude = 0.004", "amplitude = 0.02"))
    result = CliRunner().invoke(cli, ["simulate", str(bad), "--out", str(tmp_path / "o")], prog_name="hexadyn")
    assert result.exit_code == 1 and len(result.output.splitlines()) == 1, result.output
    assert "control.motion[1].amplitude" in result.output and "0.02" in result.output and "stroke" in result.output
    result = CliRunner().invoke(cli, ["simulate", str(tmp_path / "missing.toml")], prog_name="hexadyn")
    assert result.exit_code == 1 and len(result.output.splitlines()) == 1, result.output
    assert "missing.toml" in result.output and "stand_six_legs" in result.output
    assert list(tmp_path.iterdir()) == [bad]


def test_engine_errors_are_value_errors(tmp_path: Path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[scenario]\nname = "x"\nduration_s = -1.0\n')
    with pytest.raises(ValueError, match=r"bad\.toml:3: field `scenario\.duration_s` = -1: .*allowed"):
        _core.run_scenario(str(bad))
    with pytest.raises(ValueError, match="cannot read"):
        _core.load_scenario(str(tmp_path / "missing.toml"))


def test_cli_scenarios():
    result = CliRunner().invoke(cli, ["scenarios"], prog_name="hexadyn")
    assert result.exit_code == 0, result.output
    for name in hexadyn.list_scenarios():
        assert f"  {name} " in result.output
    assert "(default)" in result.output


def test_overrides_change_the_run_and_are_recorded(sine_file: Path):
    base = hexadyn.simulate(sine_file, progress=False)
    changed = hexadyn.simulate(sine_file, progress=False, overrides={"model.friction": "none", "scenario.name": "sine_without_friction"})
    assert changed.summary["friction"] == "none" and base.summary["friction"] != "none"
    assert changed.metadata["scenario_name"] == "sine_without_friction"
    assert 'friction = "none"' in changed.metadata["scenario"] and "with overrides" in changed.metadata["scenario"]
    # Less friction, less electrical energy for the same motion.
    assert changed.summary["energy_electrical_j"] < 0.8 * base.summary["energy_electrical_j"]
    with pytest.raises(ValueError, match=r"model\.frction.*unknown field"):
        hexadyn.simulate(sine_file, progress=False, overrides={"model.frction": "none"})
    with pytest.raises(TypeError, match="model.friction"):
        hexadyn.simulate(sine_file, progress=False, overrides={"model.friction": object()})


def test_summary_only_runs_match_full_runs(sine_file: Path):
    full = _core.run_scenario(str(sine_file), None, {"model.friction": "dry_viscous"})
    lean = _core.run_scenario(str(sine_file), None, {"model.friction": "dry_viscous"}, False)
    assert lean["columns"] == {} and len(full["columns"]) > 100
    for key, value in full["summary"].items():
        if key != "wall_time_s":
            assert lean["summary"][key] == value, key


def test_foothold_offset_moves_every_foothold_radially():
    """`gait.foothold_offset_m` (the spread of the feet, a design parameter of the studies):
    0 is the thesis' walk bit for bit; +-2 cm moves the mean foot reference of every leg 2 cm
    away from (towards) the body centre, and changes the energy; beyond the workspace radius it
    is refused in one line naming the field and the largest offset."""
    summary = {}
    spread = {}
    for offset in (None, 0.0, 0.02, -0.02):
        overrides = {} if offset is None else {"gait.foothold_offset_m": offset}
        r = hexadyn.simulate("validation_tripod_1_5cm", progress=False, overrides=overrides)
        summary[offset] = r.summary
        s = r.timeseries
        spread[offset] = np.array([math.hypot(s[f"foot_ref_x[{leg}]"].mean(), s[f"foot_ref_y[{leg}]"].mean()) for leg in range(6)])
    same = lambda s: {k: v for k, v in s.items() if k != "wall_time_s"}  # noqa: E731
    assert same(summary[0.0]) == same(summary[None])
    for offset in (0.02, -0.02):
        assert np.abs(spread[offset] - spread[None] - offset).max() < 1e-3, spread[offset] - spread[None]
        assert summary[offset]["clamped_ik_references"] == 0
    assert summary[-0.02]["energy_electrical_j"] > summary[None]["energy_electrical_j"] > summary[0.02]["energy_electrical_j"]
    with pytest.raises(ValueError, match=r"field `gait.foothold_offset_m` = 0.5: .*allowed: a finite offset \(m\) of magnitude below 0.14") as error:
        _core.load_scenario(str(hexadyn.resolve_scenario("validation_tripod_1_5cm")), {"gait.foothold_offset_m": 0.5})
    assert "\n" not in str(error.value)
