"""Figures of a simulation, in the style of the thesis' Chapter 6 (matplotlib, Agg).

Every function takes a :class:`~hexadyn.results.Results` and returns a
:class:`matplotlib.figure.Figure` built without pyplot: no global state, no window, nothing to
close, and the user's backend is left alone; files are rendered by Agg (PNG) and the PDF and SVG
backends. Figures display in Jupyter as they are.

- :func:`joint_figure`: one actuator (leg, joint type): joint position and reference, tracking
  error, motor current, voltage and electrical power, foot phases shaded (Figs. 6.4-6.15);
- :func:`gait_diagram`: support, transition and swing bars of every leg over time;
- :func:`trajectory_figure`: body path in the ground plane X-Y with its reference;
- :func:`averaged_power_figure`: averaged power per actuator split by foot phase
  (Tables 6.3-6.6 as a chart);
- :func:`energy_breakdown_figure`: electrical energy of each actuator split into Joule losses,
  friction work and mechanical work;
- :func:`ground_detection_figure`: the ground detection experiment (Section 5.6.3): estimated
  and true ground force of a tested leg around its first stop, with its vertical joint
  (Fig. 5.17).

:func:`figures` builds those the results support (the gait diagram and the trajectory need a
walking scenario) and :func:`save_figures` writes them as 300 dpi PNG and, on request, vector
PDF or SVG (about twice the time of the PNG files).
"""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable, Iterator, Mapping, Sequence

import matplotlib
import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from matplotlib.rcsetup import cycler

from hexadyn import energy, ground_detection
from hexadyn.vocabulary import FAILED, LANDING, REVOLUTE, LEGS, SUPPORT, SWING, TAKEOFF, actuator, actuator_column, leg_column

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.typing import RcKeyType

    from hexadyn.results import Results

#: Legs of the per-actuator figures by default: legs 0 and 2, as in Section 6.4.
DEFAULT_LEGS = (0, 2)
#: File formats written by :func:`save_figures` by default.
DEFAULT_FORMATS = ("png",)
FORMATS = ("png", "pdf", "svg")
#: Resolution of the PNG files.
DPI = 300

#: One style for every figure (paper quality: small serif-free fonts, light grid).
STYLE: dict[RcKeyType, Any] = {
    "font.size": 8,
    "axes.titlesize": 9,
    "axes.labelsize": 8,
    "legend.fontsize": 7,
    "xtick.labelsize": 7,
    "ytick.labelsize": 7,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.5,
    "lines.linewidth": 0.9,
    "axes.prop_cycle": cycler(color=["#1f4e79", "#c0392b", "#2e8b57", "#e67e22", "#7d3c98", "#7f8c8d"]),
    "figure.constrained_layout.use": True,
    "savefig.dpi": DPI,
    "pdf.fonttype": 42,
    "svg.fonttype": "none",
}
#: Colours of the series that recur across figures.
REFERENCE = "0.25"
SIMULATED = "#1f4e79"
#: Shades of grey of the foot phases (Section 6.4: "different shades of gray"); support is white.
PHASE_SHADES = {"double stance": "0.62", "takeoff": "0.78", "swing": "0.90", "landing": "0.70"}
#: Colour of a failed leg (free gait on five legs) in the gait diagram.
FAILED_COLOUR = "#e6a5a5"
#: Colours of the stacked components.
PHASE_COLOURS = {"support": "#1f4e79", "swing": "#8fb3d9", "transitions": "#e67e22"}
ENERGY_COLOURS = {"joule_j": "#c0392b", "friction_j": "#7f8c8d", "mechanical_j": "#2e8b57", "magnetic_j": "#7d3c98"}
ENERGY_LABELS = {"joule_j": "Joule losses", "friction_j": "friction work", "mechanical_j": "mechanical work", "magnetic_j": "magnetic energy change"}

#: Display scale and unit of joint positions per joint type: degrees and millimetres (Figs. 6.4-6.15).
def _position_scale(kind: str) -> tuple[float, str]:
    """Plot scale and unit of a joint position: degrees for a revolute joint, mm for a
    prismatic one."""
    return (180.0 / np.pi, "deg") if kind == REVOLUTE else (1e3, "mm")


def _symbol(joint: str) -> str:
    """A joint name as a label: ``q_r`` as the math symbol $q_r$, any other name as it is."""
    head, _, tail = joint.partition("_")
    if not (head.isalpha() and tail.isalnum()):
        return joint
    return f"${head}_{tail}$" if len(tail) == 1 else f"${head}_{{{tail}}}$"
