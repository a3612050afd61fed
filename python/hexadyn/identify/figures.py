"""The friction/velocity curves of Fig. 5.3-5.5: per joint type, the mean friction torque of
every constant-velocity section against its velocity, one colour per leg, with the fitted
dry/viscous lines; (a) negative velocities, (b) positive ones, as in the thesis. Loaded logs
(Section 5.4) get one figure per load; the Eq. 5.12 fits their own (Fig. 5.10). AMRU5's joints
are drawn as the thesis' figures (``figure_5_4_q_v``); another robot's joints in the same
layout, named after the joint (``figure_friction_femur``).
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from hexadyn.identify.identification import Identification
from hexadyn.identify.logs import LEGS
from hexadyn.identify.tables import UNITS
from hexadyn.plots import style

__all__ = ["friction_figure", "load_figure", "efficiency_figure", "figures", "figure_stem", "FIGURE_NUMBERS"]

#: The thesis figure of each AMRU5 joint type.
FIGURE_NUMBERS = {"q_r": "5_3", "q_v": "5_4", "q_h": "5_5"}
_NAMES = {"q_r": "rotational", "q_v": "vertical", "q_h": "horizontal"}
#: Display scale of the velocities per joint kind: deg/s for q_r, mm/s for q_v and q_h (Table 5.2).
_SPEED = {"revolute": (180 / np.pi, "deg/s"), "prismatic": (1e3, "mm/s")}


def figure_stem(joint: str) -> str:
    """File stem of the friction figure of `joint` (unloaded legs)."""
    return f"figure_{FIGURE_NUMBERS[joint]}_{joint}" if joint in FIGURE_NUMBERS else f"figure_friction_{joint}"


def friction_figure(ident: Identification, joint: str, load_kg: float = 0.0) -> Figure:
    """Fig. 5.3 (q_r), 5.4 (q_v) or 5.5 (q_h): friction against velocity with the fitted lines.
    The lines are drawn in joint units per second of the fit (f_v in Nm s/rad or N s/m)."""
    kind = ident.kinds[joint]
    scale, speed_unit = _SPEED[kind]
    dry_unit = UNITS[kind][0]
    with style():
        fig = Figure(figsize=(6.5, 2.8))
        axes = fig.subplots(1, 2, sharey=False)
        for ax, direction, panel in ((axes[0], -1, "(a) negative velocities"), (axes[1], 1, "(b) positive velocities")):
            for leg in LEGS:
                pts = [p for p in ident.points if p.joint == joint and p.leg == leg and p.direction == direction and p.load_kg == load_kg]
                if not pts:
                    continue
                colour = f"C{leg}"
                v = np.array([p.velocity for p in pts])
                ax.plot(v * scale, [p.torque for p in pts], linestyle="none", marker="o", markersize=2.5, color=colour, label=f"leg {leg}")
                for _, f in ident.fits:
                    if f.joint == joint and f.leg == leg and f.direction == direction and f.load_kg == load_kg:
                        line = np.linspace(0.0, v.max() if direction > 0 else v.min(), 2)
                        ax.plot(line * scale, f.tau_f_d.value + f.f_v.value * line, color=colour, linewidth=0.7)
            ax.set_title(panel)
            ax.set_xlabel(f"velocity ({speed_unit})")
            ax.set_ylabel(f"friction ({dry_unit})")
        handles, labels = axes[1].get_legend_handles_labels()
        if not handles:
            handles, labels = axes[0].get_legend_handles_labels()
        if handles:
            fig.legend(handles, labels, loc="outside right center")
        load = "" if load_kg == 0 else f", {load_kg:g} kg at the foot"
        fig.suptitle(f"Friction model for {_NAMES.get(joint, joint)} joints ({'unloaded legs' if load_kg == 0 else 'loaded legs'}{load})")
    return fig


def load_figure(ident: Identification) -> Figure:
    """Fig. 5.10: loaded dry friction of the horizontal joints against the foot load, with the
    Eq. 5.12 polynomials."""
    with style():
        fig = Figure(figsize=(4.5, 3.0))
        ax = fig.subplots()
        for f in ident.load_fits:
            colour = f"C{f.leg}"
            dry = [(g.load_kg, g.tau_f_d.value) for _, g in ident.fits if g.joint == "q_h" and g.leg == f.leg and g.direction == f.direction]
            x, y = np.array(dry).T
            ax.plot(x, y, linestyle="none", marker="o" if f.direction > 0 else "s", markersize=3, color=colour, label=f"leg {f.leg}" if f.direction > 0 else None)
            xs = np.linspace(0.0, x.max(), 50)
            ax.plot(xs, f.a_2.value * xs**2 + f.a_1.value * xs + f.a_0, color=colour, linewidth=0.7)
        ax.set_xlabel("foot load (kg)")
        ax.set_ylabel("dry friction (N)")
        ax.set_title("Dry friction of the horizontal joints versus foot load (Eq. 5.12)")
        if ident.load_fits:
            ax.legend()
    return fig


def efficiency_figure(ident: Identification, joint: str) -> Figure:
    """The efficiency law of `joint` (:mod:`hexadyn.identify.efficiency`): per section the torque
    the transmission carries beyond the no-load friction, e = tau_m - N(q'), against what the
    leg and its load need, tau_n; the lines e = tau_n / eta_f (forward, the motor drives) and
    e = eta_b tau_n (backward, the load drives) of each leg's fit."""
    dry_unit = UNITS[ident.kinds[joint]][0]
    with style():
        fig = Figure(figsize=(4.5, 3.2))
        ax = fig.subplots()
        for f in (f for f in ident.efficiency_fits if f.joint == joint):
            colour = f"C{f.leg}"
            pts = [p for p in ident.points if p.joint == joint and p.leg == f.leg]
            tau_n = np.array([p.motor_torque - p.torque for p in pts])
            no_load = np.array([(f.tau_f_d_plus.value + f.f_v_plus.value * p.velocity) if p.direction > 0 else (f.tau_f_d_minus.value + f.f_v_minus.value * p.velocity) for p in pts])
            e = np.array([p.motor_torque for p in pts]) - no_load
            ax.plot(tau_n, e, linestyle="none", marker="o", markersize=2.5, color=colour, label=f"leg {f.leg}")
            for eta, forward in ((f.eta_forward, True), (f.eta_backward, False)):
                branch = tau_n[(tau_n * np.array([p.velocity for p in pts]) > 0) == forward]
                if eta is not None and len(branch):
                    x = np.array([branch.min(), branch.max()]) if np.ptp(branch) > 0 else np.array([0.0, branch[0]])
                    ax.plot(x, x / eta.value if forward else eta.value * x, color=colour, linewidth=0.7, linestyle="-" if forward else "--")
        ax.set_xlabel(f"needed by the leg and its load, tau_n ({dry_unit})")
        ax.set_ylabel(f"carried beyond no-load, e ({dry_unit})")
        ax.set_title(f"Transmission efficiency of {_NAMES.get(joint, joint)} joints (solid: forward, dashed: backward)", fontsize="small")
        ax.legend(fontsize="x-small")
    return fig


def figures(ident: Identification) -> dict[str, Figure]:
    """Every figure of an identification, by file stem."""
    out = {}
    for joint in ident.kinds:
        for load in sorted({p.load_kg for p in ident.points if p.joint == joint}):
            stem = figure_stem(joint) + ("" if load == 0 else f"_{load:g}kg")
            out[stem] = friction_figure(ident, joint, load)
    if ident.load_fits:
        out["figure_5_10_q_h_load"] = load_figure(ident)
    for joint in dict.fromkeys(f.joint for f in ident.efficiency_fits):
        out[f"figure_efficiency_{joint}"] = efficiency_figure(ident, joint)
    return out
