"""One command-line grammar (issue 38): the same option for the same thing in every command
(docs/cli.md's table, checked against the click commands), one-line usage errors, `--set`
overrides, `hexadyn info` and `hexadyn robot-file`, and a progress bar over the figures."""

from __future__ import annotations

import json
import re
from pathlib import Path

import click
import pandas as pd
import pytest
from click.testing import CliRunner
from conftest import assert_one_line_error, shortened

import hexadyn
from hexadyn import _core, health
from hexadyn.cli import cli
from hexadyn.montecarlo import Campaign
from hexadyn.montecarlo.storage import RunKey
from hexadyn.options import COMMON, UNHEALTHY, CommonOption, parse_set

ROOT = Path(__file__).resolve().parents[2]
CLI_DOC = ROOT / "docs" / "cli.md"


def invoke(*args: str):
    return CliRunner().invoke(cli, list(args), prog_name="hexadyn")


def commands(group: click.Group = cli, prefix: str = "hexadyn") -> dict[str, click.Command]:
    """Every command `hexadyn --help` leads to, by its full name (`hexadyn robot run`)."""
    found: dict[str, click.Command] = {}
    for name, command in group.commands.items():
        if isinstance(command, click.Group):
            found.update(commands(command, f"{prefix} {name}"))
        else:
            found[f"{prefix} {name}"] = command
    return found


def documented() -> dict[str, set[str]]:
    """docs/cli.md's table of the common options: command -> the options marked."""
    lines = CLI_DOC.read_text(encoding="utf-8").splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith("| command |"))
    columns = [c.strip().strip("`") for c in lines[header].strip("|").split("|")][1:]
    assert tuple(columns) == COMMON, columns
    table = {}
    for line in lines[header + 2 :]:
        if not line.startswith("|"):
            break
        cells = [c.strip() for c in line.strip("|").split("|")]
        assert set(cells[1:]) <= {"✓", ""}, line
        table[cells[0].strip("`")] = {option for option, mark in zip(columns, cells[1:]) if mark == "✓"}
    return table


def options_of(command: click.Command) -> dict[str, click.Parameter]:
    return {opt: p for p in command.params for opt in getattr(p, "opts", []) + getattr(p, "secondary_opts", [])}


# ---------------------------------------------------------------------------------------------
# The table of docs/cli.md
# ---------------------------------------------------------------------------------------------


def test_the_documented_table_is_every_command_and_every_common_option():
    table, found = documented(), commands()
    assert sorted(table) == sorted(found)
    for name, command in found.items():
        present = {o for o in options_of(command) if o in COMMON}
        assert present == table[name], (name, sorted(present ^ table[name]))


def test_a_common_option_is_the_shared_one_wherever_it_appears():
    """Each common option comes from hexadyn.options (same spelling, short form and kind in every
    command), and no command has an option of another spelling for the same thing."""
    spellings: dict[str, set[tuple]] = {}
    for name, command in commands().items():
        opts = options_of(command)
        assert not {"--jobs", "-j", "--formats", "--out-file"} & set(opts), name
        for option in COMMON:
            if option in opts:
                param = opts[option]
                assert isinstance(param, CommonOption), (name, option)
                spellings.setdefault(option, set()).add((tuple(param.opts), param.is_flag, param.multiple))
    assert {option: len(kinds) for option, kinds in spellings.items()} == {option: 1 for option in COMMON}
    assert spellings["--out"] == {(("-o", "--out"), False, False)}


# ---------------------------------------------------------------------------------------------
# Usage errors: one line, exit status 2
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "args, words",
    [
        (["simulate", "--formats", "png"], ["No such option '--formats'", "'--format'", "hexadyn simulate --help"]),
        (["compare-friction", "--jobs", "2"], ["No such option '--jobs'", "hexadyn compare-friction --help"]),
        (["compare-friction", "-j", "2"], ["No such option '-j'"]),
        (["simulate", "--format", "gif"], ["'--format'", "'gif'", "png, pdf, svg"]),
        (["export", "folder"], ["Missing option '--format'", "hexadyn export --help"]),
        (["export", "folder", "--format", "xls"], ["'xls'", "one of csv, mcap"]),
        (["robot-file", "hexbot"], ["'hexbot'", "amru5", "phantomx"]),
        (["robot", "run", "stand_six_legs", "--bogus"], ["No such option '--bogus'", "hexadyn robot run --help"]),
        (["no-such-command"], ["No such command 'no-such-command'"]),
        (["--bogus"], ["No such option '--bogus'"]),
        (["simulate", "--set", "gait.period_s"], ["'--set'", "KEY=VALUE"]),
        (["simulate", "--set", "model.friction=lugre"], ["'lugre' is not a TOML literal", "--set 'model.friction=\"...\"'"]),
        (["simulate", "--set", "scenario.duration_s=1979-05-27"], ["not a TOML literal of a scenario field"]),
    ],
)
def test_usage_errors_are_one_line_with_status_2(args, words):
    result = invoke(*args)
    assert result.exit_code == 2, (result.exit_code, result.output)
    assert result.stdout == "" and len(result.stderr.splitlines()) == 1 and result.stderr.startswith("Error: "), result.stderr
    for w in words:
        assert w in result.stderr, (w, result.stderr)


