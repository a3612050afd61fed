"""Property-based abuse of `hexadyn identify` and `hexadyn montecarlo` (issue 39): damaged
identification logs (dropped, renamed or added columns, text and extreme cells, scaled units,
time gaps, rows cut, reversed or duplicated, bytes flipped), Monte Carlo configurations (runs,
velocities, variants, seeds, workers, friction statistics files of any content) and corrupt
campaign folders. Every case ends with exit status 0 (then the outputs hold finite numbers), or
1 or 2 with exactly one `Error:` line (exit status 1: nothing else on stderr), never a
traceback, a Python warning or a folder left behind by a refused command.

The cases run the command line in this process (click's runner) for speed; the simulations of
a Monte Carlo campaign are left out (its walks are the engine's, fuzzed by test_fuzz.py): what
is checked is everything around them. A few cases run as subprocesses, as a user would, to
show that no traceback reaches stderr there either.
"""

from __future__ import annotations

import functools
import math
import os
import shutil
import subprocess
import sys
import tempfile
import tomllib
import warnings
from pathlib import Path

import pytest
from click.testing import CliRunner
from conftest import shortened
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from identify_logs import sawtooth_frame

from hexadyn.cli import cli
from hexadyn.montecarlo import Campaign, CampaignStore, FrictionDistributions, RunKey
from hexadyn.montecarlo import campaign as campaign_module
from hexadyn.montecarlo.campaign import MAX_SIMULATIONS
from hexadyn.montecarlo.storage import CAMPAIGN_FILE, DATABASE_FILE

ROOT = Path(__file__).resolve().parents[2]
PHANTOMX = ROOT / "robots" / "phantomx" / "phantomx.toml"
#: Cases per surface: 2700 in about 50 s on a 2-core machine at a load of 7 (27 s, 18 s, 4 s;
#: the subprocesses 9 s).
LOG_CASES = 800
CONFIG_CASES = 1500
DATABASE_CASES = 400

TEXTS = ["abc", "", " ", "nan", "inf", "-inf", "1e308", "-1e308", "1e-320", "0", "-0", "99999999999999999999999", "0x10", "1,5", "true", '"', "\x00", "é"]
FACTORS = [0.0, -1.0, 1e-9, 1e-3, 0.5, 0.9, 1.1, 2.0, 1e3, 1e9, 1e300, -1e300]
COLUMNS = ["t", "q_v[1]", "i_q_v[1]", "q_v[4]", "i_q_v[4]", "u_q_v[1]", "u_q_v[4]", "i_meas_q_v[1]", "foot_load_kg[1]", "foot_load_kg[4]", "q_r[1]", "i_q_r[1]", "q_h[4]", "q_v[7]", "i_q_v[-1]", "femur[1]", "i_femur[1]", "x"]


#: The transient dropped after each reversal (`--transient`) of most cases: the base log's
#: sections are short (a thousand samples in all, fast to identify).
TRANSIENT = "0.3"


@functools.cache
def base_frame():
    """A clean q_v campaign of legs 1 and 4 at three velocities, identified with `--transient
    0.3` (the default 1.5 s finds its sections too short)."""
    return sawtooth_frame("q_v", legs=(1, 4), speeds_fraction=(0.4, 0.6, 0.8))


@pytest.fixture(scope="module")
def base_log() -> bytes:
    return base_frame().to_csv(index=False).encode()


@pytest.fixture
def scratch():
    """A folder for the outputs, in memory when the machine has /dev/shm (no disk syncs)."""
    folder = Path(tempfile.mkdtemp(prefix="hexadyn-fuzz-", dir="/dev/shm" if os.path.isdir("/dev/shm") else None))
    yield folder
    shutil.rmtree(folder, ignore_errors=True)


