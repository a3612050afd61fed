"""A Monte Carlo campaign over the joint friction uncertainty (Section 6.5).

A campaign simulates a walking scenario (default: the validation walk of Table 6.2,
``validation_tripod_1_5cm``) once for every (variant, velocity, run): the friction is drawn per
run (:mod:`~hexadyn.montecarlo.sampling`) and set identical for every leg through
``[model.joint_friction]``; the velocity is the forward heading velocity ``gait.heading.vx_m_s``.
The two friction variants of Section 6.5 share the draws (common random numbers):

- ``dry_viscous``: dry/viscous friction (Eq. 6.1) on the three joints, the horizontal viscous
  slope neglected, no load influence;
- ``dry_viscous_load``: the same with the load influence on the horizontal dry friction
  (Eq. 5.12), whose coefficients are drawn too.

The defaults (velocities, runs per velocity) come from the ``[monte_carlo]`` table of the
scenario's robot description: 1000 runs at 1, 1.5, 2 and 2.5 cm/s for the AMRU5.

A robot with serial legs (the PhantomX: ``phantomx_montecarlo``, the default scenario of
``robot="phantomx"``) draws its drives' friction from the Gaussians of its ``[monte_carlo]``
table, written to ``[model.joint_friction.<joint>]`` under its own joint names; it has no load
influence, so only the ``dry_viscous`` variant.
"""

from __future__ import annotations

import functools
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

from hexadyn._core import __version__
from hexadyn.montecarlo import execution
from hexadyn.montecarlo.execution import Executor, ProcessPool, Progress, Ray
from hexadyn.montecarlo.sampling import FrictionDistributions, draw_friction, read_friction_stats
from hexadyn.montecarlo.storage import WARNINGS_COLUMN, CampaignStore, RunKey
from hexadyn.montecarlo.tables import specific_resistance_table, write_results
from hexadyn.runner import resolve_scenario

__all__ = ["DEFAULT_SCENARIO", "DEFAULT_SCENARIOS", "MAX_SIMULATIONS", "VARIANTS", "DEFAULT_VARIANTS", "Campaign", "run_campaign", "study_tables", "variant_fields", "variants_of"]

#: Scenario of a campaign without an explicit one: the Table 6.2 validation walk.
DEFAULT_SCENARIO = "validation_tripod_1_5cm"

#: The campaign scenario of each shipped robot (``hexadyn montecarlo --robot NAME``).
DEFAULT_SCENARIOS = {"amru5": DEFAULT_SCENARIO, "phantomx": "phantomx_montecarlo"}

#: Friction variants -> the scenario fields selecting their model: those of Section 6.5,
#: dry/viscous (Eq. 6.1) without and with the load influence of Eq. 5.12, and the transmission
#: efficiency of the thesis' prospects (Chapter 8), whose no-load friction is drawn as the
#: dry/viscous one and whose efficiencies are the robot's unless a friction statistics file
#: gives their distributions (``hexadyn identify`` of loaded logs).
VARIANTS = {
    "dry_viscous": {"model.friction": "dry_viscous", "model.load_dependence": False},
    "dry_viscous_load": {"model.friction": "dry_viscous", "model.load_dependence": True},
    "efficiency": {"model.friction": "efficiency", "model.load_dependence": False},
}
#: The variants of a campaign that names none: Section 6.5's (those the robot allows).
DEFAULT_VARIANTS = ("dry_viscous", "dry_viscous_load")

#: The most simulations (runs x velocities x variants) a campaign may hold: 125 times the
#: thesis' 8000 (1000 runs, 4 velocities, 2 variants), four and a half days of 60 s walks on
#: one core at 0.4 s each; its list of runs takes about 100 MB.
MAX_SIMULATIONS = 1_000_000


def variant_fields(variant: str) -> dict[str, Any]:
    """The scenario fields that select a variant's friction model (:data:`VARIANTS`)."""
    return dict(VARIANTS[variant])


