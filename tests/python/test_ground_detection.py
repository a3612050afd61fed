"""The ground detection experiment (Section 5.6.3) from Python: Table 5.7 from the results,
written by `hexadyn simulate` and `hexadyn ground-detection`, and the Fig. 5.17 figure."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import hexadyn
from hexadyn import ground_detection, plots
from hexadyn.cli import cli

from conftest import assert_drawn

#: Legs 0 and 3, two thresholds, two trials each: 2 x (4 + 4 x 8 + 1) s.
SHORT = {
    "ground_detection.legs": [0, 3],
    "ground_detection.thresholds_n": [40.0, 60.0],
    "ground_detection.trials": 2,
    "scenario.duration_s": 74.0,
}


@pytest.fixture(scope="module")
def run(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("gd") / "run"
    hexadyn.simulate("ground_detection", out, progress=False, overrides=SHORT)
    return out


def test_table_5_7_from_the_results(run: Path):
    results = hexadyn.Results.load(run)
    trials = ground_detection.trials(results)
    assert len(trials) == 8
    assert sorted(set(zip(trials["leg"], trials["threshold_n"]))) == [(0, 40.0), (0, 60.0), (3, 40.0), (3, 60.0)]
    assert list(trials["trial"]) == [1, 2] * 4
    # The stop happens when the estimate reaches the threshold, at the simulated force of that row.
    assert (trials["f_estimate_n"] >= trials["threshold_n"]).all()
    ts = results.timeseries
    for _, row in trials.iterrows():
        assert ts.at[row["t_s"], f"Fn[{int(row['leg'])}]"] == row["f_true_n"]
        assert row["error_pct"] == pytest.approx(100 * (row["threshold_n"] - row["f_true_n"]) / row["threshold_n"])
    table = ground_detection.table(trials)
    assert list(table.columns) == ["F_1", "F_2", "E_eps_pct", "sigma_eps_pct"]
    leg0 = trials[(trials["leg"] == 0) & (trials["threshold_n"] == 40.0)]["error_pct"]
    assert table.loc[(0, 40.0), "E_eps_pct"] == pytest.approx(leg0.mean())
    assert table.loc[(0, 40.0), "sigma_eps_pct"] == pytest.approx(np.std(leg0, ddof=1))
    # The files written with the results folder.
    saved = (run / ground_detection.TABLE_FILE).read_text()
    assert saved.splitlines()[0] == "leg,threshold_n,F_1,F_2,E_eps_pct,sigma_eps_pct"
    assert (run / ground_detection.TRIALS_FILE).read_text().count("\n") == 9
    fig = plots.ground_detection_figure(results)
    plots.save_figures({"ground_detection": fig}, run.parent)
    assert_drawn(run.parent / "ground_detection.png", [plots.SIMULATED, "#c0392b"])
    # The measured currents: the true ones through the 30 Hz filter, no noise by default.
    assert np.abs(ts["i_meas_q_v[0]"] - ts["i_q_v[0]"]).max() > 0


def test_cli_ground_detection(run: Path):
    (run / ground_detection.TABLE_FILE).unlink()
    result = CliRunner().invoke(cli, ["ground-detection", str(run)], prog_name="hexadyn")
    assert result.exit_code == 0, result.output
    assert "8 stops" in result.output and "E_eps_pct" in result.output
    assert (run / ground_detection.TABLE_FILE).exists()


def test_cli_ground_detection_on_other_results(tmp_path: Path):
    out = tmp_path / "stand"
    hexadyn.simulate("stand_six_legs", out, progress=False, overrides={"scenario.duration_s": 0.05})
    result = CliRunner().invoke(cli, ["ground-detection", str(out)], prog_name="hexadyn")
    assert result.exit_code == 1
    assert "not the results of a ground detection run" in result.output
