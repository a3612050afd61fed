"""`hexadyn identify` refuses, in one line naming the file, the column and row, the value and
what is allowed, the logs it cannot fit honestly (issue 39): text in a column, a leg without
its current, a gap in the time, a time in other units than seconds, positions or currents out
of physical bounds, a friction of the wrong sign; and broken results folders or robot files
end in one line, never a traceback."""

from __future__ import annotations

import json
import math
import os
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from identify_logs import sawtooth_frame

import hexadyn
from hexadyn.cli import cli
from hexadyn.identify import IdentifyError, identify, load_log
from hexadyn.identify.checks import CURRENT_LIMIT_STALLS, STEP_TOLERANCE, check_friction_sign
from hexadyn.identify.torques import leg_model
from conftest import assert_one_line_error


@pytest.fixture(scope="module")
def frame() -> pd.DataFrame:
    """A q_v campaign of the six legs with the robot's own friction."""
    return sawtooth_frame("q_v", legs=range(6))


def invoke(*args: str):
    return CliRunner().invoke(cli, ["identify", *args])


def test_a_clean_log_gives_the_robot_friction(frame, tmp_path):
    """The synthetic log passes every check and gives back the friction it was made with."""
    path = tmp_path / "clean.csv"
    frame.to_csv(path, index=False)
    ident = identify([load_log(path)])
    assert len(ident.fits) == 12
    for _, f in ident.fits:
        sense = "plus" if f.direction > 0 else "minus"
        truth = dict(leg_model(None).joint(f.leg, "q_v"))
        assert f.tau_f_d.value == pytest.approx(truth[f"tau_f_d_{sense}"], rel=1e-3)
        assert f.f_v.value == pytest.approx(truth[f"f_v_{sense}"], rel=1e-3)


def text_at(column: str, row: int, text: str = "abc"):
    def damage(f: pd.DataFrame) -> pd.DataFrame:
        f = f.astype({column: object})
        f.loc[row, column] = text
        return f

    return damage


def scaled(column: str, factor: float):
    return lambda f: f.assign(**{column: f[column] * factor})