def drawn_by(distributions: FrictionDistributions, variant: str) -> dict[str, tuple[float, float]]:
    """The Gaussians a variant's runs use: the load coefficients of Eq. 5.12 only with the
    load influence, the efficiencies only with the efficiency law."""
    load = VARIANTS[variant]["model.load_dependence"]
    efficiency = VARIANTS[variant]["model.friction"] == "efficiency"
    return {f: g for f, g in distributions.gaussians.items() if (load or f not in distributions.load_parameters) and (efficiency or f not in distributions.efficiency_parameters)}


def study_tables(distributions: FrictionDistributions, variant: str = "dry_viscous") -> dict[str, dict[str, Any]]:
    """The friction of a variant's runs as the ``[fixed]`` and ``[parameters]`` tables of a
    design study (docs/studies.md): each drawn field a ``truncated_normal`` on its accepted
    interval (:meth:`FrictionDistributions.accepted_interval`, the distribution
    :func:`draw_friction` samples by rejection), a field of zero sigma and the robot's fixed
    fields set as ``[fixed]`` with the variant's friction model. A study of these tables
    samples what the campaign draws (its design instead of independent draws)."""
    fields = drawn_by(distributions, variant)
    parameters = {f: {"distribution": "truncated_normal", "range": list(distributions.accepted_interval(f)), "mean": mu, "std": sigma} for f, (mu, sigma) in fields.items() if sigma > 0}
    fixed = {**variant_fields(variant), **distributions.fixed, **{f: mu for f, (mu, sigma) in fields.items() if sigma == 0}}
    return {"fixed": fixed, "parameters": parameters}


def variants_of(distributions: FrictionDistributions) -> tuple[str, ...]:
    """The variants a robot's set-up allows: the load influence needs drawn load coefficients
    (AMRU5's horizontal joints, Eq. 5.12); a serial robot has ``dry_viscous`` and
    ``efficiency``."""
    return tuple(v for v, fields in VARIANTS.items() if not fields["model.load_dependence"] or distributions.load_parameters)


