"""The ``hexadyn`` command line.

User errors end with one line on stderr (``Error: ...``) and exit status 1, never a traceback.
Set ``HEXADYN_DEBUG=1`` to see the traceback of such an error.
"""

from __future__ import annotations

import os

import click

import hexadyn

# Exceptions that report bad input (a missing file, a wrong value in a scenario) rather than a
# bug: they are shown as one clean line.
USER_ERRORS: tuple[type[BaseException], ...] = (OSError, ValueError)


class HexadynGroup(click.Group):
    """A click group that turns user errors raised by any command into one-line messages."""

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except USER_ERRORS as exc:
            if os.environ.get("HEXADYN_DEBUG"):
                raise
            raise click.ClickException(_one_line(exc)) from exc


@click.group(cls=HexadynGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(hexadyn.__version__, "-V", "--version", prog_name="hexadyn", message="%(prog)s %(version)s")
def cli() -> None:
    """Multiphysics dynamics and gait control of six-legged walking robots."""


@cli.command()
def info() -> None:
    """Print the engine version and the default robot description."""
    from hexadyn import _core

    robot = hexadyn.default_robot_path()
    click.echo(f"hexadyn {hexadyn.__version__}")
    click.echo(f"engine: {_core.__version__} ({_core.__file__})")
    if robot is None:
        click.echo(f"default robot: {hexadyn.DEFAULT_ROBOT} (description not shipped yet)")
    else:
        click.echo(f"default robot: {hexadyn.DEFAULT_ROBOT} ({robot})")


def main(argv: list[str] | None = None) -> None:
    """Entry point of the ``hexadyn`` console script."""
    cli.main(args=argv, prog_name="hexadyn")


def _one_line(exc: BaseException) -> str:
    if isinstance(exc, OSError) and exc.strerror and exc.filename:
        return f"{exc.filename}: {exc.strerror}"
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


if __name__ == "__main__":  # pragma: no cover
    main()
