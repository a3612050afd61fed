"""The Scenario object: load a shipped scenario or a file, set fields with the engine's
validation, rename, write out and run; results folders numbered like the CLI's; summary.json
with true JSON types."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from click.testing import CliRunner

import hexadyn
from hexadyn import Results, Scenario, _core
from hexadyn.cli import cli

from conftest import shortened


@pytest.fixture
def sine_file(tmp_path: Path) -> Path:
    return shortened("leg_sine", tmp_path, 0.1)


def test_load_a_shipped_scenario_or_a_file(sine_file: Path):
    s = Scenario.load("validation_tripod_1_5cm")
    assert s.path == hexadyn.SCENARIOS_DIR / "validation_tripod_1_5cm.toml"
    assert s.name == "validation_tripod_1_5cm" and s.duration_s == 60.0
    assert s.description.startswith("Table 6.2 validation walk")
    assert s.fields == {} and not s.derived
    assert s.to_toml() == s.path.read_text()
    assert Scenario.load(sine_file).path == Scenario.from_file(sine_file).path == sine_file
    assert Scenario.from_file(sine_file).duration_s == 0.1
    # A shipped name is not a file; a missing name lists the shipped ones.
    with pytest.raises(FileNotFoundError, match="leg_sine"):
        Scenario.from_file("leg_sine")
    with pytest.raises(FileNotFoundError, match="stand_six_legs"):
        Scenario.load("no_such_scenario")


def test_list_scenarios_gives_the_names_the_cli_shows():
    names = hexadyn.list_scenarios()
    assert names == sorted(names) and "validation_tripod_1_5cm" in names
    assert [hexadyn.resolve_scenario(n) for n in names] == hexadyn.scenario_files()
    shown = CliRunner().invoke(cli, ["scenarios"], prog_name="hexadyn").output.splitlines()[1:]
    assert [line.split()[0] for line in shown] == names


def test_set_is_validated_as_overrides_are():
    s = Scenario.load("path_spline")
    for field, value, shown, allowed in [
        ("gait.period_s", -1.0, "-1", "allowed: a leg cycle time >= 0.1333 s"),
        ("gait.perod_s", 1.2, "1.2", "allowed: expected one of `period_s`"),
        ("model.friction", "coulomb", '"coulomb"', "allowed: expected one of `none`, `dry_viscous`, `lugre`"),
        ("gait.period_s", "slow", '"slow"', "allowed: expected f64"),
    ]:
        with pytest.raises(ValueError) as caught:
            s.set(field, value)
        message = str(caught.value)
        assert "\n" not in message and f"`{field}` = {shown}:" in message and allowed in message, message
        # The same message as the engine gives for the override (one validation, not two).
        with pytest.raises(ValueError) as direct:
            _core.load_scenario(str(s.path), {field: value})
        assert message == str(direct.value)
        assert s.fields == {} and s.to_toml() == s.path.read_text(), "a refused value leaves the scenario as it was"
    with pytest.raises(TypeError, match="model.friction"):
        s.set("model.friction", object())
    assert s.set("gait.period_s", 14.0) is s
    assert s.fields == {"gait.period_s": 14.0}
    assert _core.load_scenario(str(s.path), s.overrides())["gait"]["period_s"] == 14.0


def test_update_sets_several_fields_at_once_or_none():
    s = Scenario.load("path_spline")
    with pytest.raises(ValueError, match="`model.friction` = \"coulomb\""):
        s.update({"gait.period_s": 14.0, "model.friction": "coulomb"})
    assert s.fields == {}, "a refused field leaves the scenario as it was, the valid ones too"
    assert s.update({"gait.period_s": 14.0, "model.friction": "lugre"}) is s
    assert s.fields == {"gait.period_s": 14.0, "model.friction": "lugre"}
    info = _core.load_scenario(str(s.path), s.overrides())
    assert info["gait"]["period_s"] == 14.0 and "lugre" in info["text"]


def test_an_edited_scenario_says_it_is_derived_until_renamed():
    s = Scenario.load("validation_tripod_1_5cm")
    original = s.description
    s.set("gait.heading.vx_m_s", 0.02).set("model.friction", "dry_viscous")
    assert s.derived and s.name == "validation_tripod_1_5cm"
    assert s.description == f"{original} [derived: gait.heading.vx_m_s = 0.02, model.friction = 'dry_viscous']"
    text = s.to_toml()
    assert "vx_m_s = 0.02" in text and 'friction = "dry_viscous"' in text and "[derived: " in text
    with pytest.raises(ValueError, match="scenario.name.*empty"):
        s.rename("", "nothing")
    assert s.derived and s.name == "validation_tripod_1_5cm"
    assert s.rename("walk_2cm", "The validation walk at 2 cm/s, dry/viscous friction") is s
    assert not s.derived
    assert (s.name, s.description) == ("walk_2cm", "The validation walk at 2 cm/s, dry/viscous friction")
    assert 'name = "walk_2cm"' in s.to_toml() and "[derived: " not in s.to_toml()
    # Renaming alone changes nothing of the scenario itself: nothing to call derived.
    assert not Scenario.load("leg_sine").rename("sine", "a sine").derived


def test_the_written_text_loads_as_the_same_scenario(tmp_path: Path):
    s = Scenario.load("path_spline").set("gait.period_s", 10.0).set("scenario.duration_s", 30.0)
    copy = tmp_path / "copy.toml"
    copy.write_text(s.to_toml())
    again = Scenario.from_file(copy)
    assert (again.name, again.description, again.duration_s) == (s.name, s.description, 30.0)
    assert again.description.endswith("[derived: gait.period_s = 10.0, scenario.duration_s = 30.0]")
    assert _core.load_scenario(str(copy))["gait"] == _core.load_scenario(str(s.path), s.overrides())["gait"]


def test_simulate_is_simulate_with_the_fields_as_overrides(sine_file: Path):
    s = Scenario.from_file(sine_file).set("model.friction", "none")
    r = s.simulate(progress=False)
    assert isinstance(r, Results) and r.summary["friction"] == "none"
    direct = hexadyn.simulate(sine_file, progress=False, overrides=s.overrides())
    assert {k: v for k, v in r.summary.items() if k != "wall_time_s"} == {k: v for k, v in direct.summary.items() if k != "wall_time_s"}
    assert r.metadata["scenario"] == s.to_toml()
    assert r.timeseries.equals(direct.timeseries)


def test_results_folders_are_numbered_like_the_cli(sine_file: Path, tmp_path: Path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    s = Scenario.from_file(sine_file)
    first = s.simulate(progress=False, save=True)
    second = hexadyn.simulate(sine_file, progress=False, save=True)
    third = CliRunner().invoke(cli, ["simulate", str(sine_file), "--no-progress", "--no-plots"], prog_name="hexadyn")
    assert third.exit_code == 0, third.output
    assert (first.path, second.path) == (Path("results/leg_sine"), Path("results/leg_sine-2"))
    assert "Results: results/leg_sine-3\n" in third.output
    assert Results.load(second.path).summary["scenario"] == "leg_sine"
    renamed = s.set("model.friction", "none").rename("sine/no friction", "no friction").simulate(progress=False, save=True)
    assert renamed.path == Path("results/sine_no_friction"), "the name made a safe folder name"
    # An explicit folder is the caller's choice: refused if it exists, as --out is.
    with pytest.raises(FileExistsError):
        hexadyn.simulate(sine_file, "results/leg_sine", progress=False)


def test_summary_json_has_true_types(tmp_path: Path):
    """Every field of a walk's summary.json has the JSON type of its value: booleans as
    booleans, counts as integers, figures as numbers (null when not finite), text as strings
    that are neither booleans nor numbers in disguise."""
    results = hexadyn.simulate(shortened("path_spline", tmp_path, 0.3), tmp_path / "walk", progress=False)
    stored = json.loads((tmp_path / "walk" / "summary.json").read_text())
    summary = results.summary
    assert stored.keys() == summary.keys() and len(stored) > 50
    assert stored["navigation"] is True and stored["gait_pattern"] == "tripod"
    for name in ["rows", "integration_steps", "rejected_steps", "limit_switch_cuts", "gait_switches", "min_feet_on_ground"]:
        assert type(stored[name]) is int, name
    for name, value in stored.items():
        kept = summary[name]
        if isinstance(kept, float) and not math.isfinite(kept):
            assert value is None, name
        else:
            assert type(value) is type(kept) or (type(kept), type(value)) == (tuple, list), (name, value, kept)
        if isinstance(value, str):
            assert value.lower() not in ("true", "false", "null"), (name, value)
            with pytest.raises(ValueError):
                float(value)
