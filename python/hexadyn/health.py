"""Health checks of a run: whether its own figures say the results mean something.

:func:`check` reads a run's summary (the engine's totals and diagnostics) and returns one line
per failed check; :func:`hexadyn.simulate` stores them as the summary's ``warnings`` (in
``summary.json``), ``hexadyn simulate`` prints them prominently and ``--strict`` makes them an
error (``compare-friction`` and ``montecarlo`` check each of their runs alike). A run with accepted but extreme settings (a loose integrator tolerance, a stiff or
slippery ground) can finish with exit status 0 and still be numerical nonsense; these checks
catch what a reader of the figures would catch:

- the energy balance (``energy_balance_error_relative``: the balance error over the sum of the
  magnitudes of its terms, zero up to integration error);
- the largest foot penetration into the ground (``max_penetration_m``) against the penetration
  of the robot standing on three feet on that ground (``static_penetration_m``);
- the body falling (``body_height_change_m`` against ``initial_body_height_m``);
- walking, the XY tracking error of the body against the scale of the scenario (the reference
  distance) and the distance walked against the path the heading commanded
  (``commanded_path_length_m``; the desired pose's ``reference_distance_m`` for results without
  it);
- the free gait's stability margin (``min_stability_margin_m``): below zero the body's centre
  was beyond an edge of the feet in support, −∞ fewer than three feet were in support;
- walking, joint references clamped into the joint ranges (``clamped_ik_references``) and
  limit switches cutting a motor (``limit_switch_cuts``); in the free gait, what it should never
  hold for long, each with when it began: a deadlock (``longest_deadlock_s``, or one still on at
  the end), fewer than three loaded feet (``longest_support_loss_s``), a foot in takeoff or
  swing carrying load (``longest_airborne_load_s``, one foot's, ``longest_airborne_load_leg``);
- a foot beyond the border of a terrain mesh (``foot_left_terrain_t_s``), where there is no
  ground;
- any non-finite figure.

The thresholds are stated with their reasons next to them; every shipped scenario passes them
(``hexadyn simulate NAME --strict``, ``tests/python/test_robust.py``).
"""

from __future__ import annotations

import math
from typing import Any, Mapping, TypeGuard

__all__ = ["MAX_AIRBORNE_LOAD_S", "MAX_DEADLOCK_S", "MAX_SUPPORT_LOSS_S", "check", "MAX_BALANCE_ERROR", "MAX_BODY_DROP", "MAX_DISTANCE_FRACTION", "MAX_PENETRATION_RATIO", "MAX_TRACKING_FRACTION", "TRACKING_ALLOWANCE_M"]

# INTERPRETATION: the thesis checks its simulations by the energy balance (Section 6.3) without
# a figure for the error it accepts. The shipped scenarios close the balance to below 0.5 %
# (relative to the sum of the magnitudes of its terms); 1e3 as integrator tolerance leaves
# 12.8 %. 2 % is a clear margin above the former and far below the latter.
#: Largest relative energy balance error of a healthy run.
MAX_BALANCE_ERROR = 0.02
# The feet of the shipped runs go at most 1.2 times as deep as three feet carrying the robot's
# weight at rest (``static_penetration_m``: 2.3 mm on the ground of Table 3.3, 50 mm on the soft
# ground of Section 7.6); three times that means the contact law was overrun (a foot through
# the ground, a step too coarse for the ground's stiffness).
#: Largest foot penetration of a healthy run, in units of the static penetration.
MAX_PENETRATION_RATIO = 3.0
# A body losing more than half of its height over the run has fallen: no shipped scenario, not
# even the unpowered ones whose joints are back-driven (9 mm), comes near.
#: Largest drop of the body over the run, as a fraction of its height at the start.
MAX_BODY_DROP = 0.5
# Walking: a body that strays from its desired path by more than the whole length of the path,
# or walks half again as far (or half as far) as the reference, is not walking as commanded
# (integrator.tolerance = 1e6 walked 282 m of a 0.9 m reference). The shipped walks track to
# millimetres, except the plain foot cycle on soft ground without navigation, whose drift of
# 0.6 m over 1.44 m is the point of Fig. 7.24 (soft_ground_plain).
#: Largest XY tracking error of a healthy walk, in units of the reference distance.
MAX_TRACKING_FRACTION = 1.0
#: Largest difference between the distance walked and the reference, in units of the reference.
MAX_DISTANCE_FRACTION = 0.5
#: Tracking error and distance difference always allowed (m): about a step.
TRACKING_ALLOWANCE_M = 0.05