def run_cli(args: list[str]):
    """The command in this process; Python warnings are errors of the command (they would be
    lines on the user's stderr)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = CliRunner().invoke(cli, args, prog_name="hexadyn")
    assert not caught, [f"{w.category.__name__}: {w.message}" for w in caught]
    return result


def assert_clean_end(result, out: Path) -> bool:
    """Exit status 0, or 1 or 2 with one `Error:` line; returns whether it succeeded."""
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        import traceback

        raise AssertionError("".join(traceback.format_exception(result.exception)))
    assert "Traceback" not in result.output
    assert result.exit_code in (0, 1, 2), (result.exit_code, result.output)
    if result.exit_code == 0:
        return True
    errors = [line for line in result.stderr.splitlines() if line.startswith("Error: ")]
    assert len(errors) == 1, result.stderr
    if result.exit_code == 1:
        assert result.stderr.splitlines() == errors, result.stderr
    return False


# ---------------------------------------------------------------------------------------------
# hexadyn identify: damaged logs
# ---------------------------------------------------------------------------------------------


@st.composite
def damaged_log(draw) -> bytes:
    import numpy as np
    import pandas as pd

    f = base_frame().copy()
    for _ in range(draw(st.integers(0, 3))):
        f = f.loc[:, ~f.columns.duplicated()]  # a renamed column may have taken another's name
        kind = draw(st.sampled_from(["drop", "rename", "text", "scale", "constant", "add", "gap", "rows", "noise"]))
        columns = list(f.columns)
        column = draw(st.sampled_from(columns)) if columns else None
        n = len(f)
        if kind == "drop" and column is not None:
            f = f.drop(columns=[column])
        elif kind == "rename" and column is not None:
            f = f.rename(columns={column: draw(st.sampled_from(COLUMNS))})
        elif kind == "text" and column is not None and n:
            f[column] = f[column].astype(object)
            f.iloc[draw(st.integers(0, n - 1)), columns.index(column)] = draw(st.sampled_from(TEXTS))
        elif kind == "scale" and column is not None and f[column].dtype.kind == "f":
            with np.errstate(all="ignore"):
                f[column] = f[column] * draw(st.sampled_from(FACTORS))
        elif kind == "constant" and column is not None:
            f[column] = draw(st.sampled_from([0.0, 1.0, -1.0, 1e300, math.nan, math.inf]))
        elif kind == "add":
            f[draw(st.sampled_from(COLUMNS))] = draw(st.sampled_from([0.0, 5.0, 10.0, -1.0, 1e300, -5.0, "x"]))
        elif kind == "gap" and "t" in f and f["t"].dtype.kind == "f" and n:
            f.loc[draw(st.integers(0, n - 1)) :, "t"] += draw(st.sampled_from([5.0, 0.005, -0.01, 1e9, math.nan]))
        elif kind == "rows":
            how = draw(st.sampled_from(["head", "tail", "reverse", "duplicate", "every_other", "swap"]))
            k = draw(st.integers(0, max(n - 1, 0)))
            if how == "head":
                f = f.iloc[:k]
            elif how == "tail":
                f = f.iloc[k:]
            elif how == "reverse":
                f = f.iloc[::-1]
            elif how == "duplicate":
                f = pd.concat([f, f.iloc[k : k + 50]])
            elif how == "every_other":
                f = f.iloc[:: draw(st.integers(2, 200))]
            elif n > 1:
                order = list(range(n))
                j = draw(st.integers(0, n - 1))
                order[k], order[j] = order[j], order[k]
                f = f.iloc[order]
            f = f.reset_index(drop=True)
        elif kind == "noise" and column is not None and f[column].dtype.kind == "f":
            rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
            f[column] = f[column] + rng.normal(0.0, draw(st.sampled_from([1e-6, 1e-3, 1.0])), n)
    text = f.to_csv(index=False).encode()
    edit = draw(st.sampled_from(["none"] * 6 + ["truncate", "flip", "non_utf8", "comment", "separator"]))
    if edit == "truncate":
        text = text[: draw(st.integers(0, len(text)))]
    elif edit == "flip" and text:
        i = draw(st.integers(0, len(text) - 1))
        text = text[:i] + bytes([draw(st.integers(0, 255))]) + text[i + 1 :]
    elif edit == "non_utf8":
        i = draw(st.integers(0, len(text)))
        text = text[:i] + draw(st.sampled_from([b"\xff", b"\xc3", b"\x00"])) + text[i:]
    elif edit == "comment":
        i = text.find(b"\n", draw(st.integers(0, len(text)))) + 1
        text = text[:i] + b"# a comment, 1, 2\n" + text[i:]
    elif edit == "separator":
        text = text.replace(b",", b";")
    return text


def test_damaged_logs_end_in_one_line_or_finite_fits(scratch, monkeypatch):
    # No figures: matplotlib's, they take twice the identification's time (test_identify.py
    # draws them).
    monkeypatch.setattr("hexadyn.identify.figures.figures", lambda ident: {})
    outcomes = {"refused": 0, "identified": 0}

    @settings(max_examples=LOG_CASES, deadline=None, database=None, suppress_health_check=list(HealthCheck))
    @given(log=damaged_log(), joint=st.sampled_from([None] * 6 + ["q_v", "q_r", "femur"]), transient=st.sampled_from([TRANSIENT] * 8 + [None, "0", "3", "1e9", "nan"]), robot=st.sampled_from([None] * 12 + [str(PHANTOMX), "/dev/zero"]))
    def check(log: bytes, joint, transient, robot) -> None:
        path, out = scratch / "log.csv", scratch / "ident"
        path.write_bytes(log)
        shutil.rmtree(out, ignore_errors=True)
        args = ["identify", str(path), "--out", str(out)]
        for option, value in (("--joint", joint), ("--transient", transient), ("--robot", robot)):
            if value is not None:
                args += [option, value]
        result = run_cli(args)
        if not assert_clean_end(result, out):
            assert not out.exists()
            outcomes["refused"] += 1
            return
        fragment = tomllib.loads((out / "joint_friction.toml").read_text())
        values = [v for keys in fragment["model"]["joint_friction"].values() for v in keys.values()]
        assert values and all(math.isfinite(v) for v in values), values
        outcomes["identified"] += 1

    check()
    assert outcomes["refused"] > LOG_CASES / 4 and outcomes["identified"] > LOG_CASES / 20, outcomes


# ---------------------------------------------------------------------------------------------
# hexadyn montecarlo: configurations and friction statistics
# ---------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def walk(tmp_path_factory) -> Path:
    return shortened("validation_tripod_1_5cm", tmp_path_factory.mktemp("fuzz_walk"), duration=2.0)


@pytest.fixture
def no_simulations(monkeypatch):
    """A campaign runs through its store and table without its walks and figures."""
    monkeypatch.setattr(campaign_module.Campaign, "_simulate", lambda self, *args: None)
    monkeypatch.setattr(campaign_module, "write_results", lambda table, folder: None)


AMRU5_FIELDS = list(FrictionDistributions.of_robot("amru5").gaussians)
FIELDS = [*AMRU5_FIELDS, *FrictionDistributions.of_robot("phantomx").gaussians, "model.joint_friction.q_h.f_v_plus", "model.mu", "x"]
#: Any number TOML holds: floats of any size, NaN and infinities, integers beyond 64 bits.
NUMBERS = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-(2**70), 2**70), st.sampled_from([0.0, 1.0, -3.0, 311.4, 62.3, -2.9999999999, 1e-300]))


def wild_or(valid, wild, wild_share: int = 4):
    """`valid` values mostly, `wild` ones one time in `wild_share`: most cases pass most
    options, so that the campaign is accepted often enough to be checked too."""
    return st.integers(0, wild_share - 1).flatmap(lambda k: wild if k == 0 else valid)


def gaussian(field: str):
    """A plausible (mu, sigma) of a field: near its robot's, with the sign of its physical values."""
    mu, sigma = dict(FrictionDistributions.of_robot("amru5").gaussians).get(field, (0.59, 0.25))
    return st.tuples(st.floats(0.5, 1.5).map(lambda k: mu * k), st.floats(0.0, 2.0).map(lambda k: sigma * k))


