"""What the identification hands to a simulation: the ``[model.joint_friction]`` fragment of a
scenario file (docs/scenario-format.md) and the friction statistics of the Monte Carlo runs
(Table 6.7, ``hexadyn montecarlo --friction-stats``).

The fragment gives every leg the same friction, the mean over the legs and the campaigns of
each identified parameter (as the Monte Carlo runs of Section 6.5 do). The Section 6.1 rule
applies: a negative viscous slope is not physical and is written as 0 (the measured value in
a comment). The breakaway torques of the vertical joints are written as comments: the scenario
fragment has no stiction key (the robot description holds them, Table 5.4).

The efficiency law (:mod:`hexadyn.identify.efficiency`, from logs at two foot loads or more)
has its own fragment, its no-load friction and efficiencies (mean over the legs), to use with
``friction = "efficiency"``; the statistics of its efficiencies join the Monte Carlo inputs
(the ``efficiency`` variant draws them).

A serial robot's drives have one dry friction and one viscous slope for both senses
(``tau_f_d``, ``f_v``): the fragment gives the mean of the two senses (the senses in a comment).

The statistics follow the construction of Table 6.7 (``description/monte_carlo.rs``): per
parameter, mu* is the mean of the leg means (each the mean over the campaigns, Eq. 5.8) and
sigma* the (n - 1) standard deviation of the leg means (Eq. 5.9).
"""

from __future__ import annotations

import math

import numpy as np
import tomlkit
from tomlkit.items import Table

from hexadyn.identify.efficiency import EFFICIENCY_KEYS
from hexadyn.identify.identification import Identification
from hexadyn.identify.logs import LEGS
from hexadyn.identify.tables import mean_sigma

__all__ = ["leg_means", "efficiency_means", "joint_friction_fragment", "efficiency_fragment", "friction_stats", "friction_stats_toml"]

#: Fragment key -> (direction, attribute of the fit).
STEADY_KEYS = {"tau_f_d_plus": (1, "tau_f_d"), "f_v_plus": (1, "f_v"), "tau_f_d_minus": (-1, "tau_f_d"), "f_v_minus": (-1, "f_v")}
LOAD_KEYS = {"a_2_plus": (1, "a_2"), "a_1_plus": (1, "a_1"), "a_2_minus": (-1, "a_2"), "a_1_minus": (-1, "a_1")}
#: A serial drive's keys, one dry friction and one viscous slope for both senses
#: (docs/robot-format.md): key -> (key of the plus sense, of the minus sense, sign of the minus
#: one). INTERPRETATION: the mean of the two senses (the thesis fits them apart, Table 5.3).
SERIAL_KEYS = {"tau_f_d": ("tau_f_d_plus", "tau_f_d_minus", -1.0), "f_v": ("f_v_plus", "f_v_minus", 1.0)}


def _sense_means(ident: Identification, joint: str) -> dict[str, list[float]]:
    """Key of Table 5.3 -> the mean over the campaigns of each leg (NaN for a leg without)."""
    return {key: [mean_sigma([getattr(f, attr).value for f in ident.unloaded(joint, leg, direction)])[0] for leg in LEGS] for key, (direction, attr) in STEADY_KEYS.items()}


def _drive_keys(ident: Identification, senses: dict[str, list[float]]) -> dict[str, list[float]]:
    """Per-sense values (keys of Table 5.3, one per leg) under the keys of the robot's drives: a
    serial drive's one dry friction and one viscous slope (:data:`SERIAL_KEYS`); the other
    keys kept."""
    if ident.leg_mechanism != "serial":
        return senses
    serial = {key: [(p + sign * m) / 2 for p, m in zip(senses[plus], senses[minus])] for key, (plus, minus, sign) in SERIAL_KEYS.items()}
    return serial | {key: values for key, values in senses.items() if key not in STEADY_KEYS}


def leg_means(ident: Identification, joint: str) -> dict[str, list[float]]:
    """Fragment key -> the mean over the campaigns of each leg that has it."""
    out = _drive_keys(ident, _sense_means(ident, joint))
    out = {key: [v for v in values if not math.isnan(v)] for key, values in out.items()}
    if joint == "q_h":
        for key, (direction, attr) in LOAD_KEYS.items():
            out[key] = [getattr(f, attr).value for f in ident.load_fits if f.direction == direction]
    return {k: v for k, v in out.items() if v}


def efficiency_means(ident: Identification, joint: str) -> dict[str, list[float]]:
    """Key of the efficiency law (``tau_f_d_plus``... or a serial drive's ``tau_f_d``, ``f_v``;
    ``eta_forward``, ``eta_backward``) -> the value of each leg whose fit determined it."""
    fits = [f for f in ident.efficiency_fits if f.joint == joint]
    out = _drive_keys(ident, {key: [getattr(f, attr).value for f in fits] for key, attr in EFFICIENCY_KEYS.items() if key in STEADY_KEYS})
    for key in ("eta_forward", "eta_backward"):
        values = [e.value for e in (getattr(f, EFFICIENCY_KEYS[key]) for f in fits) if e is not None]
        if values:
            out[key] = values
    return out


def _physical(key: str, value: float) -> float:
    """The Section 6.1 rule and the signs the scenario fields allow: only a dry friction or a
    load coefficient of the minus sense is negative."""
    if key.startswith("eta_"):
        return min(value, 1.0)  # 0 < eta <= 1; a fit that gives no eta > 0 is no efficiency law
    return min(value, 0.0) if key.endswith("_minus") and not key.startswith("f_v") else max(value, 0.0)


