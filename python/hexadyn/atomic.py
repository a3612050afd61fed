"""Atomic writes: a file or a folder appears complete or not at all.

Both functions let a callback fill a temporary sibling of the target (same folder, hence same
file system), sync it to disk and rename it to the target. A failure removes the temporary and
leaves an existing target untouched. The temporaries are named ``.NAME.PID.XXXXXXXX.partial``
(``.old`` for a replaced folder on its way out), PID being the writing process: a process killed
while writing (``kill -9``, a power cut) cannot remove its temporary, so every write first
removes the temporaries in its folder whose process is gone (:func:`remove_stale`), and every
``hexadyn`` command those of the results root (``results/``, :mod:`hexadyn.cli`). Used for
results folders (:mod:`hexadyn.report`), the friction comparison (:mod:`hexadyn.compare`) and
the Monte Carlo files (:mod:`hexadyn.montecarlo`, whose table and figures are one set of files
in the campaign folder: :func:`write_files`).
"""

from __future__ import annotations

import errno
import os
import shutil
import tempfile
from pathlib import Path
from typing import Callable, Sequence

__all__ = ["refuse_existing", "remove_stale", "write_file", "write_files", "write_folder"]

#: Suffixes of the temporaries of this module.
_TEMPORARY_SUFFIXES = (".partial", ".old")


def refuse_existing(target: str | os.PathLike, what: str) -> None:
    """Raises FileExistsError if `target` exists; `what` names it ("results folder")."""
    if Path(target).exists():
        raise FileExistsError(errno.EEXIST, f"the {what} exists (choose another folder or overwrite it)", os.fspath(target))


def write_file(path: Path, write: Callable[[Path], object]) -> None:
    """Writes a file atomically: ``write(tmp)`` fills a temporary file next to `path`, which is
    synced to disk and renamed to `path` (replacing an existing file)."""
    remove_stale(path.parent)
    fd, name = tempfile.mkstemp(prefix=_prefix(path), suffix=".partial", dir=path.parent)
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


def write_files(folder: Path, names: Sequence[str], write: Callable[[Path], object]) -> None:
    """Writes the files `names` of `folder` as one set: ``write(tmp)`` fills a temporary folder
    next to them with every one of them; they are synced to disk and renamed into `folder` in
    the order of `names`, the last one last: once it is there the others are too (readers look
    for the last). On failure (of `write`, a missing file, Ctrl-C) the temporary folder is
    removed and the files in `folder` are untouched."""
    remove_stale(folder)
    tmp = Path(tempfile.mkdtemp(prefix=_prefix(folder / names[-1]), suffix=".partial", dir=folder))
    try:
        write(tmp)
        for name in names:
            _fsync(tmp / name)
        for name in names:
            os.replace(tmp / name, folder / name)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    _fsync_dir(folder)


def write_folder(target: Path, write: Callable[[Path], object]) -> None:
    """Writes a folder atomically: ``write(tmp)`` fills a temporary folder next to `target`,
    whose files are then synced to disk and which is renamed to `target`, replacing an existing
    `target` only once complete. On failure nothing is left: neither the temporary folder nor
    the parents this call created, and an existing `target` is untouched."""
    created = _make_parents(target.parent)
    remove_stale(target.parent)
    tmp: Path | None = None
    try:
        tmp = Path(tempfile.mkdtemp(prefix=_prefix(target), suffix=".partial", dir=target.parent))
        os.chmod(tmp, 0o777 & ~_umask())
        write(tmp)
        for path in sorted(tmp.rglob("*")):
            if path.is_file():
                _fsync(path)
        if target.exists():
            old = Path(tempfile.mkdtemp(prefix=_prefix(target), suffix=".old", dir=target.parent))
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


def remove_stale(folder: str | os.PathLike) -> list[Path]:
    """Removes the temporaries (``.NAME.PID.XXXXXXXX.partial`` or ``.old``) in `folder` whose
    writing process PID is no longer alive, and returns them. Those of live processes (another
    run writing into the same folder) are left alone, as is anything not named so."""
    removed = []
    try:
        entries = list(Path(folder).iterdir())
    except OSError:
        return removed
    for path in entries:
        pid = _owner(path.name)
        if pid is None or _alive(pid):
            continue
        try:
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path)
            else:
                path.unlink()
        except FileNotFoundError:  # removed meanwhile by another run
            pass
        removed.append(path)
    return removed


def _prefix(target: Path) -> str:
    return f".{target.name}.{os.getpid()}."


def _owner(name: str) -> int | None:
    """The PID in the name of a temporary of this module, else None."""
    suffix = next((s for s in _TEMPORARY_SUFFIXES if name.endswith(s)), None)
    if not name.startswith(".") or suffix is None:
        return None
    parts = name[: -len(suffix)].rsplit(".", 2)
    if len(parts) != 3 or not parts[0] or not parts[1].isdigit():
        return None
    return int(parts[1])


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's live process
        return True
    except OverflowError:
        return False
    return True


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