@st.composite
def stats_text(draw) -> bytes:
    """A friction statistics file: plausible Gaussians mostly, entries of any shape and value,
    or broken bytes."""
    lines = ["[friction_stats]"] if draw(st.integers(0, 9)) else ["[other]"]
    for _ in range(draw(st.integers(0, 4))):
        field = draw(wild_or(st.sampled_from(AMRU5_FIELDS), st.sampled_from(FIELDS)))
        shape = draw(wild_or(st.just("table"), st.sampled_from(["table", "no_sigma", "text", "number", "list"])))
        mu, sigma = (repr(float(x)) for x in draw(wild_or(gaussian(field), st.tuples(NUMBERS, NUMBERS))))
        value = {
            "table": f"{{ mu = {mu}, sigma = {sigma}, legs = 6 }}",
            "no_sigma": f"{{ mu = {mu} }}",
            "text": '{ mu = "x", sigma = 1.0 }',
            "number": mu,
            "list": f"[{mu}, {sigma}]",
        }[shape]
        lines.append(f'"{field}" = {value}')
    text = "\n".join(lines).encode()
    edit = draw(st.sampled_from(["none"] * 8 + ["truncate", "bom", "non_utf8"]))
    if edit == "truncate":
        text = text[: draw(st.integers(0, len(text)))]
    elif edit == "bom":
        text = b"\xef\xbb\xbf" + text
    elif edit == "non_utf8":
        text = text + b"\xff"
    return text


