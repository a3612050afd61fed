"""The identified parameters as tables in the thesis' layout: Table 5.3 (dry and viscous
friction per joint type, legs as columns, mean and standard deviation over the campaigns),
Table 5.4 (breakaway of the vertical joints per load) and Table 5.5 (Eq. 5.12 coefficients),
plus the long table of every estimate with its confidence intervals.

Mean and standard deviation over n campaigns follow Eq. 5.8-5.9 (sample standard deviation,
n - 1); with one campaign the standard deviation is not defined and shown as "-".
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from hexadyn.identify.fit import Estimate
from hexadyn.identify.identification import Identification
from hexadyn.identify.logs import LEGS, UNITS

__all__ = ["mean_sigma", "table_5_3", "table_5_4", "table_5_5", "table_efficiency", "estimates", "markdown"]

def mean_sigma(values: list[float]) -> tuple[float, float]:
    """Eq. 5.8 and 5.9: the mean and the (n - 1) standard deviation (NaN for n < 2)."""
    x = np.asarray(values, dtype=float)
    if len(x) == 0:
        return float("nan"), float("nan")
    return float(x.mean()), float(x.std(ddof=1)) if len(x) > 1 else float("nan")


def _leg_columns() -> pd.MultiIndex:
    return pd.MultiIndex.from_product([[f"leg {leg}" for leg in LEGS], ["mu", "sigma"]])


def table_5_3(ident: Identification, joint: str) -> pd.DataFrame:
    """Rows tau_f,d^+, f_v^+, tau_f,d^-, f_v^- of `joint` (unloaded), columns (leg, mu/sigma)."""
    dry, viscous = UNITS[ident.kinds[joint]]
    rows = {}
    for direction, sign in ((1, "+"), (-1, "-")):
        for name, unit, attr in ((f"tau_f,d^{sign} ({dry})", dry, "tau_f_d"), (f"f_v^{sign} ({viscous})", viscous, "f_v")):
            rows[name] = [x for leg in LEGS for x in mean_sigma([getattr(f, attr).value for f in ident.unloaded(joint, leg, direction)])]
    return pd.DataFrame.from_dict(rows, orient="index", columns=_leg_columns())


def table_5_4(ident: Identification) -> pd.DataFrame:
    """Rows (load, tau_f,s^+/-) in N, columns (leg, mu/sigma)."""
    rows = {}
    for load in sorted({b.load_kg for b in ident.breakaways}):
        for direction, sign in ((1, "+"), (-1, "-")):
            rows[f"{load:g} kg: tau_f,s^{sign} (N)"] = [
                x for leg in LEGS for x in mean_sigma([b.tau_f_s for b in ident.breakaways if b.leg == leg and b.direction == direction and b.load_kg == load and not b.reason])
            ]
    return pd.DataFrame.from_dict(rows, orient="index", columns=_leg_columns())


def table_5_5(ident: Identification) -> pd.DataFrame:
    """Rows a_2^+, a_2^-, a_1^+, a_1^- (N/kg^2, N/kg), columns (leg, value/stderr): one fit
    over all the loaded campaigns per leg and direction."""
    columns = pd.MultiIndex.from_product([[f"leg {leg}" for leg in LEGS], ["value", "stderr"]])
    rows = {}
    for name, attr, unit in (("a_2", "a_2", "N/kg^2"), ("a_1", "a_1", "N/kg")):
        for direction, sign in ((1, "+"), (-1, "-")):
            row = []
            for leg in LEGS:
                fit = next((f for f in ident.load_fits if f.leg == leg and f.direction == direction), None)
                e: Estimate | None = getattr(fit, attr) if fit else None
                row += [e.value, e.stderr] if e else [np.nan, np.nan]
            rows[f"{name}^{sign} ({unit})"] = row
    return pd.DataFrame.from_dict(rows, orient="index", columns=columns)


def table_efficiency(ident: Identification, joint: str) -> pd.DataFrame:
    """Rows eta_f, eta_b and the no-load tau_f,d^+-, f_v^+- of the efficiency law of `joint`
    (:mod:`hexadyn.identify.efficiency`), columns (leg, value/stderr): one fit over the loads
    per leg."""
    dry, viscous = UNITS[ident.kinds[joint]]
    columns = pd.MultiIndex.from_product([[f"leg {leg}" for leg in LEGS], ["value", "stderr"]])
    names = {"eta_forward": "eta_f", "eta_backward": "eta_b", "tau_f_d_plus": f"N: tau_f,d^+ ({dry})", "f_v_plus": f"N: f_v^+ ({viscous})", "tau_f_d_minus": f"N: tau_f,d^- ({dry})", "f_v_minus": f"N: f_v^- ({viscous})"}
    rows = {}
    for attr, name in names.items():
        row = []
        for leg in LEGS:
            fit = next((f for f in ident.efficiency_fits if f.joint == joint and f.leg == leg), None)
            e: Estimate | None = getattr(fit, attr) if fit else None
            row += [e.value, e.stderr] if e else [np.nan, np.nan]
        rows[name] = row
    return pd.DataFrame.from_dict(rows, orient="index", columns=columns)


def estimates(ident: Identification) -> pd.DataFrame:
    """Every estimate, one row each: source log, joint, leg, direction, load, parameter, value,
    standard error, the Jacobian and bootstrap confidence intervals (95 %)."""
    rows = []
    for source, f in ident.fits:
        for name, e in (("tau_f_d", f.tau_f_d), ("f_v", f.f_v)):
            rows.append(_row(source, f.joint, f.leg, f.direction, f.load_kg, name, e, f.points))
    for f in ident.load_fits:
        for name, e in (("a_2", f.a_2), ("a_1", f.a_1)):
            rows.append(_row("loaded logs", "q_h", f.leg, f.direction, float("nan"), name, e, len(f.loads_kg)))
    for f in ident.efficiency_fits:
        loads = "loaded logs " + ", ".join(f"{x:g}" for x in f.loads_kg) + " kg"
        for name, e in (("tau_f_d", f.tau_f_d_plus), ("f_v", f.f_v_plus)):
            rows.append(_row(loads, f.joint, f.leg, 1, float("nan"), f"{name} (no load, efficiency law)", e, f.points))
        for name, e in (("tau_f_d", f.tau_f_d_minus), ("f_v", f.f_v_minus)):
            rows.append(_row(loads, f.joint, f.leg, -1, float("nan"), f"{name} (no load, efficiency law)", e, f.points))
        for name, e in (("eta_forward", f.eta_forward), ("eta_backward", f.eta_backward)):
            if e is not None:
                rows.append(_row(loads, f.joint, f.leg, 0, float("nan"), name, e, f.points))
    for b in ident.breakaways:
        nan = float("nan")
        rows.append(_row(b.source, b.joint, b.leg, b.direction, b.load_kg, "tau_f_s", Estimate(b.tau_f_s, nan, nan, nan, nan, nan), 0 if b.reason else 1) | {"note": b.reason})
    return pd.DataFrame(rows)


def _row(source, joint, leg, direction, load, name, e: Estimate, points) -> dict:
    return {
        "source": source,
        "joint": joint,
        "leg": leg,
        "direction": {1: "plus", -1: "minus"}.get(direction, "both"),
        "load_kg": load,
        "parameter": name,
        "value": e.value,
        "stderr": e.stderr,
        "ci95_low": e.ci_low,
        "ci95_high": e.ci_high,
        "bootstrap95_low": e.boot_low,
        "bootstrap95_high": e.boot_high,
        "points": points,
    }


def markdown(table: pd.DataFrame, title: str, digits: int = 1) -> str:
    """A table as GitHub Markdown with a caption line; NaN shows as "-"."""
    header = ["", *[" ".join(map(str, c)) if isinstance(c, tuple) else str(c) for c in table.columns]]
    lines = [f"{title}", "", "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for name, row in table.iterrows():
        cells = ["-" if pd.isna(v) else f"{v:.{digits}f}" for v in row]
        lines.append("| " + " | ".join([str(name), *cells]) + " |")
    return "\n".join(lines) + "\n"