_LEG_RANGE = f"{LEGS[0]}..{LEGS[-1]}"

__all__ = [
    "DEFAULT_FORMATS",
    "DEFAULT_LEGS",
    "averaged_power_figure",
    "energy_breakdown_figure",
    "figures",
    "gait_diagram",
    "ground_detection_figure",
    "joint_figure",
    "parse_legs",
    "posture_figure",
    "save_figures",
    "stability_figure",
    "style",
    "trajectory_figure",
]


@contextmanager
def style() -> Iterator[None]:
    """The rc settings of every hexadyn figure (:data:`STYLE`), while building and saving."""
    with matplotlib.rc_context(STYLE):
        yield


def _title(results: Results) -> str:
    return str(results.metadata.get("scenario_name") or results.summary.get("scenario") or "")


# -------------------------------------------------------------------------------------------------
# Foot phases
# -------------------------------------------------------------------------------------------------


def _spans(t_end: np.ndarray, dt: float, mask: np.ndarray) -> list[tuple[float, float]]:
    """(start, width) of the runs of periods (t_end - dt, t_end] where mask holds."""
    m = np.concatenate([[False], mask, [False]]).astype(np.int8)
    starts = np.flatnonzero(np.diff(m) == 1)
    stops = np.flatnonzero(np.diff(m) == -1)
    return [(t_end[a] - dt, t_end[b - 1] - t_end[a] + dt) for a, b in zip(starts, stops)]


def _shade_phases(axes: Iterable, results: Results, leg: int) -> list[Patch]:
    """Shades the foot phases of a leg on every axis; returns the legend handles."""
    phases = energy.foot_phases(results)
    if phases is None:
        return []
    t = phases.index.to_numpy()
    dt = float(t[1] - t[0]) if len(t) > 1 else 0.0
    code = phases[leg].to_numpy()
    double = (phases.to_numpy() == SUPPORT).all(axis=1)
    masks = {
        "double stance": double,
        "takeoff": code == TAKEOFF,
        "swing": code == SWING,
        "landing": code == LANDING,
    }
    spans = {name: _spans(t, dt, mask) for name, mask in masks.items()}
    for ax in axes:
        for name, s in spans.items():
            if s:
                ax.broken_barh(s, (0, 1), transform=ax.get_xaxis_transform(), facecolor=PHASE_SHADES[name], edgecolor="none", zorder=0)
    return [Patch(facecolor=PHASE_SHADES[name], label=name) for name, s in spans.items() if s]


# -------------------------------------------------------------------------------------------------
# Figures
# -------------------------------------------------------------------------------------------------


def joint_figure(results: Results, leg: int, joint: str) -> Figure:
    """Reference, tracking error, current, voltage and power of one actuator (Figs. 6.4-6.15).

    Panels, sharing the time axis (foot phases shaded): the joint position q and its reference
    (deg for q_r, mm for q_v and q_h), the tracking error q_ref - q, the motor current i (A,
    sampled at each control instant), the voltage u (V, held over each control period) and the
    electrical power u i (W, mean over each control period, Eq. 6.7). Without references (an
    unpowered scenario) the error panel is left out.
    """
    _check_leg(leg)
    kind = results.joints.kind(joint)
    ts = results.timeseries
    name = actuator(joint, leg)
    scale, unit = _position_scale(kind)
    t = ts.index.to_numpy()
    reference = leg_column(f"{joint}_ref", leg)
    has_ref = reference in ts.columns
    p = energy.power(results)[name]
    with style():
        fig = Figure(figsize=(6.3, 7.2 if has_ref else 6.0))
        axes = fig.subplots(5 if has_ref else 4, 1, sharex=True)
        it = iter(axes)
        ax = next(it)
        ax.plot(t, ts[name] * scale, color=SIMULATED, label="simulated")
        if has_ref:
            ax.plot(t, ts[reference] * scale, color=REFERENCE, linestyle="--", label="reference")
        ax.set_ylabel(f"{_symbol(joint)} [{unit}]")
        handles, _ = ax.get_legend_handles_labels()
        if has_ref:
            ax = next(it)
            ax.plot(t, (ts[reference] - ts[name]) * scale, color=SIMULATED)
            ax.set_ylabel(f"tracking error [{unit}]")
        ax = next(it)
        ax.plot(t, ts[actuator_column("i", name)], color=SIMULATED)
        ax.set_ylabel("current [A]")
        ax = next(it)
        ax.plot(t, ts[actuator_column("u", name)], color=SIMULATED, drawstyle="steps-pre")
        ax.set_ylabel("voltage [V]")
        ax = next(it)
        ax.plot(p.index.to_numpy(), p.to_numpy(), color=SIMULATED, drawstyle="steps-pre")
        ax.set_ylabel("power [W]")
        ax.set_xlabel("time [s]")
        ax.set_xlim(t[0], t[-1])
        shades = _shade_phases(axes, results, leg)
        axes[0].legend(handles=handles + shades, loc="lower left", bbox_to_anchor=(0, 1.02), ncol=6, frameon=False, borderaxespad=0)
        fig.suptitle(f"{_title(results)}: leg {leg}, {kind} joint {_symbol(joint)}")
    return fig


