"""A design study: its runs, simulated and stored by the Monte Carlo machinery, and its results.

:meth:`Study.create` validates a study (file or :class:`~hexadyn.study.spec.StudySpec`) and
draws its runs (:func:`hexadyn.study.design.samples`); :meth:`Study.run` simulates the runs not
stored yet on the local cores or on Ray (:mod:`hexadyn.montecarlo.execution`), stores each in
the study folder's SQLite database (:class:`hexadyn.montecarlo.storage.RunStore`: resumable
after an interruption or ``kill -9``, never a run twice) and writes the tables and the figures.

The model of a run is the study's scenario under the run's overrides (:class:`ScenarioModel`,
whose outputs are entries of the run's summary, as :func:`hexadyn.simulate` gives it), or any
picklable callable of the parameters (:class:`FunctionModel`: an analytic function, for tests of
the machinery); everything else follows the same path.
"""

from __future__ import annotations

import functools
import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterable, Mapping

import numpy as np

from hexadyn import atomic
from hexadyn._core import __version__
from hexadyn.montecarlo import execution
from hexadyn.montecarlo.execution import SERIES_FIGURES, Executor, ProcessPool, Progress, Ray
from hexadyn.montecarlo.storage import WARNINGS_COLUMN, Layout, RunStore
from hexadyn.study import analysis, design
from hexadyn.study.spec import StudySpec, read_study

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["FORMAT", "RUNS_FILE", "STUDY_FILE", "FunctionModel", "ScenarioModel", "Study", "StudyResults", "run_study"]

STUDY_FILE = "study.json"
#: Identifies a hexadyn study folder in study.json.
FORMAT = "hexadyn-study"
#: The tables of a study folder: its runs (one row per run), the indices and the second-order
#: Sobol' indices (when the design gives them), as CSV and Parquet.
RUNS_FILE = "runs.csv"
INDICES_FILE = "indices.csv"
SECOND_ORDER_FILE = "second_order.csv"


@dataclass(frozen=True)
class ScenarioModel:
    """A run of a scenario file: ``fixed`` and the run's parameters as overrides; its outputs
    are the ``outputs`` entries of the summary (None where a run's summary lacks one)."""

    scenario: str
    fixed: Mapping[str, Any]
    outputs: tuple[str, ...]
    #: Runs per task: a walk takes long enough to be stored on its own.
    runs_per_task = 1

    def __call__(self, parameters: Mapping[str, float]) -> dict[str, Any]:
        # execution.simulate_run as the module holds it in the worker (a test's held replacement).
        outcome = execution.simulate_run(self.scenario, {**self.fixed, **parameters}, self.outputs)
        if outcome["status"] != "ok":
            return outcome
        return {"status": "ok", "outputs": outcome["summary"], "warnings": outcome["warnings"]}


@dataclass(frozen=True)
class FunctionModel:
    """Any callable ``function(parameters) -> {output: value}`` (picklable: a module-level
    function); a ValueError it raises is the run's failure."""

    function: Callable[[Mapping[str, float]], Mapping[str, float]]
    #: Runs per task: a function is fast, its runs are stored by the thousand.
    runs_per_task = 1024

    def __call__(self, parameters: Mapping[str, float]) -> dict[str, Any]:
        try:
            return {"status": "ok", "outputs": dict(self.function(parameters))}
        except ValueError as exc:
            return {"status": "failed", "error": " ".join(str(exc).split())}


def _evaluate(model: Callable[[Mapping[str, float]], dict[str, Any]], runs: list[tuple[int, dict[str, float]]]) -> list[tuple[int, dict[str, Any]]]:
    """The task of a worker: (run index, outcome) of each run."""
    return [(i, model(parameters)) for i, parameters in runs]


@dataclass(frozen=True)
class StudyResults:
    """What :meth:`Study.run` returns and writes: ``runs`` (one row per run: ``run_index``,
    ``status``, ``error``, the parameters, the outputs), ``indices`` (:func:`analysis.indices`)
    and ``second_order`` (:func:`analysis.second_order_indices`), None where the design gives
    none, and the study ``folder``."""

    runs: pd.DataFrame
    indices: pd.DataFrame | None
    second_order: pd.DataFrame | None
    folder: Path

    @property
    def failures(self) -> pd.DataFrame:
        """The failed runs: ``run_index`` and ``error``."""
        return self.runs.loc[self.runs["status"] != "ok", ["run_index", "error"]].reset_index(drop=True)

    @property
    def unhealthy(self) -> pd.DataFrame:
        """The runs of a scenario that failed a health check (:func:`hexadyn.health.check`):
        ``run_index`` and ``warnings`` (the list of the failed checks), in run order."""
        runs = self.runs if WARNINGS_COLUMN in self.runs else self.runs.assign(**{WARNINGS_COLUMN: None})
        runs = runs.loc[runs["status"] == "ok", ["run_index", WARNINGS_COLUMN]].copy()
        runs[WARNINGS_COLUMN] = [json.loads(w) if isinstance(w, str) else [] for w in runs[WARNINGS_COLUMN]]
        return runs[runs[WARNINGS_COLUMN].map(bool)].reset_index(drop=True)


