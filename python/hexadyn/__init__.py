"""hexadyn: multiphysics dynamics and gait control of six-legged walking robots.

The numerics live in the Rust engine (``hexadyn._core``); this package is the user's front::

    import hexadyn
    results = hexadyn.simulate("stand_six_legs")     # a shipped scenario or a scenario file
    results.timeseries["Z"]                          # pandas DataFrame indexed by t (s)
    results.units["Z"], results.summary["body_height_change_m"]
    hexadyn.list_scenarios()                         # the shipped scenario files

    from hexadyn import report                       # the results folder with tables and plots
    report.save(results, "results/stand")            # atomic; hexadyn.Results.load(folder)

The modules build on each other in one direction, each importing only modules listed before
it: ``vocabulary``, ``atomic``, ``health`` (column names, atomic writes, health checks of a run),
``results`` (the data), ``energy`` (the power analysis), ``plots`` (figures), ``report`` (the
results folder), ``runner`` (:func:`simulate`), then ``compare``, ``montecarlo`` and ``cli``.
"""

from __future__ import annotations

from pathlib import Path

from hexadyn._core import __version__
from hexadyn.results import Results
from hexadyn.runner import SCENARIOS_DIR, list_scenarios, resolve_scenario, simulate

__all__ = [
    "__version__",
    "DEFAULT_ROBOT",
    "default_robot_path",
    "Results",
    "SCENARIOS_DIR",
    "list_scenarios",
    "resolve_scenario",
    "simulate",
]

#: Name of the default robot description (the AMRU5 of the thesis).
DEFAULT_ROBOT = "amru5"


def default_robot_path() -> Path | None:
    """Path of the default robot description file, or None while the package ships none.

    The engine is asked first (``_core.default_robot_path``, once the bindings expose it); then
    the package data ``hexadyn/robots/amru5.toml`` is looked for.
    """
    from hexadyn import _core

    from_engine = getattr(_core, "default_robot_path", None)
    if callable(from_engine):
        path = from_engine()
        return Path(path) if path else None
    packaged = Path(__file__).resolve().parent / "robots" / f"{DEFAULT_ROBOT}.toml"
    return packaged if packaged.is_file() else None
