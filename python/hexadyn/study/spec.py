"""The study file (docs/studies.md): what a design study varies, how it samples and what it
analyses, read and validated like a scenario file.

A study file is TOML with four tables: ``[study]`` (the base scenario, the outputs, the seed),
``[fixed]`` (scenario fields set for every run), ``[design]`` (the method and its sizes) and
``[parameters."<dotted key>"]`` (one per varied field, its range or distribution). Every value
is checked here; an error is one line naming the file, the field, the value and what is
allowed. Whether a dotted key is a field of the scenario is the engine's to say
(:meth:`hexadyn.study.Study.create` loads the scenario with the study's overrides).
"""

from __future__ import annotations

import json
import math
import os
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, NoReturn

from hexadyn.fields import is_field_value

__all__ = ["DISTRIBUTIONS", "METHODS", "Design", "Parameter", "StudySpec", "parse_study", "read_study"]

#: The designs: a full factorial grid, a Latin hypercube, Sobol' with Saltelli's scheme, Morris.
METHODS = ("grid", "latin", "sobol", "morris")

#: The distributions of a sampled parameter -> the keys that define it (SALib's names after).
DISTRIBUTIONS = {
    "uniform": ("range",),
    "normal": ("mean", "std"),
    "truncated_normal": ("range", "mean", "std"),
    "lognormal": ("mean", "std"),
}
_SALIB_DISTRIBUTIONS = {"uniform": "unif", "normal": "norm", "truncated_normal": "truncnorm", "lognormal": "lognorm"}

#: The keys of ``[design]`` each method takes (``method`` besides), with their defaults.
DESIGN_KEYS: dict[str, dict[str, Any]] = {
    "grid": {"levels": None},
    "latin": {"samples": None},
    "sobol": {"samples": None, "second_order": False, "confidence": 0.95, "resamples": 1000},
    "morris": {"samples": None, "levels": 4, "confidence": 0.95, "resamples": 1000},
}

#: The most runs a study may hold (as a Monte Carlo campaign).
MAX_RUNS = 1_000_000

#: A dotted key: identifiers joined by dots (``gait.period_s``, ``model.joint_friction.q_h.tau_f_d_plus``).
_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*\Z")
#: Column names of the runs table a parameter or an output may not take.
RESERVED = ("run_index", "status", "error")


@dataclass(frozen=True)
class Parameter:
    """A varied field: its dotted ``key`` and either a ``distribution`` (sampled designs; the
    grid takes ``uniform`` only, over ``levels`` points of ``range``) or explicit grid
    ``values``."""

    key: str
    distribution: str | None = "uniform"
    range: tuple[float, float] | None = None
    mean: float | None = None
    std: float | None = None
    values: tuple[float, ...] | None = None
    levels: int | None = None

    def salib(self) -> tuple[str, list[float]]:
        """SALib's distribution name and its ``bounds`` entry."""
        assert self.distribution is not None
        numbers: dict[str, list[Any]] = {"range": list(self.range or ()), "mean": [self.mean], "std": [self.std]}
        return _SALIB_DISTRIBUTIONS[self.distribution], [x for k in DISTRIBUTIONS[self.distribution] for x in numbers[k]]

    def grid(self, levels: int) -> tuple[float, ...]:
        """The grid's values of the parameter: its ``values``, or ``levels`` (its own, else the
        design's) evenly spaced points of its range, both ends included."""
        if self.values is not None:
            return self.values
        assert self.range is not None
        n = self.levels or levels
        lo, hi = self.range
        return tuple(float(lo + (hi - lo) * i / (n - 1)) for i in range(n)) if n > 1 else ((lo + hi) / 2,)

    def nominal(self) -> float:
        """A typical value (the middle of the range or of the values, the mean; the median of
        a lognormal), for the check of the study's overrides before any run."""
        if self.values is not None:
            return self.values[len(self.values) // 2]
        if self.distribution == "lognormal":
            return math.exp(self.mean or 0.0)
        if self.mean is not None:
            return self.mean
        assert self.range is not None
        return (self.range[0] + self.range[1]) / 2


@dataclass(frozen=True)
class Design:
    """The ``[design]`` table: the method and its sizes (``None``: not taken by the method)."""

    method: str
    samples: int | None = None
    levels: int | None = None
    second_order: bool = False
    confidence: float = 0.95
    resamples: int = 1000


@dataclass(frozen=True)
class StudySpec:
    """A validated study: see the module and docs/studies.md for every field."""

    source: str
    name: str
    description: str
    scenario: str
    outputs: tuple[str, ...]
    design: Design
    parameters: tuple[Parameter, ...]
    fixed: dict[str, Any] = field(default_factory=dict)
    seed: int = 0
    folder: Path = Path(".")

    def configuration(self) -> dict[str, Any]:
        """The study as JSON data (what must match to resume a study folder)."""
        return {
            "name": self.name,
            "outputs": list(self.outputs),
            "seed": self.seed,
            "fixed": self.fixed,
            "design": {k: v for k, v in vars(self.design).items() if v is not None},
            "parameters": [{k: v for k, v in vars(p).items() if v is not None} for p in self.parameters],
        }


def read_study(path: str | os.PathLike) -> StudySpec:
    """Reads and validates a study file. Raises ValueError (OSError for a missing file) with
    one line naming the file, the field, the value and what is allowed."""
    from hexadyn import inputs

    path = Path(path)
    try:
        table = tomllib.loads(inputs.read_text(path))
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path}: not a TOML study file: {exc}") from exc
    return parse_study(table, os.fspath(path), name=path.stem, folder=path.parent)


