"""Running the simulations of a campaign or a design study: on the local cores (a process
pool) or on Ray.

Both executors take a picklable function and (key, payload) tasks, and yield (key,
``function(payload)``) as the tasks finish, in any order; the caller (the parent process, or the
Ray driver) stores the results. A Monte Carlo campaign's function is :func:`simulate_run` of its
scenario, whose outcome is ``{"status": "ok", "summary": {...}, "warnings": [...]}`` (the
entries of :func:`~hexadyn.montecarlo.storage.summary_columns` of the robot's joints, and the
failed health checks of the run) or ``{"status": "failed", "error": message}`` for a simulation the engine rejected (ValueError); any exception
stops the campaign. Closing the generator (Ctrl-C, an exception in the caller) cancels the
tasks not finished yet and stops the workers.
"""

from __future__ import annotations

import itertools
import os
import signal
import threading
import time
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from contextlib import closing
from typing import Any, Callable, Generator, Hashable, Iterable, Mapping, Protocol, Sequence, Union

from hexadyn.montecarlo.storage import summary_columns

__all__ = ["SERIES_FIGURES", "Executor", "ProcessPool", "Progress", "Ray", "run_and_store", "simulate_run"]

#: A task: its key (handed back with its result) and the argument of the executor's function.
Task = tuple[Hashable, Any]

#: ``progress`` argument of a campaign's or a study's ``run``: a tqdm bar over the runs (True),
#: nothing (False) or a callable ``progress(finished_runs, total_runs)`` called after each store.
Progress = Union[bool, Callable[[int, int], object]]

#: The figures of a run's summary that :func:`hexadyn.energy.add_energy_figures` computes from
#: the time series (:func:`hexadyn.simulate` adds them; the engine's summary has the others).
SERIES_FIGURES = ("energy_mechanical_j", "friction_share", "joule_share")

#: Tasks submitted ahead per worker process or CPU of the Ray cluster (one running, one queued
#: to start at once): the tasks of a campaign, up to a million, are not all held at a time.
IN_FLIGHT_PER_CPU = 2

#: Ray: walks per task. Between two tasks a Ray worker waits about 3.5 ms for the next one
#: (2.6 % of the 4000-walk campaign's time at 0.13 s per walk, where the process pool loses
#: 0.3 %); four walks per task pay it once for four.
WALKS_PER_TASK = 4


def run_and_store(executor: Executor, function: Callable[[Any], Any], tasks: Iterable[Task], store: Callable[[Hashable, Any], Sequence[tuple[str, Mapping[str, Any]]]], *, name: str, total: int, done: int, progress: Progress) -> None:
    """Runs `tasks` on `executor` and hands each finished task's (key, result) to `store`, which
    stores it and returns (label, outcome) of each run it held; the progress (a tqdm bar named
    `name` over `total` runs, `done` of them stored before, or the `progress` callable) advances
    by them, and each failed run is written as one line with its label. Closing on an exception
    or Ctrl-C stops the workers (:meth:`Executor.run`)."""
    from tqdm.auto import tqdm

    bar = tqdm(total=total, initial=done, desc=name, unit="run", disable=progress is not True)
    try:
        with closing(executor.run(function, tasks)) as outcomes:
            for key, result in outcomes:
                runs = store(key, result)
                done += len(runs)
                bar.update(len(runs))
                for label, outcome in runs:
                    if outcome["status"] == "failed":
                        bar.write(f"failed (stored, not retried): {label}: {outcome['error']}")
                if callable(progress):
                    progress(done, total)
    finally:
        bar.close()


def simulate_run(scenario: str, overrides: Mapping[str, Any], entries: Sequence[str] | None = None) -> dict[str, Any]:
    """Runs one simulation and returns its outcome: the summary ``entries`` (default: the
    :func:`~hexadyn.montecarlo.storage.summary_columns` of the robot's joints, the split of E
    per joint under the robot's joint names) and the failed health checks of the run
    (:func:`hexadyn.health.check`, as :func:`hexadyn.simulate` makes them). The engine's
    summary alone (no time series) unless an entry is one of :data:`SERIES_FIGURES`: then the
    run is :func:`hexadyn.simulate`'s, series in memory. An entry the summary lacks is None."""
    from hexadyn import _core, health
    from hexadyn.vocabulary import Joints

    try:
        if entries is not None and any(e in SERIES_FIGURES for e in entries):
            from hexadyn.runner import simulate

            summary = simulate(scenario, progress=False, overrides=overrides).summary
        else:
            raw = _core.run_scenario(scenario, None, dict(overrides), timeseries=False)
            summary = {**raw["summary"], "warnings": health.check(raw["summary"])}
            entries = summary_columns(Joints.of_robot(raw["robot"]).names) if entries is None else entries
    except ValueError as exc:
        return {"status": "failed", "error": " ".join(str(exc).split())}
    return {"status": "ok", "summary": {c: summary.get(c) for c in entries}, "warnings": summary["warnings"]}


def _several(function: Callable[[Any], Any]) -> Callable[[list[Any]], list[Any]]:
    """A task of several payloads: ``function`` of each, in order."""

    def run(payloads: list[Any]) -> list[Any]:
        return [function(p) for p in payloads]

    return run