# Issue 37's criteria of a successful walk over uneven ground: never fewer than three loaded feet
# for more than 0.2 s, no foot in takeoff or swing carrying load (the engine's
# AIRBORNE_LOAD_SHARE of the weight, 50 N on AMRU5) for more than 0.3 s. A deadlock is
# permanent after 20 s (four times the 5 s a leg needs for takeoff, swing and landing on AMRU5:
# one that the legs finishing their motion clear ends well before; crates/hexadyn/src/analysis/
# outcome.rs).
#: Longest time with fewer than three loaded feet in a healthy walk (s).
MAX_SUPPORT_LOSS_S = 0.2
#: Longest time a foot in takeoff or swing may carry load (s).
MAX_AIRBORNE_LOAD_S = 0.3
#: Longest deadlock of a healthy free gait (s).
MAX_DEADLOCK_S = 20.0


# The specific resistance of a run that walks no distance, and the shares of the electrical
# energy of a run that draws none (unpowered), are 0/0: not applicable, not a failure. Their
# numerators and denominators are figures of their own and are checked as such.
#: Ratios whose NaN means "not applicable".
RATIOS = ("specific_resistance", "friction_share", "joule_share")


def check(summary: Mapping[str, Any]) -> list[str]:
    """The failed health checks of a run's summary, one line each (empty: healthy)."""
    warnings = []
    margin, when = summary.get("min_stability_margin_m"), summary.get("min_stability_margin_t_s")
    bad = [k for k, v in summary.items() if isinstance(v, float) and not math.isfinite(v) and k not in RATIOS and not (k == "min_stability_margin_m" and v == -math.inf)]
    if bad:
        warnings.append(f"non-finite figures: {', '.join(bad)}")
    balance = summary.get("energy_balance_error_relative")
    if _finite(balance) and abs(balance) > MAX_BALANCE_ERROR:
        warnings.append(
            f"energy balance error {100 * abs(balance):.2f} % of the energy flows (allowed {100 * MAX_BALANCE_ERROR:g} %): "
            "the integration is too coarse (integrator.tolerance, integrator.h_max_s)"
        )
    penetration, scale = summary.get("max_penetration_m"), summary.get("static_penetration_m")
    if _finite(penetration) and _finite(scale) and penetration > MAX_PENETRATION_RATIO * scale:
        warnings.append(
            f"a foot went {penetration * 1e3:.1f} mm into the ground, more than {MAX_PENETRATION_RATIO:g} x the {scale * 1e3:.1f} mm "
            "of the robot standing on three feet: check model.k_gnd and the integrator settings"
        )
    height, change = summary.get("initial_body_height_m"), summary.get("body_height_change_m")
    if _finite(height) and _finite(change) and height > 0 and -change > MAX_BODY_DROP * height:
        warnings.append(f"the body fell by {-change * 1e3:.0f} mm, more than {100 * MAX_BODY_DROP:g} % of its initial height {height * 1e3:.0f} mm")
    error, reference = summary.get("tracking_error_xy_max_m"), summary.get("reference_distance_m")
    if _finite(error) and _finite(reference):
        allowed = TRACKING_ALLOWANCE_M + MAX_TRACKING_FRACTION * reference
        if error > allowed:
            warnings.append(f"the body strayed {error:.3f} m from its desired path (allowed {allowed:.3f} m for a {reference:.3f} m reference): the walk did not follow its command")
        # Against the commanded heading's path where the engine gives it: the desired pose halts
        # while the free gait is deadlocked, and a walk halted for good matched it.
        walked, commanded = summary.get("distance_walked_m"), summary.get("commanded_path_length_m")
        target, what = (commanded, "commanded") if _finite(commanded) else (reference, "reference")
        allowed = TRACKING_ALLOWANCE_M + MAX_DISTANCE_FRACTION * target
        if _finite(walked) and abs(walked - target) > allowed:
            warnings.append(f"the body walked {walked:.3f} m for a {target:.3f} m {what} path (allowed difference {allowed:.3f} m)")
    left, foot = summary.get("foot_left_terrain_t_s"), summary.get("foot_left_terrain")
    if _finite(left):
        warnings.append(f"foot {foot} went beyond the border of the terrain mesh at t = {left:.2f} s: there is no ground there (make the mesh cover the walk)")
    warnings += _walk_episodes(summary)
    if margin == -math.inf:
        warnings.append(f"fewer than three feet were in support at t = {when:.2f} s (free gait): the robot stood on no support polygon")
    elif _finite(margin) and margin < 0:
        warnings.append(f"the stability margin fell to {margin * 1e3:.1f} mm at t = {when:.2f} s (free gait): the body's centre was beyond an edge of the feet in support")
    return warnings