@pytest.mark.parametrize(
    "damage, words",
    [
        pytest.param(text_at("i_q_v[2]", 7), ["column `i_q_v[2]`, row 7 (t = 0.07 s): 'abc' is not a number; allowed: finite numbers"], id="text-in-a-current"),
        pytest.param(text_at("t", 7), ["column `t`, row 7: 'abc' is not a number"], id="text-in-the-time"),
        pytest.param(lambda f: f.drop(columns=["i_q_v[5]"]), ["column `q_v[5]` has no current (`i_q_v[5]` or `i_meas_q_v[5]`) while q_v of leg(s) 0, 1, 2, 3, 4 have theirs"], id="a-leg-without-its-current"),
        pytest.param(lambda f: f.drop(columns=["q_v[5]"]), ["column `i_q_v[5]` without the position `q_v[5]`"], id="a-current-without-its-position"),
        pytest.param(lambda f: f.assign(t=np.where(f.index > 1000, f["t"] + 5.0, f["t"])), ["time step 5.01 s from row 1000 to 1001 (t = 10.0 -> 15.01 s)", "allowed: a constant step, within 50% of the median 0.01 s"], id="a-5-s-gap"),
        pytest.param(lambda f: f.drop(index=[1000]), ["time step 0.02 s from row 999 to 1000"], id="a-dropped-sample"),
        pytest.param(scaled("t", 1e9), ["time step 1e+07 (median of column `t`); allowed: 0.0001 to 1 s"], id="time-in-ns"),
        pytest.param(scaled("t", 1e3), ["time step 10 (median of column `t`)"], id="time-in-ms"),
        pytest.param(scaled("q_v[3]", 1e3), ["column `q_v[3]`, row 0 (t = 0.0 s): 43.5; allowed: the q_v range [0.04, 0.075] of the robot description +-10% of the stroke"], id="positions-in-mm"),
        pytest.param(scaled("i_q_v[2]", 1e300), ["column `i_q_v[2]`, row 0 (t = 0.0 s):", f"allowed: |i| <= {CURRENT_LIMIT_STALLS:g} u_n / R = 32.12 A (u_n = 15 V, R = 0.934 ohm"], id="currents-of-1e300"),
        pytest.param(lambda f: f.assign(**{"i_q_v[2]": 0.0}), ["q_v[2]: tau_f,d^- = +42.8009 N, the wrong sign (friction opposes the motion: allowed < 0 (minus sense))"], id="a-zero-current"),
        pytest.param(scaled("i_q_v[4]", -1.0), ["q_v[4]: tau_f,d^+ = -", "the wrong sign"], id="a-current-of-the-opposite-sign"),
        pytest.param(lambda f: f.assign(**{"foot_load_kg[2]": np.where(f.index < 10, 0.0, 5.0)}), ["column `foot_load_kg[2]` changes at row 10 (t = 0.1 s): 5 after 0 kg; allowed: one load per log (constant)"], id="a-changing-load"),
        pytest.param(lambda f: f.assign(**{"foot_load_kg[2]": 1e300}), ["column `foot_load_kg[2]`, row 0 (t = 0.0 s): 1e+300; allowed: 0 to the robot's mass, 34.45 kg"], id="a-load-of-1e300-kg"),
        pytest.param(lambda f: f.assign(**{"foot_load_kg[2]": "ten"}), ["column `foot_load_kg[2]`, row 0 (t = 0.0 s): 'ten' is not a number"], id="a-load-in-words"),
        pytest.param(lambda f: f.iloc[:0], ["0 samples; a log needs at least 2"], id="only-the-header"),
    ],
)
def test_a_log_that_cannot_be_fitted_honestly_is_refused(frame, tmp_path, damage, words):
    path = tmp_path / "log.csv"
    damage(frame.copy()).to_csv(path, index=False)
    out = tmp_path / "ident"
    assert_one_line_error(invoke(str(path), "--out", str(out)), f"Error: {path}: ", *words)
    assert not out.exists()


def test_logger_jitter_within_the_tolerance_passes(frame, tmp_path):
    """Steps within the tolerance of the median (a logger's jitter) are a constant step."""
    jitter = np.random.default_rng(0).uniform(-0.8, 0.8, len(frame)) * STEP_TOLERANCE / 2 * 0.01
    path = tmp_path / "jitter.csv"
    frame.assign(t=frame["t"] + jitter).to_csv(path, index=False)
    assert len(identify([load_log(path)]).fits) == 12


@pytest.mark.parametrize(
    "value, low, high, refused",
    [(-5.0, -6.0, -4.0, True), (-5.0, -6.0, 1.0, False), (-5.0, math.nan, math.nan, True), (5.0, 4.0, 6.0, False), (0.0, 0.0, 0.0, False)],
)
def test_a_wrong_sign_is_refused_only_beyond_its_interval(value, low, high, refused):
    """Plus sense: a negative dry friction whose 95 % interval holds zero is noise around a
    friction near zero (kept: the fragment writes 0, Section 6.1); beyond it, refused."""
    if refused:
        with pytest.raises(IdentifyError, match="the wrong sign"):
            check_friction_sign("log.csv: q_v[2]", "tau_f,d^+", 1, value, low, high, "N")
    else:
        check_friction_sign("log.csv: q_v[2]", "tau_f,d^+", 1, value, low, high, "N")


# ---------------------------------------------------------------------------------------------
# Results folders and robot files
# ---------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def results_folder(tmp_path_factory) -> Path:
    """A q_v campaign simulated for 1.5 cycles at two velocities (a valid results folder)."""
    motion = [{"leg": leg, "joint": "q_v", "kind": "sawtooth", "min": 0.04, "max": 0.075, "speed": 0.004, "speed_step": 0.004, "speed_max": 0.008} for leg in range(6)]
    out = tmp_path_factory.mktemp("results") / "q_v"
    hexadyn.simulate("identification_q_v", out=out, progress=False, plots=False, overrides={"scenario.duration_s": 28.0, "control.motion": motion})
    return out


