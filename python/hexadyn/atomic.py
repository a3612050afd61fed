"""Atomic writes: a file or a folder appears complete or not at all.

Both functions let a callback fill a temporary sibling of the target (same folder, hence same
file system), sync it to disk and rename it to the target. A failure removes the temporary and
leaves an existing target untouched. Used for results folders (:mod:`hexadyn.report`), the
friction comparison (:mod:`hexadyn.compare`) and the Monte Carlo files
(:mod:`hexadyn.montecarlo`).
"""

from __future__ import annotations

import errno
import os
import shutil
import tempfile
from pathlib import Path
from typing import Callable

__all__ = ["refuse_existing", "write_file", "write_folder"]


def refuse_existing(target: str | os.PathLike, what: str) -> None:
    """Raises FileExistsError if `target` exists; `what` names it ("results folder")."""
    if Path(target).exists():
        raise FileExistsError(errno.EEXIST, f"the {what} exists (choose another folder or overwrite it)", os.fspath(target))


def write_file(path: Path, write: Callable[[Path], object]) -> None:
    """Writes a file atomically: ``write(tmp)`` fills a temporary file next to `path`, which is
    synced to disk and renamed to `path` (replacing an existing file)."""
    fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".partial", dir=path.parent)
    os.close(fd)
    tmp = Path(name)
    try:
        write(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        _fsync(tmp)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    _fsync_dir(path.parent)


def write_folder(target: Path, write: Callable[[Path], object]) -> None:
    """Writes a folder atomically: ``write(tmp)`` fills a temporary folder next to `target`,
    whose files are then synced to disk and which is renamed to `target`, replacing an existing
    `target` only once complete. On failure nothing is left: neither the temporary folder nor
    the parents this call created, and an existing `target` is untouched."""
    created = _make_parents(target.parent)
    tmp: Path | None = None
    try:
        tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".partial", dir=target.parent))
        os.chmod(tmp, 0o777 & ~_umask())
        write(tmp)
        for path in sorted(tmp.rglob("*")):
            if path.is_file():
                _fsync(path)
        if target.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".old", dir=target.parent))
            os.rename(target, old / "previous")
            try:
                os.rename(tmp, target)
            except BaseException:
                os.rename(old / "previous", target)
                raise
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.rename(tmp, target)
        tmp = None
    except BaseException:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
        for d in created:
            try:
                d.rmdir()
            except OSError:
                break
        raise
    _fsync_dir(target.parent)


def _make_parents(folder: Path) -> list[Path]:
    """Creates `folder` and its missing parents; returns those created, deepest first."""
    missing = []
    p = folder.absolute()
    while not p.exists():
        missing.append(p)
        p = p.parent
    for d in reversed(missing):
        d.mkdir(exist_ok=True)
    return missing


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _fsync(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_dir(path: Path) -> None:
    try:
        _fsync(path)
    except OSError:  # pragma: no cover - directories cannot be fsynced on some platforms
        pass