#: The free gait's episodes: summary key, longest healthy duration (s), what happened.
_FREE_GAIT_EPISODES: tuple[tuple[str, float, str], ...] = (
    ("deadlock", MAX_DEADLOCK_S, "the free gait was deadlocked"),
    ("support_loss", MAX_SUPPORT_LOSS_S, "fewer than three feet carried the robot"),
    ("airborne_load", MAX_AIRBORNE_LOAD_S, "a foot in takeoff or swing carried load"),
)


def _walk_episodes(summary: Mapping[str, Any]) -> list[str]:
    """The walk's warnings of :func:`check`: its clamped references and its limit-switch cuts
    (gait runs only: the identification campaigns drive the joints to their switches on
    purpose) and, in the free gait, its longest episodes. The periodic gaits lose their
    support on purpose in the thesis' own cases (Section 7.6: the plain foot cycle on soft
    ground, `soft_ground_plain`, a foot carrying load for 1.3 s into its swing; the fixed
    tripod on the low step and the rough ground, 0.5-0.8 s on two feet): the free gait is the
    thesis' answer to that ground, and there such an episode is a failure."""
    if "gait_pattern" not in summary:
        return []
    warnings: list[str] = []
    for key, bound, what in _FREE_GAIT_EPISODES if summary["gait_pattern"] == "free" else ():
        duration, start = summary.get(f"longest_{key}_s"), summary.get(f"longest_{key}_t_s")
        leg = summary.get(f"longest_{key}_leg")
        if isinstance(leg, int) and not isinstance(leg, bool):
            what = f"{what} (leg {leg})"
        if _finite(duration) and _finite(start) and duration > bound:
            warnings.append(f"{what} for {duration:.2f} s from t = {start:.2f} s (allowed {bound:g} s)")
    if summary.get("deadlocked_at_end") is True and not any(w.startswith("the free gait was deadlocked") for w in warnings):
        start = summary.get("longest_deadlock_t_s")
        warnings.append("the free gait was still deadlocked at the end" + (f" (its longest deadlock began at t = {start:.2f} s)" if _finite(start) else ""))
    clamped, last = summary.get("clamped_ik_references"), summary.get("last_clamped_ik_reference_t_s")
    if isinstance(clamped, int) and not isinstance(clamped, bool) and clamped > 0:
        when = f", the last at t = {last:.2f} s" if _finite(last) else ""
        warnings.append(f"{clamped} foot references were beyond the leg's reach and clamped into the joint ranges{when}")
    cuts = summary.get("limit_switch_cuts")
    if isinstance(cuts, int) and not isinstance(cuts, bool) and cuts > 0:
        warnings.append(f"the limit switches cut a motor {cuts} times: a joint was driven into its end-stop")
    return warnings


def _finite(x: object) -> TypeGuard[float]:
    """A finite number (not a boolean)."""
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
