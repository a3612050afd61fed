"""The transmission efficiencies of the efficiency-based friction (the thesis' second prospect,
Chapter 8: "efficiency of transmission naturally accounts for the load acting on it ... the
tedious identification of friction with different load conditions could be avoided"), from
the same sawtooth logs at several foot loads as Section 5.4.

The law (``physics/friction.rs``, ``Efficiency``): the friction is the no-load friction N(q')
of Eq. 6.1 plus a loss proportional to the torque the transmission carries beyond it,
e = tau_m - N. In a constant-velocity section the joint passes on what the leg and its load
need, tau_n = tau_m - tau_f (gravity, foot load, the window's inertia: Eq. 5.7 and 5.14), so
that

- forward (the motor drives the load, tau_n q' > 0): tau_m = N(q') + tau_n / eta_f;
- backward (the load drives the motor, tau_n q' < 0): tau_m = N(q') + eta_b tau_n.

Per joint and leg, every section of every load is one point (q', tau_m, tau_n), and the
linear model tau_m = tau_f,d^+- + f_v^+- q' + c_f tau_n[forward] + c_b tau_n[backward] (a dry
friction and a viscous slope per sense, as Table 5.3) is fitted by least squares
(:func:`hexadyn.identify.fit.fit_linear`): eta_f = 1 / c_f and eta_b = c_b, with N the
no-load friction of the law. The loads must set tau_n apart from the dry friction: two loads
at least (the unloaded campaign counts, its tau_n is the leg's own gravity). A branch no
section of the joint falls in (the load never drives the motor, say) leaves its efficiency
undetermined (None).

Unlike Eq. 5.12, which fits the unloaded dry friction and its growth with the load apart, the
no-load N here comes out of the same fit: on a vertical joint even the unloaded sections carry
the leg's weight, and their dry friction holds its loss.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexadyn.identify.fit import Estimate, fit_linear
from hexadyn.identify.steady import SectionPoint

__all__ = ["EfficiencyFit", "fit_efficiency", "EFFICIENCY_KEYS"]

#: Fragment key (docs/scenario-format.md, "Joint friction models") -> attribute of the fit.
EFFICIENCY_KEYS = {
    "tau_f_d_plus": "tau_f_d_plus",
    "f_v_plus": "f_v_plus",
    "tau_f_d_minus": "tau_f_d_minus",
    "f_v_minus": "f_v_minus",
    "eta_forward": "eta_forward",
    "eta_backward": "eta_backward",
}


@dataclass(frozen=True)
class EfficiencyFit:
    """The efficiency law of one joint of one leg: the no-load friction N (Eq. 6.1) and the
    forward and backward efficiencies (None where no section falls in the branch)."""

    joint: str
    leg: int
    tau_f_d_plus: Estimate
    f_v_plus: Estimate
    tau_f_d_minus: Estimate
    f_v_minus: Estimate
    eta_forward: Estimate | None
    eta_backward: Estimate | None
    loads_kg: tuple[float, ...]
    points: int


def fit_efficiency(points: list[SectionPoint], seed: int = 0) -> EfficiencyFit | None:
    """The law through the sections of one joint and leg (every load, both senses); None when
    they do not determine it (fewer than two loads, a sense without sections at two
    velocities, or no branch the loads set apart)."""
    loads = sorted({p.load_kg for p in points})
    if len(loads) < 2:
        return None
    v = np.array([p.velocity for p in points])
    tau_m = np.array([p.motor_torque for p in points])
    tau_n = tau_m - np.array([p.torque for p in points])
    plus = np.array([p.direction > 0 for p in points])
    forward = tau_n * v > 0
    columns = {
        "tau_f_d_plus": plus * 1.0,
        "f_v_plus": plus * v,
        "tau_f_d_minus": ~plus * 1.0,
        "f_v_minus": ~plus * v,
        "c_f": np.where(forward, tau_n, 0.0),
        "c_b": np.where(forward, 0.0, tau_n),
    }
    used = {name: x for name, x in columns.items() if np.any(x != 0.0)}
    if not {"tau_f_d_plus", "f_v_plus", "tau_f_d_minus", "f_v_minus"} <= set(used) or not {"c_f", "c_b"} & set(used):
        return None
    X = np.column_stack(list(used.values()))
    scaled = X / np.abs(X).max(axis=0)
    if len(points) <= X.shape[1] or np.linalg.matrix_rank(scaled, tol=1e-9) < X.shape[1]:
        return None
    fitted = dict(zip(used, fit_linear(X, tau_m, seed)))
    p0 = points[0]
    return EfficiencyFit(
        p0.joint,
        p0.leg,
        fitted["tau_f_d_plus"],
        fitted["f_v_plus"],
        fitted["tau_f_d_minus"],
        fitted["f_v_minus"],
        _reciprocal(fitted["c_f"]) if "c_f" in fitted else None,
        fitted.get("c_b"),
        tuple(loads),
        len(points),
    )


def _reciprocal(c: Estimate) -> Estimate:
    """eta_f = 1 / c_f: the standard error to first order (se / c^2), the intervals' ends
    mapped (1/x decreases: the ends swap; an interval through zero leaves them undetermined)."""

    def ends(low: float, high: float) -> tuple[float, float]:
        if not low * high > 0:
            return float("nan"), float("nan")
        return 1.0 / high, 1.0 / low

    return Estimate(1.0 / c.value, c.stderr / c.value**2, *ends(c.ci_low, c.ci_high), *ends(c.boot_low, c.boot_high))