@dataclass(frozen=True)
class Campaign:
    """What a campaign simulates; build it with :meth:`create`, run it with :meth:`run`."""

    scenario: Path
    scenario_name: str
    scenario_text: str
    velocities_m_per_s: tuple[float, ...]
    runs_per_velocity: int
    variants: tuple[str, ...]
    seed: int
    distributions: FrictionDistributions
    #: Scenario fields set on every run by dotted name (``hexadyn montecarlo --set``); a run's
    #: friction, velocity and name are set over them.
    fields: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def create(
        cls,
        scenario: str | os.PathLike = DEFAULT_SCENARIO,
        *,
        velocities: Sequence[float] | None = None,
        runs_per_velocity: int | None = None,
        variants: Sequence[str] | None = None,
        seed: int = 0,
        friction_stats: str | os.PathLike | None = None,
        overrides: Mapping[str, Any] | None = None,
    ) -> Campaign:
        """Validates a campaign; ``None`` takes the robot's ``[monte_carlo]`` defaults (all
        variants for ``variants``). `friction_stats`: a file written by ``hexadyn identify``
        whose Gaussians replace the robot's (Table 6.7). `overrides`: scenario fields set on
        every run (:attr:`fields`); the campaign's scenario text (``campaign.json``, compared on
        resuming) is then the effective one, listing them. Raises ValueError (one line) for bad
        input: among others a distribution a draw is too rarely kept from
        (:meth:`FrictionDistributions.check`) or more than :data:`MAX_SIMULATIONS` runs."""
        from hexadyn import _core

        path = resolve_scenario(scenario)
        fields = dict(overrides or {})
        info = _core.load_scenario(os.fspath(path), fields or None)
        if info["gait"] is None:
            raise ValueError(f"{path}: a Monte Carlo campaign needs a walking scenario (control.mode = \"gait\"), for the specific resistance")
        distributions = FrictionDistributions.of_robot(info["robot"])
        if friction_stats is not None:
            distributions = distributions.with_stats(read_friction_stats(friction_stats), os.fspath(friction_stats))
        distributions.check(distributions.robot if friction_stats is None else os.fspath(friction_stats))
        runs = distributions.runs_per_velocity if runs_per_velocity is None else runs_per_velocity
        if isinstance(runs, bool) or not isinstance(runs, int) or runs < 1:
            raise ValueError(f"runs per velocity = {runs!r}: need an integer >= 1")
        velocities = tuple(float(v) for v in (distributions.velocities_m_per_s if velocities is None else velocities))
        if not velocities or not all(math.isfinite(v) and v > 0 for v in velocities):
            raise ValueError(f"velocities = {list(velocities)}: need one or more finite velocities > 0 (m/s)")
        allowed = variants_of(distributions)
        variants = tuple(v for v in allowed if v in DEFAULT_VARIANTS) if variants is None else tuple(variants)
        unknown = [v for v in variants if v not in allowed]
        if unknown or not variants or len(set(variants)) != len(variants):
            why = "" if len(allowed) == len(VARIANTS) else f" (no load influence on the legs of {distributions.robot})"
            raise ValueError(f"variants = {list(variants)}: need distinct variants among {', '.join(allowed)}{why}")
        per_run = len(velocities) * len(variants)
        if runs * per_run > MAX_SIMULATIONS:
            raise ValueError(
                f"runs per velocity = {runs}: need at most {MAX_SIMULATIONS // per_run} with {len(velocities)} velocities and "
                f"{len(variants)} variants (a campaign holds at most {MAX_SIMULATIONS} simulations)"
            )
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            raise ValueError(f"seed = {seed!r}: need an integer >= 0")
        campaign = cls(path, info["name"], info["text"], velocities, runs, variants, seed, distributions, fields)
        # The overrides must fit the scenario (a constant heading, ...): check one run of each
        # variant now rather than store every run as failed.
        for variant in variants:
            _core.load_scenario(os.fspath(path), campaign.overrides(RunKey(variant, 0, 0)))
        return campaign

    def keys(self) -> list[RunKey]:
        """Every run, in the order they are started: run index first, so that a campaign
        stopped midway holds about as many runs for every velocity and variant."""
        return [RunKey(variant, vi, ri) for ri in range(self.runs_per_velocity) for vi in range(len(self.velocities_m_per_s)) for variant in self.variants]

    def friction(self, key: RunKey) -> dict[str, float]:
        """The ``[model.joint_friction]`` fields of a run: the draw of (velocity, run) without
        the load coefficients for the variant without load influence, and the fixed values."""
        drawn = draw_friction(self.distributions, self.seed, key.velocity_index, key.run_index)
        used = drawn_by(self.distributions, key.variant)
        return {**{k: v for k, v in drawn.items() if k in used}, **self.distributions.fixed}

    def overrides(self, key: RunKey) -> dict[str, Any]:
        """The scenario overrides of a run."""
        return {
            **self.fields,
            "scenario.name": f"{self.scenario_name}-{key.variant}-v{key.velocity_index}-r{key.run_index}",
            **variant_fields(key.variant),
            "gait.heading.vx_m_s": self.velocities_m_per_s[key.velocity_index],
            **self.friction(key),
        }

    def configuration(self) -> dict[str, Any]:
        """The content of ``campaign.json``: what must match to resume a campaign."""
        d = self.distributions
        return {
            "hexadyn_version": __version__,
            "scenario": self.scenario_name,
            "scenario_text": self.scenario_text,
            "robot": d.robot,
            "velocities_m_per_s": list(self.velocities_m_per_s),
            "runs_per_velocity": self.runs_per_velocity,
            "variants": list(self.variants),
            "seed": self.seed,
            "truncation_sigmas": d.truncation_sigmas,
            "gaussians": d.gaussians,
            "physical_bounds": d.physical_bounds,
            "load_parameters": list(d.load_parameters),
            "fixed": d.fixed,
        }

    def run(self, out: str | os.PathLike, *, workers: int | None = None, ray: str | None = None, progress: Progress = True):
        """Runs the campaign into the folder ``out`` (resuming it if it holds this campaign)
        and returns Table 6.8 (:func:`~hexadyn.montecarlo.tables.specific_resistance_table`),
        also written there with Fig. 6.20.

        ``workers`` processes on the local cores (default: all), or Ray tasks when ``ray`` is a
        cluster address (``"local"``: a Ray instance started here with ``workers`` CPUs); never
        more workers than runs left to simulate. On Ctrl-C (KeyboardInterrupt, also raised by
        ``progress``) the running simulations are stopped and the finished ones are kept:
        running again resumes. Failed simulations are stored and counted in the table's
        ``failed`` column (:meth:`failures` lists them); so are the failed health checks of
        each run (:meth:`unhealthy` lists the runs with any).
        """
        executor: Executor = Ray(ray, workers) if ray else ProcessPool(workers)
        keys = self.keys()
        with CampaignStore.open(out, self.configuration(), self.distributions.joints) as store:
            finished = store.finished()
            pending = [k for k in keys if k not in finished]
            if pending:
                self._simulate(store, executor.capped(len(pending)), pending, len(keys), progress)
            table = specific_resistance_table(store.runs(), self.variants)
        write_results(table, store.folder)
        return table

    def failures(self, out: str | os.PathLike):
        """The failed simulations stored in the campaign folder ``out``: a DataFrame of
        ``variant``, ``velocity_m_s``, ``run_index`` and ``error``, in run order."""
        runs = self._runs(out)
        return runs.loc[runs["status"] != "ok", ["variant", "velocity_m_s", "run_index", "error"]].reset_index(drop=True)

    def unhealthy(self, out: str | os.PathLike):
        """The simulations stored in the campaign folder ``out`` that failed a health check
        (:func:`hexadyn.health.check`): a DataFrame of ``variant``, ``velocity_m_s``,
        ``run_index`` and ``warnings`` (the list of the failed checks), in run order. Runs
        stored by a hexadyn that did not record the checks (``warnings`` NULL) are not listed."""
        runs = self._runs(out)
        runs = runs.loc[runs["status"] == "ok", ["variant", "velocity_m_s", "run_index", WARNINGS_COLUMN]]
        runs[WARNINGS_COLUMN] = [json.loads(w) if isinstance(w, str) else [] for w in runs[WARNINGS_COLUMN]]  # NULL (NaN): not checked
        return runs[runs[WARNINGS_COLUMN].map(bool)].reset_index(drop=True)

    def _runs(self, out: str | os.PathLike):
        """Every run stored in the campaign folder ``out`` (:meth:`CampaignStore.runs`)."""
        with CampaignStore.open(out, self.configuration(), self.distributions.joints) as store:
            return store.runs()

    def _simulate(self, store: CampaignStore, executor: Executor, pending: list[RunKey], total: int, progress: Progress) -> None:
        def stored(key: RunKey, outcome: dict[str, Any]) -> list[tuple[str, dict[str, Any]]]:
            velocity = self.velocities_m_per_s[key.velocity_index]
            store.add(key, velocity, self.friction(key), outcome)
            return [(f"{key.variant}, V_x = {velocity} m/s, run {key.run_index}", outcome)]

        tasks: Iterable = ((key, self.overrides(key)) for key in pending)
        # execution.simulate_run as the module holds it when the campaign starts, so that a
        # benchmark's timed replacement is what the workers call.
        simulate = functools.partial(execution.simulate_run, os.fspath(self.scenario))
        execution.run_and_store(executor, simulate, tasks, stored, name=self.scenario_name, total=total, done=total - len(pending), progress=progress)


def run_campaign(
    out: str | os.PathLike,
    scenario: str | os.PathLike = DEFAULT_SCENARIO,
    *,
    velocities: Sequence[float] | None = None,
    runs_per_velocity: int | None = None,
    variants: Sequence[str] | None = None,
    seed: int = 0,
    workers: int | None = None,
    ray: str | None = None,
    progress: Progress = True,
):
    """:meth:`Campaign.create` then :meth:`Campaign.run`: returns Table 6.8 as a DataFrame."""
    campaign = Campaign.create(scenario, velocities=velocities, runs_per_velocity=runs_per_velocity, variants=variants, seed=seed)
    return campaign.run(out, workers=workers, ray=ray, progress=progress)
