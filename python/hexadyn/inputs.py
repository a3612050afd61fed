"""The files a user names, read only if they are regular files of a bounded size.

Every file the Python side reads on a user's word (a results folder's ``metadata.json``,
``summary.json`` and ``timeseries.parquet``, a robot description to export, a drives
description to import with) is opened by :func:`open_input`: its type and size are checked
with ``stat`` before it is opened, the opening does not wait (``O_NONBLOCK``) and the open file
is checked again, so that a named pipe, a device, a socket or a directory is refused at once,
saying what it is and what is allowed, instead of waiting for a pipe's writer (deaf to Ctrl-C)
or reading a device without end. The engine reads its own input files (scenarios, robot
descriptions, terrains, heading and height CSV files, link configurations) the same way
(``fields::open_input`` in Rust), with the same messages::

    /tmp/pipe: a named pipe (FIFO), not a regular file; allowed: a regular file of at most 64 MB
"""

from __future__ import annotations

import os
import stat
from typing import BinaryIO

__all__ = ["MAX_INPUT_BYTES", "check_input", "open_input", "read_text"]

#: The largest text input read (the engine's ``fields::MAX_INPUT_BYTES``): far above any real
#: one (kilobytes; a results folder's metadata holds the scenario and robot texts).
MAX_INPUT_BYTES = 64 * 2**20


def check_input(path: str | os.PathLike, limit: int | None = MAX_INPUT_BYTES) -> int:
    """The size of `path` if it is a regular file of at most `limit` bytes (None: any size);
    ValueError naming the path, what it is and what is allowed otherwise (FileNotFoundError if
    there is nothing there)."""
    return _checked(path, os.stat(path), limit)


def open_input(path: str | os.PathLike, limit: int | None = MAX_INPUT_BYTES) -> BinaryIO:
    """`path` opened for reading in binary, once checked as a regular file of at most `limit`
    bytes (:func:`check_input`), before and after opening it without waiting."""
    check_input(path, limit)
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    try:
        _checked(path, os.fstat(fd), limit)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_text(path: str | os.PathLike, limit: int = MAX_INPUT_BYTES) -> str:
    """The UTF-8 text of the input file `path` (:func:`open_input`); ValueError naming it if it
    is not one, grew past `limit` while read, or is not UTF-8."""
    with open_input(path, limit) as f:
        data = f.read(limit + 1)
    if len(data) > limit:
        raise ValueError(f"{os.fspath(path)}: grew past {_size(limit)} while read; allowed: {_allowed(limit)}")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"{os.fspath(path)}: not UTF-8 text (invalid byte at offset {exc.start}); allowed: UTF-8 text") from None


def _checked(path: str | os.PathLike, st: os.stat_result, limit: int | None) -> int:
    if not stat.S_ISREG(st.st_mode):
        raise ValueError(f"{os.fspath(path)}: {_kind(st.st_mode)}; allowed: {_allowed(limit)}")
    if limit is not None and st.st_size > limit:
        raise ValueError(f"{os.fspath(path)}: {st.st_size} bytes, too large; allowed: {_allowed(limit)}")
    return st.st_size


def _kind(mode: int) -> str:
    """What a file that is not a regular file is (the engine's words)."""
    if stat.S_ISFIFO(mode):
        return "a named pipe (FIFO), not a regular file"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device, not a regular file"
    if stat.S_ISSOCK(mode):
        return "a socket, not a regular file"
    if stat.S_ISDIR(mode):
        return "a directory, not a file"
    return "not a regular file"


def _allowed(limit: int | None) -> str:
    return "a regular file" if limit is None else f"a regular file of at most {_size(limit)}"


def _size(n: int) -> str:
    """A limit in bytes as the engine writes it (64 MB, 1 GB: binary multiples)."""
    for unit, shift in (("GB", 30), ("MB", 20)):
        if n >= 1 << shift and n % (1 << shift) == 0:
            return f"{n >> shift} {unit}"
    return f"{n} bytes"

