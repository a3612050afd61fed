"""Running scenarios: the shipped scenario files and :func:`simulate`.

The shipped scenarios live in the package, ``hexadyn/scenarios/*.toml`` (in the repository:
``python/hexadyn/scenarios/``), so that they are installed with the package by ``pip install .``
as well as by the editable developer install. A scenario is given either as the path of a file
or as the name of a shipped scenario (``"stand_six_legs"`` or ``"stand_six_legs.toml"``).
"""

from __future__ import annotations

import errno
import os
import shutil
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence, Union

from hexadyn import atomic, inputs
from hexadyn.results import IN_MEMORY_LIMIT_BYTES, TIMESERIES_FILE, Results, SeriesWriter

#: Folder of the scenario files shipped with the package.
SCENARIOS_DIR = Path(__file__).resolve().parent / "scenarios"

#: Rows of the series the engine hands over at a time (2000 rows of a 280-column run: 4.5 MB);
#: :class:`~hexadyn.results.SeriesWriter` gathers them into row groups.
CHUNK_ROWS = 2_000

#: ``progress`` argument of :func:`simulate`: a tqdm bar (True), nothing (False) or a callable
#: ``progress(t_s, duration_s)``.
Progress = Union[bool, Callable[[float, float], object]]

__all__ = ["SCENARIOS_DIR", "free_results_folder", "list_scenarios", "resolve_scenario", "safe_folder_name", "scenario_files", "simulate"]


def list_scenarios() -> list[str]:
    """The names of the shipped scenarios, sorted (what ``hexadyn scenarios`` lists and
    :func:`simulate` takes)."""
    return [p.stem for p in scenario_files()]


def scenario_files() -> list[Path]:
    """The shipped scenario files, sorted by name."""
    return sorted(SCENARIOS_DIR.glob("*.toml"))


def resolve_scenario(scenario: str | os.PathLike) -> Path:
    """The scenario file for a path or the name of a shipped scenario.

    An existing file wins; otherwise a bare name (no folder) is looked up among the shipped
    scenarios, with or without ``.toml``. Raises FileNotFoundError naming the shipped scenarios,
    or ValueError saying what `scenario` is if it is there but not a regular file (a named pipe,
    a directory...).
    """
    path = Path(scenario)
    if path.is_file():
        return path
    text = os.fspath(scenario)
    if path.name == text:
        stem = text[: -len(".toml")] if text.endswith(".toml") else text
        shipped = SCENARIOS_DIR / f"{stem}.toml"
        if shipped.is_file():
            return shipped
    if os.path.lexists(path):
        inputs.check_input(path)  # not a regular file: says what it is
    names = ", ".join(list_scenarios())
    raise FileNotFoundError(errno.ENOENT, f"no such scenario file, nor a shipped scenario ({names})", text)


def simulate(
    scenario: str | os.PathLike,
    out: str | os.PathLike | None = None,
    progress: Progress = True,
    *,
    save: bool = False,
    overwrite: bool = False,
    overrides: Mapping[str, Any] | None = None,
    plots: bool = False,
    legs: Sequence[int] | None = None,
    formats: Sequence[str] | None = None,
) -> Results:
    """Runs a scenario and returns its :class:`~hexadyn.results.Results`, whose summary also
    holds the key figures of the power analysis (:func:`hexadyn.energy.add_energy_figures`) and
    the failed health checks of the run (``warnings``, :func:`hexadyn.health.check`).

    Without `out` (nor `save`) the time series is kept in memory; a run whose series would
    exceed :data:`IN_MEMORY_LIMIT_BYTES` is refused before it starts (give `out`). With `out` the
    series is streamed to ``timeseries.parquet`` in the results folder as the run goes (memory
    bounded by a constant whatever the duration), the folder is written atomically
    (:func:`hexadyn.report.save`) and ``results.timeseries`` is read from it on first access; a
    run whose series would not fit on the disk is refused before it starts.

    Args:
        scenario: a scenario file, or the name of a shipped scenario (see :func:`list_scenarios`).
        out: if given, the results are saved to this folder (atomically, with the power tables,
            see :func:`hexadyn.report.save`); it must not exist unless ``overwrite`` is true.
        progress: True for a tqdm progress bar over the simulated time (on stderr), and one
            over the figures written (`plots`), False for none, or a callable
            ``progress(t_s, duration_s)`` called about every 1 % of the run (no bar of the
            figures then).
        save: without `out`, save the results to ``results/<scenario name>`` (relative to the
            working directory), or ``results/<scenario name>-2``, ``-3``... if it exists, as
            ``hexadyn simulate`` does (:func:`free_results_folder`); ``results.path`` tells which.
        overwrite: replace an existing ``out`` folder.
        overrides: scenario fields set from outside the file, by dotted name, e.g.
            ``{"model.friction": "dry_viscous", "gait.heading.vx_m_s": 0.01}`` (values: bool,
            int, float, str, lists and dicts of those), what :meth:`hexadyn.Scenario.overrides`
            gives. The results' metadata then holds the effective scenario text.
        plots, legs, formats: with `out`, the figures of :func:`hexadyn.report.plot` in
            ``out/plots`` (skipped for a series too long for memory).

    Raises:
        FileNotFoundError: no such scenario.
        ValueError: the scenario is invalid (one line naming the file, the field, the value and
            what is allowed), the simulation failed, or the series would not fit.
        FileExistsError: ``out`` exists and ``overwrite`` is false (checked before running).
    """
    from hexadyn import _core, energy, health, report  # pandas and matplotlib: not at `import hexadyn`

    path = resolve_scenario(scenario)
    if out is not None and not overwrite:
        atomic.refuse_existing(out, "results folder")
    overrides = dict(overrides) if overrides else None
    info = _core.load_scenario(os.fspath(path), overrides)  # invalid: nothing is created
    if out is None and save:
        out = free_results_folder(info["name"])
    rows = info["duration_s"] / info["period_s"] + 1  # a float: a finite duration may still overflow an integer

    def finish(results: Results) -> Results:
        energy.add_energy_figures(results)
        results.summary["warnings"] = health.check(results.summary)
        return results

    if out is None:
        chunks: list[Mapping[str, Any]] = []

        def keep(columns: Mapping[str, Any], units: Mapping[str, str]) -> None:
            if not chunks:
                _refuse_beyond(rows, len(columns), IN_MEMORY_LIMIT_BYTES, "memory", "pass out= to stream the series to a results folder")
            chunks.append(columns)

        raw = _run(path, info, overrides, progress, keep)
        import numpy as np
        import pandas as pd

        frame = pd.DataFrame({name: np.concatenate([c[name] for c in chunks]) for name in chunks[0]}).set_index("t")
        return finish(Results.from_engine(raw, scenario_path=path, timeseries=frame))

    def record(tmp: Path) -> Results:
        with SeriesWriter(tmp / TIMESERIES_FILE) as writer:

            def write(columns: Mapping[str, Any], units: Mapping[str, str]) -> None:
                if writer.rows == 0:
                    free = shutil.disk_usage(tmp).free
                    _refuse_beyond(rows, len(columns), free, f"the free space of the disk of {out}", "shorten scenario.duration_s or choose another --out")
                    writer.units = dict(units)
                writer.write_columns(columns)

            raw = _run(path, info, overrides, progress, write)
        results = Results.from_engine(raw, scenario_path=path)
        results.path = tmp
        return finish(results)

    return report.save_run(record, out, overwrite=overwrite, plots=plots, legs=legs, formats=formats, progress=progress is True)