@pytest.mark.parametrize("workers", ["0", "-3", "two"])
def test_workers_are_refused_alike_by_every_command(workers, tmp_path):
    errors = {command: invoke(command, "--workers", workers, "--out", str(tmp_path / command)) for command in ("compare-friction", "montecarlo")}
    lines = {command: r.stderr.replace(f"'hexadyn {command} --help'", "HELP") for command, r in errors.items()}
    assert all(r.exit_code == 2 for r in errors.values()), {c: r.output for c, r in errors.items()}
    assert len(set(lines.values())) == 1 and f"Invalid value for '--workers': " in lines["montecarlo"], lines
    assert not any((tmp_path / command).exists() for command in errors)


def test_a_group_without_a_command_prints_its_help():
    result = invoke("robot")
    assert result.exit_code == 2 and "Commands:" in result.output and "emulate" in result.output


# ---------------------------------------------------------------------------------------------
# --set
# ---------------------------------------------------------------------------------------------


def test_set_values_are_toml_literals():
    assert parse_set(["gait.period_s=12", "model.friction = \"lugre\"", "a.b=true", "x.y=[1, 2.5]", "z={q = 1}", "gait.period_s=6.0"]) == {
        "gait.period_s": 6.0,
        "model.friction": "lugre",
        "a.b": True,
        "x.y": [1, 2.5],
        "z": {"q": 1},
    }
    for bad in ["=1", "a..b=1", "a=", "a=lugre", "a=[1,", "a=1979-05-27"]:
        with pytest.raises(ValueError, match=re.escape(repr(bad))):
            parse_set([bad])


def test_simulate_set_runs_the_derived_scenario(tmp_path):
    out = tmp_path / "run"
    result = invoke("simulate", "stand_six_legs", "--set", "scenario.duration_s=0.05", "--set", 'model.friction="none"', "--out", str(out), "--no-progress", "--no-plots")
    assert result.exit_code == 0, result.output
    results = hexadyn.Results.load(out)
    assert results.summary["duration_s"] == pytest.approx(0.05) and results.summary["friction"] == "none"
    assert results.endpoints().index[-1] == pytest.approx(0.05)
    scenario = _core.load_scenario(str(hexadyn.SCENARIOS_DIR / "stand_six_legs.toml"))
    description = json.loads((out / "metadata.json").read_text())["scenario"]
    assert scenario["description"] in description and "[derived: scenario.duration_s = 0.05, model.friction = 'none']" in description
    assert scenario["duration_s"] != 0.05


def test_a_bad_set_field_is_one_line_and_writes_nothing(tmp_path):
    out = tmp_path / "run"
    result = invoke("simulate", "stand_six_legs", "--set", "model.frction=1", "--out", str(out), "--no-progress")
    assert result.exit_code == 1 and result.stderr.count("\n") == 1, result.output
    assert "field `model.frction` = 1: unknown field" in result.stderr and "friction" in result.stderr
    assert not out.exists()


def test_compare_friction_sets_the_fields_on_every_run(tmp_path):
    walk = shortened("validation_tripod_1_5cm", tmp_path, 0.5)
    out = tmp_path / "cmp"
    result = invoke("compare-friction", str(walk), "--velocities", "1.5", "--models", "none,lugre", "--set", "scenario.duration_s=0.3", "--out", str(out), "--workers", "1", "--no-progress", "--no-plots")
    assert result.exit_code == 0, result.output
    robot = pd.read_csv(out / "robot_power.csv").set_index("model")
    assert robot["duration_s"].to_dict() == {"none": pytest.approx(0.3), "lugre": pytest.approx(0.3)}
    assert not (out / "plots").exists()


def test_robot_run_sets_the_fields_of_its_scenario(tmp_path):
    out = tmp_path / "robot"
    result = invoke("robot", "run", "stand_six_legs", "--link", "loopback", "--emulated", "--set", "scenario.duration_s=0.2", "--out", str(out), "--no-progress", "--no-plots")
    assert result.exit_code == 0, result.output
    results = hexadyn.Results.load(out)
    assert results.timeseries.index[-1] == pytest.approx(0.2) and results.summary["duration_s"] == pytest.approx(0.2)
    assert "[derived: scenario.duration_s = 0.2]" in results.metadata["scenario"]
    assert _core.load_scenario(str(hexadyn.SCENARIOS_DIR / "stand_six_legs.toml"))["duration_s"] != 0.2


