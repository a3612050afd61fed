"""Design studies (``hexadyn study STUDY.toml``; docs/studies.md): how the outputs of a walk
(the specific resistance, the tracking errors, the longest deadlock, any figure of its summary)
respond to the scenario fields it varies, and how sensitive they are to each::

    from hexadyn.study import Study
    study = Study.create("python/hexadyn/studies/specific_resistance_1_5cm.toml")
    results = study.run("results/study")        # resumes if interrupted
    results.indices                              # Sobol' S1, ST and their confidence intervals

Modules: :mod:`~hexadyn.study.spec` (the study file), :mod:`~hexadyn.study.design` (the runs of
a grid, a Latin hypercube, a Sobol' or a Morris design), :mod:`~hexadyn.study.study` (the runs,
simulated and stored by :mod:`hexadyn.montecarlo`'s machinery), :mod:`~hexadyn.study.analysis`
(the indices), :mod:`~hexadyn.study.figures` and :mod:`~hexadyn.study.command` (the command).
"""

import importlib
from typing import Any

#: The names of the package -> their module, imported on first use: `hexadyn --help` and the
#: other commands do not pay for numpy and the Monte Carlo machinery.
_EXPORTS = {
    **dict.fromkeys(["Design", "Parameter", "StudySpec", "parse_study", "read_study"], "hexadyn.study.spec"),
    **dict.fromkeys(["FunctionModel", "ScenarioModel", "Study", "StudyResults", "run_study"], "hexadyn.study.study"),
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name not in _EXPORTS:
        raise AttributeError(f"module 'hexadyn.study' has no attribute {name!r}")
    return getattr(importlib.import_module(_EXPORTS[name]), name)