@dataclass(frozen=True)
class Study:
    """A validated study and its runs; build it with :meth:`create`, run it with :meth:`run`."""

    spec: StudySpec
    model: Callable[[Mapping[str, float]], dict[str, Any]]
    model_name: str
    scenario_text: str
    samples: np.ndarray

    @classmethod
    def create(cls, study: str | os.PathLike | StudySpec, *, model: Callable[[Mapping[str, float]], Mapping[str, float]] | None = None, fixed: Mapping[str, Any] | None = None) -> Study:
        """Validates a study (a study file, or a :class:`StudySpec`) and draws its runs.

        Without `model` the runs are the study's scenario (``study.scenario``: a file, relative
        to the study file, or a shipped scenario name) under ``[fixed]``, `fixed` (fields set
        from outside, ``--set``) and the run's parameters; the overrides and the outputs are
        checked on a run at the parameters' nominal values (:meth:`Parameter.nominal`): a field
        the scenario lacks or refuses, or an output its summary has no number for, is one line
        naming them. With `model`, a picklable callable of the parameters: the study's
        scenario is not used.
        """
        spec = study if isinstance(study, StudySpec) else read_study(study)
        if fixed:
            spec = _with_fixed(spec, fixed)
        samples = design.samples(spec)
        if model is not None:
            name = f"{getattr(model, '__module__', '?')}.{getattr(model, '__qualname__', type(model).__qualname__)}"
            return cls(spec, FunctionModel(model), name, "", samples)
        if not spec.scenario:
            raise ValueError(f"{spec.source}: field `study.scenario` is missing; it is required (a scenario file or a shipped scenario name)")
        path = _scenario_path(spec)
        scenario_model = ScenarioModel(os.fspath(path), dict(spec.fixed), spec.outputs)
        _check_outputs(spec, scenario_model)
        return cls(spec, scenario_model, "scenario", path.read_text(), samples)

    def parameters(self, run_index: int) -> dict[str, float]:
        """The parameter values of a run, by dotted key."""
        return {p.key: float(x) for p, x in zip(self.spec.parameters, self.samples[run_index])}

    def layout(self) -> Layout:
        """The study folder's files and runs table."""
        columns = {**{p.key: "REAL NOT NULL" for p in self.spec.parameters}, **{o: "REAL" for o in self.spec.outputs}}
        if self.model_name == "scenario":
            columns[WARNINGS_COLUMN] = "TEXT"  # the failed health checks of a run (JSON list)
        return Layout("design study", FORMAT, STUDY_FILE, {"run_index": "INTEGER"}, columns)

    def configuration(self) -> dict[str, Any]:
        """The content of ``study.json``: what must match to resume a study folder."""
        return {"hexadyn_version": __version__, "study": self.spec.configuration(), "model": self.model_name, "scenario_text": self.scenario_text, "runs": len(self.samples)}

    def run(self, out: str | os.PathLike, *, workers: int | None = None, ray: str | None = None, progress: Progress = True, plots: bool = True, formats: tuple[str, ...] = ("png",)) -> StudyResults:
        """Runs the study into the folder ``out`` (resuming it if it holds this study) and
        writes its tables and (unless not `plots`) figures there; returns them.

        ``workers``, ``ray`` and ``progress`` as :meth:`hexadyn.montecarlo.Campaign.run`: local
        processes or Ray tasks; Ctrl-C (KeyboardInterrupt) keeps the finished runs, and running
        again resumes. Failed runs are stored and not retried (:attr:`StudyResults.failures`).
        """
        executor: Executor = Ray(ray, workers) if ray else ProcessPool(workers)
        with RunStore.open(out, self.configuration(), self.layout()) as store:
            finished = {key for (key,) in store.finished()}
            pending = [i for i in range(len(self.samples)) if i not in finished]
            if pending:
                tasks = math.ceil(len(pending) / self.model.runs_per_task)  # type: ignore[attr-defined]
                self._simulate(store, executor.capped(tasks), pending, progress)
            runs = store.runs()
        results = StudyResults(runs, analysis.indices(self.spec, runs), analysis.second_order_indices(self.spec, runs), store.folder)
        write_results(self.spec, results, plots, formats)
        return results

    def _simulate(self, store: RunStore, executor: Executor, pending: list[int], progress: Progress) -> None:
        def stored(_: Any, results: list[tuple[int, dict[str, Any]]]) -> list[tuple[str, dict[str, Any]]]:
            store.add_rows([self._row(i, outcome) for i, outcome in results])
            return [(f"run {i}", outcome) for i, outcome in results]

        total = len(self.samples)
        size = self.model.runs_per_task  # type: ignore[attr-defined]
        chunks = (pending[k : k + size] for k in range(0, len(pending), size))
        tasks: Iterable = ((chunk[0], [(i, self.parameters(i)) for i in chunk]) for chunk in chunks)
        execution.run_and_store(executor, functools.partial(_evaluate, self.model), tasks, stored, name=self.spec.name, total=total, done=total - len(pending), progress=progress)

    def _row(self, run_index: int, outcome: Mapping[str, Any]) -> dict[str, Any]:
        outputs = outcome.get("outputs", {})
        values: dict[str, Any] = {o: _number(outputs.get(o)) for o in self.spec.outputs}
        if self.model_name == "scenario":
            values[WARNINGS_COLUMN] = json.dumps(outcome["warnings"]) if "warnings" in outcome else None
        return {"run_index": run_index, "status": outcome["status"], "error": outcome.get("error"), **self.parameters(run_index), **values}


