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

from hexadyn.study.spec import Design, Parameter, StudySpec, parse_study, read_study
from hexadyn.study.study import FunctionModel, ScenarioModel, Study, StudyResults, run_study

__all__ = ["Design", "FunctionModel", "Parameter", "ScenarioModel", "Study", "StudyResults", "StudySpec", "parse_study", "read_study", "run_study"]
