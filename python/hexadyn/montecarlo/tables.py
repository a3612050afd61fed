"""Results of a campaign: Table 6.8 (mean and standard deviation of the specific resistance
per velocity and friction variant) and Fig. 6.20 (means and +-3 sigma intervals vs velocity)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

from hexadyn import atomic
from hexadyn.montecarlo.storage import DATABASE_FILE

if TYPE_CHECKING:  # pandas is imported when a table is made: the Ray workers import this package, not pandas
    import pandas as pd

__all__ = ["TABLE_FILE", "TABLE_COLUMNS", "FIGURE_FILES", "specific_resistance_table", "failure_line", "warning_line", "write_results", "write_table", "plot_specific_resistance"]

TABLE_FILE = "specific_resistance.csv"
FIGURE_FILES = ("specific_resistance.png", "specific_resistance.pdf")
TABLE_COLUMNS = (
    "variant",
    "velocity_m_s",
    "runs",
    "failed",
    "specific_resistance_mean",
    "specific_resistance_std",
    "specific_resistance_minus_3_sigma",
    "specific_resistance_plus_3_sigma",
    "average_power_w_mean",
)


def specific_resistance_table(runs: pd.DataFrame, variants: tuple[str, ...]) -> pd.DataFrame:
    """Table 6.8 from the stored runs (:meth:`CampaignStore.runs`).

    One row per variant and velocity, in the order of ``variants`` then of the velocities:
    ``runs`` (succeeded simulations), ``failed``, the mean and the standard deviation (n - 1) of
    the specific resistance ξ = E/(m g l) (Eq. 6.6), mean - 3σ and mean + 3σ (Fig. 6.20), and the
    mean averaged power E/T (W, Fig. 6.19a).
    """
    import pandas as pd

    rows = []
    for variant in variants:
        for _, group in runs[runs["variant"] == variant].groupby("velocity_index"):
            ok = group[group["status"] == "ok"]
            mean, std = ok["specific_resistance"].mean(), ok["specific_resistance"].std(ddof=1)
            rows.append(
                {
                    "variant": variant,
                    "velocity_m_s": group["velocity_m_s"].iloc[0],
                    "runs": len(ok),
                    "failed": len(group) - len(ok),
                    "specific_resistance_mean": mean,
                    "specific_resistance_std": std,
                    "specific_resistance_minus_3_sigma": mean - 3 * std,
                    "specific_resistance_plus_3_sigma": mean + 3 * std,
                    "average_power_w_mean": ok["average_power_w"].mean(),
                }
            )
    return pd.DataFrame(rows, columns=TABLE_COLUMNS)


def failure_line(failed: pd.DataFrame, total: int, folder: str | os.PathLike) -> str:
    """One line naming the failed simulations of a campaign (:meth:`Campaign.failures
    <hexadyn.montecarlo.Campaign.failures>`) of `total`, by variant and velocity, with the first
    error and where they are kept."""
    first = failed.iloc[0]
    return f"{len(failed)} of {total} simulations failed: {_runs_named(failed)}: {first['error']}; kept as failed in {Path(folder) / DATABASE_FILE} (not retried)"


def warning_line(unhealthy: pd.DataFrame, total: int, folder: str | os.PathLike) -> str:
    """One line naming the simulations of a campaign that failed a health check
    (:meth:`Campaign.unhealthy <hexadyn.montecarlo.Campaign.unhealthy>`) of `total`, by variant
    and velocity, with the first one's failed checks and where they are kept."""
    first = unhealthy.iloc[0]
    return f"{len(unhealthy)} of {total} simulations failed a health check: {_runs_named(unhealthy)}: {'; '.join(first['warnings'])} (column warnings of {Path(folder) / DATABASE_FILE})"


def _runs_named(runs: pd.DataFrame) -> str:
    """Runs of a campaign by variant and velocity (the first :data:`_SHOWN` groups and run
    indices of each), then the first run: ``dry_viscous at V_x = 0.01 m/s (2: run 0, 1); the
    first (dry_viscous, V_x = 0.01 m/s, run 0)``."""
    groups = []
    for (variant, velocity), group in runs.groupby(["variant", "velocity_m_s"], sort=False):
        indices = group["run_index"].tolist()
        shown = ", ".join(map(str, indices[:_SHOWN])) + (", ..." if len(indices) > _SHOWN else "")
        groups.append(f"{variant} at V_x = {velocity:g} m/s ({len(indices)}: run {shown})")
    more = f" and {len(groups) - _SHOWN} more" if len(groups) > _SHOWN else ""
    first = runs.iloc[0]
    return f"{'; '.join(groups[:_SHOWN])}{more}; the first ({first['variant']}, V_x = {first['velocity_m_s']:g} m/s, run {first['run_index']})"


#: Groups and run indices a failure line names before "...".
_SHOWN = 4


def write_results(table: pd.DataFrame, folder: Path) -> None:
    """Writes Table 6.8 and Fig. 6.20 into ``folder`` as one set (:func:`hexadyn.atomic.write_files`):
    the figures, then the table: a ``specific_resistance.csv`` is never there without its
    figures, and a failure leaves the previous set and no temporary file."""

    def write(tmp: Path) -> None:
        write_table(table, tmp)
        plot_specific_resistance(table, tmp)

    atomic.write_files(folder, (*FIGURE_FILES, TABLE_FILE), write)


def write_table(table: pd.DataFrame, folder: Path) -> Path:
    """Writes Table 6.8 as ``folder/specific_resistance.csv``."""
    path = folder / TABLE_FILE
    table.to_csv(path, index=False, float_format="%.17g")
    return path


def plot_specific_resistance(table: pd.DataFrame, folder: Path) -> list[Path]:
    """Fig. 6.20: mean ξ and its ±3σ band versus velocity, one curve per variant; written as
    PNG (300 dpi) and PDF into ``folder``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.0, 4.0))
    try:
        for variant, rows in table.groupby("variant", sort=False):
            v_cm_s = rows["velocity_m_s"] * 100.0
            (line,) = ax.plot(v_cm_s, rows["specific_resistance_mean"], "o-", label=f"{variant} (mean)")
            ax.fill_between(
                v_cm_s,
                rows["specific_resistance_minus_3_sigma"],
                rows["specific_resistance_plus_3_sigma"],
                color=line.get_color(),
                alpha=0.2,
                label=f"{variant} (±3σ)",
            )
        ax.set_xlabel("velocity $V_x$ (cm/s)")
        ax.set_ylabel("specific resistance ξ = E/(m g l)")
        ax.set_title("Specific resistance, Monte Carlo over joint friction")
        ax.grid(True, alpha=0.3)
        ax.legend()
        fig.tight_layout()
        paths = [folder / name for name in FIGURE_FILES]
        for path in paths:
            fig.savefig(path, format=path.suffix[1:], dpi=300)
    finally:
        plt.close(fig)
    return paths
