"""Scenario fields set by their dotted names (``hexadyn --set KEY=VALUE``, a study's
``[fixed]`` and ``[parameters]``, the ``overrides=`` of :func:`hexadyn.simulate`): the TOML
values such a field can hold."""

from __future__ import annotations

from typing import Any

__all__ = ["is_field_value"]


def is_field_value(value: Any) -> bool:
    """Whether a TOML value is one a scenario field can hold: a boolean, a number, a string, or
    an array or inline table of those (TOML's dates and times are not)."""
    if isinstance(value, list):
        return all(is_field_value(v) for v in value)
    if isinstance(value, dict):
        return all(is_field_value(v) for v in value.values())
    return isinstance(value, (bool, int, float, str))
