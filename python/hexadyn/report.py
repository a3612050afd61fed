"""A results folder with its analysis, written atomically (all or nothing)::

    from hexadyn import report
    report.save(results, "results/walk", plots=True)    # the folder below
    report.plot(results, "results/walk/plots")          # (re)writes the figures only

The folder holds the files of :class:`~hexadyn.results.Results` (``timeseries.parquet``,
``metadata.json``, ``summary.json``; read back by :meth:`Results.load
<hexadyn.results.Results.load>`) and:

- ``power.csv``: averaged power per leg and joint type, split by foot phase
  (:func:`hexadyn.energy.averaged_power`, Tables 6.3-6.6);
- ``energy.csv``: energy breakdown per actuator (:func:`hexadyn.energy.energy_breakdown`);
- ``ground_detection.csv`` and ``ground_detection_table.csv`` (runs of control mode
  ``ground_detection``): the stops and Table 5.7 (:mod:`hexadyn.ground_detection`);
- ``plots/`` (on request): the figures of :func:`hexadyn.plots.figures`.

This module is the top of the analysis layers (results -> energy -> plots -> report).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Callable, Mapping, Sequence

import pandas as pd
from matplotlib.figure import Figure

from hexadyn import atomic, energy, ground_detection
from hexadyn import plots as plotting
from hexadyn.results import IN_MEMORY_LIMIT_BYTES, Results

POWER_FILE = "power.csv"
ENERGY_FILE = "energy.csv"
PLOTS_DIR = "plots"

__all__ = ["ENERGY_FILE", "PLOTS_DIR", "POWER_FILE", "plot", "save", "write_csv"]


def save(
    results: Results,
    folder: str | os.PathLike,
    *,
    overwrite: bool = False,
    plots: bool = False,
    legs: Sequence[int] | None = None,
    formats: Sequence[str] | None = None,
    progress: bool = False,
) -> Path:
    """Writes the results folder atomically and returns its path (also set as ``results.path``).

    The files (and with ``plots`` the figures of :func:`plot` in ``plots/``) are written into a
    temporary folder next to ``folder`` which is then renamed to ``folder``: either the complete
    folder appears or nothing does (a failure removes the temporary folder and any parent
    folders this call created). An existing ``folder`` is an error (FileExistsError) unless
    ``overwrite`` is true, in which case it is replaced only once the new folder is complete.
    ``legs``, ``formats`` and ``progress`` are those of :func:`plot`.
    """
    if not overwrite:
        atomic.refuse_existing(folder, "results folder")
    figures = _figures(results, legs) if plots and skipped_analysis(results) is None else None  # before anything is written
    save_run(lambda tmp: results, folder, overwrite=overwrite, plots=plots, legs=legs, formats=formats, figures=figures, progress=progress)
    return Path(folder)


def save_run(
    run: Callable[[Path], Results],
    folder: str | os.PathLike,
    *,
    overwrite: bool = False,
    plots: bool = False,
    legs: Sequence[int] | None = None,
    formats: Sequence[str] | None = None,
    figures: Mapping[str, Figure] | None = None,
    progress: bool = False,
) -> Results:
    """:func:`save` of the results ``run(tmp)`` returns, called with the temporary folder so
    that it may stream its time series there (:func:`hexadyn.simulate`). The power table and
    the figures need the series in memory and a control period: they are left out, with a note
    in the summary (``analysis_skipped``, :func:`skipped_analysis`), for a series over
    :data:`hexadyn.results.IN_MEMORY_LIMIT_BYTES` or of a single instant."""
    target = Path(folder)
    if not overwrite:
        atomic.refuse_existing(target, "results folder")
    kept: list[Results] = []

    def write(tmp: Path) -> None:
        results = run(tmp)
        kept.append(results)
        skipped = skipped_analysis(results)
        small = skipped is None
        if not small:
            results.summary["analysis_skipped"] = f"{POWER_FILE} and the figures: {skipped}"
        results.write(tmp)
        if small:
            write_csv(tmp / POWER_FILE, energy.averaged_power(results))
        write_csv(tmp / ENERGY_FILE, energy.energy_breakdown(results))
        if small and ground_detection.has_experiment(results):
            stops = ground_detection.trials(results)
            write_csv(tmp / ground_detection.TRIALS_FILE, stops.set_index(["leg", "threshold_n", "trial"]))
            write_csv(tmp / ground_detection.TABLE_FILE, ground_detection.table(stops))
        if plots and small:
            (tmp / PLOTS_DIR).mkdir()
            _save_figures(figures if figures is not None else _figures(results, legs), tmp / PLOTS_DIR, formats, progress)

    atomic.write_folder(target, write)
    results = kept[0]
    results.path = target
    return results


def in_memory(results: Results) -> bool:
    """Whether the time series is small enough for the analyses in memory."""
    return results.series_bytes <= IN_MEMORY_LIMIT_BYTES


def skipped_analysis(results: Results) -> str | None:
    """Why the analyses in memory (the power table, the figures) cannot be made of the results,
    or None if they can: a series too long for memory, or of a single instant (a robot run
    stopped at its first control period), which has no period to average powers over."""
    if not in_memory(results):
        return f"the time series ({results.shape[0]} instants) is too long to analyse in memory"
    if results.shape[0] < 2:
        return "the time series has a single instant: no control period to average powers over"
    return None


def plot(
    results: Results,
    folder: str | os.PathLike | None = None,
    *,
    legs: Sequence[int] | None = None,
    formats: Sequence[str] | None = None,
    progress: bool = False,
) -> dict[str, Figure]:
    """Builds the figures of the results and, with ``folder``, writes them there.

    Returns the matplotlib figures by file stem (``leg0_q_r``, ..., ``gait_diagram``,
    ``trajectory``, ``averaged_power``, ``energy_breakdown``; see :mod:`hexadyn.plots`).
    ``legs``: the legs of the per-actuator figures (default 0 and 2, as in Section 6.4).
    ``formats``: file formats among png (300 dpi), pdf and svg (default png). The folder is
    written atomically and replaces an existing one: ``report.plot(results, results.path /
    "plots")`` regenerates the plots of a saved results folder. ``progress``: a bar on stderr
    over the figures as they are written (:func:`hexadyn.plots.save_figures`).
    """
    figures = _figures(results, legs)
    if folder is not None:
        atomic.write_folder(Path(folder), lambda tmp: _save_figures(figures, tmp, formats, progress))
    return figures


def write_csv(path: Path, table: pd.DataFrame) -> None:
    """Writes a table as CSV (floats with 9 significant digits)."""
    with open(path, "w", encoding="utf-8", newline="") as f:
        table.to_csv(f, float_format="%.9g")


def _figures(results: Results, legs: Sequence[int] | None) -> dict[str, Figure]:
    energy.control_period(results)  # a time axis the figures can be drawn on, or ValueError
    return plotting.figures(results, plotting.DEFAULT_LEGS if legs is None else legs)


def _save_figures(figures: Mapping[str, Figure], folder: Path, formats: Sequence[str] | None, progress: bool) -> None:
    plotting.save_figures(figures, folder, plotting.DEFAULT_FORMATS if formats is None else formats, progress=progress)
