"""The steady-state friction curve of Section 5.2 (Eq. 5.3-5.4, Table 5.3) and its load
dependence (Section 5.4, Eq. 5.12, Table 5.5), from sawtooth logs.

Per section (:mod:`hexadyn.identify.sections`): the mean friction torque over the averaging
window (:func:`hexadyn.identify.torques.friction_torque`) against the section's velocity. Per
joint and direction, the line tau = tau_f,d + f_v q' is fitted through the sections (f_v is a
slope in both directions, as in Table 5.3 and the scenario files). With a load at the foot the
same line is fitted per load; its intercept is the loaded dry friction tilde tau_f,d(x), and
tilde tau_f,d(x) - a_0 = a_2 x^2 + a_1 x is fitted over the loads with a_0 the unloaded dry
friction (Eq. 5.12).

INTERPRETATION: under load the thesis fits only the dry friction ("viscous coefficient has been
identified very low"); fitting the line and keeping its intercept gives the same dry friction
when f_v = 0 and stays unbiased when it is not.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexadyn.identify.fit import Estimate, fit_linear
from hexadyn.identify.logs import Log
from hexadyn.identify.sections import SectionOptions, find_sections
from hexadyn.identify.torques import friction_torque, joint_constants

__all__ = ["SectionPoint", "section_points", "DryViscousFit", "fit_dry_viscous", "LoadFit", "fit_load"]

DIRECTIONS = {1: "plus", -1: "minus"}


@dataclass(frozen=True)
class SectionPoint:
    """One point of a friction/velocity curve (Fig. 5.3-5.5)."""

    source: str
    joint: str
    leg: int
    direction: int
    load_kg: float
    velocity: float
    torque: float
    t_start: float
    t_stop: float
    #: The mean motor torque n k_t i (Eq. 5.17) over the section's window; ``motor_torque -
    #: torque`` is what the leg and its load need (the transmitted torque of the efficiency fit).
    motor_torque: float


def section_points(log: Log, joint: str, leg: int, options: SectionOptions) -> list[SectionPoint]:
    """The (velocity, mean friction torque) of every complete section of the joint's log."""
    t = log.t
    where = f"{log.source}: {joint}[{leg}]"
    sections = find_sections(t, log.position(joint, leg), options, where)
    points = []
    torque_per_ampere = joint_constants(log, joint, leg)["torque_per_ampere"]
    for s in sections:
        mean = float(np.mean(friction_torque(log, joint, leg, s.window, s.velocity, s.acceleration)))
        motor = torque_per_ampere * float(np.mean(log.current(joint, leg)[s.window]))
        points.append(SectionPoint(log.source, joint, leg, s.direction, log.foot_load_kg[leg], s.velocity, mean, float(t[s.start]), float(t[s.stop - 1]), motor))
    return points


@dataclass(frozen=True)
class DryViscousFit:
    """tau_f,d and f_v of one joint and direction (Eq. 5.3-5.4 with the line of Eq. 6.1)."""

    joint: str
    leg: int
    direction: int
    load_kg: float
    tau_f_d: Estimate
    f_v: Estimate
    points: int


def fit_dry_viscous(points: list[SectionPoint], seed: int = 0) -> DryViscousFit:
    """The line through the points of one joint, direction and load."""
    p0 = points[0]
    v = np.array([p.velocity for p in points])
    tau = np.array([p.torque for p in points])
    if len(points) < 2 or np.ptp(v) <= 1e-6 * np.max(np.abs(v)):
        raise ValueError(f"{p0.source}: {p0.joint}[{p0.leg}] {DIRECTIONS[p0.direction]}: {len(points)} section(s) at one velocity; a dry/viscous line needs sections at two velocities at least")
    tau_f_d, f_v = fit_linear(np.column_stack([np.ones_like(v), v]), tau, seed)
    return DryViscousFit(p0.joint, p0.leg, p0.direction, p0.load_kg, tau_f_d, f_v, len(points))


@dataclass(frozen=True)
class LoadFit:
    """a_2, a_1 of Eq. 5.12 for one horizontal joint and direction, with a_0 used."""

    leg: int
    direction: int
    a_0: float
    a_2: Estimate
    a_1: Estimate
    loads_kg: tuple[float, ...]


def fit_load(unloaded: float, loaded: list[DryViscousFit], seed: int = 0) -> LoadFit:
    """Eq. 5.12 through the loaded dry frictions, a_0 = `unloaded`."""
    x = np.array([f.load_kg for f in loaded])
    y = np.array([f.tau_f_d.value for f in loaded]) - unloaded
    a_2, a_1 = fit_linear(np.column_stack([x**2, x]), y, seed)
    return LoadFit(loaded[0].leg, loaded[0].direction, unloaded, a_2, a_1, tuple(sorted(x.tolist())))
