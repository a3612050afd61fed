"""Power and energy of the actuators, specific resistance (thesis Section 6.4, Eq. 6.6-6.11).

Everything here is computed from a :class:`~hexadyn.results.Results` and returned as pandas
objects; nothing is simulated.

Sampling convention. Row k of the time series is the control instant t_k. Its electrical
columns (``u_*``, ``i_*``) belong to the control period (t_{k-1}, t_k] ending at t_k, during
which the voltage u_k commanded by the controller at t_{k-1} was held; the foot phase
``phase[l]`` of row k is the one the gait controller computed at t_k, i.e. the phase of the
*next* period. Hence the power of period k is attributed to the phase of row k-1: the phase in
which the controller commanded that period's voltage. The first row (t_0, no period before it)
carries no power.

Power. The power of actuator j over period k is the mean electrical power of Eq. 6.7 over that
period, P_k = (E_el(t_k) - E_el(t_{k-1})) / Δt, from the engine's cumulative ``E_el_*`` columns
(∫ u i dt integrated at every integration step). With u held, P_k = u_k · mean(i) over the
period, so Σ_k P_k Δt = E_el exactly, whereas the product of the samples u_k i_k (what the
robot's current sensors give, :func:`sampled_power`) is Eq. 6.7 with one current sample per
period and differs from it by the variation of i within the period.

Energy breakdown of actuator j over the run (cumulative columns at the end minus the start):
electrical E_el = ∫ u i dt, Joule losses ∫ (R + R_bridge) i² dt in coil and H-bridge, friction
work ∫ τ_f q' dt and, with the inductance modelled (``model.inductance = true``), the change of
the magnetic energy ½ L i². What remains is the mechanical work done by the actuator on the
mechanism (legs and body), ∫ (τ_m - τ_f) q' dt:

    E_mech = E_el - E_joule - E_fric - Δ(½ L i²).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np
import pandas as pd

from hexadyn import _core
from hexadyn.vocabulary import LANDING, LEGS, SUPPORT, SWING, TAKEOFF, actuator, actuator_column, leg_column, phase_codes

if TYPE_CHECKING:
    from hexadyn.results import Results

#: Phase groups of the power tables: name -> phase codes. Transitions are takeoff and landing.
PHASE_GROUPS: dict[str, tuple[int, ...]] = {"support": (SUPPORT,), "swing": (SWING,), "transitions": (TAKEOFF, LANDING)}
#: Name of the whole-run group in the power tables.
ALL = "all"
TOTAL = "total"

__all__ = [
    "ALL",
    "PHASE_GROUPS",
    "TOTAL",
    "add_energy_figures",
    "averaged_power",
    "control_period",
    "energy_breakdown",
    "energy_figures",
    "fit_power_velocity",
    "foot_phases",
    "power",
    "robot_mass",
    "sampled_power",
    "specific_resistance",
    "specific_resistance_asymptote",
    "specific_resistance_fit",
]


def _columns(results: Results, quantity: str) -> list[str]:
    """The columns of an actuator quantity for every actuator: ``E_el_q_r[0]``, ..."""
    return [actuator_column(quantity, a) for a in results.joints.actuators]


def _require(frame: pd.DataFrame, columns: Sequence[str], what: str) -> None:
    missing = [c for c in columns if c not in frame.columns]
    if missing:
        raise ValueError(f"{what} needs the time-series columns {', '.join(missing[:3])}{' ...' if len(missing) > 3 else ''}, which these results lack")


def control_period(results: Results) -> float:
    """The control period Δt (s) of the results' time series; ValueError saying what is wrong
    with a time axis the analyses and the figures cannot use (a single instant, times not
    increasing by equal steps)."""
    return _period(results.timeseries.index)


def _period(t: pd.Index) -> float:
    """The control period Δt (s) of a time series with equally spaced instants."""
    steps = np.diff(t.to_numpy())
    if steps.size == 0:
        raise ValueError("the time series has a single instant: no control period to compute powers over")
    dt = float(np.median(steps))
    if not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"the time series' instants do not increase (median step {dt:g} s); allowed: times increasing by the control period")
    if not np.allclose(steps, dt, rtol=1e-6, atol=1e-12):
        raise ValueError(f"the time series is not equally spaced (steps from {steps.min():g} to {steps.max():g} s)")
    return dt


def power(results: Results) -> pd.DataFrame:
    """Mean electrical power of each actuator over each control period (W), Eq. 6.7.

    One row per control period, indexed by its end t_k (the first instant has no period and no
    row), one column per actuator (``q_r[0]``, ``q_v[0]``, ``q_h[0]``, ``q_r[1]``, ...):
    P_k = ΔE_el / Δt (see the module doc), so that ``(power(r) * Δt).sum()`` is the electrical
    energy of each actuator.
    """
    ts = results.timeseries
    columns = _columns(results, "E_el")
    _require(ts, columns, "the power")
    dt = _period(ts.index)
    p = np.diff(ts[columns].to_numpy(), axis=0) / dt
    return pd.DataFrame(p, index=ts.index[1:], columns=list(results.joints.actuators))


def sampled_power(results: Results) -> pd.DataFrame:
    """The product of the sampled voltage and current, u_k i_k (W), per actuator.

    Same rows as :func:`power`. Eq. 6.7 as the robot's sensors see it (one current sample per
    period); Σ u_k i_k Δt approximates E_el to the variation of the current within a period.
    """
    ts = results.timeseries
    _require(ts, _columns(results, "u") + _columns(results, "i"), "the sampled power")
    u = ts[_columns(results, "u")].to_numpy()
    i = ts[_columns(results, "i")].to_numpy()
    return pd.DataFrame((u * i)[1:], index=ts.index[1:], columns=list(results.joints.actuators))


def foot_phases(results: Results) -> pd.DataFrame | None:
    """The foot phase code of each leg during each control period, or None without a gait.

    Same rows as :func:`power`; column l is the phase of leg l in which the controller
    commanded the period's voltage (``phase[l]`` of the previous row, see the module doc).
    ValueError naming the column if a value is not a phase code.
    """
    ts = results.timeseries
    columns = [leg_column("phase", leg) for leg in LEGS]
    if not all(c in ts.columns for c in columns):
        return None
    codes = phase_codes(ts[columns].to_numpy()[:-1], columns, ts.index).astype(int)
    return pd.DataFrame(codes, index=ts.index[1:], columns=list(LEGS))


def averaged_power(results: Results) -> pd.DataFrame:
    """Averaged power per leg and joint type, split by foot phase (W): Tables 6.3-6.6.

    Rows: a MultiIndex (phase, leg) with phase ``"all"`` then, in walking scenarios,
    ``"support"``, ``"swing"`` and ``"transitions"`` (takeoff + landing), and leg 0..5 then
    ``"total"``. Columns: ``q_r``, ``q_v``, ``q_h`` and ``total``. A phase entry is the energy
    the actuator drew while its foot was in that phase divided by the duration of the run, so
    that the three phase blocks add up to ``"all"``; divide by the time spent in the phase for
    the mean power during the phase. ``table.loc["all"]`` is the layout of Tables 6.3-6.6.
    """
    p = power(results)
    joints = results.joints.names
    dt = _period(results.timeseries.index)
    duration = dt * len(p)
    phases = foot_phases(results)
    groups: dict[str, tuple[int, ...] | None] = {ALL: None}
    if phases is not None:
        groups.update(PHASE_GROUPS)
    blocks = {}
    for name, codes in groups.items():
        rows = {}
        for leg in LEGS:
            mask = slice(None) if codes is None or phases is None else phases[leg].isin(codes).to_numpy()
            rows[leg] = [p[actuator(j, leg)].to_numpy()[mask].sum() * dt / duration for j in joints]
        block = pd.DataFrame.from_dict(rows, orient="index", columns=list(joints))
        block.loc[TOTAL] = block.sum()
        block[TOTAL] = block.sum(axis=1)
        blocks[name] = block
    table = pd.concat(blocks, names=["phase", "leg"])
    table.columns.name = "joint"
    return table


def _robot_properties(results: Results) -> dict[str, float]:
    """Mass and motor inductance of the robot description stored with the results, as the
    engine reads it (``_core.robot_properties``)."""
    return _core.robot_properties(results.metadata.get("robot", ""), "the robot description stored with these results")


def _magnetic_energy_change(results: Results) -> np.ndarray:
    """Δ(½ L i²) per actuator (J), non-zero only if the scenario models the inductance
    (``[model] inductance = true``, Eq. 3.91)."""
    if not _models_inductance(results):
        return np.zeros(len(results.joints.actuators))
    inductance = np.tile(_robot_properties(results)["inductance_h"], len(LEGS))
    i = results.endpoints()[_columns(results, "i")].to_numpy()
    return 0.5 * inductance * (i[-1] ** 2 - i[0] ** 2)


def _models_inductance(results: Results) -> bool:
    """``[model] inductance`` as the engine read it (``metadata["model"]``); results saved
    before the engine reported it are read by the engine from their stored scenario text."""
    model = results.metadata.get("model")
    if isinstance(model, dict) and "inductance" in model:
        return bool(model["inductance"])
    return bool(_core.scenario_model(results.metadata.get("scenario", ""), "the scenario stored with these results")["inductance"])


def energy_breakdown(results: Results) -> pd.DataFrame:
    """Energy breakdown of each actuator over the run (J).

    One row per actuator (index ``q_r[0]``, ``q_v[0]``, ...), columns ``leg``, ``joint``,
    ``electrical_j`` (Eq. 6.7), ``joule_j``, ``friction_j``, ``magnetic_j`` (Δ½ L i², zero
    without inductance) and ``mechanical_j`` = electrical - joule - friction - magnetic, the
    work done on the mechanism (see the module doc). Mechanical work may be negative: the
    mechanism then drives the motor (e.g. a vertical joint lowering the body).
    """
    ends = results.endpoints()
    kinds = {"electrical_j": "E_el", "joule_j": "E_joule", "friction_j": "E_fric"}
    _require(ends, [c for quantity in kinds.values() for c in _columns(results, quantity)], "the energy breakdown")
    first, last = ends.iloc[0], ends.iloc[-1]
    joints = results.joints
    table = pd.DataFrame(index=pd.Index(joints.actuators, name="actuator"))
    table["leg"] = [leg for leg in LEGS for _ in joints.names]
    table["joint"] = list(joints.names) * len(LEGS)
    for key, quantity in kinds.items():
        cols = _columns(results, quantity)
        table[key] = last[cols].to_numpy() - first[cols].to_numpy()
    table["magnetic_j"] = _magnetic_energy_change(results)
    table["mechanical_j"] = table["electrical_j"] - table["joule_j"] - table["friction_j"] - table["magnetic_j"]
    return table


def robot_mass(results: Results) -> float:
    """The robot mass m (kg) of Eq. 6.6.

    ``robot_mass_kg`` of the summary when the engine reports it (m_0 + 6 m_leg), otherwise
    the total mass stated in the robot description the results were computed with
    (``inertia.total_mass_kg``, Table B.2, as the engine reads it): the m of results saved
    before the engine reported its mass.
    """
    if "robot_mass_kg" in results.summary:
        return float(results.summary["robot_mass_kg"])
    try:
        return _robot_properties(results)["stated_mass_kg"]
    except ValueError as exc:
        raise ValueError(f"the summary of these results has no robot_mass_kg, and their robot description gives no inertia.total_mass_kg: {exc}") from None


def specific_resistance(energy_j: float, mass_kg: float, distance_m: float) -> float:
    """Specific resistance ξ = E / (m g l), Eq. 6.6 (dimensionless): the engine's formula
    (``_core.specific_resistance``, that of the summary's ``specific_resistance``).

    Args:
        energy_j: total energy E expended, e.g. the electrical energy of Eq. 6.7 (J).
        mass_kg: vehicle mass m (kg), positive.
        distance_m: distance l travelled (m), positive.
    """
    if not mass_kg > 0:
        raise ValueError(f"specific resistance: mass = {mass_kg} kg; allowed: > 0")
    if not distance_m > 0:
        raise ValueError(f"specific resistance: distance = {distance_m} m; allowed: > 0 (the robot must travel)")
    return _core.specific_resistance(energy_j, mass_kg, distance_m)


def fit_power_velocity(velocity_m_s: Sequence[float], power_w: Sequence[float]) -> tuple[float, float]:
    """Least-squares fit of P = α + β V_x, Eq. 6.8; returns (α in W, β in W s/m = N).

    α is read as the pure losses of the vehicle and β V_x as the power needed to propel it.
    Needs at least two distinct velocities.
    """
    v = np.asarray(velocity_m_s, dtype=float)
    p = np.asarray(power_w, dtype=float)
    if v.shape != p.shape or v.ndim != 1:
        raise ValueError(f"power fit: {v.size} velocities and {p.size} powers; allowed: two 1-D sequences of the same length")
    if np.unique(v).size < 2:
        raise ValueError(f"power fit: velocities {v.tolist()}; allowed: at least two distinct velocities")
    if not (np.isfinite(v).all() and np.isfinite(p).all()):
        raise ValueError("power fit: velocities and powers must be finite")
    a = np.column_stack([np.ones_like(v), v])
    (alpha, beta), *_ = np.linalg.lstsq(a, p, rcond=None)
    return float(alpha), float(beta)


def specific_resistance_fit(alpha_w: float, beta_n: float, mass_kg: float, velocity_m_s: Any) -> Any:
    """ξ(V) = α / (m g V) + β / (m g), Eq. 6.11, for a velocity or an array of velocities (m/s).

    That is Eq. 6.6 for the power P = α + β V of Eq. 6.8: the energy P T over the distance V T.
    """
    v = np.asarray(velocity_m_s, dtype=float)
    if (v <= 0).any():
        raise ValueError("specific resistance: velocities must be positive")
    xi = np.vectorize(lambda x: specific_resistance(alpha_w + beta_n * x, mass_kg, x), otypes=[float])(v)
    return float(xi) if xi.ndim == 0 else xi


def specific_resistance_asymptote(beta_n: float, mass_kg: float) -> float:
    """ξ(V → ∞) = β / (m g) of Eq. 6.11: Eq. 6.6 for the propulsion force β alone, whose work
    over a distance l is β l."""
    return specific_resistance(beta_n, mass_kg, 1.0)


def energy_figures(results: Results) -> dict[str, float]:
    """Key figures of the power analysis, for the summary (summary.json).

    ``average_power_w`` (total electrical energy over the duration), ``energy_mechanical_j``
    (Σ of the breakdown's mechanical work), ``friction_share`` (friction work over the
    electrical energy, Σ E_fric / Σ E_el), ``joule_share``, ``robot_mass_kg`` (the m used, see
    :func:`robot_mass`) and, when the robot walked, ``specific_resistance`` ξ of Eq. 6.6 with
    E = Σ E_el (Eq. 6.7) and l = ``distance_walked_m``. :func:`add_energy_figures` adds those
    the engine's summary does not already hold.
    """
    b = energy_breakdown(results)
    e_el = float(b["electrical_j"].sum())
    t = results.endpoints().index
    duration = float(t[-1] - t[0])
    mass = robot_mass(results)
    figures = {
        # A run stopped at its first instant (a safety stop of `hexadyn robot run`) has no duration.
        "average_power_w": e_el / duration if duration > 0 else math.nan,
        "energy_mechanical_j": float(b["mechanical_j"].sum()),
        "friction_share": float(b["friction_j"].sum()) / e_el if e_el else math.nan,
        "joule_share": float(b["joule_j"].sum()) / e_el if e_el else math.nan,
        "robot_mass_kg": mass,
    }
    distance = results.summary.get("distance_walked_m")
    if distance is not None and distance > 0:
        figures["specific_resistance"] = specific_resistance(e_el, mass, float(distance))
    return figures


def add_energy_figures(results: Results) -> None:
    """Adds to ``results.summary`` the figures of :func:`energy_figures` it does not hold yet
    (the engine's own ``robot_mass_kg``, ``average_power_w`` and ``specific_resistance`` win).
    :func:`hexadyn.simulate` calls it on every run."""
    for key, value in energy_figures(results).items():
        results.summary.setdefault(key, value)
