"""Friction identification from logged experiments (thesis Chapter 5, Sections 5.1-5.4).

The experiments are shipped scenarios (``identification_q_r``, ``_q_v``, ``_q_h``: the sawtooth
campaigns of Table 5.2; ``identification_breakaway_plus``/``_minus``: Section 5.3;
``identification_loaded_q_h``: Section 5.4; ``identification_loaded_q_v``: the efficiencies of
the efficiency-based friction, Chapter 8 prospect; on the PhantomX's serial legs the sawtooth campaigns
``phantomx_identification_coxa``, ``_femur``, ``_tibia``). :func:`identify` reads their results
folders, or CSV logs of a real robot (:mod:`hexadyn.identify.reading`), and fits the friction
parameters with their confidence intervals; :func:`hexadyn.identify.output.save` writes the tables of Tables
5.3-5.5, the figures of Fig. 5.3-5.5, the ``[model.joint_friction]`` fragment and the friction
statistics of the Monte Carlo runs. ``hexadyn identify`` is the command line
(docs/identification.md).

Modules: ``logs`` (the log and its columns), ``reading`` (results folders and CSV files),
``checks`` (what a log and a fit must be to be identified honestly: numbers, a constant time
step, every leg of a campaign, physical magnitudes, the friction's sign), ``sensors`` (the
current sensor chain of Section 5.6.2 and the encoders, for preprocessing and test logs),
``sections`` (constant-velocity sections), ``torques`` (friction torque from current and leg
model), ``fit`` (least squares and confidence intervals), ``steady`` (Eq. 5.3-5.4, 5.12),
``breakaway`` (Eq. 5.10-5.11), ``identification`` (the whole set of logs), ``tables``,
``fragment``, ``figures``, ``output``, ``command``.
"""

from importlib import import_module

#: Public names -> their module, imported on first use: `hexadyn --help` and the other commands
#: do not pay for numpy, pandas and scipy (the CLI registers `hexadyn.identify.command`).
_EXPORTS = {
    "BreakawayOptions": "breakaway",
    "Identification": "identification",
    "identify": "identification",
    "IdentifyError": "logs",
    "Log": "logs",
    "load_log": "reading",
    "SectionOptions": "sections",
}

__all__ = ["BreakawayOptions", "Identification", "IdentifyError", "Log", "SectionOptions", "identify", "load_log"]


def __getattr__(name: str):
    if name not in _EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(import_module(f"{__name__}.{_EXPORTS[name]}"), name)