class Executor(Protocol):
    """Runs ``function`` on the payload of each (key, payload) task, yielding (key, result) as
    they finish."""

    def run(self, function: Callable[[Any], Any], tasks: Iterable[Task]) -> Generator[tuple[Hashable, Any], None, None]: ...

    def capped(self, tasks: int) -> Executor:
        """The same executor with no more workers than `tasks` (the tasks it is given)."""
        ...


class ProcessPool:
    """The local cores: a ``concurrent.futures.ProcessPoolExecutor`` of ``workers`` processes
    (default: every core), given :data:`IN_FLIGHT_PER_CPU` tasks per worker at a time, a new
    one as each finishes. The workers ignore SIGINT: Ctrl-C reaches the parent, which stops
    them; a worker whose parent died (SIGKILL) exits by itself (:func:`_init_worker`)."""

    def __init__(self, workers: int | None = None) -> None:
        _check_workers(workers)
        self.workers = workers or os.cpu_count() or 1

    def capped(self, tasks: int) -> ProcessPool:
        return ProcessPool(max(1, min(self.workers, tasks)))

    def run(self, function: Callable[[Any], Any], tasks: Iterable[Task]) -> Generator[tuple[Hashable, Any], None, None]:
        executor = ProcessPoolExecutor(max_workers=self.workers, initializer=_init_worker, initargs=(os.getpid(),))
        queue = iter(tasks)
        running: dict[Future, Hashable] = {}

        def submit(count: int) -> None:
            for key, payload in itertools.islice(queue, count):
                running[executor.submit(function, payload)] = key

        try:
            submit(IN_FLIGHT_PER_CPU * self.workers)
            while running:
                done, _ = wait(running, return_when=FIRST_COMPLETED)
                for future in done:
                    submit(1)
                    yield running.pop(future), future.result()
        except BaseException:
            executor.shutdown(wait=False, cancel_futures=True)
            _terminate_workers(executor)
            raise
        executor.shutdown()


def _check_workers(workers: int | None) -> None:
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ValueError(f"workers = {workers!r}: need an integer >= 1 (at most the runs left are started)")


def _init_worker(parent: int) -> None:
    """Ignores SIGINT and exits once the parent process is gone: the workers of a killed
    campaign would otherwise wait for tasks forever (they hold both ends of the task queue)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)

    def exit_when_orphaned() -> None:
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=exit_when_orphaned, name="exit-when-orphaned", daemon=True).start()


def _terminate_workers(executor: ProcessPoolExecutor) -> None:
    """Stops the simulations still running (``terminate_workers`` from Python 3.14; the pool's
    process table before)."""
    terminate = getattr(executor, "terminate_workers", None)
    if terminate is not None:
        terminate()
        return
    for process in list((executor._processes or {}).values()):
        process.terminate()


class Ray:
    """A Ray cluster (``address``), or a Ray instance started here for ``address = "local"``
    (with ``workers`` CPUs, default every core). An already initialized Ray (``ray.init`` called
    by the user) is used as it is and left running."""

    def __init__(self, address: str, workers: int | None = None) -> None:
        _check_workers(workers)
        self.address = address
        self.workers = workers

    def capped(self, tasks: int) -> Ray:
        """A local Ray instance gets no more CPUs than tasks; a cluster is used as it is."""
        if self.address != "local":
            return self
        return Ray(self.address, max(1, min(self.workers or os.cpu_count() or 1, tasks)))

    def run(self, function: Callable[[Any], Any], tasks: Iterable[Task]) -> Generator[tuple[Hashable, Any], None, None]:
        try:
            import ray
        except ImportError as exc:
            raise ValueError("--ray needs Ray: pip install 'hexadyn[ray]'") from exc

        started = not ray.is_initialized()
        if started:
            if self.address == "local":
                ray.init(num_cpus=self.workers, include_dashboard=False, log_to_driver=False)
            else:
                ray.init(address=self.address, log_to_driver=False)
        remote = ray.remote(num_cpus=1)(_several(function))
        # At most IN_FLIGHT_PER_CPU tasks (of WALKS_PER_TASK walks) per CPU of the cluster are
        # submitted at a time, a new one as each finishes: the driver's ray.wait then looks at a
        # few refs, not at the whole campaign (1.3 ms per call over 2000 refs, for each of
        # thousands of walks).
        in_flight = max(1, int(IN_FLIGHT_PER_CPU * ray.cluster_resources().get("CPU", 1)))
        queue = iter(tasks)
        refs: dict[Any, list[Hashable]] = {}

        def submit(count: int) -> None:
            for _ in range(count):
                batch = list(itertools.islice(queue, WALKS_PER_TASK))
                if not batch:
                    return
                refs[remote.remote([payload for _, payload in batch])] = [key for key, _ in batch]

        try:
            submit(in_flight)
            while refs:
                (done,), _ = ray.wait(list(refs), num_returns=1)
                submit(1)
                yield from zip(refs.pop(done), ray.get(done))
        except BaseException:
            for ref in refs:
                ray.cancel(ref, force=True)
            raise
        finally:
            if started:
                ray.shutdown()