def parse_study(table: Mapping[str, Any], source: str = "study", *, name: str = "study", folder: str | os.PathLike = ".") -> StudySpec:
    """Validates the tables of a study (a study file as read by ``tomllib``, or the same
    dictionary built in Python); `source` names it in errors, `name` is its default name,
    `folder` the folder a relative scenario file is taken from."""
    check = _Checker(source)
    check.keys("", table, ("study", "fixed", "design", "parameters"), required=("study", "design", "parameters"))
    study = check.table("study", table["study"])
    check.keys("study", study, ("name", "description", "scenario", "outputs", "seed"), required=("outputs",))
    outputs = check.names("study.outputs", study["outputs"])
    fixed = check.table("fixed", table.get("fixed", {}))
    for key, value in fixed.items():
        check.key("fixed", key)
        if not is_field_value(value):
            check.bad(f"fixed.\"{key}\"", value, "a value a scenario field holds: a boolean, a number, a string, or a list or table of them (not a date or a time)")
    design = _design(check, check.table("design", table["design"]))
    parameters = check.table("parameters", table["parameters"])
    if not parameters:
        check.bad("parameters", parameters, "one or more tables [parameters.\"<dotted key>\"]")
    params = tuple(_parameter(check, key, spec, design.method) for key, spec in parameters.items())
    for p in params:
        if p.key in fixed:
            check.bad(f"fixed.\"{p.key}\"", fixed[p.key], "a field that is not also a parameter")
        if p.key in outputs:
            check.bad(f"parameters.\"{p.key}\"", p.key, "a name that is not also an output")
    if design.method == "grid" and design.levels is None and any(p.values is None and p.levels is None for p in params):
        check.bad("design.levels", None, "an integer >= 2 (the grid's points per parameter), or `levels` or `values` in every parameter")
    spec = StudySpec(
        source=source,
        name=check.string("study.name", study.get("name", name)),
        description=check.string("study.description", study.get("description", "")),
        scenario=check.string("study.scenario", study.get("scenario", "")) if "scenario" in study else "",
        outputs=outputs,
        design=design,
        parameters=params,
        fixed=dict(fixed),
        seed=check.integer("study.seed", study.get("seed", 0), 0),
        folder=Path(folder),
    )
    runs = run_count(spec)
    if runs > MAX_RUNS:
        check.bad("design", spec.configuration()["design"], f"at most {MAX_RUNS} runs ({runs} with these sizes)")
    return spec


def run_count(spec: StudySpec) -> int:
    """The runs of a study's design: the grid's product of levels, the Latin hypercube's
    samples, Sobol's N (D + 2) or N (2 D + 2) with second-order indices, Morris' r (D + 1)."""
    d, design = len(spec.parameters), spec.design
    if design.method == "grid":
        return math.prod(len(p.grid(design.levels or 0)) for p in spec.parameters)
    assert design.samples is not None
    if design.method == "latin":
        return design.samples
    if design.method == "sobol":
        return design.samples * ((2 * d + 2) if design.second_order else (d + 2))
    return design.samples * (d + 1)


def _design(check: _Checker, table: Mapping[str, Any]) -> Design:
    method = table.get("method")
    if not isinstance(method, str) or method not in METHODS:
        check.bad("design.method", method, f"one of {', '.join(METHODS)}")
    taken = DESIGN_KEYS[method]
    check.keys("design", table, ("method", *taken), required=tuple(k for k, v in taken.items() if v is None and k == "samples"))
    values = {**taken, **{k: v for k, v in table.items() if k != "method"}}
    if "samples" in taken:
        samples = check.integer("design.samples", values["samples"], 2)
        if method == "sobol" and samples & (samples - 1):
            check.bad("design.samples", samples, "a power of two (the Sobol' sequence's balance), e.g. 64, 128, 256")
        values["samples"] = samples
    if values.get("levels") is not None:
        values["levels"] = check.integer("design.levels", values["levels"], 2)
        if method == "morris" and values["levels"] % 2:
            check.bad("design.levels", values["levels"], "an even integer >= 2 (Morris' grid levels)")
    if "second_order" in taken and not isinstance(values["second_order"], bool):
        check.bad("design.second_order", values["second_order"], "true or false")
    if "confidence" in taken:
        confidence = values["confidence"]
        if not _number(confidence) or not 0 < confidence < 1:
            check.bad("design.confidence", confidence, "a number in (0, 1), e.g. 0.95")
        values["resamples"] = check.integer("design.resamples", values["resamples"], 10)
    return Design(method=method, **{k: values[k] for k in taken})


