"""Constant-velocity sections of a sawtooth log (Section 5.2.3).

A section is a run of samples over which the joint moves in one direction. Its beginning holds
the transient of the velocity tracking after a reversal ("inertia effects are thus different
from zero"); the averaging window starts ``transient_s`` after the section's start and ends
``margin_s`` before its end. The velocity of a section is its mean over the window, the position change over the window's
duration (encoder positions: no differentiation of quantized samples). What is left of the
transient in the window is measured as the mean acceleration, the change of the velocity (the
least-squares slopes of the position over +- ``end_velocity_s`` at the window's ends) over the
window's duration: its inertia is removed with the leg model
(:func:`hexadyn.identify.torques.friction_torque`). On AMRU5 the reflected rotor inertia of
q_v (J_r n_v^2 = 3e4 kg) makes a velocity still settling by 0.3 % after 1.5 s worth 1 % of
the viscous slope.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexadyn.identify.logs import IdentifyError

__all__ = ["Section", "SectionOptions", "find_sections"]


@dataclass(frozen=True)
class SectionOptions:
    """How sections are cut.

    INTERPRETATION: the thesis omits "the beginning where there is a transient" without a
    duration. The joint PI loops (Table 4.1: T_i = 0.5 s for every joint) track a ramp with an
    error that settles as exp(-t / T_i)-like terms; 1.5 s (3 T_i) is dropped after every
    reversal, and 0.1 s before the next one (the reference turns before the joint does). The
    identified bias this leaves is measured on simulated logs (docs/identification.md).
    """

    transient_s: float = 1.5
    margin_s: float = 0.1
    #: Fewest samples in an averaging window; a shorter section is an error.
    min_samples: int = 20
    #: Half-width of the centred difference that gives the direction of motion (s).
    direction_window_s: float = 0.2
    #: Half-width of the position fits that give the velocity at the window's ends (s).
    end_velocity_s: float = 0.05


@dataclass(frozen=True)
class Section:
    """One constant-velocity section: its sample range and averaging window (indices into the
    log), the mean velocity and acceleration over the window (joint units per s, per s^2) and
    the direction (+1 or -1)."""

    start: int
    stop: int
    window: slice
    velocity: float
    acceleration: float
    direction: int


def find_sections(t: np.ndarray, q: np.ndarray, options: SectionOptions, where: str) -> list[Section]:
    """The complete sections of a sawtooth position record `q(t)`: every run between two
    reversals, and the first run (which starts from rest); a run cut by the end of the log is
    left out. `where` names the log and joint in errors.

    Raises:
        IdentifyError: the joint does not move back and forth, or a section leaves fewer than
            ``min_samples`` samples after the transient is dropped.
    """
    direction = _direction(t, q, options.direction_window_s)
    runs = _runs(direction, min_length=max(2, int(round(2 * options.direction_window_s / float(np.median(np.diff(t)))))))
    if not runs:
        raise IdentifyError(f"{where}: the joint does not move (position range {np.ptp(q):.3g})")
    # A run is complete when the motion reverses after it; the last one is cut by the log's end.
    bounds = [(a, b, d) for (a, b, d), nxt in zip(runs[:-1], runs[1:]) if nxt[2] != d]
    sections = []
    for a, b, d in bounds:
        window = np.flatnonzero((t >= t[a] + options.transient_s) & (t <= t[b - 1] - options.margin_s))
        if len(window) < options.min_samples:
            raise IdentifyError(
                f"{where}: the velocity section at t = {t[a]:.2f}-{t[b - 1]:.2f} s is too short to fit: "
                f"{len(window)} samples after dropping the first {options.transient_s} s (transient) and the last "
                f"{options.margin_s} s; needs at least {options.min_samples} (longer sections: a slower velocity or a larger range)"
            )
        first, last = int(window[0]), int(window[-1])
        duration = t[last] - t[first]
        velocity = (q[last] - q[first]) / duration
        h = max(1, int(round(options.end_velocity_s / float(np.median(np.diff(t))))))
        v0, v1 = _slope(t, q, max(a, first - h), first + h + 1), _slope(t, q, last - h, min(b, last + h + 1))
        sections.append(Section(a, b, slice(first, last + 1), float(velocity), float((v1 - v0) / duration), d))
    if len(sections) < 2:
        raise IdentifyError(f"{where}: {len(sections)} complete constant-velocity section(s); the sawtooth needs sections in both directions")
    return sections


def _slope(t: np.ndarray, q: np.ndarray, a: int, b: int) -> float:
    """Least-squares slope of q over samples a..b-1."""
    return float(np.polyfit(t[a:b] - t[a:b].mean(), q[a:b], 1)[0])


def _runs(direction: np.ndarray, min_length: int) -> list[tuple[int, int, int]]:
    """(start, stop, sign) of the runs of one direction of motion: runs shorter than
    `min_length` samples (encoder steps, noise at a reversal) are dropped, and runs of the same
    sign separated only by stills or dropped runs are merged."""
    edges = np.flatnonzero(np.diff(direction) != 0) + 1
    starts = np.concatenate([[0], edges])
    stops = np.concatenate([edges, [len(direction)]])
    merged: list[tuple[int, int, int]] = []
    for a, b in zip(starts.tolist(), stops.tolist()):
        d = int(direction[a])
        if d == 0 or b - a < min_length:
            continue
        if merged and merged[-1][2] == d:
            merged[-1] = (merged[-1][0], b, d)
        else:
            merged.append((a, b, d))
    return merged


def _direction(t: np.ndarray, q: np.ndarray, half_width_s: float) -> np.ndarray:
    """+1, -1 or 0 (still) per sample: sign of the centred difference over +- half_width_s,
    with a dead band of a thousandth of the largest such difference (encoder steps, noise)."""
    dt = float(np.median(np.diff(t)))
    w = max(1, int(round(half_width_s / dt)))
    dq = np.zeros_like(q)
    dq[w:-w] = q[2 * w :] - q[: -2 * w]
    dead = 1e-3 * np.max(np.abs(dq))
    return np.where(dq > dead, 1, np.where(dq < -dead, -1, 0))