def gait_diagram(results: Results) -> Figure:
    """Gait diagram: for every leg, bars over the time it supports the body (black), its takeoff
    and landing transitions (grey), a failed leg held up by the free gait (light red); the gaps
    are the swing phases."""
    phases = energy.foot_phases(results)
    if phases is None:
        raise ValueError("gait diagram: these results have no foot phases (not a walking scenario)")
    t = phases.index.to_numpy()
    dt = float(t[1] - t[0]) if len(t) > 1 else 0.0
    legend = {"support": ((SUPPORT,), "black"), "takeoff / landing": ((TAKEOFF, LANDING), "0.6")}
    if (phases.to_numpy() == FAILED).any():
        legend["failed, held up"] = ((FAILED,), FAILED_COLOUR)
    with style():
        fig = Figure(figsize=(6.3, 2.4))
        ax = fig.subplots()
        for row, leg in enumerate(LEGS):
            for codes, colour in legend.values():
                ax.broken_barh(_spans(t, dt, np.isin(phases[leg].to_numpy(), codes)), (row - 0.35, 0.7), facecolor=colour, edgecolor="none")
        ax.set_yticks(range(len(LEGS)), [f"leg {leg}" for leg in LEGS])
        ax.set_ylim(len(LEGS) - 0.5, -0.5)
        ax.set_xlim(t[0] - dt, t[-1])
        ax.set_xlabel("time [s]")
        ax.grid(axis="y", visible=False)
        ax.legend(handles=[Patch(facecolor=c, label=n) for n, (_, c) in legend.items()] + [Patch(facecolor="white", edgecolor="0.5", label="swing")], loc="lower left", bbox_to_anchor=(0, 1.02), ncol=3, frameon=False, borderaxespad=0)
        fig.suptitle(f"{_title(results)}: gait diagram")
    return fig


#: The columns of the trajectory figure: the body path and its reference, and the feet (for the
#: footholds). A `hexadyn robot run` has the reference only: the robot has no navigation system.
TRAJECTORY_COLUMNS = {"X", "Y", "X_ref", "Y_ref", *(leg_column(c, leg) for c in ("foot_x", "foot_y") for leg in LEGS)}


def trajectory_figure(results: Results) -> Figure:
    """The body path in the ground plane (X, Y) with its reference and the footholds (equal
    axes), and below it the XY tracking error over time."""
    ts = results.timeseries
    phases = energy.foot_phases(results)
    if not TRAJECTORY_COLUMNS <= set(ts.columns) or phases is None:
        raise ValueError("trajectory: these results have no body path X, Y with its reference X_ref, Y_ref and the feet (not a walking scenario, or a robot run: no navigation system)")
    t = ts.index.to_numpy()
    with style():
        fig = Figure(figsize=(6.3, 4.4))
        path, error = fig.subplots(2, 1, height_ratios=[2, 1])
        for leg in LEGS:
            # A foothold: where the foot is at the first instant of each support run.
            support = phases[leg].to_numpy() == SUPPORT
            first = np.flatnonzero(support & ~np.concatenate([[False], support[:-1]]))
            x, y = ts[leg_column("foot_x", leg)].to_numpy()[1:][first], ts[leg_column("foot_y", leg)].to_numpy()[1:][first]
            path.plot(x * 1e3, y * 1e3, linestyle="none", marker="o", markersize=2.5, color="0.6", label="footholds" if leg == 0 else None)
        path.plot(ts["X_ref"] * 1e3, ts["Y_ref"] * 1e3, color=REFERENCE, linestyle="--", label="reference")
        path.plot(ts["X"] * 1e3, ts["Y"] * 1e3, color=SIMULATED, label="body")
        path.plot(ts["X"].iloc[0] * 1e3, ts["Y"].iloc[0] * 1e3, "o", color=SIMULATED, markersize=4, label="start")
        path.plot(ts["X"].iloc[-1] * 1e3, ts["Y"].iloc[-1] * 1e3, "s", color=SIMULATED, markersize=4, label="end")
        path.set_aspect("equal", adjustable="datalim")
        path.set_xlabel("X [mm]")
        path.set_ylabel("Y [mm]")
        path.legend(loc="lower left", bbox_to_anchor=(0, 1.02), ncol=5, frameon=False, borderaxespad=0)
        error.plot(t, np.hypot(ts["X"] - ts["X_ref"], ts["Y"] - ts["Y_ref"]) * 1e3, color=SIMULATED)
        error.set_xlim(t[0], t[-1])
        error.set_xlabel("time [s]")
        error.set_ylabel("XY tracking error [mm]")
        fig.suptitle(f"{_title(results)}: body trajectory in the ground plane")
    return fig


