"""The small text inputs the Python side reads itself (the robot description of `hexadyn
identify --robot`, the friction statistics of `hexadyn montecarlo --friction-stats`), with the
rule of the engine's inputs (``crates/hexadyn/src/fields``, ``read_input``): a regular file of at
most :data:`MAX_INPUT_BYTES`, UTF-8, so that naming a device (``/dev/zero``), a FIFO or a huge
file fails at once with one line instead of filling memory or waiting forever.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

__all__ = ["MAX_INPUT_BYTES", "read_text"]

#: The largest input text file read: 64 MB, the engine's ``MAX_INPUT_BYTES``.
MAX_INPUT_BYTES = 64 << 20


def read_text(path: str | os.PathLike, what: str) -> str:
    """The text of the input file `path`; `what` names it in errors ("robot description").

    Raises:
        OSError: the file cannot be read (missing, no permission).
        ValueError: not a regular file, larger than :data:`MAX_INPUT_BYTES`, or not UTF-8.
    """
    path = Path(path)
    mode = os.stat(path).st_mode  # before opening: opening a FIFO waits for a writer
    if not stat.S_ISREG(mode):
        kind = "a directory" if stat.S_ISDIR(mode) else "not a regular file"
        raise ValueError(f"{path}: {what}: {kind}; allowed: a text file of at most {MAX_INPUT_BYTES >> 20} MB")
    with open(path, "rb") as file:
        data = file.read(MAX_INPUT_BYTES + 1)
    if len(data) > MAX_INPUT_BYTES:
        raise ValueError(f"{path}: {what}: more than the {MAX_INPUT_BYTES >> 20} MB allowed for an input file")
    try:
        return data.decode("utf-8-sig")  # a leading byte order mark is dropped
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path}: {what}: not UTF-8 text (invalid byte at offset {exc.start})") from None
