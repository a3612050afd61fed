"""The time plots beside the 3D view: chosen signals of one leg and the gait diagram, as uPlot
charts of the viser panel, decimated for display, with a cursor at the current time.

The cursor is one more series of each chart: flat at the bottom of the chart but for a spike to
its top at the sample nearest the current time.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
import viser
import viser.uplot

from hexadyn.view.data import LEGS, Run, decimation
from hexadyn.vocabulary import FAILED, LANDING, SUPPORT, SWING, TAKEOFF

#: Most samples per chart (the panel is a few hundred pixels wide).
PLOT_POINTS = 800
CURSOR_COLOUR = "#d0206f"
SERIES_COLOURS = ("#1f5fbf", "#2a9d3a", "#c0392b", "#8e44ad", "#e67e22", "#16a085")
#: Height of a gait diagram bar per phase code (support high, swing low, takeoff and landing half
#: way); a failed leg held up (free gait on five legs) is drawn half way too, dashed.
GAIT_LEVEL = {SUPPORT: 0.7, TAKEOFF: 0.35, SWING: 0.0, LANDING: 0.35, FAILED: 0.35}
#: Dash pattern (pixels) of a failed leg's line in the gait diagram.
FAILED_DASH = (3.0, 4.0)


#: The series of one chart: (label, terms) pairs for a leg and a joint; terms as in _evaluate.
SeriesOf = Callable[[int, str], list[tuple[str, tuple[str, ...]]]]


def signal_groups(run: Run) -> dict[str, SeriesOf]:
    """The plottable signal groups of `run`: name -> the series of a leg's joint chart. Groups
    whose columns are not recorded are left out."""
    have = set(run.columns)

    def every(pattern: str) -> bool:
        return all(pattern.format(j=j, l=leg) in have for j in run.joints.names for leg in range(LEGS))

    groups: dict[str, SeriesOf] = {}
    if every("{j}_ref[{l}]"):
        groups["Joint positions"] = lambda leg, j: [(f"{j}[{leg}]", (f"{j}[{leg}]",)), (f"{j}_ref[{leg}]", (f"{j}_ref[{leg}]",))]
        groups["Tracking errors"] = lambda leg, j: [(f"{j}_ref[{leg}] - {j}[{leg}]", (f"{j}_ref[{leg}]", f"-{j}[{leg}]"))]
    else:
        groups["Joint positions"] = lambda leg, j: [(f"{j}[{leg}]", (f"{j}[{leg}]",))]
    if every("i_{j}[{l}]"):
        groups["Currents"] = lambda leg, j: [(f"i_{j}[{leg}] (A)", (f"i_{j}[{leg}]",))]
        if every("u_{j}[{l}]"):
            groups["Power"] = lambda leg, j: [(f"u i {j}[{leg}] (W)", (f"u_{j}[{leg}]*i_{j}[{leg}]",))]
    return groups


def _evaluate(run: Run, terms: tuple[str, ...], rows: np.ndarray) -> np.ndarray:
    """A signal from column terms: "c" (+c), "-c" (-c) or "a*b" (product), summed."""
    names = sorted({name.lstrip("-") for term in terms for name in term.split("*")})
    data = run.read(names)
    total = np.zeros(rows.size)
    for term in terms:
        sign = -1.0 if term.startswith("-") else 1.0
        value = np.ones(rows.size)
        for name in term.lstrip("-").split("*"):
            value = value * data[name][rows]
        total += sign * value
    return total


class Chart:
    """One uPlot chart of decimated signals with a time cursor."""

    def __init__(self, gui: viser.GuiApi, title: str, t: np.ndarray, series: list[tuple[str, np.ndarray]], height: int, y_range: tuple[float, float] | None = None, dashed: frozenset[str] = frozenset()):
        self.t = t
        self.values = [v for _, v in series]
        self._range = np.array(y_range) if y_range is not None else np.array([np.nanmin(self.values), np.nanmax(self.values)])
        configs = [viser.uplot.Series(label="t (s)")]
        configs += [
            viser.uplot.Series(label=label, stroke=SERIES_COLOURS[i % len(SERIES_COLOURS)], width=1.5, **({"dash": FAILED_DASH} if label in dashed else {}))
            for i, (label, _) in enumerate(series)
        ]
        configs.append(viser.uplot.Series(label="now", stroke=CURSOR_COLOUR, width=1.5))
        scales = {"x": viser.uplot.Scale(time=False, auto=False, range=(float(t[0]), float(t[-1])))}
        if y_range is not None:
            scales["y"] = viser.uplot.Scale(auto=False, range=(float(y_range[0]), float(y_range[1])))
        self.handle = gui.add_uplot(data=self._data(0), series=tuple(configs), title=title, scales=scales, height=height, legend=viser.uplot.Legend(show=False))

    def _data(self, k: int) -> tuple[np.ndarray, ...]:
        return (self.t, *self.values, _spike(self._range, self.t.size, k))

    def move_cursor(self, t: float) -> None:
        """Puts the cursor at time `t`."""
        k = int(np.clip(np.searchsorted(self.t, t), 0, self.t.size - 1))
        self.handle.data = self._data(k)

    def remove(self) -> None:
        self.handle.remove()


def _spike(y_range: np.ndarray, n: int, k: int) -> np.ndarray:
    """The cursor series: at the bottom of `y_range` but for its top at sample `k`."""
    lo, hi = float(y_range[0]), float(y_range[1])
    if hi <= lo:
        lo, hi = lo - 1.0, hi + 1.0
    spike = np.full(n, lo)
    spike[k] = hi
    return spike


class SignalCharts:
    """The three joint charts (q_r, q_v, q_h on AMRU5) of one leg for one signal group."""

    def __init__(self, gui: viser.GuiApi, run: Run, group: str, leg: int):
        series_of = signal_groups(run)[group]
        rows = decimation(run.t.size, PLOT_POINTS)
        t = run.t[rows]
        self.charts = []
        for j in run.joints.names:
            series = [(label, _evaluate(run, terms, rows)) for label, terms in series_of(leg, j)]
            self.charts.append(Chart(gui, f"{group}: {series[0][0]}", t, series, height=150))

    def move_cursor(self, t: float) -> None:
        for chart in self.charts:
            chart.move_cursor(t)

    def remove(self) -> None:
        for chart in self.charts:
            chart.remove()


def gait_chart(gui: viser.GuiApi, run: Run) -> Chart:
    """The gait diagram: one bar per leg (leg 0 on top), high in support, low in swing, half way
    during takeoff and landing; a failed leg (free gait on five legs) is a dashed line half way,
    labelled "(failed)"."""
    rows = decimation(run.t.size, PLOT_POINTS)
    phases = run.phases[rows]
    levels = np.vectorize(lambda p: GAIT_LEVEL.get(int(p), 0.0))(phases)
    failed = (phases == FAILED).any(axis=0)
    series = [(f"leg {leg}" + (" (failed)" if failed[leg] else ""), (LEGS - 1 - leg) + levels[:, leg]) for leg in range(LEGS)]
    dashed = frozenset(label for (label, _), f in zip(series, failed) if f)
    title = "Gait diagram (high: support, low: swing, dashed: failed leg held up), legs 0-5 top to bottom"
    return Chart(gui, title, run.t[rows], series, height=200, y_range=(-0.2, LEGS), dashed=dashed)
