"""Running scenarios: the shipped scenario files and :func:`simulate`.

The shipped scenarios live in the package, ``hexadyn/scenarios/*.toml`` (in the repository:
``python/hexadyn/scenarios/``), so that they are installed with the package by ``pip install .``
as well as by the editable developer install. A scenario is given either as the path of a file
or as the name of a shipped scenario (``"stand_six_legs"`` or ``"stand_six_legs.toml"``).
"""

from __future__ import annotations

import errno
import os
from pathlib import Path
from typing import Any, Callable, Mapping, Union

from hexadyn import atomic
from hexadyn.results import Results

#: Folder of the scenario files shipped with the package.
SCENARIOS_DIR = Path(__file__).resolve().parent / "scenarios"

#: ``progress`` argument of :func:`simulate`: a tqdm bar (True), nothing (False) or a callable
#: ``progress(t_s, duration_s)``.
Progress = Union[bool, Callable[[float, float], object]]

__all__ = ["SCENARIOS_DIR", "list_scenarios", "resolve_scenario", "simulate"]


def list_scenarios() -> list[Path]:
    """The shipped scenario files, sorted by name."""
    return sorted(SCENARIOS_DIR.glob("*.toml"))


def resolve_scenario(scenario: str | os.PathLike) -> Path:
    """The scenario file for a path or the name of a shipped scenario.

    An existing file wins; otherwise a bare name (no folder) is looked up among the shipped
    scenarios, with or without ``.toml``. Raises FileNotFoundError naming the shipped scenarios.
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
    names = ", ".join(p.stem for p in list_scenarios())
    raise FileNotFoundError(errno.ENOENT, f"no such scenario file, nor a shipped scenario ({names})", text)


def simulate(
    scenario: str | os.PathLike,
    out: str | os.PathLike | None = None,
    progress: Progress = True,
    *,
    overwrite: bool = False,
    overrides: Mapping[str, Any] | None = None,
) -> Results:
    """Runs a scenario and returns its :class:`~hexadyn.results.Results`, whose summary also
    holds the key figures of the power analysis (:func:`hexadyn.energy.add_energy_figures`).

    Args:
        scenario: a scenario file, or the name of a shipped scenario (see :func:`list_scenarios`).
        out: if given, the results are also saved to this folder (atomically, with the power
            tables, see :func:`hexadyn.report.save`); it must not exist unless ``overwrite``
            is true.
        progress: True for a tqdm progress bar over the simulated time (on stderr), False for
            none, or a callable ``progress(t_s, duration_s)`` called about every 1 % of the run.
        overwrite: replace an existing ``out`` folder.
        overrides: scenario fields set from outside the file, by dotted name, e.g.
            ``{"model.friction": "dry_viscous", "gait.heading.vx_m_s": 0.01}`` (values: bool,
            int, float, str, lists and dicts of those). The results' metadata then holds the
            effective scenario text.

    Raises:
        FileNotFoundError: no such scenario.
        ValueError: the scenario is invalid (one line naming the file, the field, the value and
            what is allowed), or the simulation failed.
        FileExistsError: ``out`` exists and ``overwrite`` is false (checked before running).
    """
    from hexadyn import _core, energy, report  # pandas and matplotlib: not at `import hexadyn`

    path = resolve_scenario(scenario)
    if out is not None and not overwrite:
        atomic.refuse_existing(out, "results folder")
    overrides = dict(overrides) if overrides else None
    if progress is True:
        raw = _run_with_bar(_core, path, overrides)
    else:
        raw = _core.run_scenario(os.fspath(path), progress if callable(progress) else None, overrides)
    results = Results.from_engine(raw, scenario_path=path)
    energy.add_energy_figures(results)
    if out is not None:
        report.save(results, out, overwrite=overwrite)
    return results


def _run_with_bar(core, path: Path, overrides: dict | None) -> dict:
    from tqdm.auto import tqdm

    info = core.load_scenario(os.fspath(path), overrides)
    duration = float(info["duration_s"])
    with tqdm(total=duration, desc=info["name"], unit="s", unit_scale=False, bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.2f}/{total:.2f} s simulated [{elapsed}<{remaining}]") as bar:

        def update(t: float, _duration: float) -> None:
            bar.update(min(t, duration) - bar.n)

        raw = core.run_scenario(os.fspath(path), update, overrides)
        bar.update(duration - bar.n)  # the last instant is duration up to rounding
    return raw


#: Where the commands put results folders when no ``--out`` is given.
RESULTS_ROOT = Path("results")


def free_results_folder(name: str) -> Path:
    """``results/<name>``, or ``results/<name>-2``, ``-3``... whichever does not exist yet."""
    base = RESULTS_ROOT / name
    if not base.exists():
        return base
    n = 2
    while (candidate := base.with_name(f"{base.name}-{n}")).exists():
        n += 1
    return candidate
