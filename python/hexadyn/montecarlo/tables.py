"""Results of a campaign: Table 6.8 (mean and standard deviation of the specific resistance
per velocity and friction variant) and Fig. 6.20 (means and +-3 sigma intervals vs velocity)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from hexadyn import atomic

if TYPE_CHECKING:  # pandas is imported when a table is made: the Ray workers import this package, not pandas
    import pandas as pd

__all__ = ["TABLE_FILE", "TABLE_COLUMNS", "FIGURE_FILES", "specific_resistance_table", "write_table", "plot_specific_resistance"]

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


def write_table(table: pd.DataFrame, folder: Path) -> Path:
    """Writes Table 6.8 as ``specific_resistance.csv`` (atomically)."""
    path = folder / TABLE_FILE
    atomic.write_file(path, lambda tmp: table.to_csv(tmp, index=False, float_format="%.17g"))
    return path


def plot_specific_resistance(table: pd.DataFrame, folder: Path) -> list[Path]:
    """Fig. 6.20: mean ξ and its ±3σ band versus velocity, one curve per variant; written as
    PNG (300 dpi) and PDF into ``folder`` (each atomically)."""
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
        paths = []
        for name in FIGURE_FILES:
            path = folder / name
            fmt = path.suffix[1:]
            atomic.write_file(path, lambda tmp: fig.savefig(tmp, format=fmt, dpi=300))
            paths.append(path)
    finally:
        plt.close(fig)
    return paths
