"""Figures (hexadyn.plots), report.plot and the plots written by `hexadyn simulate` and
`hexadyn plot`: every PNG must hold drawn content, and a failure must leave nothing behind."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner
from matplotlib.figure import Figure

import hexadyn
from hexadyn import Results, plots, report
from hexadyn.cli import cli

from conftest import assert_drawn, shortened

WALK_STEMS = {"gait_diagram", "trajectory", "averaged_power", "energy_breakdown"}


def test_results_plot_writes_every_figure(walk: Results, tmp_path: Path):
    figures = report.plot(walk, tmp_path / "plots", legs=[2])
    assert set(figures) == {"leg2_q_r", "leg2_q_v", "leg2_q_h"} | WALK_STEMS
    assert all(isinstance(f, Figure) for f in figures.values())
    assert sorted(p.name for p in (tmp_path / "plots").iterdir()) == sorted(f"{s}.png" for s in figures)
    for stem in figures:
        assert_drawn(tmp_path / "plots" / f"{stem}.png", [plots.SIMULATED] if stem.startswith("leg") or stem == "trajectory" else [])
    # The joint figure: position, tracking error, current, voltage, power, labelled with units.
    labels = [ax.get_ylabel() for ax in figures["leg2_q_v"].axes if ax.get_ylabel()]
    assert labels == ["$q_v$ [mm]", "tracking error [mm]", "current [A]", "voltage [V]", "power [W]"]
    assert figures["leg2_q_v"].axes[-1].get_xlabel() == "time [s]"
    legend = [t.get_text() for t in figures["leg2_q_v"].axes[0].get_legend().get_texts()]
    assert legend[:2] == ["simulated", "reference"] and {"swing", "takeoff", "landing", "double stance"} <= set(legend)
    # Regenerating replaces the folder's content atomically.
    report.plot(walk, tmp_path / "plots", legs=[], formats=["svg", "pdf"])
    assert sorted(p.name for p in (tmp_path / "plots").iterdir()) == sorted(f"{s}.{f}" for s in WALK_STEMS for f in ("svg", "pdf"))
    assert (tmp_path / "plots" / "gait_diagram.pdf").read_bytes().startswith(b"%PDF")
    assert [p.name for p in tmp_path.iterdir()] == ["plots"]


def test_parse_legs():
    assert plots.parse_legs("all") == (0, 1, 2, 3, 4, 5)
    assert plots.parse_legs("2,0,2") == (2, 0)
    for bad in ["6", "-1", "0;2", ""]:
        with pytest.raises(ValueError, match="allowed: "):
            plots.parse_legs(bad)


def test_plot_errors_leave_nothing(walk: Results, tmp_path: Path, monkeypatch):
    with pytest.raises(ValueError, match=r"leg = 6; allowed: 0\.\.5"):
        report.plot(walk, tmp_path / "p", legs=[6])
    with pytest.raises(ValueError, match="allowed: one or more of png, pdf, svg"):
        report.plot(walk, tmp_path / "p", formats=["jpeg"])
    with pytest.raises(ValueError, match="joint = 'q_x'"):
        plots.joint_figure(walk, 0, "q_x")
    assert list(tmp_path.iterdir()) == []

    # A failure while writing the figures: neither the results folder nor a temporary folder.
    real = plots.save_figures

    def failing(figures, folder, formats, progress=False):
        real(dict(list(figures.items())[:1]), folder, formats, progress=progress)
        raise OSError(28, "No space left on device", str(folder))

    monkeypatch.setattr(plots, "save_figures", failing)
    with pytest.raises(OSError, match="No space left"):
        report.save(walk, tmp_path / "run", plots=True, legs=[0])
    assert list(tmp_path.iterdir()) == []


def test_figures_without_a_gait(tmp_path: Path):
    r = hexadyn.simulate(shortened("unpowered_lugre", tmp_path, 0.3), progress=False)
    figures = plots.figures(r, legs=[4])
    assert set(figures) == {"leg4_q_r", "leg4_q_v", "leg4_q_h", "averaged_power", "energy_breakdown"}
    labels = [ax.get_ylabel() for ax in figures["leg4_q_v"].axes]
    assert "tracking error [mm]" not in labels, "no reference without control"
    with pytest.raises(ValueError, match="not a walking scenario"):
        plots.gait_diagram(r)
    with pytest.raises(ValueError, match="not a walking scenario"):
        plots.trajectory_figure(r)


def test_cli_simulate_and_plot(walk_file: Path, tmp_path: Path):
    out = tmp_path / "walk"
    runner = CliRunner()
    result = runner.invoke(cli, ["simulate", str(walk_file), "--out", str(out), "--no-progress"], prog_name="hexadyn")
    assert result.exit_code == 0, result.output
    assert "averaged power per actuator (W)" in result.output and "specific resistance" in result.output
    assert "by foot phase: support" in result.output
    assert f"plots       {out / 'plots'} (10 files)" in result.output
    stems = {f"leg{leg}_{j}" for leg in (0, 2) for j in ("q_r", "q_v", "q_h")} | WALK_STEMS
    assert {p.name for p in (out / "plots").iterdir()} == {f"{s}.png" for s in stems}
    assert_drawn(out / "plots" / "leg0_q_h.png", [plots.SIMULATED])
    assert sorted(p.name for p in out.iterdir()) == ["energy.csv", "metadata.json", "plots", "power.csv", "summary.json", "timeseries.parquet"]

    # `hexadyn plot` regenerates the plots of a results folder.
    result = runner.invoke(cli, ["plot", str(out), "--legs", "5", "--format", "png,svg"], prog_name="hexadyn")
    assert result.exit_code == 0, result.output
    assert "7 figures x 2 formats" in result.output
    assert {p.name for p in (out / "plots").glob("leg*")} == {f"leg5_{j}.{f}" for j in ("q_r", "q_v", "q_h") for f in ("png", "svg")}
    assert_drawn(out / "plots" / "leg5_q_r.png", [plots.SIMULATED])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["walk"], "no temporary folder left"

    for args, message in [
        (["plot", str(out), "--legs", "7"], "leg = 7"),
        (["plot", str(out), "--format", "gif"], "gif"),
        (["plot", str(tmp_path / "missing")], "no such results folder"),
        (["plot", str(tmp_path)], "not a hexadyn results folder"),
    ]:
        result = runner.invoke(cli, args, prog_name="hexadyn")
        assert result.exit_code != 0 and message in result.output and "Traceback" not in result.output, (args, result.output)

    quiet = tmp_path / "quiet"
    result = runner.invoke(cli, ["simulate", str(walk_file), "--out", str(quiet), "--no-progress", "--no-plots"], prog_name="hexadyn")
    assert result.exit_code == 0, result.output
    assert not (quiet / "plots").exists() and (quiet / "power.csv").is_file()


def test_gait_diagram_and_viewer_know_a_failed_leg(walk: Results):
    """Phase code 4 (a failed leg held up by the free gait on five legs) has its own bar and
    legend entry in the gait diagram, and its own level and colour in the viewer."""
    from hexadyn import vocabulary
    from hexadyn.view import charts, scene

    ts = walk.timeseries.copy()
    ts["phase[3]"] = float(vocabulary.FAILED)
    five = Results(ts, walk.units, walk.summary, walk.metadata)
    legend = [t.get_text() for t in plots.gait_diagram(five).axes[0].get_legend().get_texts()]
    assert "failed, held up" in legend
    assert "failed, held up" not in [t.get_text() for t in plots.gait_diagram(walk).axes[0].get_legend().get_texts()]
    for code in vocabulary.PHASE_CODES.values():
        assert code in charts.GAIT_LEVEL and code in scene.PHASE_COLOURS, code
    assert len(set(scene.PHASE_COLOURS[c] for c in vocabulary.PHASE_CODES.values())) == len(vocabulary.PHASE_CODES)


def test_free_gait_stability_figure(tmp_path: Path):
    """A free gait run has the stability figure: the `stability_margin` column in mm against
    time, the smallest value (the summary's) in its title, and a drawn PNG."""
    r = hexadyn.simulate(shortened("free_gait_straight", tmp_path, 12.0), tmp_path / "out", progress=False)
    figures = report.plot(r, tmp_path / "plots", legs=[])
    assert {"posture", "stability"} <= set(figures)
    line = figures["stability"].axes[0].get_lines()[0]
    margin = r.timeseries["stability_margin"].to_numpy()
    assert line.get_xdata() == pytest.approx(r.timeseries.index.to_numpy())
    assert line.get_ydata() == pytest.approx(margin * 1e3)
    assert f"smallest {r.summary['min_stability_margin_m'] * 1e3:.1f} mm" in figures["stability"]._suptitle.get_text()
    assert 0.0 < r.summary["min_stability_margin_m"] == margin.min()
    assert_drawn(tmp_path / "plots" / "stability.png", [plots.SIMULATED], width_in=6.3)


def test_plot_draws_a_robot_run_without_its_trajectory(tmp_path: Path, monkeypatch):
    """Found by test_fuzz_cli.py: `hexadyn plot` on a `hexadyn robot run` folder ended in a
    KeyError traceback (the trajectory figure asked for the feet, which the master does not
    measure). It draws the figures the master's record supports, as `robot run` does."""
    monkeypatch.setattr(Figure, "savefig", lambda self, fname, *a, **k: Path(fname).write_bytes(b""))  # the figures built, not rendered
    out = tmp_path / "run"
    runner = CliRunner()
    result = runner.invoke(cli, ["robot", "run", str(shortened("validation_tripod_1_5cm", tmp_path, 0.1)), "--link", "loopback", "--emulated", "--no-plots", "--no-progress", "--out", str(out)])
    assert result.exit_code == 0, result.output
    result = runner.invoke(cli, ["plot", str(out), "--no-progress"])
    assert result.exit_code == 0, (result.output, result.exception)
    drawn = {p.stem for p in (out / "plots").iterdir()}
    assert {"gait_diagram", "averaged_power", "energy_breakdown", "leg0_q_r"} <= drawn and "trajectory" not in drawn, drawn
    with pytest.raises(ValueError, match="no navigation system"):
        plots.trajectory_figure(Results.load(out))
