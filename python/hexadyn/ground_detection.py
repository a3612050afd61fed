"""The ground detection experiment of Section 5.6.3 read from its results (Table 5.7)::

    import hexadyn
    from hexadyn import ground_detection
    results = hexadyn.simulate("ground_detection")
    trials = ground_detection.trials(results)      # one row per stop of a tested leg
    table = ground_detection.table(trials)         # Table 5.7: per leg and threshold

A run of control mode ``ground_detection`` records, per control instant, the detector's force
estimate ``F_gnd_est[l]`` (N) and flag ``gnd_detected[l]`` of every leg, the tested leg
``gd_leg``, its threshold ``gd_threshold`` (N) and trial ``gd_trial``, and ``gd_stop`` = 1 at
the instant the tested leg stops on a detection. The true contact force at that instant is the
simulated normal force ``Fn[gd_leg]``, the reading of the thesis' U9B force transducer.

The error follows Table 5.7: eps_F = (threshold - F_true) / threshold, in percent: positive when
the estimate overestimates the force (the leg stops early), negative when it stops late.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from hexadyn.results import Results

if TYPE_CHECKING:
    import pandas as pd

#: Results columns of the experiment.
STOP = "gd_stop"
LEG = "gd_leg"
THRESHOLD = "gd_threshold"
TRIAL = "gd_trial"
TRIALS_FILE = "ground_detection.csv"
TABLE_FILE = "ground_detection_table.csv"

__all__ = ["TABLE_FILE", "TRIALS_FILE", "format_table", "has_experiment", "table", "trials"]


def has_experiment(results: Results) -> bool:
    """Whether the results come from a ``ground_detection`` run."""
    return STOP in results.timeseries.columns


def trials(results: Results) -> pd.DataFrame:
    """One row per stop: ``leg``, ``threshold_n``, ``trial`` (from 1, as Table 5.7), ``t_s``,
    ``f_true_n`` (simulated normal force on the foot), ``f_estimate_n`` (F_z,gnd of Eq. 5.22)
    and ``error_pct`` (eps_F)."""
    import pandas as pd

    if not has_experiment(results):
        raise ValueError(f"the results have no {STOP} column: not a control.mode = \"ground_detection\" run")
    ts = results.timeseries
    stops = ts[ts[STOP] == 1.0]
    legs = stops[LEG].astype(int)
    rows = pd.DataFrame(
        {
            "leg": legs.to_numpy(),
            "threshold_n": stops[THRESHOLD].to_numpy(),
            "trial": stops[TRIAL].astype(int).to_numpy() + 1,
            "t_s": stops.index.to_numpy(),
            "f_true_n": [ts.at[t, f"Fn[{leg}]"] for t, leg in zip(stops.index, legs)],
            "f_estimate_n": [ts.at[t, f"F_gnd_est[{leg}]"] for t, leg in zip(stops.index, legs)],
        }
    )
    rows["error_pct"] = 100.0 * (rows["threshold_n"] - rows["f_true_n"]) / rows["threshold_n"]
    return rows


def table(trials: pd.DataFrame) -> pd.DataFrame:
    """Table 5.7: per (leg, threshold) the true force of each trial (columns ``F_1`` ...), the
    mean ``E_eps_pct`` and the standard deviation ``sigma_eps_pct`` of the error (sample
    standard deviation, 0 for a single trial)."""
    forces = trials.pivot_table(index=["leg", "threshold_n"], columns="trial", values="f_true_n")
    forces.columns = [f"F_{n}" for n in forces.columns]
    errors = trials.groupby(["leg", "threshold_n"])["error_pct"]
    out = forces.join(errors.mean().rename("E_eps_pct")).join(errors.std(ddof=1).fillna(0.0).rename("sigma_eps_pct"))
    return out


def format_table(table: pd.DataFrame) -> str:
    """The table as text, forces in N with one decimal, errors in percent."""
    return table.to_string(float_format=lambda v: f"{v:7.1f}")