def posture_figure(results: Results) -> Figure:
    """The free gait's posture against the body's X (Fig. 7.33-7.41 style): above, the body
    height above the ground plane the controller estimates from its contact points; below, the
    roll and pitch of the body (simulated, and as the controller knows them), in degrees."""
    ts = results.timeseries
    if "body_clearance" not in ts.columns:
        raise ValueError("posture: these results have no body_clearance column (not a free gait scenario)")
    x = ts["X"].to_numpy() * 1e3
    with style():
        fig = Figure(figsize=(6.3, 4.4))
        height, angles = fig.subplots(2, 1, sharex=True)
        height.plot(x, ts["body_clearance"] * 1e3, color=SIMULATED, label="estimated ground plane")
        height.set_ylabel("body height [mm]")
        height.legend(loc="lower left", bbox_to_anchor=(0, 1.02), frameon=False, borderaxespad=0)
        for name, colour in (("roll", SIMULATED), ("pitch", REFERENCE)):
            angles.plot(x, np.degrees(ts[name]), color=colour, label=name)
            angles.plot(x, np.degrees(ts[f"posture_{name}"]), color=colour, linestyle=":", label=f"{name} (controller)")
        angles.set_xlabel("X [mm]")
        angles.set_ylabel("angle [deg]")
        angles.legend(loc="best", ncol=2, frameon=False)
        fig.suptitle(f"{_title(results)}: posture against X")
    return fig


def stability_figure(results: Results) -> Figure:
    """The free gait's tip-over stability against time (beyond the thesis): the normalized
    energy stability margin of the feet in support as the controller knows them (the
    ``stability_margin`` column, mm); below zero the body's centre is beyond an edge of its
    support polygon, and it is not drawn with fewer than three feet in support."""
    ts = results.timeseries
    if "stability_margin" not in ts.columns:
        raise ValueError("stability: these results have no stability_margin column (not a free gait scenario)")
    t = ts.index.to_numpy()
    margin = ts["stability_margin"].to_numpy() * 1e3
    with style():
        fig = Figure(figsize=(6.3, 2.8))
        ax = fig.subplots()
        ax.plot(t, np.where(np.isfinite(margin), margin, np.nan), color=SIMULATED, label="energy stability margin")
        ax.axhline(0.0, color=REFERENCE, linestyle=":", label="tip-over")
        ax.set_xlabel("t [s]")
        ax.set_ylabel("margin [mm]")
        ax.legend(loc="best", frameon=False)
        finite = margin[np.isfinite(margin)]
        lowest = f", smallest {finite.min():.1f} mm" if finite.size else ""
        fig.suptitle(f"{_title(results)}: stability margin{lowest}")
    return fig


def averaged_power_figure(results: Results) -> Figure:
    """Averaged power per actuator (W), stacked by foot phase when the robot walks."""
    table = energy.averaged_power(results)
    phases = [p for p in energy.PHASE_GROUPS if p in table.index.get_level_values("phase")] or [energy.ALL]
    parts = pd.DataFrame({p: _per_actuator(table.loc[p]) for p in phases})
    colours = {**PHASE_COLOURS, energy.ALL: SIMULATED}
    with style():
        fig = Figure(figsize=(6.3, 3.0))
        ax = fig.subplots()
        _stacked_actuator_bars(ax, parts, {p: colours[p] for p in phases}, {p: p for p in phases})
        ax.set_ylabel("averaged power [W]")
        fig.suptitle(f"{_title(results)}: averaged power per actuator (total {table.loc[(energy.ALL, energy.TOTAL), energy.TOTAL]:.3g} W)")
    return fig