#: `--velocities` values (cm/s): a few valid ones, or numbers of any size, zero, negative, words.
VELOCITIES = wild_or(
    st.lists(st.sampled_from(["1", "1.5", "2", "2.5"]), min_size=1, max_size=3, unique=True),
    st.lists(st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr), st.sampled_from(["1", "0", "-1", "fast", "", "1e400", "1000"])), min_size=1, max_size=4),
).map(",".join)
VARIANTS = wild_or(st.sampled_from(["dry_viscous", "dry_viscous_load", "dry_viscous,dry_viscous_load"]), st.lists(st.sampled_from(["dry_viscous", "dry_viscous_load", "coulomb", "", " dry_viscous"]), min_size=1, max_size=3).map(",".join))
#: `--runs`: the campaign at its largest allowed is test_montecarlo_checks.py's (a million runs
#: to list: 0.1 s a case).
RUNS = wild_or(st.integers(1, 3), st.one_of(st.integers(-3, 0), st.sampled_from([MAX_SIMULATIONS + 1, 10**12, 2**63, "x", "1.5", ""])))
SEEDS = wild_or(st.integers(0, 2**32), st.integers(-3, 2**70))
WORKERS = wild_or(st.sampled_from([1, 2, 200]), st.sampled_from([-1, 0, 10**9, "two"]))


@st.composite
def montecarlo_args(draw, walk: Path, stats: Path) -> list[str]:
    """The options of a campaign; each left out half of the time, wild one time in four."""
    args = ["montecarlo"]
    scenario = draw(wild_or(st.just(str(walk)), st.sampled_from([None, "stand_six_legs", "no_such_scenario", "phantomx_montecarlo"]), 8))
    if scenario is not None:
        args.append(scenario)
    if draw(st.integers(0, 9)) == 0:
        args += ["--robot", draw(st.sampled_from(["amru5", "phantomx"]))]
    args += ["--runs", str(draw(RUNS))]
    for option, values in (("--velocities", VELOCITIES), ("--variants", VARIANTS), ("--seed", SEEDS), ("--workers", WORKERS)):
        if draw(st.booleans()):
            args += [option, str(draw(values))]
    if draw(st.integers(0, 2)) == 0:
        stats.write_bytes(draw(stats_text()))
        args += ["--friction-stats", str(stats)]
    return args + ["--no-progress"]


def test_monte_carlo_configurations_end_in_one_line_or_a_campaign(walk, scratch, no_simulations):
    outcomes = {"refused": 0, "accepted": 0}

    @settings(max_examples=CONFIG_CASES, deadline=None, database=None, suppress_health_check=list(HealthCheck))
    @given(data=st.data())
    def check(data) -> None:
        out = scratch / "mc"
        shutil.rmtree(out, ignore_errors=True)
        args = data.draw(montecarlo_args(walk, scratch / "friction_stats.toml"))
        result = run_cli([*args, "--out", str(out)])
        if assert_clean_end(result, out):
            assert (out / CAMPAIGN_FILE).is_file() and (out / DATABASE_FILE).is_file()
            outcomes["accepted"] += 1
        else:
            assert not out.exists(), result.output
            outcomes["refused"] += 1

    check()
    assert outcomes["refused"] > CONFIG_CASES / 4 and outcomes["accepted"] > CONFIG_CASES / 20, outcomes


@pytest.fixture(scope="module")
def stored_campaign(walk, tmp_path_factory) -> tuple[Campaign, Path]:
    """A campaign folder holding two stored runs (outcomes made up: no walk is simulated)."""
    campaign = Campaign.create(walk, velocities=[0.01], runs_per_velocity=3, variants=["dry_viscous"], seed=1)
    folder = tmp_path_factory.mktemp("stored") / "mc"
    with CampaignStore.open(folder, campaign.configuration(), campaign.distributions.joints) as store:
        for run in range(2):
            key = RunKey("dry_viscous", 0, run)
            summary = {c: 1.0 + run for c in store.columns}
            store.add(key, 0.01, campaign.friction(key), {"status": "ok", "summary": summary} if run else {"status": "failed", "error": "rejected"})
    return campaign, folder


