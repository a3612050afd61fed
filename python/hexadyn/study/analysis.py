"""The sensitivity indices of a design study, from its runs (SALib's ``SALib.analyze``).

- Sobol' (``method = "sobol"``): per output and parameter the first-order index S1 and the
  total index ST with the half-widths of their bootstrap confidence intervals (``S1_conf``,
  ``ST_conf``, at ``design.confidence`` over ``design.resamples`` resamples); with
  ``second_order`` the second-order indices S2 of each pair of parameters too.
- Morris (``method = "morris"``): mu (mean elementary effect), mu* (mean of its absolute
  value, with ``mu_star_conf``) and sigma (its standard deviation).
- The grid and the Latin hypercube give no indices: their runs are read through the response
  curves (:mod:`hexadyn.study.figures`).

An output with a failed run or a value that is not finite gets no indices (NaN): Saltelli's
and Morris' estimators need every run of their design.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from hexadyn.study.design import problem
from hexadyn.study.spec import StudySpec

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["INDEX_COLUMNS", "SECOND_ORDER_COLUMNS", "indices", "second_order_indices"]

#: The columns of each method's indices table (after ``output`` and ``parameter``).
INDEX_COLUMNS = {"sobol": ("S1", "S1_conf", "ST", "ST_conf"), "morris": ("mu", "mu_star", "mu_star_conf", "sigma")}
#: The columns of the second-order Sobol' table.
SECOND_ORDER_COLUMNS = ("output", "parameter", "other_parameter", "S2", "S2_conf")


def indices(spec: StudySpec, runs: pd.DataFrame) -> pd.DataFrame | None:
    """One row per output and parameter with the method's :data:`INDEX_COLUMNS` (None for the
    grid and the Latin hypercube). `runs`: the study's runs in run order."""
    import pandas as pd

    method = spec.design.method
    if method not in INDEX_COLUMNS:
        return None
    rows = []
    for output in spec.outputs:
        result = _analyze(spec, runs, output)
        for i, p in enumerate(spec.parameters):
            values = {c: (float(result[c][i]) if result is not None else math.nan) for c in INDEX_COLUMNS[method]}
            rows.append({"output": output, "parameter": p.key, **values})
    return pd.DataFrame(rows, columns=["output", "parameter", *INDEX_COLUMNS[method]])


def second_order_indices(spec: StudySpec, runs: pd.DataFrame) -> pd.DataFrame | None:
    """The second-order Sobol' indices S2 of each pair of parameters (:data:`SECOND_ORDER_COLUMNS`),
    for a Sobol' design with ``second_order = true``; None otherwise."""
    import pandas as pd

    if spec.design.method != "sobol" or not spec.design.second_order:
        return None
    rows = []
    keys = [p.key for p in spec.parameters]
    for output in spec.outputs:
        result = _analyze(spec, runs, output)
        for i in range(len(keys)):
            for j in range(i + 1, len(keys)):
                s2, conf = (float(result["S2"][i, j]), float(result["S2_conf"][i, j])) if result is not None else (math.nan, math.nan)
                rows.append({"output": output, "parameter": keys[i], "other_parameter": keys[j], "S2": s2, "S2_conf": conf})
    return pd.DataFrame(rows, columns=SECOND_ORDER_COLUMNS)


def _analyze(spec: StudySpec, runs: pd.DataFrame, output: str) -> Any:
    """SALib's analysis of one output, or None if a run failed or a value is not finite."""
    y = runs[output].to_numpy(dtype=float)
    if (runs["status"] != "ok").any() or not np.isfinite(y).all():
        return None
    design = spec.design
    if design.method == "sobol":
        from SALib.analyze import sobol

        return sobol.analyze(
            problem(spec), y, calc_second_order=design.second_order, num_resamples=design.resamples, conf_level=design.confidence, seed=spec.seed
        )
    from SALib.analyze import morris

    x = runs[[p.key for p in spec.parameters]].to_numpy(dtype=float)
    return morris.analyze(problem(spec), x, y, num_resamples=design.resamples, conf_level=design.confidence, num_levels=design.levels, seed=spec.seed)