def energy_breakdown_figure(results: Results) -> Figure:
    """Energy of each actuator (J): Joule losses, friction work and mechanical work stacked
    (negative parts below zero) and the electrical energy drawn as a marker, their sum."""
    b = energy.energy_breakdown(results)
    components = [c for c in ENERGY_COLOURS if c != "magnetic_j" or b[c].any()]
    with style():
        fig = Figure(figsize=(6.3, 3.0))
        ax = fig.subplots()
        x = _stacked_actuator_bars(ax, b[components], {c: ENERGY_COLOURS[c] for c in components}, ENERGY_LABELS)
        ax.plot(x, b["electrical_j"], linestyle="none", marker="D", markersize=3.5, color="black", label="electrical energy")
        ax.legend(loc="lower left", bbox_to_anchor=(0, 1.02), ncol=5, frameon=False, borderaxespad=0)
        ax.set_ylabel("energy [J]")
        fig.suptitle(f"{_title(results)}: energy per actuator (electrical {b['electrical_j'].sum():.4g} J)")
    return fig


def _per_actuator(block: pd.DataFrame) -> pd.Series:
    """A (leg x joint) block of :func:`energy.averaged_power` as one value per actuator."""
    joints = [j for j in block.columns if j != energy.TOTAL]
    return pd.Series({actuator(j, leg): block.loc[leg, j] for leg in LEGS for j in joints})