@st.composite
def damaged_folder(draw, folder: Path) -> dict[str, bytes]:
    """The files of the campaign folder with runs.sqlite (mostly) or campaign.json damaged."""
    files = {name: (folder / name).read_bytes() for name in (CAMPAIGN_FILE, DATABASE_FILE)}
    name = draw(st.sampled_from([DATABASE_FILE] * 4 + [CAMPAIGN_FILE]))
    data = files[name]
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["truncate", "flip", "zero_page", "junk"]))
        if kind == "truncate":
            data = data[: draw(st.integers(0, len(data)))]
        elif kind == "flip" and data:
            i = draw(st.integers(0, len(data) - 1))
            data = data[:i] + bytes([draw(st.integers(0, 255))]) + data[i + 1 :]
        elif kind == "zero_page" and data:
            i = draw(st.integers(0, len(data) - 1)) // 4096 * 4096
            data = data[:i] + bytes(min(4096, len(data) - i)) + data[i + 4096 :]
        elif kind == "junk":
            data = data + bytes(draw(st.binary(min_size=1, max_size=200)))
    files[name] = data
    return files


def test_corrupt_campaign_folders_end_in_one_line(stored_campaign, scratch, walk, no_simulations):
    campaign, folder = stored_campaign
    args = ["montecarlo", str(walk), "--velocities", "1", "--runs", "3", "--variants", "dry_viscous", "--seed", "1", "--no-progress"]
    outcomes = {"refused": 0, "resumed": 0}

    @settings(max_examples=DATABASE_CASES, deadline=None, database=None, suppress_health_check=list(HealthCheck))
    @given(files=damaged_folder(folder))
    def check(files: dict[str, bytes]) -> None:
        out = scratch / "mc"
        shutil.rmtree(out, ignore_errors=True)
        out.mkdir()
        for name, data in files.items():
            (out / name).write_bytes(data)
        result = run_cli([*args, "--out", str(out)])
        outcomes["resumed" if assert_clean_end(result, out) else "refused"] += 1

    check()
    assert outcomes["refused"] > DATABASE_CASES / 4, outcomes


# ---------------------------------------------------------------------------------------------
# As a user runs them: no traceback on stderr
# ---------------------------------------------------------------------------------------------


def test_subprocesses_print_one_line_and_no_traceback(base_log, walk, stored_campaign, tmp_path):
    lines = base_log.decode().splitlines()
    cells = lines[8].split(",")  # sample 7: t, q_v[1], i_q_v[1], ...
    lines[8] = ",".join([*cells[:2], "abc", *cells[3:]])
    log = tmp_path / "abc.csv"
    log.write_text("\n".join(lines) + "\n")
    stats = tmp_path / "narrow.toml"
    stats.write_text('[friction_stats]\n"model.joint_friction.q_v.tau_f_d_plus" = { mu = -2.9999999999, sigma = 1.0 }\n')
    corrupt = tmp_path / "corrupt"
    shutil.copytree(stored_campaign[1], corrupt)
    data = (corrupt / DATABASE_FILE).read_bytes()
    (corrupt / DATABASE_FILE).write_bytes(data[: len(data) // 2])
    cases = [
        (["identify", str(log), "--out", str(tmp_path / "a")], f"{log}: column `i_q_v[1]`, row 7"),
        (["identify", str(log), "--robot", "/dev/zero", "--out", str(tmp_path / "b")], "/dev/zero: a device, not a regular file"),
        (["montecarlo", str(walk), "--runs", "999999999999", "--out", str(tmp_path / "c")], "runs per velocity = 999999999999"),
        (["montecarlo", str(walk), "--friction-stats", "/dev/zero", "--out", str(tmp_path / "d")], "/dev/zero: a device, not a regular file"),
        (["montecarlo", str(walk), "--friction-stats", str(stats), "--out", str(tmp_path / "e")], "keeps a draw with probability 4.43e-13"),
        (["montecarlo", str(walk), "--velocities", "1", "--runs", "3", "--variants", "dry_viscous", "--seed", "1", "--no-progress", "--out", str(corrupt)], "not a readable campaign database"),
    ]
    env = {k: v for k, v in os.environ.items() if k != "HEXADYN_DEBUG"}
    # Started together (each spends its second in imports), then read one by one.
    processes = [(subprocess.Popen([sys.executable, "-m", "hexadyn.cli", *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env), args, words) for args, words in cases]
    for process, args, words in processes:
        _, err = process.communicate(timeout=300)
        assert process.returncode == 1, (args, err)
        lines = err.splitlines()
        assert len(lines) == 1 and lines[0].startswith("Error: ") and words in lines[0], (args, err)