def run_study(study: str | os.PathLike | StudySpec, out: str | os.PathLike, *, workers: int | None = None, ray: str | None = None, progress: Progress = True) -> StudyResults:
    """:meth:`Study.create` then :meth:`Study.run`."""
    return Study.create(study).run(out, workers=workers, ray=ray, progress=progress)


def write_results(spec: StudySpec, results: StudyResults, plots: bool, formats: tuple[str, ...]) -> None:
    """Writes the tables (CSV and Parquet) and the figures into the study folder as one set
    (:func:`hexadyn.atomic.write_files`), ``runs.csv`` last."""
    from hexadyn.plots import save_figures
    from hexadyn.study.figures import figures

    tables = {"second_order": results.second_order, "indices": results.indices, "runs": results.runs}
    tables = {name: table for name, table in tables.items() if table is not None}
    figs = figures(spec, results.runs, results.indices) if plots else {}
    names = [f"{stem}.{fmt}" for stem in figs for fmt in formats]
    names += [f"{name}.{ext}" for name in tables for ext in ("parquet", "csv")]

    def write(tmp: Path) -> None:
        save_figures(figs, tmp, formats)
        for name, table in tables.items():
            table.to_parquet(tmp / f"{name}.parquet", index=False)
            table.to_csv(tmp / f"{name}.csv", index=False, float_format="%.17g")

    try:
        atomic.write_files(results.folder, names, write)
    finally:
        for fig in figs.values():
            fig.clear()


def _number(value: Any) -> float | None:
    """An output value as stored: a number (booleans as 0 and 1), None for a missing one."""
    if value is None:
        return None
    if isinstance(value, (bool, int, float)):
        return float(value)
    raise ValueError(f"output value {value!r}: not a number")


def _with_fixed(spec: StudySpec, fixed: Mapping[str, Any]) -> StudySpec:
    """The study with more ``[fixed]`` fields (they win over the file's)."""
    import dataclasses

    clash = [k for k in fixed if k in {p.key for p in spec.parameters}]
    if clash:
        raise ValueError(f"{spec.source}: --set {clash[0]}: the study varies this field (parameters.\"{clash[0]}\"); allowed: a field the study does not vary")
    return dataclasses.replace(spec, fixed={**spec.fixed, **fixed})


def _scenario_path(spec: StudySpec) -> Path:
    """The study's scenario: a file relative to the study file's folder, else a shipped name."""
    from hexadyn.runner import resolve_scenario

    relative = spec.folder / spec.scenario
    try:
        return relative if relative.is_file() else resolve_scenario(spec.scenario)
    except FileNotFoundError as exc:
        raise ValueError(f"{spec.source}: field `study.scenario` = \"{spec.scenario}\": {exc.strerror}; allowed: a scenario file (relative to the study file) or a shipped scenario name") from None


def _check_outputs(spec: StudySpec, model: ScenarioModel) -> None:
    """Loads the scenario with the study's overrides at the nominal parameter values and runs
    it once (its engine summary): the overrides and the outputs are checked before any run is
    stored."""
    from hexadyn import _core

    overrides = {**spec.fixed, **{p.key: p.nominal() for p in spec.parameters}}
    try:
        summary = _core.run_scenario(model.scenario, None, overrides, timeseries=False)["summary"]
    except ValueError as exc:
        raise ValueError(f"{spec.source}: {' '.join(str(exc).split())}") from None
    numbers = sorted({k for k, v in summary.items() if isinstance(v, (bool, int, float))} | set(SERIES_FIGURES))
    for output in spec.outputs:
        if output not in numbers:
            raise ValueError(f"{spec.source}: field `study.outputs` = \"{output}\": not a figure of the summary of {summary['scenario']}; allowed: {', '.join(numbers)}")
