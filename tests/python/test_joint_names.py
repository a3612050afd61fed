"""Per-robot joint names: a robot description that names its joints otherwise (``[joints]
names``) gets the same simulation, bit for bit, with its own names in every column, table, plot
and scenario motion; names that would make two columns one are refused with one line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import hexadyn
from hexadyn import energy, plots, vocabulary
from conftest import shortened

ROOT = Path(__file__).resolve().parents[2]
AMRU5 = ("q_r", "q_v", "q_h")
RENAMED = ("slew", "lift", "reach")


def renamed_robot(folder: Path, names: tuple[str, ...] | str = RENAMED) -> Path:
    """AMRU5's description with other joint names."""
    text = (ROOT / "robots" / "amru5.toml").read_text()
    stated = 'names = ["q_r", "q_v", "q_h"]'
    assert text.count(stated) == 1
    listed = names if isinstance(names, str) else "[" + ", ".join(f'"{n}"' for n in names) + "]"
    path = folder / "renamed.toml"
    path.write_text(text.replace(stated, f"names = {listed}"))
    return path


def rename(column: str) -> str:
    """The column of the renamed robot that holds AMRU5's `column`."""
    head, bracket, leg = column.partition("[")
    for old, new in zip(AMRU5, RENAMED):
        if head == old or head.endswith("_" + old) or head.startswith(old + "_"):
            return head.replace(old, new, 1) + bracket + leg
    return column


@pytest.fixture(scope="module")
def pair(tmp_path_factory) -> tuple[hexadyn.Results, hexadyn.Results]:
    """The leg_sine scenario (PI references on leg joints, every joint column) for AMRU5 and
    for the renamed robot, 1 s each."""
    folder = tmp_path_factory.mktemp("names")
    scenario = shortened("leg_sine", folder, 1.0)
    robot = renamed_robot(folder)
    text = scenario.read_text()
    for old, new in zip(AMRU5, RENAMED):
        text = text.replace(f'joint = "{old}"', f'joint = "{new}"')
    renamed = folder / "leg_sine_renamed.toml"
    renamed.write_text(text)
    return hexadyn.simulate(scenario, progress=False), hexadyn.simulate(renamed, progress=False, overrides={"scenario.robot": str(robot)})


def test_the_names_change_and_nothing_else(pair):
    amru5, other = pair
    assert other.joints == vocabulary.Joints(RENAMED, ("revolute", "prismatic", "prismatic"))
    expected = [rename(c) for c in amru5.timeseries.columns]
    assert list(other.timeseries.columns) == expected
    assert sum(a != b for a, b in zip(amru5.timeseries.columns, expected)) >= 18 * 9, "every joint column renamed"
    assert {rename(c): u for c, u in amru5.units.items()} == other.units
    np.testing.assert_array_equal(amru5.timeseries.to_numpy(), other.timeseries.to_numpy())
    assert other.units["tau_f_slew[0]"] == "Nm" and other.units["tau_f_lift[0]"] == "N"


def test_power_tables_and_plots_use_the_robots_names(pair, tmp_path):
    amru5, other = pair
    table = energy.averaged_power(other)
    assert list(table.columns) == [*RENAMED, energy.TOTAL]
    np.testing.assert_array_equal(table.to_numpy(), energy.averaged_power(amru5).to_numpy())
    breakdown = energy.energy_breakdown(other)
    assert list(breakdown.index[:3]) == ["slew[0]", "lift[0]", "reach[0]"]
    assert set(breakdown["joint"]) == set(RENAMED)
    figures = plots.figures(other, legs=(1,))
    assert {"leg1_slew", "leg1_lift", "leg1_reach"} <= set(figures)
    assert figures["leg1_lift"]._suptitle.get_text().endswith("prismatic joint lift")
    assert figures["leg1_lift"].axes[0].get_ylabel() == "lift [mm]"
    with pytest.raises(ValueError, match=r"joint = 'q_v'; allowed: slew, lift, reach"):
        plots.joint_figure(other, 1, "q_v")


def test_a_motion_names_a_joint_of_the_robot(tmp_path):
    robot = renamed_robot(tmp_path)
    with pytest.raises(ValueError, match=r'control\.motion\[0\]\.joint` = "q_r": no such joint; allowed: one of the robot\'s joints: slew, lift, reach'):
        hexadyn.simulate(shortened("leg_sine", tmp_path, 0.1), progress=False, overrides={"scenario.robot": str(robot)})


@pytest.mark.parametrize(
    ("names", "problem"),
    [
        ('["a", "b"]', "2 names"),
        ('["a", "a", "b"]', "would share results columns"),
        ('["q", "q_dot", "b"]', "would share results columns"),
        ('["phase", "b", "c"]', "per-leg column"),
        ('["a b", "b", "c"]', "not an identifier"),
    ],
)
def test_names_that_would_make_two_columns_one_are_refused(tmp_path, names, problem):
    robot = renamed_robot(tmp_path, names)
    with pytest.raises(ValueError) as error:
        hexadyn.simulate("leg_sine", progress=False, overrides={"scenario.robot": str(robot)})
    message = str(error.value)
    assert "\n" not in message and str(robot) in message and "joints.names" in message and problem in message, message


def test_monte_carlo_stores_the_split_per_joint_under_the_robots_names(tmp_path):
    from hexadyn.montecarlo.execution import simulate_run
    from hexadyn.montecarlo.storage import per_joint_columns

    scenario = shortened("validation_tripod_1_5cm", tmp_path, 2.0)
    amru5 = simulate_run(str(scenario), {})
    renamed = simulate_run(str(scenario), {"scenario.robot": str(renamed_robot(tmp_path))})
    assert amru5["status"] == renamed["status"] == "ok", (amru5, renamed)
    # The same run; the per-joint columns carry each robot's own names, in its joint order.
    assert [k for k in amru5["summary"] if k.startswith("energy_electrical_") and k != "energy_electrical_j"] == list(per_joint_columns(AMRU5))
    assert [k for k in renamed["summary"] if k.startswith("energy_electrical_") and k != "energy_electrical_j"] == list(per_joint_columns(RENAMED))
    assert list(renamed["summary"].values())[:-1] == list(amru5["summary"].values())[:-1]  # all but the wall time
    split = [renamed["summary"][c] for c in per_joint_columns(RENAMED)]
    assert sum(split) == pytest.approx(renamed["summary"]["energy_electrical_j"], rel=1e-12)
    assert min(split) > 0.0, split


def test_the_viewer_reads_the_robots_joint_columns(pair, tmp_path):
    from hexadyn import report
    from hexadyn.view.data import Run

    amru5, other = pair
    report.save(other, tmp_path / "renamed")
    run = Run(tmp_path / "renamed")
    assert run.joints.names == RENAMED
    np.testing.assert_array_equal(run.q[:, 6:9], other.timeseries[["slew[0]", "lift[0]", "reach[0]"]].to_numpy())
    np.testing.assert_array_equal(run.q, amru5.timeseries[["X", "Y", "Z", "yaw", "pitch", "roll", *amru5.joints.actuators]].to_numpy())
