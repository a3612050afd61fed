"""Friction-model comparison of the validation walk (thesis Section 6.4, Tables 6.3-6.6 and
Fig. 6.19).

One scenario (by default the validation case of Table 6.2) is run with each friction model of
:data:`MODELS` (no friction, dry/viscous Eq. 6.1, LuGre, dry/viscous with the load dependence of
the horizontal joints Eq. 5.12, and the transmission-efficiency law of the thesis' prospects,
Chapter 8) at each velocity V_x, in parallel on the local cores. The
scenario fields are changed through the overrides of :func:`hexadyn.simulate`; the step period
and the number of steps stay those of the scenario, so the step length grows with V_x as in
Section 6.3.

Outputs (:func:`compare_friction`, written atomically by :func:`save`):

- ``power_by_model.csv``: averaged power per leg and joint type for every velocity and model;
  :func:`joint_tables` turns it into the layout of Tables 6.3-6.6 (one table per joint type,
  rows legs 0-5 and total, one column per model);
- ``robot_power.csv``: per velocity and model the averaged robot power, the electrical and
  friction energies, the distance walked, the specific resistance ξ (Eq. 6.6), the friction
  share (friction work over electrical energy), the failed health checks of the run
  (``warnings``, :func:`hexadyn.health.check`, separated by ``; ``, empty for a healthy run) and
  the share of the power due to friction (1 - P_none / P_model, Section 6.6: "more than 80 %");
- ``fit.csv``: per model α and β of P = α + β V_x (Eq. 6.8) and the asymptote β / (m g) of ξ;
- ``plots/``: Fig. 6.19 (a) power and (b) specific resistance versus velocity with the fits,
  and the averaged power per actuator and model (Tables 6.3-6.6 as bar charts).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from hexadyn import atomic, energy, plots
from hexadyn.montecarlo.execution import ProcessPool
from hexadyn.report import write_csv
from hexadyn.runner import resolve_scenario, simulate
from hexadyn.vocabulary import LEGS

#: Friction models of the comparison: name -> scenario overrides (Section 6.1 and 6.4.4).
MODELS: dict[str, dict[str, Any]] = {
    "none": {"model.friction": "none", "model.load_dependence": False},
    "dry_viscous": {"model.friction": "dry_viscous", "model.load_dependence": False},
    "lugre": {"model.friction": "lugre", "model.load_dependence": False},
    "dry_viscous_load": {"model.friction": "dry_viscous", "model.load_dependence": True},
    "efficiency": {"model.friction": "efficiency", "model.load_dependence": False},
}
#: Legend labels of the models.
MODEL_LABELS = {
    "none": "no friction",
    "dry_viscous": "dry/viscous",
    "lugre": "LuGre",
    "dry_viscous_load": "dry/viscous + load",
    "efficiency": "efficiency",
}
#: Colour and marker of each model in every figure.
MODEL_COLOURS = {"none": "#1f4e79", "dry_viscous": "#c0392b", "lugre": "#2e8b57", "dry_viscous_load": "#e67e22", "efficiency": "#7d3c98"}
MODEL_MARKERS = {"none": "o", "dry_viscous": "s", "lugre": "^", "dry_viscous_load": "D", "efficiency": "v"}
#: Velocities V_x of Table 6.2 and Fig. 6.19 (m/s).
DEFAULT_VELOCITIES = (0.01, 0.015, 0.02, 0.025)
#: Scenario field of the forward velocity.
VELOCITY_FIELD = "gait.heading.vx_m_s"
#: Columns of the fit table (no rows with a single velocity: the fit needs two).
FIT_COLUMNS = ("alpha_w", "beta_n", "xi_asymptote", "mass_kg")
#: Separates the failed health checks of a run in the ``warnings`` column.
WARNING_SEPARATOR = "; "
POWER_FILE = "power_by_model.csv"
ROBOT_FILE = "robot_power.csv"
FIT_FILE = "fit.csv"

__all__ = [
    "DEFAULT_VELOCITIES",
    "MODELS",
    "Comparison",
    "compare_friction",
    "figures",
    "joint_tables",
    "save",
    "warning_lines",
]


@dataclass
class Comparison:
    """The tables of a friction-model comparison (see the module doc for the columns)."""

    scenario: str
    #: Averaged power per (velocity_m_s, model, leg) and joint type q_r, q_v, q_h, total (W).
    power: pd.DataFrame
    #: One row per (velocity_m_s, model): robot power, energies, distance, ξ, friction shares,
    #: the run's failed health checks (``warnings``).
    robot: pd.DataFrame
    #: One row per model: alpha_w, beta_n, xi_asymptote (β / (m g)), mass_kg.
    fit: pd.DataFrame
    #: The velocity of the Tables 6.3-6.6 layout (m/s).
    table_velocity: float


def _overrides(scenario: Path, base: Mapping[str, Any], model: str, velocity: float) -> dict[str, Any]:
    """The fields of one run: the caller's `base` fields, then the model's and the velocity."""
    return {**base, **MODELS[model], VELOCITY_FIELD: velocity, "scenario.name": f"{scenario.stem}_{model}_{velocity * 100:g}cm"}


def _validate(scenario: Path, base: Mapping[str, Any], runs: Sequence[tuple[str, float]]) -> None:
    """Checks the scenario and every run without simulating."""
    from hexadyn import _core

    gait = _core.load_scenario(os.fspath(scenario), dict(base) or None)["gait"]
    if gait is None or gait["heading"] != "constant":
        raise ValueError(f"{scenario}: the friction comparison needs a walking scenario with a constant heading ([control] mode = \"gait\", [gait.heading] kind = \"constant\")")
    for model, velocity in runs:
        try:
            _core.load_scenario(os.fspath(scenario), _overrides(scenario, base, model, velocity))
        except ValueError as exc:
            raise ValueError(f"friction model {model}, V_x = {velocity:g} m/s: {exc}") from None


def _run(scenario: str, base: Mapping[str, Any], model: str, velocity: float) -> dict[str, Any]:
    """One run (in a worker process): its averaged power table and robot figures."""
    try:
        results = simulate(scenario, progress=False, overrides=_overrides(Path(scenario), base, model, velocity))
    except ValueError as exc:
        raise ValueError(f"friction model {model}, V_x = {velocity:g} m/s: {exc}") from None
    s = results.summary
    return {
        "model": model,
        "velocity_m_s": velocity,
        "power": energy.averaged_power(results).loc[energy.ALL],
        "robot": {
            "average_power_w": s["average_power_w"],
            "energy_electrical_j": s["energy_electrical_j"],
            "energy_friction_j": s["energy_friction_j"],
            "distance_m": s["distance_walked_m"],
            "duration_s": s["duration_s"],
            "mass_kg": s["robot_mass_kg"],
            "specific_resistance": s.get("specific_resistance", np.nan),
            "friction_share": s["friction_share"],
            "warnings": WARNING_SEPARATOR.join(s["warnings"]),
        },
    }


def _run_task(task: tuple[str, Mapping[str, Any], str, float]) -> dict[str, Any]:
    """:func:`_run` of one (scenario, fields, model, velocity) task of the process pool."""
    return _run(*task)


def compare_friction(
    scenario: str | os.PathLike,
    velocities: Sequence[float] = DEFAULT_VELOCITIES,
    *,
    models: Sequence[str] = tuple(MODELS),
    workers: int | None = None,
    progress: bool | Callable[[int, int], object] = True,
    overrides: Mapping[str, Any] | None = None,
) -> Comparison:
    """Runs `scenario` with every friction model at every velocity (m/s) and tabulates them.

    Args:
        scenario: a walking scenario file or shipped scenario name (constant heading).
        velocities: forward velocities V_x (m/s); the fit (``fit``) needs two distinct ones and is
            empty with a single velocity.
        models: names among :data:`MODELS`.
        workers: worker processes (default: the number of CPUs, at most the number of runs).
        progress: a tqdm bar over the runs (True), none (False), or ``progress(done, total)``.
        overrides: scenario fields set on every run, by dotted name (the ``overrides=`` of
            :func:`hexadyn.simulate`); the model's fields, the velocity and the name of a run
            are set over them.

    Raises ValueError naming the model, the velocity and the field for a run the scenario
    cannot take (e.g. a velocity whose stride does not fit the workspace).
    """
    path = resolve_scenario(scenario)
    velocities = _check_velocities(velocities)
    unknown = [m for m in models if m not in MODELS]
    if unknown or not models:
        raise ValueError(f"friction models {', '.join(map(str, unknown)) or 'none given'}; allowed: {', '.join(MODELS)}")
    runs = [(m, v) for v in velocities for m in models]
    base = dict(overrides or {})
    _validate(path, base, runs)  # before any run starts
    outputs = []
    bar = _progress_bar(progress, len(runs))
    tasks = [(n, (os.fspath(path), base, m, v)) for n, (m, v) in enumerate(runs)]
    try:
        for _, output in ProcessPool(workers).capped(len(runs)).run(_run_task, tasks):
            outputs.append(output)
            bar(len(outputs))
    finally:
        bar(None)
    return _tabulate(Path(path).stem, outputs, velocities, list(models), _scenario_velocity(path, base))


def _check_velocities(velocities: Sequence[float]) -> list[float]:
    v = [float(x) for x in velocities]
    if not v or any(not (x > 0 and math.isfinite(x)) for x in v):
        raise ValueError(f"velocities {v}; allowed: positive velocities (m/s), at least two distinct ones for the fit of Eq. 6.8")
    return sorted(set(v))


def _scenario_velocity(path: Path, base: Mapping[str, Any]) -> float | None:
    """The scenario's own V_x (with the `base` fields), as the engine read it (None without a
    constant heading)."""
    from hexadyn import _core

    gait = _core.load_scenario(os.fspath(path), dict(base) or None)["gait"]
    return None if gait is None else gait["vx_m_s"]


def _progress_bar(progress: bool | Callable[[int, int], object], total: int) -> Callable[[int | None], object]:
    """A callback taking the number of finished runs (None when finished)."""
    if callable(progress):
        return lambda n: None if n is None else progress(n, total)
    if not progress:
        return lambda n: None
    from tqdm.auto import tqdm

    bar = tqdm(total=total, desc="friction models", unit="run")

    def update(n: int | None) -> None:
        if n is None:
            bar.close()
        else:
            bar.update(n - bar.n)

    return update


def _tabulate(name: str, outputs: list[dict], velocities: list[float], models: list[str], own_velocity: float | None) -> Comparison:
    order = {(v, m): k for k, (v, m) in enumerate((v, m) for v in velocities for m in models)}
    outputs = sorted(outputs, key=lambda o: order[(o["velocity_m_s"], o["model"])])
    power = pd.concat({(o["velocity_m_s"], o["model"]): o["power"] for o in outputs}, names=["velocity_m_s", "model", "leg"])
    robot = pd.DataFrame([o["robot"] for o in outputs], index=pd.MultiIndex.from_tuples([(o["velocity_m_s"], o["model"]) for o in outputs], names=["velocity_m_s", "model"]))
    if "none" in models:
        p_none = robot.xs("none", level="model")["average_power_w"]
        robot["friction_power_share"] = 1 - robot.index.get_level_values("velocity_m_s").map(p_none).to_numpy() / robot["average_power_w"].to_numpy()
    fit_rows = {}
    for m in models if len(velocities) >= 2 else ():  # the fit of Eq. 6.8 needs two velocities
        r = robot.xs(m, level="model")
        alpha, beta = energy.fit_power_velocity(r.index.to_numpy(), r["average_power_w"].to_numpy())
        mass = float(r["mass_kg"].iloc[0])
        fit_rows[m] = {"alpha_w": alpha, "beta_n": beta, "xi_asymptote": energy.specific_resistance_asymptote(beta, mass), "mass_kg": mass}
    fit = pd.DataFrame.from_dict(fit_rows, orient="index", columns=list(FIT_COLUMNS)).rename_axis("model")
    table_velocity = own_velocity if own_velocity in velocities else velocities[0]
    return Comparison(name, power, robot, fit, table_velocity)


def warning_lines(comparison: Comparison) -> list[str]:
    """The runs that failed a health check, one line each naming the model and the velocity
    (empty: every run healthy)."""
    robot = comparison.robot
    return [f"friction model {model}, V_x = {velocity:g} m/s: {warnings}" for (velocity, model), warnings in robot["warnings"].items() if warnings]


def joint_tables(comparison: Comparison, velocity: float | None = None) -> dict[str, pd.DataFrame]:
    """Tables 6.3-6.6: for each joint of the robot, the averaged power (W) per leg (rows 0-5, total)
    and friction model (columns), at `velocity` (default: the comparison's table velocity)."""
    v = comparison.table_velocity if velocity is None else velocity
    at = comparison.power.xs(v, level="velocity_m_s")
    joints = [j for j in at.columns if j != energy.TOTAL]
    return {j: at[j].unstack("model")[list(at.index.unique("model"))].rename_axis(index="leg", columns=None) for j in joints}


def figures(comparison: Comparison) -> dict[str, Figure]:
    """Fig. 6.19 (a) ``power_velocity`` and (b) ``specific_resistance`` with the α/β fits, and
    ``power_by_model``: the averaged power per actuator and model at the table velocity."""
    robot, fit = comparison.robot, comparison.fit
    models = list(robot.index.unique("model"))
    v_all = np.array(sorted(robot.index.unique("velocity_m_s")))
    v_line = np.linspace(v_all.min() * 0.9, v_all.max() * 1.05, 100)
    out = {}
    with plots.style():
        for stem, title, ylabel, value, curve in [
            ("power_velocity", "(a) averaged power, fit P = α + β V (Eq. 6.8)", "averaged robot power [W]", "average_power_w", lambda f, v: f.alpha_w + f.beta_n * v),
            ("specific_resistance", "(b) specific resistance, fit of Eq. 6.11", "specific resistance ξ [-]", "specific_resistance", lambda f, v: energy.specific_resistance_fit(f.alpha_w, f.beta_n, f.mass_kg, v)),
        ]:
            fig = Figure(figsize=(5.0, 3.6))
            ax = fig.subplots()
            for m in models:
                r = robot.xs(m, level="model")
                ax.plot(r.index.to_numpy() * 100, r[value], linestyle="none", marker=MODEL_MARKERS[m], color=MODEL_COLOURS[m], label=MODEL_LABELS[m])
                if m in fit.index:
                    ax.plot(v_line * 100, curve(fit.loc[m], v_line), color=MODEL_COLOURS[m], linewidth=0.8)
            ax.set_xlabel("velocity $V_x$ [cm/s]")
            ax.set_ylabel(ylabel)
            ax.legend(frameon=False)
            fig.suptitle(f"{comparison.scenario}\n{title}")
            out[stem] = fig
        tables = joint_tables(comparison)
        fig = Figure(figsize=(6.3, 6.0))
        axes = fig.subplots(3, 1, sharex=True)
        width = 0.8 / len(models)
        x = np.arange(len(LEGS))
        for ax, (joint, table) in zip(axes, tables.items()):
            for k, m in enumerate(models):
                ax.bar(x - 0.4 + width * (k + 0.5), table[m].loc[list(LEGS)].to_numpy(), width, color=MODEL_COLOURS[m], label=f"{MODEL_LABELS[m]} ({table.loc[energy.TOTAL, m]:.3g} W)")
            ax.set_ylim(top=ax.get_ylim()[1] * 1.4)  # room for the legend
            ax.legend(loc="upper left", title="model (total)", ncol=2, frameon=False)
            ax.set_ylabel(f"${joint}$ power [W]")
            ax.grid(axis="x", visible=False)
        axes[-1].set_xticks(x, [f"leg {leg}" for leg in LEGS])
        fig.suptitle(f"{comparison.scenario}: averaged power per actuator, $V_x$ = {comparison.table_velocity * 100:g} cm/s (Tables 6.3-6.6)")
        out["power_by_model"] = fig
    return out


def save(
    comparison: Comparison,
    folder: str | os.PathLike,
    *,
    overwrite: bool = False,
    formats: Sequence[str] = plots.DEFAULT_FORMATS,
    with_plots: bool = True,
    progress: bool = False,
) -> Path:
    """Writes the tables and (with `with_plots`) the figures of a comparison into `folder`,
    atomically; `progress`: a bar over the figures (:func:`hexadyn.plots.save_figures`)."""
    target = Path(folder)
    if not overwrite:
        atomic.refuse_existing(target, "comparison folder")
    figs = figures(comparison) if with_plots else {}

    def write(tmp: Path) -> None:
        write_csv(tmp / POWER_FILE, comparison.power)
        write_csv(tmp / ROBOT_FILE, comparison.robot)
        write_csv(tmp / FIT_FILE, comparison.fit)
        if figs:
            (tmp / "plots").mkdir()
            plots.save_figures(figs, tmp / "plots", formats, progress=progress)

    atomic.write_folder(target, write)
    return target