def _refuse_beyond(rows: float, columns: int, limit: float, where: str, advice: str) -> None:
    """Refuses a series of `rows` x `columns` 8-byte values larger than `limit` bytes."""
    estimate = 8 * rows * columns
    if estimate > limit:
        raise ValueError(f"the time series would take about {_size(estimate)} ({rows:.0f} instants x {columns} columns x 8 bytes), more than {where} ({_size(limit)}); {advice}")


def _size(n: float) -> str:
    for unit in ("bytes", "kB", "MB", "GB", "TB"):
        if n < 1000 or unit == "TB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1000
    raise AssertionError("unreachable")


def _run(path: Path, info: Mapping[str, Any], overrides: dict[str, Any] | None, progress: Progress, chunk: Callable[[Mapping[str, Any], Mapping[str, str]], None]) -> dict[str, Any]:
    """The engine's run, the series handed to `chunk` as it goes."""
    from hexadyn import _core

    if progress is not True:
        return _core.run_scenario(os.fspath(path), progress if callable(progress) else None, overrides, chunk=chunk, chunk_rows=CHUNK_ROWS)
    from tqdm.auto import tqdm

    duration = float(info["duration_s"])
    with tqdm(total=duration, desc=info["name"], unit="s", unit_scale=False, bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.2f}/{total:.2f} s simulated [{elapsed}<{remaining}]") as bar:

        def update(t: float, _duration: float) -> None:
            bar.update(min(t, duration) - bar.n)

        raw = _core.run_scenario(os.fspath(path), update, overrides, chunk=chunk, chunk_rows=CHUNK_ROWS)
        bar.update(duration - bar.n)  # the last instant is duration up to rounding
    return raw


#: Where the commands put results folders when no ``--out`` is given.
RESULTS_ROOT = Path("results")


def safe_folder_name(name: str) -> str:
    """A name (a scenario's ``scenario.name``) as the name of one folder: letters, digits,
    ``.``, ``_`` and ``-`` are kept, anything else (``/``, ``\\``, spaces, control characters)
    becomes ``_``; leading dots are dropped (no hidden folder, no ``..``); at most 100
    characters; ``scenario`` if nothing is left. Only ``--out`` chooses another place."""
    kept = "".join(c if (c.isalnum() and c.isascii()) or c in "._-" else "_" for c in name)
    kept = kept.lstrip(".")[:100]
    return kept or "scenario"


def free_results_folder(name: str) -> Path:
    """``results/<name>``, or ``results/<name>-2``, ``-3``... whichever does not exist yet;
    the name is made a safe folder name first (:func:`safe_folder_name`)."""
    base = RESULTS_ROOT / safe_folder_name(name)
    if not base.exists():
        return base
    n = 2
    while (candidate := base.with_name(f"{base.name}-{n}")).exists():
        n += 1
    return candidate
