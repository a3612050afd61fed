"""The identification folder, written atomically (:mod:`hexadyn.atomic`):

- ``table_5_3_<joint>.csv`` / ``.md``: dry and viscous friction per leg (Table 5.3 layout);
- ``table_5_4_breakaway.csv`` / ``.md``: breakaway of the vertical joints (Table 5.4);
- ``table_5_5_load.csv`` / ``.md``: Eq. 5.12 coefficients of the horizontal joints (Table 5.5);
- ``table_efficiency_<joint>.csv`` / ``.md``: the efficiency law per leg (eta_f, eta_b and the
  no-load friction) of the joints logged at two foot loads or more;
- ``estimates.csv``: every estimate with its standard error and 95 % intervals (Jacobian and
  bootstrap); ``sections.csv``: every constant-velocity section (velocity, mean torque);
- ``joint_friction.toml``: the ``[model.joint_friction]`` fragment of a scenario file (on
  serial legs one dry friction and one viscous slope per joint);
- ``joint_friction_efficiency.toml``: the same for ``friction = "efficiency"`` (no-load friction
  and efficiencies), with loaded logs;
- ``friction_stats.toml``: the Monte Carlo inputs (``hexadyn montecarlo --friction-stats``);
- ``figure_5_3_q_r.png``... (Fig. 5.3-5.5, 5.10; ``figure_friction_<joint>`` for another
  robot's joints) in the requested formats.
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path
from typing import Sequence

import pandas as pd

from hexadyn import atomic
from hexadyn.identify import figures, fragment, tables
from hexadyn.identify.identification import Identification

__all__ = ["save"]


def save(ident: Identification, out: str | os.PathLike, *, overwrite: bool = False, formats: Sequence[str] = ("png",)) -> Path:
    """Writes the identification folder `out` (see the module docs); returns its path.

    Raises:
        FileExistsError: `out` exists and `overwrite` is false.
    """
    out = Path(out)
    if not overwrite:
        atomic.refuse_existing(out, "identification folder")
    atomic.write_folder(out, lambda tmp: _write(ident, tmp, formats))
    return out


def _write(ident: Identification, folder: Path, formats: Sequence[str]) -> None:
    from hexadyn.plots import save_figures

    # A serial robot's servos are small (the PhantomX's dry friction is 0.59 Nm): three decimals.
    digits = 3 if ident.leg_mechanism == "serial" else 1
    for joint in [j for j in ident.kinds if any(f.joint == j for _, f in ident.fits)]:
        _table(tables.table_5_3(ident, joint), folder / f"table_5_3_{joint}", f"Table 5.3 ({joint}): dry and viscous friction, unloaded legs; mean and standard deviation over the campaigns (Eq. 5.8-5.9)", digits)
    if ident.breakaways:
        _table(tables.table_5_4(ident), folder / "table_5_4_breakaway", "Table 5.4: breakaway friction of the vertical joints (N), mean and standard deviation over the campaigns")
    if ident.load_fits:
        _table(tables.table_5_5(ident), folder / "table_5_5_load", "Table 5.5: coefficients of Eq. 5.12 (load in kg), value and standard error", digits=3)
    for joint in dict.fromkeys(f.joint for f in ident.efficiency_fits):
        _table(tables.table_efficiency(ident, joint), folder / f"table_efficiency_{joint}", f"Efficiency law of {joint} (Chapter 8 prospect): forward and backward efficiencies and no-load friction per leg, value and standard error", digits=3)
    tables.estimates(ident).to_csv(folder / "estimates.csv", index=False)
    pd.DataFrame([dataclasses.asdict(p) for p in ident.points]).to_csv(folder / "sections.csv", index=False)
    (folder / "joint_friction.toml").write_text(fragment.joint_friction_fragment(ident), encoding="utf-8")
    if ident.efficiency_fits:
        (folder / "joint_friction_efficiency.toml").write_text(fragment.efficiency_fragment(ident), encoding="utf-8")
    (folder / "friction_stats.toml").write_text(fragment.friction_stats_toml(ident), encoding="utf-8")
    save_figures(figures.figures(ident), folder, formats)


def _table(table: pd.DataFrame, stem: Path, title: str, digits: int = 1) -> None:
    table.to_csv(stem.with_suffix(".csv"))
    stem.with_suffix(".md").write_text(tables.markdown(table, title, digits), encoding="utf-8")