def _stacked_actuator_bars(ax: Axes, parts: pd.DataFrame, colours: Mapping[str, str], labels: Mapping[str, str]) -> np.ndarray:
    """Bars of the 18 actuators (the index of `parts`, leg by leg) grouped by leg, the columns of
    `parts` stacked (positive parts upwards from zero, negative ones downwards); returns the bar
    positions."""
    per_leg = len(parts) // len(LEGS)
    x = np.array([(per_leg + 1) * (i // per_leg) + i % per_leg for i in range(len(parts))], dtype=float)
    up = np.zeros(len(x))
    down = np.zeros(len(x))
    for column in parts.columns:
        v = parts[column].to_numpy()
        base = np.where(v >= 0, up, down)
        ax.bar(x, v, 0.8, bottom=base, color=colours[column], label=labels[column])
        up += np.clip(v, 0, None)
        down += np.clip(v, None, 0)
    ax.axhline(0, color="black", linewidth=0.6)
    ax.set_xticks(x, [a.partition("[")[0].removeprefix("q_") for a in parts.index])
    ax.tick_params(axis="x", length=0)
    ax.grid(axis="x", visible=False)
    groups = ax.secondary_xaxis(-0.09)
    groups.set_xticks([(per_leg + 1) * leg + (per_leg - 1) / 2 for leg in LEGS], [f"leg {leg}" for leg in LEGS])
    groups.tick_params(length=0)
    groups.spines["bottom"].set_visible(False)
    ax.legend(loc="lower left", bbox_to_anchor=(0, 1.02), ncol=5, frameon=False, borderaxespad=0)
    return x


# -------------------------------------------------------------------------------------------------
# All figures of a run
# -------------------------------------------------------------------------------------------------


def parse_legs(text: str) -> tuple[int, ...]:
    """Legs from the command line: ``"0,2"`` or ``"all"``."""
    if text.strip().lower() == "all":
        return LEGS
    try:
        legs = tuple(int(s) for s in text.split(","))
    except ValueError:
        raise ValueError(f"legs = {text!r}; allowed: comma-separated legs {_LEG_RANGE} (e.g. 0,2) or all") from None
    for leg in legs:
        _check_leg(leg)
    return tuple(dict.fromkeys(legs))


def _check_leg(leg: int) -> None:
    if leg not in LEGS:
        raise ValueError(f"leg = {leg!r}; allowed: {_LEG_RANGE}")


def figures(results: Results, legs: Sequence[int] = DEFAULT_LEGS) -> dict[str, Figure]:
    """The figures the results support, by file stem: ``leg0_q_r`` ... for the given legs, then
    ``gait_diagram`` and ``trajectory`` (walking scenarios), ``posture`` and ``stability`` (free gait),
    ``averaged_power`` and ``energy_breakdown``."""
    for leg in legs:
        _check_leg(leg)
    out = {f"leg{leg}_{j}": joint_figure(results, leg, j) for leg in legs for j in results.joints.names}
    if energy.foot_phases(results) is not None:
        out["gait_diagram"] = gait_diagram(results)
    if TRAJECTORY_COLUMNS <= set(results.timeseries.columns):
        out["trajectory"] = trajectory_figure(results)
    if "body_clearance" in results.timeseries.columns:
        out["posture"] = posture_figure(results)
    if "stability_margin" in results.timeseries.columns:
        out["stability"] = stability_figure(results)
    out["averaged_power"] = averaged_power_figure(results)
    out["energy_breakdown"] = energy_breakdown_figure(results)
    if ground_detection.has_experiment(results):
        out["ground_detection"] = ground_detection_figure(results)
    return out


def ground_detection_figure(results: Results, leg: int | None = None) -> Figure:
    """Fig. 5.17: the ground force F_z,gnd estimated from the motor current (Eq. 5.22) and the
    simulated normal force on the foot, from 3 s before to 5 s after the first stop of ``leg``
    (default: the first leg that stopped), the threshold dashed; below, the vertical joint q_v
    and its reference (the reference is held at the stop, then the sawtooth resumes)."""
    trials = ground_detection.trials(results)
    if trials.empty:
        raise ValueError("no stop on a detection in these results")
    leg = int(trials["leg"].iloc[0]) if leg is None else leg
    _check_leg(leg)
    first = trials[trials["leg"] == leg]
    if first.empty:
        raise ValueError(f"leg {leg} never stopped on a detection; legs that did: {sorted(set(trials['leg']))}")
    t0, threshold = float(first["t_s"].iloc[0]), float(first["threshold_n"].iloc[0])
    ts = results.timeseries.loc[t0 - 3.0 : t0 + 5.0]
    t = ts.index.to_numpy()
    with style():
        fig = Figure(figsize=(6.3, 4.2))
        top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=[2, 1])
        top.plot(t, ts[f"F_gnd_est[{leg}]"], color=SIMULATED, label="estimated $F_{z,gnd}$ (Eq. 5.22)")
        top.plot(t, ts[leg_column("Fn", leg)], color="#c0392b", label="true normal force")
        top.axhline(threshold, color=REFERENCE, linestyle="--", label=f"threshold {threshold:g} N")
        top.axvline(t0, color="0.6", linewidth=0.6)
        top.set_ylabel("ground force [N]")
        top.legend(loc="upper left", frameon=False)
        bottom.plot(t, ts[leg_column("q_v", leg)] * 1e3, color=SIMULATED, label="$q_v$")
        bottom.plot(t, ts[leg_column("q_v_ref", leg)] * 1e3, color=REFERENCE, linestyle="--", label="reference")
        bottom.set_ylabel("$q_v$ [mm]")
        bottom.set_xlabel("time [s]")
        bottom.legend(loc="upper left", frameon=False)
        bottom.set_xlim(t[0], t[-1])
        fig.suptitle(f"{_title(results)}: ground detection, leg {leg}")
    return fig


def save_figures(figs: Mapping[str, Figure], folder: str | Path, formats: Sequence[str] = DEFAULT_FORMATS, *, progress: bool = False) -> list[Path]:
    """Writes every figure as ``folder/<stem>.<format>`` (PNG at 300 dpi); returns the paths.

    The folder must exist. Use :func:`hexadyn.report.plot` or :func:`hexadyn.report.save` to
    write a complete plots folder atomically. `progress`: a tqdm bar on stderr that advances
    figure by figure, naming the one being drawn (the drawing takes most of the time: 0.3 s
    a PNG, vector files about twice that).
    """
    from tqdm.auto import tqdm

    bad = [f for f in formats if f not in FORMATS]
    if bad or not formats:
        raise ValueError(f"plot formats = {', '.join(formats) or 'none'}; allowed: one or more of {', '.join(FORMATS)}")
    folder = Path(folder)
    paths = []
    with style(), tqdm(total=len(figs), desc="plots", unit="figure", disable=not progress) as bar:
        for stem, fig in figs.items():
            bar.set_postfix_str(stem, refresh=False)
            for fmt in formats:
                path = folder / f"{stem}.{fmt}"
                fig.savefig(path, format=fmt, dpi=DPI)
                paths.append(path)
            bar.update()
    return paths
