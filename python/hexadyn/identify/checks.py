"""What a log must be for the identification to fit it honestly, and what a fit must give.

:func:`check_log` runs on every log :func:`hexadyn.identify.reading.load_log` reads and refuses,
with one line naming the file, the column and row, the value and what is allowed:

- a column the identification reads (time, positions, currents, voltages, foot loads) that
  holds anything else than finite numbers;
- a time column that does not increase by a constant step: every step within
  :data:`STEP_TOLERANCE` of the median step (the sections, the direction of motion and the
  breakaway smoothing count samples), the median within :data:`STEP_RANGE_S` (a time in
  milliseconds or nanoseconds, not seconds, is far out);
- a leg left out of a campaign: in a CSV log, a current without its joint's position, or the
  position of a joint whose other legs have currents without a current of its own (the
  identification would silently give one leg fewer);
- positions outside the joint's range widened by :data:`RANGE_MARGIN` of its stroke (other
  units: millimetres, degrees), currents above :data:`CURRENT_LIMIT_STALLS` stall currents at
  the nominal voltage, foot loads not constant or outside 0 to the robot's mass.

:func:`check_friction_sign` refuses a dry or breakaway friction of the wrong sign (friction
opposes the motion: positive in the plus sense, negative in the minus one) beyond its 95 %
interval: a current of the wrong sign or no current at all (a zero current leaves the leg's
gravity as "friction").
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pandas as pd

from hexadyn.identify.logs import LEGS, IdentifyError, Log, column, some_columns

__all__ = ["check_log", "check_friction_sign", "STEP_RANGE_S", "STEP_TOLERANCE", "RANGE_MARGIN", "CURRENT_LIMIT_STALLS"]

#: The median sampling step a log may have (s): a robot logs at its control period (10 ms on
#: AMRU5); a step outside is a time column in other units than seconds.
STEP_RANGE_S = (1e-4, 1.0)
#: How far a sampling step may depart from the log's median step, as a fraction of it: the
#: jitter of a logger passes, a dropped sample (twice the step) or a gap does not.
STEP_TOLERANCE = 0.5
#: Margin around a joint's range [lower, upper] of the robot description, as a fraction of the
#: stroke, within which its logged positions must stay: the simulated AMRU5 overtravels its q_v
#: stroke by 0.5 %; a position in millimetres or degrees is far out.
RANGE_MARGIN = 0.1
#: The largest current magnitude a motor can draw, in stall currents at the nominal voltage
#: u_n / R: a motor reversing at its no-load speed (a back EMF of u_n) against -u_n draws two.
CURRENT_LIMIT_STALLS = 2.0
#: Column prefixes of a joint's quantities the identification reads (position, currents, voltage).
_JOINT_QUANTITIES = ("q", "i", "i_meas", "u")


def check_log(log: Log) -> Log:
    """`log` with every column it reads as numbers, after the checks of the module docs.

    Raises:
        IdentifyError: naming the file, the column and row or the joint, the value and what is
            allowed.
    """
    try:
        names = log.joints.names
    except ValueError as exc:
        raise IdentifyError(f"{log.source}: {' '.join(str(exc).split())}") from None
    log = _numbers(log, names)
    _check_time(log)
    _check_columns(log, names)
    _check_bounds(log, names)
    return log


def check_friction_sign(where: str, name: str, direction: int, value: float, low: float, high: float, unit: str) -> None:
    """Refuses a dry (or breakaway) friction `value` of the wrong sign for `direction` whose 95 %
    interval [low, high] excludes zero (an interval not determined, NaN, excludes nothing:
    the value alone decides). `where` names the log and joint, `name` the parameter."""
    wrong = value < 0 if direction > 0 else value > 0
    covers_zero = low <= 0.0 <= high
    if wrong and not covers_zero:
        allowed = "> 0 (plus sense)" if direction > 0 else "< 0 (minus sense)"
        raise IdentifyError(
            f"{where}: {name} = {value:+.6g} {unit}, the wrong sign (friction opposes the motion: allowed {allowed}); "
            "the current column reads zero or the opposite sign of the motor current (check its sign and that it is the joint's)"
        )


def _numbers(log: Log, names: tuple[str, ...]) -> Log:
    """The log with its time and the columns it reads as floats; refuses text in them."""
    frame = log.frame
    read = {column(kind, j, leg) for j in names for leg in LEGS for kind in _JOINT_QUANTITIES} | {f"foot_load_kg[{leg}]" for leg in LEGS}
    text = [c for c in frame.columns if c in read and frame[c].dtype.kind != "f"]
    if not text and frame.index.dtype.kind == "f":
        return log
    t = _as_float(pd.Series(frame.index.to_numpy()), log.source, "t", None).to_numpy()
    out = frame.copy()
    for c in text:
        out[c] = _as_float(frame[c].reset_index(drop=True), log.source, c, t).to_numpy()
    out.index = pd.Index(t, name="t")
    return Log(log.source, out, log.robot_text, log.foot_load_kg, log.motions)


def _as_float(values: pd.Series, source: str, name: str, t: np.ndarray | None) -> pd.Series:
    """The column as floats; refuses a cell that is not a number (naming the row and its t)."""
    if values.dtype.kind in "fiu":
        return values.astype(float)
    numbers = pd.to_numeric(values, errors="coerce")
    bad = np.flatnonzero(numbers.isna().to_numpy() & values.notna().to_numpy())
    if len(bad):
        k = int(bad[0])
        at = "" if t is None else f" (t = {float(t[k])!r} s)"
        raise IdentifyError(f"{source}: column `{name}`, row {k}{at}: {_short(values.iloc[k])} is not a number; allowed: finite numbers")
    return numbers.astype(float)


def _check_time(log: Log) -> None:
    t = log.t
    if len(t) < 2:
        raise IdentifyError(f"{log.source}: {len(t)} samples; a log needs at least 2")
    if not np.all(np.isfinite(t)):
        k = int(np.flatnonzero(~np.isfinite(t))[0])
        raise IdentifyError(f"{log.source}: time t is not finite at row {k} ({t[k]}); allowed: finite times in s")
    steps = np.diff(t)
    if np.any(steps <= 0):
        k = int(np.flatnonzero(steps <= 0)[0])
        raise IdentifyError(f"{log.source}: time is not strictly increasing: t[{k}] = {t[k]} s, t[{k + 1}] = {t[k + 1]} s; allowed: one row per sample, in time order")
    dt = float(np.median(steps))
    low, high = STEP_RANGE_S
    if not low <= dt <= high:
        raise IdentifyError(f"{log.source}: time step {dt:.6g} (median of column `t`); allowed: {low:g} to {high:g} s (the time in seconds: not ms, us or ns)")
    off = np.flatnonzero(np.abs(steps - dt) > STEP_TOLERANCE * dt)
    if len(off):
        k = int(off[0])
        raise IdentifyError(
            f"{log.source}: time step {steps[k]:.6g} s from row {k} to {k + 1} (t = {float(t[k])!r} -> {float(t[k + 1])!r} s), "
            f"{len(off)} such step(s); allowed: a constant step, within {STEP_TOLERANCE:.0%} of the median {dt:.6g} s (split the log at gaps)"
        )


def _check_columns(log: Log, names: tuple[str, ...]) -> None:
    frame = log.frame
    if not any(log.has(j, leg) for j in names for leg in LEGS):
        j = names[1]
        raise IdentifyError(f"{log.source}: no joint with both a position (`{j}[2]`...) and a current (`i_{j}[2]` or `i_meas_{j}[2]`) column of the robot's joints {', '.join(names)}; the log has {some_columns(frame.columns)}")
    if log.motions is None:
        for j in names:
            currents = [leg for leg in LEGS if _current(frame, j, leg)]
            for leg in LEGS:
                position = column("q", j, leg)
                if _current(frame, j, leg) and position not in frame:
                    raise IdentifyError(f"{log.source}: column `{_current(frame, j, leg)}` without the position `{position}`; allowed: a current with its joint's position (add `{position}` or drop the current)")
                if currents and position in frame and leg not in currents:
                    raise IdentifyError(
                        f"{log.source}: column `{position}` has no current (`{column('i', j, leg)}` or `{column('i_meas', j, leg)}`) "
                        f"while {j} of leg(s) {', '.join(map(str, currents))} have theirs; allowed: every leg of a campaign with its current "
                        f"(add the current, or drop `{position}` to leave leg {leg} out)"
                    )
    for name in frame.columns:
        values = frame[name]
        if values.dtype.kind == "f" and not np.all(np.isfinite(values.to_numpy())):
            k = int(np.flatnonzero(~np.isfinite(values.to_numpy()))[0])
            raise IdentifyError(f"{log.source}: column `{name}` is not finite at row {k} (t = {log.t[k]} s): {values.iloc[k]}; allowed: finite numbers")


def _check_bounds(log: Log, names: tuple[str, ...]) -> None:
    from hexadyn.identify.torques import joint_constants

    frame = log.frame
    for j in names:
        for leg in LEGS:
            c = None
            position = column("q", j, leg)
            if position in frame:
                c = joint_constants(log, j, leg)
                margin = RANGE_MARGIN * (c["upper"] - c["lower"])
                _within(log, position, c["lower"] - margin, c["upper"] + margin, f"the {j} range [{c['lower']:.6g}, {c['upper']:.6g}] of the robot description +-{RANGE_MARGIN:.0%} of the stroke (SI units: m, rad)")
            for kind in ("i", "i_meas"):
                current = column(kind, j, leg)
                if current in frame:
                    c = c or joint_constants(log, j, leg)
                    limit = CURRENT_LIMIT_STALLS * c["nominal_voltage"] / c["resistance"]
                    _within(log, current, -limit, limit, f"|i| <= {CURRENT_LIMIT_STALLS:g} u_n / R = {limit:.4g} A (u_n = {c['nominal_voltage']:g} V, R = {c['resistance']:.4g} ohm; currents in A)")
    mass = _robot_mass(log.robot_text)
    for leg in LEGS:
        name = f"foot_load_kg[{leg}]"
        if name in frame:
            values = frame[name].to_numpy()
            changed = np.flatnonzero(values != values[0])
            if len(changed):
                k = int(changed[0])
                raise IdentifyError(f"{log.source}: column `{name}` changes at row {k} (t = {log.t[k]} s): {values[k]:g} after {values[0]:g} kg; allowed: one load per log (constant)")
            _within(log, name, 0.0, mass, f"0 to the robot's mass, {mass:.4g} kg")
    for leg, load in enumerate(log.foot_load_kg):
        if not 0.0 <= load <= mass:
            raise IdentifyError(f"{log.source}: foot load of leg {leg} = {load!r} kg; allowed: 0 to the robot's mass, {mass:.4g} kg")


def _within(log: Log, name: str, low: float, high: float, allowed: str) -> None:
    values = log.frame[name].to_numpy()
    out = np.flatnonzero((values < low) | (values > high))
    if len(out):
        k = int(out[0])
        raise IdentifyError(f"{log.source}: column `{name}`, row {k} (t = {log.t[k]} s): {values[k]:.6g}; allowed: {allowed}")


def _current(frame: pd.DataFrame, joint: str, leg: int) -> str | None:
    """The current column of a joint the log has (the measured one first), or None."""
    return next((c for c in (column("i_meas", joint, leg), column("i", joint, leg)) if c in frame), None)


@lru_cache(maxsize=8)
def _robot_mass(robot_text: str | None) -> float:
    from hexadyn import _core

    return float(_core.robot_properties(robot_text or _core.shipped_robot_text("amru5"), "robot description of the log")["mass_kg"])


def _short(value: object) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."

