"""The options every ``hexadyn`` command spells the same way (docs/cli.md).

A command that writes an output, runs in parallel, draws a progress bar, writes figures or runs
a scenario takes the option of this module for it, whatever the command: ``-o/--out``,
``--overwrite``, ``--workers``, ``--format``, ``--no-progress``, ``--no-plots``, ``--strict``,
``--set KEY=VALUE``. Each is a :class:`CommonOption`, so that the table of docs/cli.md (command
x option) is checked against the commands themselves (tests/python/test_cli_grammar.py). What
may differ between commands is the help text of ``--out`` and ``--overwrite`` (a folder or a
file) and the formats ``--format`` allows.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any, Callable, Sequence, TypeVar

import click

from hexadyn.fields import is_field_value

__all__ = [
    "COMMON",
    "CommonOption",
    "figure_format_option",
    "format_option",
    "no_plots_option",
    "no_progress_option",
    "out_option",
    "overwrite_option",
    "parse_set",
    "set_option",
    "strict_option",
    "UNHEALTHY",
    "warn_unhealthy",
    "workers_option",
]

F = TypeVar("F", bound=Callable[..., Any])

#: The common options, in the column order of the table of docs/cli.md.
COMMON = ("--out", "--overwrite", "--workers", "--format", "--no-progress", "--no-plots", "--strict", "--set")


class CommonOption(click.Option):
    """An option of :data:`COMMON`, made by one of the functions of this module."""


def out_option(help: str, *, required: bool = False, folder: bool = True) -> Callable[[F], F]:
    """``-o/--out PATH``: where the command writes (a folder, or a file with ``folder=False``)."""
    kind = click.Path(file_okay=not folder, dir_okay=folder, path_type=Path)
    return click.option("-o", "--out", "out", cls=CommonOption, type=kind, required=required, help=help)


def overwrite_option(what: str = "folder") -> Callable[[F], F]:
    """``--overwrite``: replace an existing ``--out`` (a folder or a file)."""
    return click.option("--overwrite", cls=CommonOption, is_flag=True, help=f"Replace the --out {what} if it exists.")


def workers_option(help: str = "Parallel simulations (default: every core).") -> Callable[[F], F]:
    """``--workers N``: parallel processes, an integer >= 1."""
    return click.option("--workers", cls=CommonOption, type=click.IntRange(min=1), default=None, help=help)


def format_option(allowed: Sequence[str] | Callable[[], Sequence[str]], default: str | None, help: str, *, several: bool, required: bool = False) -> Callable[[F], F]:
    """``--format``: one of `allowed` (or of what it returns, asked when the option is parsed),
    or with `several` a comma-separated list of them (the value is then a tuple, duplicates
    dropped)."""

    def parse(ctx: click.Context, param: click.Parameter, value: str | None) -> Any:
        if value is None:
            return None
        allowed_now = allowed() if callable(allowed) else allowed
        chosen = tuple(dict.fromkeys(f.strip().lower() for f in value.split(",") if f.strip()))
        if not chosen or any(f not in allowed_now for f in chosen) or (not several and len(chosen) > 1):
            listing = f"comma-separated formats among {', '.join(allowed_now)}" if several else f"one of {', '.join(allowed_now)}"
            raise click.BadParameter(f"{value!r}; allowed: {listing}")
        return chosen if several else chosen[0]

    # No default at all when there is none: click checks a required option only then.
    defaults = {} if default is None else {"default": default, "show_default": True}
    return click.option("--format", "format_", cls=CommonOption, required=required, callback=parse, help=help, **defaults)


def figure_format_option() -> Callable[[F], F]:
    """``--format`` of the commands that draw figures: formats of :data:`hexadyn.plots.FORMATS`,
    comma-separated (matplotlib is imported when the option is parsed, not before)."""

    def figure_formats() -> Sequence[str]:
        from hexadyn.plots import FORMATS

        return FORMATS

    return format_option(figure_formats, "png", "Figure file formats: png (300 dpi), pdf, svg, comma-separated.", several=True)


def no_progress_option() -> Callable[[F], F]:
    """``--no-progress``: no progress bar (of the runs, nor of the figures)."""
    return click.option("--no-progress", cls=CommonOption, is_flag=True, help="No progress bars.")


def no_plots_option() -> Callable[[F], F]:
    """``--no-plots``: no figures."""
    return click.option("--no-plots", cls=CommonOption, is_flag=True, help="Do not write the figures.")


#: Exit status of ``--strict`` when a health check of a run failed.
UNHEALTHY = 3


def strict_option() -> Callable[[F], F]:
    """``--strict``: a failed health check of a run is an error, exit status :data:`UNHEALTHY`."""
    return click.option("--strict", cls=CommonOption, is_flag=True, help=f"Exit with status {UNHEALTHY} if a health check of a run fails (see `warnings` in summary.json).")


def warn_unhealthy(warnings: Sequence[str], strict: bool) -> None:
    """Prints the failed health checks of the runs, one ``WARNING:`` line each on stderr; with
    ``--strict``, any ends the command with status :data:`UNHEALTHY`."""
    for warning in warnings:
        click.secho(f"WARNING: {warning}", fg="red", bold=True, err=True)
    if warnings and strict:
        raise SystemExit(UNHEALTHY)


def set_option() -> Callable[[F], F]:
    """``--set KEY=VALUE`` (repeatable): scenario fields by dotted name, the ``overrides=`` of
    :func:`hexadyn.simulate`; the value is a TOML literal. The value of the option is the dict
    of the fields, in the order given (a later ``--set`` of the same field wins)."""

    def parse(ctx: click.Context, param: click.Parameter, values: tuple[str, ...]) -> dict[str, Any]:
        try:
            return parse_set(values)
        except ValueError as exc:
            raise click.BadParameter(str(exc)) from None

    return click.option(
        "--set",
        "overrides",
        cls=CommonOption,
        multiple=True,
        metavar="KEY=VALUE",
        callback=parse,
        help='Set a scenario field by its dotted name, the value a TOML literal: --set gait.heading.vx_m_s=0.02 --set \'model.friction="lugre"\'. Repeatable.',
    )


def parse_set(values: Sequence[str]) -> dict[str, Any]:
    """``["gait.period_s=12", 'model.friction="lugre"']`` -> ``{"gait.period_s": 12, ...}``:
    each value parsed as a TOML literal (a number, a quoted string, true/false, an array or an
    inline table). ValueError naming the item and what is allowed otherwise. The fields
    themselves are checked by the engine, as those of a scenario file."""
    fields: dict[str, Any] = {}
    for item in values:
        key, equals, literal = item.partition("=")
        key = key.strip()
        if not equals or not key or any(not part.strip() for part in key.split(".")):
            raise ValueError(f"{item!r}; allowed: KEY=VALUE with the dotted name of a scenario field, e.g. gait.period_s=12")
        try:
            value = tomllib.loads(f"value = {literal.strip()}")["value"]
        except tomllib.TOMLDecodeError:
            value = None
        if value is None or not is_field_value(value):
            raise ValueError(f"{item!r}: the value {literal.strip()!r} is not a TOML literal of a scenario field; allowed: a number, true or false, a quoted string (--set '{key}=\"...\"'), an array or an inline table of those")
        fields[key] = value
    return fields


