"""The identification of a set of logs: which experiment each joint of each log is, the fits of
Sections 5.2-5.4, and their statistics over campaigns (Eq. 5.8-5.9).

Every log is one measurement campaign of the joints it moved (the thesis repeated each campaign
five times): a sawtooth log gives one dry/viscous fit per joint, direction and foot load; a
voltage-ramp log one breakaway per joint. The tables give, per leg, the mean and the standard
deviation of these over the campaigns.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Iterable

import numpy as np

from hexadyn.identify.breakaway import Breakaway, BreakawayOptions, breakaway
from hexadyn.identify.checks import check_friction_sign
from hexadyn.identify.efficiency import EfficiencyFit, fit_efficiency
from hexadyn.identify.logs import LEGS, UNITS, IdentifyError, Log
from hexadyn.identify.sections import SectionOptions
from hexadyn.identify.steady import DryViscousFit, LoadFit, SectionPoint, fit_dry_viscous, fit_load, section_points

__all__ = ["Identification", "identify", "experiment_of", "SAWTOOTH", "BREAKAWAY"]

SAWTOOTH = "sawtooth"
BREAKAWAY = "breakaway"


@dataclass
class Identification:
    """What the logs gave.

    Attributes:
        points: every constant-velocity section (Fig. 5.3-5.5).
        fits: one dry/viscous line per (log, joint, leg, direction) and foot load.
        breakaways: one tau_f,s per (log, leg, direction) of the vertical joints.
        load_fits: Eq. 5.12 per (leg, direction) of the horizontal joints, with loaded logs.
        efficiency_fits: the efficiency law per (joint, leg) whose sawtooth logs have two foot
            loads or more (:mod:`hexadyn.identify.efficiency`).
        kinds: joint name -> kind (``"revolute"``, ``"prismatic"``: the units) of the logs'
            robot, in the order of a leg's joints.
        leg_mechanism: the logs' robot's ("pantograph" or "serial"): a serial drive has one
            dry friction and one viscous slope for both senses (its fragment's keys).
    """

    points: list[SectionPoint] = field(default_factory=list)
    fits: list[tuple[str, DryViscousFit]] = field(default_factory=list)
    breakaways: list[Breakaway] = field(default_factory=list)
    load_fits: list[LoadFit] = field(default_factory=list)
    efficiency_fits: list[EfficiencyFit] = field(default_factory=list)
    kinds: dict[str, str] = field(default_factory=dict)
    leg_mechanism: str = "pantograph"

    def unloaded(self, joint: str, leg: int, direction: int) -> list[DryViscousFit]:
        """The fits of one joint and direction without foot load, one per campaign."""
        return [f for _, f in self.fits if f.joint == joint and f.leg == leg and f.direction == direction and f.load_kg == 0.0]

    def joints(self) -> list[str]:
        """The identified joints, in the order of a leg's joints."""
        return [j for j in self.kinds if any(f.joint == j for _, f in self.fits) or any(b.joint == j for b in self.breakaways)]


def experiment_of(log: Log, joint: str, leg: int) -> str | None:
    """``"sawtooth"``, ``"breakaway"`` or None (the joint was held or is not in the log).

    A results folder says it through its scenario's motions (``sawtooth`` or
    ``voltage_ramp``). In a CSV log, a joint with a voltage column whose position moves one
    way only is a breakaway record, a joint that reverses at least twice a sawtooth.
    """
    if log.motions is not None:
        kind = log.motions.get((joint, leg))
        return {"sawtooth": SAWTOOTH, "voltage_ramp": BREAKAWAY}.get(kind or "")
    if not log.has(joint, leg):
        return None
    q = log.position(joint, leg)
    steps = np.sign(np.diff(q))
    steps = steps[steps != 0]
    reversals = int(np.count_nonzero(np.diff(steps) != 0)) if len(steps) else 0
    if f"u_{joint}[{leg}]" in log.frame and np.ptp(q) > 0 and reversals < 2:
        return BREAKAWAY
    return SAWTOOTH if np.ptp(q) > 0 else None


def identify(
    logs: Iterable[Log],
    joint: str | None = None,
    sections: SectionOptions = SectionOptions(),
    breakaway_options: BreakawayOptions = BreakawayOptions(),
    seed: int = 0,
    progress: Callable[[str], object] | None = None,
) -> Identification:
    """Identifies the friction of every joint the logs exercise (only `joint` if given).

    Raises:
        IdentifyError: a log lacks what its experiment needs (naming the file and the column,
            section or joint), or nothing in the logs can be identified.
    """
    result = Identification()
    for log in logs:
        _same_robot(result, log, joint)
        found = False
        for j in log.joints.names if joint is None else (joint,):
            for leg in LEGS:
                kind = experiment_of(log, j, leg)
                if kind == SAWTOOTH:
                    _sawtooth(result, log, j, leg, sections, seed)
                elif kind == BREAKAWAY:
                    result.breakaways.append(_breakaway(log, j, leg, breakaway_options))
                found = found or kind is not None
        if not found:
            which = "any joint" if joint is None else f"a {joint} joint"
            raise IdentifyError(f"{log.source}: no sawtooth or voltage-ramp record of {which} with a position and a current column")
        if progress:
            progress(log.source)
    result.load_fits = _load_fits(result, seed)
    result.efficiency_fits = _efficiency_fits(result, seed)
    return result


def _same_robot(result: Identification, log: Log, joint: str | None) -> None:
    """Takes the joints and leg mechanism of the log's robot; refuses a log whose robot has
    other joints or legs than the logs before it, or lacks `joint`."""
    names = log.joints.names
    if joint is not None and joint not in names:
        raise IdentifyError(f"{log.source}: joint = {joint!r}: allowed the robot's joints {', '.join(names)}")
    kinds = dict(zip(names, log.joints.kinds))
    if not result.kinds:
        result.kinds, result.leg_mechanism = kinds, log.leg_mechanism
    elif kinds != result.kinds or log.leg_mechanism != result.leg_mechanism:
        raise IdentifyError(f"{log.source}: a {log.leg_mechanism} robot with joints {', '.join(names)}; allowed: the robot of the first log ({result.leg_mechanism}, joints {', '.join(result.kinds)}), one robot per identification")


def _sawtooth(result: Identification, log: Log, joint: str, leg: int, options: SectionOptions, seed: int) -> None:
    points = section_points(log, joint, leg, options)
    result.points.extend(points)
    for direction in (1, -1):
        mine = [p for p in points if p.direction == direction]
        if not mine:
            raise IdentifyError(f"{log.source}: {joint}[{leg}]: no complete section in the {'plus' if direction > 0 else 'minus'} direction")
        try:
            fit = fit_dry_viscous(mine, seed)
        except ValueError as exc:
            raise IdentifyError(str(exc)) from None
        e = fit.tau_f_d
        sign = "+" if direction > 0 else "-"
        check_friction_sign(f"{log.source}: {joint}[{leg}]", f"tau_f,d^{sign}", direction, e.value, e.ci_low, e.ci_high, UNITS[log.joints.kind(joint)][0])
        result.fits.append((log.source, fit))


def _breakaway(log: Log, joint: str, leg: int, options: BreakawayOptions) -> Breakaway:
    b = breakaway(log, leg, options, joint)
    if not b.reason:
        sign = "+" if b.direction > 0 else "-"
        check_friction_sign(f"{log.source}: {joint}[{leg}]", f"tau_f,s^{sign}", b.direction, b.tau_f_s, math.nan, math.nan, UNITS[log.joints.kind(joint)][0])
    return b


def _load_fits(result: Identification, seed: int) -> list[LoadFit]:
    fits = []
    for leg in LEGS:
        for direction in (1, -1):
            loaded = [f for _, f in result.fits if f.joint == "q_h" and f.leg == leg and f.direction == direction and f.load_kg > 0]
            if len({f.load_kg for f in loaded}) < 2:
                continue
            unloaded = result.unloaded("q_h", leg, direction)
            if not unloaded:
                raise IdentifyError(f"q_h[{leg}]: loaded logs ({sorted({f.load_kg for f in loaded})} kg) without an unloaded one: Eq. 5.12 needs a_0, the unloaded dry friction (add the unloaded campaign's log)")
            a_0 = float(np.mean([f.tau_f_d.value for f in unloaded]))
            fits.append(fit_load(a_0, loaded, seed))
    return fits


def _efficiency_fits(result: Identification, seed: int) -> list[EfficiencyFit]:
    fits = []
    for joint in result.kinds:
        for leg in LEGS:
            points = [p for p in result.points if p.joint == joint and p.leg == leg]
            if any(p.load_kg > 0 for p in points):
                fit = fit_efficiency(points, seed)
                if fit is not None:
                    fits.append(fit)
    return fits