def edited(folder: Path, tmp_path: Path, edit) -> Path:
    copy = tmp_path / "edited"
    shutil.copytree(folder, copy)
    meta = json.loads((copy / "metadata.json").read_text())
    edit(meta)
    (copy / "metadata.json").write_text(json.dumps(meta))
    return copy


def test_the_results_folder_is_identified(results_folder, tmp_path):
    result = invoke(str(results_folder), "--out", str(tmp_path / "ident"))
    assert result.exit_code == 0, result.output
    fragment = tomllib.loads((tmp_path / "ident" / "joint_friction.toml").read_text())
    assert fragment["model"]["joint_friction"]["q_v"]["tau_f_d_plus"] > 0


def drop_motion_field(name: str):
    def edit(meta):
        meta["scenario"] = meta["scenario"].replace(f'\n{name} = "q_v"\n' if name == "joint" else "\nleg = 0\n", "\n", 1)

    return edit


@pytest.mark.parametrize(
    "edit, words",
    [
        pytest.param(lambda m: m.pop("robot"), ["metadata.json: no `robot` entry (the robot description the run used)"], id="no-robot"),
        pytest.param(drop_motion_field("joint"), ["metadata.json: scenario `control.motion[0].joint` = None; allowed: a string"], id="a-motion-without-joint"),
        pytest.param(drop_motion_field("leg"), ["metadata.json: scenario `control.motion[0].leg` = None; allowed: a leg 0..5"], id="a-motion-without-leg"),
        pytest.param(lambda m: m.update(scenario="[control\n"), ["metadata.json: `scenario` is not a scenario text"], id="a-scenario-not-toml"),
        pytest.param(lambda m: m.update(scenario=m["scenario"].replace("stand = true", "stand = true\nfoot_load_kg = [1, 2]")), ["metadata.json: scenario `model.foot_load_kg` = [1, 2]; allowed: 6 finite loads in kg"], id="two-loads"),
    ],
)
def test_a_broken_results_folder_is_one_line(results_folder, tmp_path, edit, words):
    folder = edited(results_folder, tmp_path, edit)
    assert_one_line_error(invoke(str(folder), "--out", str(tmp_path / "ident")), *words)


def test_a_device_or_a_fifo_as_robot_file_fails_at_once(frame, tmp_path):
    path = tmp_path / "log.csv"
    frame.to_csv(path, index=False)
    assert_one_line_error(invoke(str(path), "--robot", "/dev/zero", "--out", str(tmp_path / "a")), "/dev/zero: a device, not a regular file")
    fifo = tmp_path / "robot.fifo"
    os.mkfifo(fifo)
    assert_one_line_error(invoke(str(path), "--robot", str(fifo), "--out", str(tmp_path / "b")), f"{fifo}: a named pipe (FIFO), not a regular file")
    garbage = tmp_path / "robot.toml"
    garbage.write_bytes(b"\xff\xfe not text")
    assert_one_line_error(invoke(str(path), "--robot", str(garbage), "--out", str(tmp_path / "c")), f"{garbage}: not UTF-8 text (invalid byte at offset 0)")


def test_a_csv_log_larger_than_the_bound_is_refused_before_reading(tmp_path):
    """Found by test_fuzz_cli.py: a CSV log was read by pandas whatever its size; a sparse 1 TB
    file filled the machine's memory until the kernel killed the process. It is refused from
    its size, in one line naming it and the bound."""
    from hexadyn.identify.reading import MAX_LOG_BYTES

    log = tmp_path / "huge.csv"
    with open(log, "wb") as f:
        f.truncate(2**40)
    result = CliRunner().invoke(cli, ["identify", str(log), "--out", str(tmp_path / "out")])
    assert_one_line_error(result, f"{log}: cannot read the CSV file: {log}: {2**40} bytes, too large; allowed: a regular file of at most 1 GB")
    assert MAX_LOG_BYTES == 2**30 and not (tmp_path / "out").exists()