@pytest.mark.parametrize("command", ["run", "emulate"])
def test_the_robot_commands_refuse_a_bad_set_field_in_one_line(command, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = invoke("robot", command, "stand_six_legs", "--link", "loopback", "--set", "model.frction=1")
    assert_one_line_error(result, "field `model.frction` = 1: unknown field")
    assert list(tmp_path.iterdir()) == []


def test_compare_friction_checks_every_run_and_strict_exits_3(tmp_path, monkeypatch):
    walk = shortened("validation_tripod_1_5cm", tmp_path, 0.3)
    args = ["compare-friction", str(walk), "--velocities", "1.5", "--models", "none", "--workers", "1", "--no-progress", "--no-plots"]
    healthy = invoke(*args, "--strict", "--out", str(tmp_path / "healthy"))
    assert healthy.exit_code == 0 and "WARNING" not in healthy.stderr, healthy.output
    assert pd.read_csv(tmp_path / "healthy" / "robot_power.csv")["warnings"].isna().all()
    monkeypatch.setattr(health, "MAX_PENETRATION_RATIO", 0.0)  # every foot "too deep" (the workers are forked)
    for strict, status in [([], 0), (["--strict"], UNHEALTHY)]:
        out = tmp_path / f"unhealthy{len(strict)}"
        result = invoke(*args, *strict, "--out", str(out))
        assert result.exit_code == status, result.output
        assert re.fullmatch(r"WARNING: friction model none, V_x = 0.015 m/s: a foot went [^\n]* into the ground[^\n]*\n", result.stderr), result.stderr
        assert "into the ground" in pd.read_csv(out / "robot_power.csv").set_index("model").loc["none", "warnings"]


def test_a_campaign_sets_its_fields_on_every_run_and_stores_them(tmp_path):
    walk = shortened("validation_tripod_1_5cm", tmp_path, 2.0)
    plain = Campaign.create(walk, velocities=[0.01], runs_per_velocity=2, variants=["dry_viscous"])
    derived = Campaign.create(walk, velocities=[0.01], runs_per_velocity=2, variants=["dry_viscous"], overrides={"scenario.duration_s": 1.0})
    key = RunKey("dry_viscous", 0, 1)
    assert derived.overrides(key) == {"scenario.duration_s": 1.0, **plain.overrides(key)}
    assert plain.configuration()["scenario_text"] == walk.read_text()
    assert "scenario.duration_s = 1.0" in derived.configuration()["scenario_text"]
    with pytest.raises(ValueError, match="gait.heading.vx_m_s"):
        Campaign.create(walk, overrides={"gait.heading.vx_m_s": "fast"})


# ---------------------------------------------------------------------------------------------
# What is shipped
# ---------------------------------------------------------------------------------------------


def test_info_tells_what_is_shipped():
    result = invoke("info")
    assert result.exit_code == 0, result.output
    assert f"hexadyn {hexadyn.__version__}" in result.output and "not shipped" not in result.output
    for name in _core.SHIPPED_ROBOTS:
        assert f"  {name} " in result.output
    assert "hexadyn robot-file NAME" in result.output
    assert f"shipped scenarios: {len(hexadyn.list_scenarios())} in {hexadyn.SCENARIOS_DIR}" in result.output


@pytest.mark.parametrize("robot", list(_core.SHIPPED_ROBOTS))
def test_robot_file_prints_the_shipped_description(robot, tmp_path):
    result = invoke("robot-file", robot)
    assert result.exit_code == 0 and result.stderr == ""
    assert result.stdout == _core.shipped_robot_text(robot)
    # What it prints is a description file: a scenario runs the robot from it.
    (tmp_path / "mine.toml").write_text(result.stdout)
    assert _core.robot_properties(result.stdout, "mine.toml") == _core.robot_properties(_core.shipped_robot_text(robot), robot)


@pytest.mark.parametrize("robot, table, field", [("amru5", "[motor]", "resistance_ohm"), ("phantomx", "[base]", "mass_kg")])
def test_a_missing_field_points_to_the_robot_file_command(robot, table, field):
    text = _core.shipped_robot_text(robot)
    start = text.index(table)
    cut = re.sub(rf"(?m)^{field} = .*\n", "", text[start:], count=1)
    with pytest.raises(ValueError) as error:
        _core.robot_properties(text[:start] + cut, "mine.toml")
    message = str(error.value)
    assert "missing field" in message and f"`hexadyn robot-file {robot}`" in message and "robots/" not in message, message


# ---------------------------------------------------------------------------------------------
# Progress over the figures
# ---------------------------------------------------------------------------------------------


def test_plotting_shows_a_bar_over_the_figures_unless_no_progress(tmp_path):
    out = tmp_path / "run"
    assert invoke("simulate", str(shortened("leg_sine", tmp_path, 0.2)), "--out", str(out), "--no-progress", "--no-plots").exit_code == 0
    shown = invoke("plot", str(out), "--legs", "0")
    assert shown.exit_code == 0, shown.output
    figures = len(list((out / "plots").glob("*.png")))
    assert re.search(rf"plots: 100%.*\| {figures}/{figures} ", shown.stderr), shown.stderr
    silent = invoke("plot", str(out), "--legs", "0", "--no-progress")
    assert silent.exit_code == 0 and silent.stderr == "", silent.stderr
    assert len(list((out / "plots").glob("*.png"))) == figures
