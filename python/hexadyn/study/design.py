"""The runs of a design study: the parameter values of each run, from the study's design.

The grid is the full factorial product of every parameter's values (the first parameter
varying slowest); the Latin hypercube, the Sobol' sequence with Saltelli's cross-sampling and
Morris' trajectories come from SALib (``SALib.sample.latin``, ``.sobol``, ``.morris``), seeded
with the study's seed: the same study file gives the same runs on any machine.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np

from hexadyn.study.spec import StudySpec

__all__ = ["problem", "samples"]


def problem(spec: StudySpec) -> dict[str, Any]:
    """SALib's problem of a sampled study: the parameters' names, distributions and bounds."""
    dists, bounds = zip(*(p.salib() for p in spec.parameters))
    return {"num_vars": len(spec.parameters), "names": [p.key for p in spec.parameters], "bounds": list(bounds), "dists": list(dists)}


def samples(spec: StudySpec) -> np.ndarray:
    """The parameter values of every run (runs x parameters, in the order of
    ``spec.parameters``); as many rows as :func:`hexadyn.study.spec.run_count`."""
    design = spec.design
    if design.method == "grid":
        levels = [p.grid(design.levels or 0) for p in spec.parameters]
        return np.array(list(itertools.product(*levels)), dtype=float)
    from SALib.sample import latin, morris, sobol

    p = problem(spec)
    if design.method == "latin":
        return latin.sample(p, design.samples, seed=spec.seed)
    if design.method == "sobol":
        return sobol.sample(p, design.samples, calc_second_order=design.second_order, seed=spec.seed)
    return morris.sample(p, design.samples, num_levels=design.levels, seed=spec.seed)
