"""TOML texts read on the Python side: the scenario kept with results (its ``[model]`` flags)
and a scenario file's own fields. Robot descriptions are read by the engine only
(``_core.robot_properties``)."""

from __future__ import annotations

from typing import Any

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

__all__ = ["parse_toml"]


def parse_toml(text: str, what: str) -> dict[str, Any]:
    """Parses a TOML text; `what` names it in the ValueError raised for invalid TOML."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{what} is not valid TOML: {exc}") from None