def joint_friction_fragment(ident: Identification) -> str:
    """The ``[model.joint_friction.<joint>]`` tables of the identified joints (TOML text)."""
    doc = _document(
        "Joint friction identified by `hexadyn identify` (thesis Sections 5.2-5.4): the mean over",
        "the legs and the campaigns, the same for every leg. Paste into a scenario file, or",
        "pass its keys as overrides (docs/identification.md).",
    )
    joints = tomlkit.table(is_super_table=True)
    for joint in ident.joints():
        means = leg_means(ident, joint)
        breakaways = [b for b in ident.breakaways if b.joint == joint]
        if not means and not breakaways:
            continue
        table = _means_table(means, "(Section 6.1)")
        if ident.leg_mechanism == "serial":
            senses = {key: float(np.nanmean(values)) for key, values in _sense_means(ident, joint).items()}
            table.add(tomlkit.comment("the two senses (Table 5.3), averaged above: " + ", ".join(f"{key} = {value:.6g}" for key, value in senses.items())))
        for b_dir, sign in ((1, "plus"), (-1, "minus")):
            for load in sorted({b.load_kg for b in breakaways}):
                values = [b.tau_f_s for b in breakaways if b.direction == b_dir and b.load_kg == load and not b.reason]
                if values:
                    table.add(tomlkit.comment(f"tau_f_s_{sign} at {load:g} kg (breakaway, Table 5.4; robot description [friction.{joint}.stiction]): {np.mean(values):.6g} N"))
        joints.add(joint, table)
    return _with_joint_friction(doc, joints)


def efficiency_fragment(ident: Identification) -> str:
    """The ``[model.joint_friction.<joint>]`` tables of the efficiency law (TOML text): the
    no-load friction and the efficiencies of the joints logged at two foot loads or more."""
    doc = _document(
        "Efficiency-based friction identified by `hexadyn identify` from sawtooth logs at several",
        "foot loads (the thesis' prospects, Chapter 8): the no-load friction N of Eq. 6.1 and the",
        "forward / backward efficiencies, the mean over the legs. Use with [model] friction =",
        '"efficiency" (docs/identification.md); the other joints keep the robot\'s.',
    )
    joints = tomlkit.table(is_super_table=True)
    for joint in dict.fromkeys(f.joint for f in ident.efficiency_fits):
        joints.add(joint, _means_table(efficiency_means(ident, joint), ""))
    return _with_joint_friction(doc, joints)


def _document(*comments: str) -> tomlkit.TOMLDocument:
    """A TOML document opening with `comments`, one line each."""
    doc = tomlkit.document()
    for line in comments:
        doc.add(tomlkit.comment(line))
    return doc


def _means_table(means: dict[str, list[float]], rule: str) -> Table:
    """A joint's table: the mean of each key's values (9 significant digits), a value the
    physical signs refuse forced to its bound with the measured one in a comment."""
    table = tomlkit.table()
    for key, values in means.items():
        value = float(np.mean(values))
        kept = float(f"{_physical(key, value):.9g}")
        table.add(key, kept)
        if _physical(key, value) != value:
            table[key].comment(f"measured {value:.6g}: not physical, forced to {kept:g} {rule}".rstrip())
    return table


def _with_joint_friction(doc: tomlkit.TOMLDocument, joints: Table) -> str:
    """`doc` with the tables of `joints` under ``[model.joint_friction]``, as text."""
    model = tomlkit.table(is_super_table=True)
    model.add("joint_friction", joints)
    doc.add(tomlkit.nl())
    doc.add("model", model)
    return tomlkit.dumps(doc)


def friction_stats(ident: Identification) -> dict[str, dict[str, float]]:
    """Scenario field -> {mu, sigma, legs} of every parameter identified on two legs or more."""
    stats = {}
    for joint in ident.joints():
        for key, values in leg_means(ident, joint).items():
            if len(values) < 2:
                continue
            mu, sigma = mean_sigma(values)
            stats[f"model.joint_friction.{joint}.{key}"] = {"mu": mu, "sigma": sigma, "legs": len(values)}
        for key, values in efficiency_means(ident, joint).items():
            if key.startswith("eta_") and len(values) >= 2:
                mu, sigma = mean_sigma(values)
                stats[f"model.joint_friction.{joint}.{key}"] = {"mu": _physical(key, mu), "sigma": sigma, "legs": len(values)}
    return stats


def friction_stats_toml(ident: Identification) -> str:
    """:func:`friction_stats` as the file ``hexadyn montecarlo --friction-stats`` reads."""
    doc = _document(
        "Friction statistics identified by `hexadyn identify` (Eq. 5.8-5.9, Table 6.7 layout):",
        "mu = mean of the leg means, sigma = (n - 1) standard deviation of the leg means.",
        "`hexadyn montecarlo SCENARIO --friction-stats THIS_FILE` draws from them.",
    )
    stats = tomlkit.table()
    for field, s in friction_stats(ident).items():
        entry = tomlkit.inline_table()
        entry.update({"mu": float(f"{s['mu']:.9g}"), "sigma": float(f"{s['sigma']:.9g}"), "legs": s["legs"]})
        stats.add(field, entry)
    doc.add(tomlkit.nl())
    doc.add("friction_stats", stats)
    return tomlkit.dumps(doc)