def _parameter(check: _Checker, key: str, spec: Any, method: str) -> Parameter:
    where = f"parameters.\"{key}\""
    check.key("parameters", key)
    spec = check.table(where, spec)
    if method == "grid":
        check.keys(where, spec, ("range", "levels", "values", "distribution"))
        if spec.get("distribution", "uniform") != "uniform":
            check.bad(f"{where}.distribution", spec["distribution"], "uniform (a grid spans a range) or no distribution")
        if ("values" in spec) == ("range" in spec) or ("values" in spec and "levels" in spec):
            check.bad(where, spec, "either `range = [low, high]` (with `levels`, else design.levels) or `values = [...]`")
        if "values" in spec:
            values = spec["values"]
            if not isinstance(values, list) or not values or not all(_number(v) for v in values) or len(set(values)) != len(values):
                check.bad(f"{where}.values", values, "a list of distinct finite numbers")
            return Parameter(key, None, values=tuple(float(v) for v in values))
        levels = check.integer(f"{where}.levels", spec["levels"], 2) if "levels" in spec else None
        return Parameter(key, "uniform", range=_range(check, where, spec["range"]), levels=levels)
    distribution = spec.get("distribution", "uniform")
    if distribution not in DISTRIBUTIONS:
        check.bad(f"{where}.distribution", distribution, f"one of {', '.join(DISTRIBUTIONS)}")
    needs = DISTRIBUTIONS[distribution]
    check.keys(where, spec, ("distribution", *needs), required=needs)
    numbers: dict[str, Any] = {}
    if "range" in needs:
        numbers["range"] = _range(check, where, spec["range"])
    for k in ("mean", "std"):
        if k in needs:
            if not _number(spec[k]) or (k == "std" and spec[k] <= 0):
                check.bad(f"{where}.{k}", spec[k], "a finite number" + (" > 0" if k == "std" else ""))
            numbers[k] = float(spec[k])
    if distribution == "truncated_normal" and not numbers["range"][0] <= numbers["mean"] <= numbers["range"][1]:
        check.bad(f"{where}.mean", numbers["mean"], f"a mean within the range {list(numbers['range'])}")
    return Parameter(key, distribution, **numbers)


def _range(check: _Checker, where: str, value: Any) -> tuple[float, float]:
    if not isinstance(value, list) or len(value) != 2 or not all(_number(v) for v in value) or not value[0] < value[1]:
        check.bad(f"{where}.range", value, "[low, high], two finite numbers with low < high")
    return float(value[0]), float(value[1])


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


class _Checker:
    """Raises the one-line errors of a study named `source`."""

    def __init__(self, source: str) -> None:
        self.source = source

    def bad(self, field: str, value: Any, allowed: str) -> NoReturn:
        shown = json.dumps(value, default=str, ensure_ascii=False)
        raise ValueError(f"{self.source}: field `{field}` = {shown if len(shown) <= 80 else shown[:77] + '...'}: allowed: {allowed}")

    def keys(self, where: str, table: Mapping[str, Any], allowed: tuple[str, ...], required: tuple[str, ...] = ()) -> None:
        for key in table:
            if key not in allowed:
                self.bad(f"{where}.{key}" if where else key, table[key], f"the keys {', '.join(allowed)}" + (f" of [{where}]" if where else " (tables of a study file)"))
        for key in required:
            if key not in table:
                raise ValueError(f"{self.source}: field `{where + '.' if where else ''}{key}` is missing; it is required" + (f" in [{where}]" if where else ""))

    def table(self, where: str, value: Any) -> Mapping[str, Any]:
        if not isinstance(value, dict):
            self.bad(where, value, "a table")
        return value

    def string(self, where: str, value: Any) -> str:
        if not isinstance(value, str) or (where != "study.description" and not value.strip()):
            self.bad(where, value, "a non-empty string" if where != "study.description" else "a string")
        return value

    def integer(self, where: str, value: Any, least: int) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or value < least:
            self.bad(where, value, f"an integer >= {least}")
        return value

    def key(self, where: str, key: str) -> None:
        if not _KEY.match(key) or key in RESERVED:
            self.bad(f"{where}.\"{key}\"", key, "a dotted key of the scenario (`gait.period_s`: identifiers joined by dots), not " + ", ".join(RESERVED))

    def names(self, where: str, value: Any) -> tuple[str, ...]:
        if not isinstance(value, list) or not value or not all(isinstance(v, str) and v.isidentifier() and v not in RESERVED for v in value) or len(set(value)) != len(value):
            self.bad(where, value, "a list of distinct summary entries (`specific_resistance`, `tracking_error_xy_max_m`, ...)")
        return tuple(value)
