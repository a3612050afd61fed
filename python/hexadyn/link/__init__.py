"""The robot link of Section 2.3.2: the master/slave packets (:mod:`hexadyn.link.packets`, over
the engine's codec), and ``hexadyn robot run`` / ``hexadyn robot emulate``
(:mod:`hexadyn.link.cli`), which run a scenario's controller on the robot, or on the slave
emulator backed by the simulated robot."""

from __future__ import annotations

import errno
import os
from pathlib import Path

from hexadyn import inputs

#: The shipped link configuration on the loopback interface (``--link loopback``).
LOOPBACK = Path(__file__).resolve().parent / "loopback.toml"

__all__ = ["LOOPBACK", "resolve_link"]


def resolve_link(link: str | os.PathLike) -> Path:
    """The link configuration file for a path, or ``"loopback"`` for :data:`LOOPBACK`; ValueError
    saying what it is for a path that is not a regular file (a named pipe, a directory...)."""
    path = Path(link)
    if path.is_file():
        return path
    if os.fspath(link) == "loopback":
        return LOOPBACK
    if os.path.lexists(path):
        inputs.check_input(path)  # not a regular file: says what it is
    raise FileNotFoundError(errno.ENOENT, "no such link configuration file (or \"loopback\" for the shipped one)", os.fspath(link))
