"""hexadyn: multiphysics dynamics and gait control of six-legged walking robots.

The numerics live in the Rust engine (``hexadyn._core``); this package is the user's front::

    import hexadyn
    hexadyn.list_scenarios()                         # the shipped scenarios' names
    results = hexadyn.simulate("stand_six_legs")     # a shipped scenario or a scenario file
    results.timeseries["Z"]                          # pandas DataFrame indexed by t (s)
    results.units["Z"], results.summary["body_height_change_m"]

    s = hexadyn.Scenario.load("validation_tripod_1_5cm")   # edit a scenario, then run it
    s.set("gait.heading.vx_m_s", 0.02).rename("walk_2cm", "The validation walk at 2 cm/s")
    saved = s.simulate(save=True)                    # results/walk_2cm (-2, -3... if it exists)
    hexadyn.Results.load("results/walk_2cm")

    from hexadyn import report                       # a results folder of your choice
    report.save(results, "results/stand")            # atomic; FileExistsError if it exists

The modules build on each other in one direction, each importing only modules listed before
it: ``vocabulary``, ``atomic``, ``health`` (column names, atomic writes, health checks of a run),
``results`` (the data), ``energy`` (the power analysis), ``plots`` (figures), ``report`` (the
results folder), ``runner`` (:func:`simulate`), ``scenario`` (:class:`Scenario`), then
``compare``, ``montecarlo`` and ``cli``.
"""

from __future__ import annotations

from hexadyn._core import __version__
from hexadyn.results import Results
from hexadyn.runner import SCENARIOS_DIR, list_scenarios, resolve_scenario, scenario_files, simulate
from hexadyn.scenario import Scenario

__all__ = [
    "__version__",
    "DEFAULT_ROBOT",
    "Results",
    "SCENARIOS_DIR",
    "Scenario",
    "list_scenarios",
    "resolve_scenario",
    "scenario_files",
    "simulate",
]

#: Name of the default robot (``scenario.robot`` when a scenario names none: the AMRU5 of the
#: thesis), one of ``_core.SHIPPED_ROBOTS``; ``_core.shipped_robot_text(DEFAULT_ROBOT)`` is its
#: description, embedded in the engine.
DEFAULT_ROBOT = "amru5"
