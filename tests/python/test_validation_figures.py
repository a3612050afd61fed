"""The figures Section 6.4 of the thesis states in words for the validation walk at 1.5 cm/s
(Table 6.2: tripod, T = 12 s, 5 % overlap, enhanced cycle; the shipped scenario
``validation_tripod_1_5cm``), held so that a later change that moves them fails here.

The foot lift of that walk (0.105 m) is an INTERPRETATION fitted to the 0.8 mm of Section 6.4.2:
docs/validation-walk.md gives the fit, the step-crossing check and the open points.

Tracking errors are |q_ref - q| at the 10 ms control instants, over the whole walk (0-60 s: the
feet start at their steady footholds, so the first step is no transient that dominates; the
maximum after the first step is the same to 0.01 mm or deg) and over all six legs (the thesis
plots legs 0 and 2: their q_v and q_h maxima are within 0.5 % of the six legs', their q_r maximum
is 0.515 deg against 0.564 deg on leg 3).
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

import hexadyn

SCENARIO = "validation_tripod_1_5cm"
#: Tolerance on the figures the thesis gives as "about ...".
TOLERANCE = 0.15
#: Section 6.4.1, 6.4.2, 6.4.3: largest tracking errors (deg, mm, mm).
THESIS_MAX_ERROR = {"q_r": 0.5, "q_v": 0.8, "q_h": 0.5}
SCALE = {"q_r": 180.0 / np.pi, "q_v": 1e3, "q_h": 1e3}
#: The validation walks and the timing case, all walked with the fitted lift.
LIFTED = ["validation_tripod_1cm", "validation_tripod_1_5cm", "validation_tripod_2cm", "validation_tripod_2_5cm", "simulation_time"]
FOOT_LIFT_M = 0.105
#: Section 7.7.5: the same takeoff generation crosses an 8 cm step (Section 7.7.3).
STEP_HEIGHT_M = 0.08


@pytest.fixture(scope="module")
def walks() -> dict[str, pd.DataFrame]:
    """The walk with the three friction models of Section 6.4 (about 1.5 s of CPU)."""
    return {model: hexadyn.simulate(SCENARIO, overrides={"model.friction": model}, progress=False).timeseries for model in ("lugre", "dry_viscous", "none")}


def max_error(df: pd.DataFrame, joint: str) -> float:
    """Largest |q_ref - q| of a joint type over the walk and the six legs (deg or mm)."""
    errors = np.stack([(df[f"{joint}_ref[{leg}]"] - df[f"{joint}[{leg}]"]).abs().to_numpy() for leg in range(6)])
    return float(errors.max()) * SCALE[joint]


@pytest.mark.parametrize("model", ["lugre", "dry_viscous", "none"])
def test_largest_rotation_and_vertical_errors(walks, model):
    """Sections 6.4.1-6.4.2: "Maximum error is about 0.5 degrees" (q_r) and "about 0.8 mm"
    (q_v), the same "whatever the friction model"; within 15 % (LuGre: 0.564 deg, 0.804 mm)."""
    for joint in ("q_r", "q_v"):
        error = max_error(walks[model], joint)
        expected = THESIS_MAX_ERROR[joint]
        assert abs(error / expected - 1) <= TOLERANCE, f"{model}: largest {joint} error {error:.3f} instead of about {expected}"


def test_largest_horizontal_error_guard(walks):
    """Section 6.4.3: "Maximum tracking error is about 0.5 mm" (q_h). The model gives 0.412 mm,
    17.6 % below; the foot lift does not move it (docs/validation-walk.md). Held here within
    20 % so that a change that moves it fails; the 15 % test below is the open target."""
    error = max_error(walks["lugre"], "q_h")
    assert abs(error / THESIS_MAX_ERROR["q_h"] - 1) <= 0.20, f"largest q_h error {error:.3f} mm"
    assert error == pytest.approx(0.412, abs=0.02), f"largest q_h error {error:.3f} mm moved"


@pytest.mark.xfail(strict=True, reason="q_h max error 0.412 mm is 17.6 % below the 0.5 mm of Section 6.4.3 (open, docs/validation-walk.md)")
def test_largest_horizontal_error_within_15_percent(walks):
    error = max_error(walks["lugre"], "q_h")
    assert abs(error / THESIS_MAX_ERROR["q_h"] - 1) <= TOLERANCE, f"largest q_h error {error:.3f} mm"


def touchdowns(df: pd.DataFrame, leg: int) -> np.ndarray:
    """Times at which the leg enters its support (phase 3 landing -> 0 support)."""
    phase = df[f"phase[{leg}]"].to_numpy()
    k = np.nonzero((phase[1:] == 0) & (phase[:-1] == 3))[0] + 1
    return df.index.to_numpy()[k]


def test_settling_after_landing(walks):
    """Section 6.4.2, dry/viscous model, leg 0: at the beginning of the support (t = 24-25 s) the
    vertical joint still moves "because of the controller dynamics"; "this velocity reaches
    1e-4 m/s (limit velocity of dry/viscous model) at t ≈ 25 s". Here: the first instant after
    the touchdown of the third step from which |q_v_dot| stays below 1e-4 m/s for 1 s (24.83 s),
    within the half second the thesis states it to."""
    df = walks["dry_viscous"]
    t = df.index.to_numpy()
    down = next(x for x in touchdowns(df, 0) if 20.0 < x < 26.0)
    assert down == pytest.approx(23.7, abs=0.05), "leg 0 lands at the end of the third step's landing"
    speed = df["q_v_dot[0]"].abs().to_numpy()
    window = int(round(1.0 / (t[1] - t[0])))
    start = int(np.searchsorted(t, down))
    settled = next(t[k] for k in range(start, len(t) - window) if (speed[k : k + window] < 1e-4).all())
    assert abs(settled - 25.0) <= 0.5, f"|q_v_dot[0]| below 1e-4 m/s from t = {settled:.2f} s, not about 25 s"
    assert settled - down >= 0.5, "the joint still moves at the beginning of the support"


@pytest.mark.parametrize("window", [(26.0, 28.0), (38.0, 40.0)])
def test_vertical_irreversibility_in_support(walks, window):
    """Section 6.4.2: "the vertical irreversibility of leg 0 is correctly reproduced ... during
    the support phases (t = 26-28/38-40 s)": with LuGre the friction holds the foot load, the
    joint stands still and the motor current is a small fraction of the current that holds the
    load without friction; the dry/viscous model, linear at zero velocity, does not hold it
    (Sections 6.4.2, 6.6)."""
    a, b = window
    current = {m: df.loc[(df.index >= a) & (df.index <= b), "i_q_v[0]"].mean() for m, df in walks.items()}
    lugre = walks["lugre"].loc[(walks["lugre"].index >= a) & (walks["lugre"].index <= b)]
    assert current["none"] > 0.2, f"leg 0 carries its load through the motor without friction ({current['none']:.3f} A)"
    assert (lugre["q_v_dot[0]"].abs() < 1e-4).all()
    assert abs(current["lugre"]) < 0.1 * current["none"], f"LuGre: {current['lugre']:.3f} A vs {current['none']:.3f} A without friction"
    assert current["dry_viscous"] > 0.8 * current["none"], f"dry/viscous: {current['dry_viscous']:.3f} A"


@pytest.mark.parametrize("name", LIFTED)
def test_lift_is_the_documented_interpretation(name):
    """The five walks lift the foot by the fitted 0.105 m, which clears the 8 cm step, and say
    where the value comes from next to it."""
    text = (hexadyn.SCENARIOS_DIR / f"{name}.toml").read_text()
    line = next(line for line in text.splitlines() if line.startswith("clearance_m"))
    assert float(re.match(r"clearance_m\s*=\s*([0-9.]+)", line).group(1)) == FOOT_LIFT_M
    assert "INTERPRETATION" in text and "docs/validation-walk.md" in text
    assert FOOT_LIFT_M > STEP_HEIGHT_M
