"""A scenario as an object: a scenario file (shipped or the user's) and the fields set on it::

    from hexadyn import Scenario
    s = Scenario.load("validation_tripod_1_5cm")       # a shipped name, or Scenario.from_file(path)
    s.set("gait.heading.vx_m_s", 0.02)                  # checked by the engine at once
    s.rename("walk_2cm", "The validation walk at 2 cm/s")
    print(s.to_toml())                                  # the scenario that will run
    results = s.simulate(save=True)                     # results/walk_2cm, numbered if it exists

Fields are set by their dotted name, as the ``overrides=`` of :func:`hexadyn.simulate` (which
this object passes on) and validated by the engine like a scenario file: a wrong field or value
is one ValueError line naming the field, the value and what is allowed, and leaves the
scenario as it was. A scenario with fields set but not renamed says so in its description
(``... [derived: gait.heading.vx_m_s = 0.02]``), so that its results do not pass for the
original's.
"""

from __future__ import annotations

import copy
import errno
import os
from pathlib import Path
from typing import Any, Mapping, Sequence

from hexadyn import _core
from hexadyn.results import Results
from hexadyn.runner import Progress, resolve_scenario, simulate

__all__ = ["Scenario"]

#: The fields :meth:`Scenario.rename` sets: setting them is not a change of the scenario itself.
NAME_FIELD = "scenario.name"
DESCRIPTION_FIELD = "scenario.description"
RENAMING = (NAME_FIELD, DESCRIPTION_FIELD)


class Scenario:
    """A scenario file and the fields set on it (see the module's documentation)."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        """The scenario of an existing file, validated (ValueError otherwise); prefer
        :meth:`load` or :meth:`from_file`."""
        self.path = Path(path)
        self._fields: dict[str, Any] = {}
        self._original: dict[str, Any] = _core.load_scenario(os.fspath(self.path))
        self._info = self._original

    @classmethod
    def load(cls, scenario: str | os.PathLike[str]) -> Scenario:
        """A shipped scenario by name (``"path_spline"``, see :func:`hexadyn.list_scenarios`) or
        a scenario file; FileNotFoundError naming the shipped scenarios otherwise."""
        return cls(resolve_scenario(scenario))

    @classmethod
    def from_file(cls, path: str | os.PathLike[str]) -> Scenario:
        """The scenario file at `path` (never a shipped name); FileNotFoundError if missing."""
        if not Path(path).is_file():
            raise FileNotFoundError(errno.ENOENT, "no such scenario file", os.fspath(path))
        return cls(path)

    @property
    def name(self) -> str:
        """``scenario.name``: names the results (``summary["scenario"]``, the results folder)."""
        return str(self._info["name"])

    @property
    def description(self) -> str:
        """``scenario.description``, with the derived note of an edited, unrenamed scenario."""
        return str(self._info["description"])

    @property
    def duration_s(self) -> float:
        """Simulated time (s)."""
        return float(self._info["duration_s"])

    @property
    def fields(self) -> dict[str, Any]:
        """The fields set on the file, by dotted name, in the order they were first set."""
        return dict(self._fields)

    @property
    def derived(self) -> bool:
        """Whether fields of the scenario itself were set without :meth:`rename`."""
        return _derived(self._fields)

    def overrides(self) -> dict[str, Any]:
        """What runs: the fields set, plus the derived description (see :attr:`derived`); the
        ``overrides=`` of :func:`hexadyn.simulate`."""
        return self._effective(self._fields)

    def set(self, field: str, value: Any) -> Scenario:
        """Sets a field by dotted name (``"gait.period_s"``, ``"model.friction"``,
        ``"model.joint_friction.q_h"`` with a dict) and returns the scenario, for chaining.
        Values: bool, int, float, str, lists and dicts of those. Raises ValueError (TypeError
        for a value of another type) naming the field, the value and what is allowed; the
        scenario is then unchanged."""
        return self.update({field: value})

    def update(self, fields: Mapping[str, Any]) -> Scenario:
        """Sets several fields at once (``{"gait.period_s": 12, "model.friction": "lugre"}``,
        in order: a later one of the same name wins), checked by the engine together as
        :meth:`set` checks one, and returns the scenario; unchanged on an error."""
        return self._update({field: copy.deepcopy(value) for field, value in fields.items()})

    def rename(self, name: str, description: str) -> Scenario:
        """Gives the scenario a name and a description of its own, so that an edited scenario
        no longer passes for the original; returns the scenario."""
        return self._update({NAME_FIELD: name, DESCRIPTION_FIELD: description})

    def to_toml(self) -> str:
        """The TOML text that runs: the file's as it is, or with fields set the effective text
        (comments dropped, a header listing the fields set). Relative robot and terrain files
        in it are taken from the folder of :attr:`path`: keep a written copy there."""
        return str(self._info["text"])

    def simulate(
        self,
        out: str | os.PathLike[str] | None = None,
        progress: Progress = True,
        *,
        save: bool = False,
        overwrite: bool = False,
        plots: bool = False,
        legs: Sequence[int] | None = None,
        formats: Sequence[str] | None = None,
    ) -> Results:
        """Runs the scenario: :func:`hexadyn.simulate` with its fields as ``overrides``
        (``save=True``: the results folder ``results/<name>``, numbered like the CLI's)."""
        return simulate(self.path, out, progress, save=save, overwrite=overwrite, overrides=self.overrides(), plots=plots, legs=legs, formats=formats)

    def __repr__(self) -> str:
        return f"Scenario({os.fspath(self.path)!r}, name={self.name!r}, fields={self._fields!r})"

    def _update(self, changes: dict[str, Any]) -> Scenario:
        """Sets `changes` once the engine has validated the scenario with them."""
        fields = {**self._fields, **changes}
        self._info = _core.load_scenario(os.fspath(self.path), self._effective(fields))
        self._fields = fields
        return self

    def _effective(self, fields: dict[str, Any]) -> dict[str, Any]:
        """`fields` and, for a derived scenario, its description saying so."""
        if not _derived(fields):
            return dict(fields)
        changes = ", ".join(f"{f} = {v!r}" for f, v in fields.items() if f not in RENAMING)
        return {**fields, DESCRIPTION_FIELD: f"{self._original['description']} [derived: {changes}]"}


def _derived(fields: dict[str, Any]) -> bool:
    """Fields of the scenario itself set, and no description of its own."""
    return DESCRIPTION_FIELD not in fields and any(f not in RENAMING for f in fields)
