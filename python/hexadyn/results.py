"""Simulation results: time series with units, a summary and metadata, saved as a folder.

A results folder holds these files, written atomically (all or nothing):

- ``timeseries.parquet``: one row per control instant, indexed by ``t`` (s); the units are also
  in the Parquet schema metadata (key ``hexadyn``);
- ``metadata.json``: the scenario and robot description texts, the hexadyn version, the units
  and a one-line description of every column;
- ``summary.json``: totals and diagnostics of the run (energies, integration statistics, body
  height change, saturation, tracking errors) and the key figures of the power analysis
  (:func:`hexadyn.energy.energy_figures`: average power, friction share, specific resistance);
- ``power.csv``: averaged power per leg and joint type, split by foot phase
  (:func:`hexadyn.energy.averaged_power`, Tables 6.3-6.6);
- ``energy.csv``: energy breakdown per actuator (:func:`hexadyn.energy.energy_breakdown`);
- ``plots/`` (optional): the figures of :mod:`hexadyn.plots`.
"""

from __future__ import annotations

import datetime as _dt
import errno
import json
import math
import os
import shutil
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping, Sequence

if TYPE_CHECKING:  # pandas and matplotlib are imported when needed (keeps `import hexadyn` light)
    import pandas as pd
    from matplotlib.figure import Figure

TIMESERIES_FILE = "timeseries.parquet"
METADATA_FILE = "metadata.json"
SUMMARY_FILE = "summary.json"
POWER_FILE = "power.csv"
ENERGY_FILE = "energy.csv"
PLOTS_DIR = "plots"
#: Identifies a hexadyn results folder in metadata.json.
FORMAT = "hexadyn-results"
FORMAT_VERSION = 1

__all__ = ["Results", "TIMESERIES_FILE", "METADATA_FILE", "SUMMARY_FILE", "POWER_FILE", "ENERGY_FILE", "PLOTS_DIR", "parse_toml", "write_folder", "write_csv"]


class Results:
    """The results of one simulation.

    Attributes:
        timeseries: pandas DataFrame indexed by ``t`` (s), one column per recorded quantity
            (``Z``, ``q_v[2]``, ``i_q_v[2]``, ``tau_f_q_v[2]``, ``Fz[2]``, ...).
        units: column name -> SI unit (``"t"`` included).
        summary: totals and diagnostics (names carry their unit as a suffix).
        metadata: ``scenario`` and ``robot`` (TOML texts), ``scenario_name``, ``scenario_path``,
            ``robot_source``, ``hexadyn_version``, ``created``, ``units``, ``descriptions``.
        path: the folder the results were saved to or loaded from, if any.
    """

    def __init__(
        self,
        timeseries: pd.DataFrame,
        units: Mapping[str, str],
        summary: Mapping[str, Any],
        metadata: Mapping[str, Any],
        path: Path | None = None,
    ) -> None:
        self.timeseries = timeseries
        self.units = dict(units)
        self.summary = dict(summary)
        self.metadata = dict(metadata)
        self.path = path

    # -----------------------------------------------------------------------------------------
    # Construction
    # -----------------------------------------------------------------------------------------

    @classmethod
    def from_engine(cls, raw: Mapping[str, Any], scenario_path: str | os.PathLike | None = None) -> "Results":
        """Builds the results from the dict returned by ``hexadyn._core.run_scenario``."""
        import pandas as pd

        from hexadyn import __version__, energy

        columns = raw["columns"]
        frame = pd.DataFrame({name: values for name, values in columns.items()})
        frame = frame.set_index("t")
        units = dict(raw["units"])
        descriptions = dict(raw.get("descriptions", {}))
        summary = dict(raw["summary"])
        metadata = {
            "format": FORMAT,
            "format_version": FORMAT_VERSION,
            "hexadyn_version": __version__,
            "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
            "scenario_name": summary.get("scenario"),
            "scenario_path": None if scenario_path is None else str(scenario_path),
            "scenario": raw["scenario"],
            "robot_source": raw.get("robot_source"),
            "robot": raw["robot"],
            "units": units,
            "descriptions": descriptions,
        }
        results = cls(frame, units, summary, metadata)
        for key, value in energy.energy_figures(results).items():
            results.summary.setdefault(key, value)  # the engine's own figures win
        return results

    # -----------------------------------------------------------------------------------------
    # Access
    # -----------------------------------------------------------------------------------------

    @property
    def descriptions(self) -> dict[str, str]:
        """Column name -> one-line description."""
        return dict(self.metadata.get("descriptions", {}))

    def unit(self, column: str) -> str:
        """The unit of a column (KeyError if there is no such column)."""
        return self.units[column]

    def __repr__(self) -> str:
        rows, cols = self.timeseries.shape
        name = self.metadata.get("scenario_name")
        where = f", path={str(self.path)!r}" if self.path else ""
        return f"<Results {name!r}: {rows} instants x {cols} columns{where}>"

    # -----------------------------------------------------------------------------------------
    # Saving and loading
    # -----------------------------------------------------------------------------------------

    def save(
        self,
        folder: str | os.PathLike,
        *,
        overwrite: bool = False,
        plots: bool = False,
        legs: Sequence[int] | None = None,
        formats: Sequence[str] | None = None,
    ) -> Path:
        """Writes the results folder atomically and returns its path.

        The files (and with ``plots`` the figures of :meth:`plot` in ``plots/``) are written into
        a temporary folder next to ``folder`` which is then renamed to ``folder``: either the
        complete folder appears or nothing does (a failure removes the temporary folder and any
        parent folders this call created). An existing ``folder`` is an error (FileExistsError)
        unless ``overwrite`` is true, in which case it is replaced only once the new folder is
        complete. ``legs`` and ``formats`` are those of :meth:`plot`.
        """
        target = Path(folder)
        if target.exists() and not overwrite:
            raise FileExistsError(errno.EEXIST, "the results folder exists (choose another folder or overwrite it)", str(target))
        figures = self.figures(legs) if plots else None  # before anything is written

        def write(tmp: Path) -> None:
            self._write(tmp)
            if figures is not None:
                (tmp / PLOTS_DIR).mkdir()
                _save_figures(figures, tmp / PLOTS_DIR, formats)

        write_folder(target, write)
        self.path = target
        return target

    def figures(self, legs: Sequence[int] | None = None) -> dict[str, Figure]:
        """The figures of these results by file stem (see :func:`hexadyn.plots.figures`)."""
        from hexadyn import plots

        return plots.figures(self, plots.DEFAULT_LEGS if legs is None else legs)

    def plot(
        self,
        folder: str | os.PathLike | None = None,
        *,
        legs: Sequence[int] | None = None,
        formats: Sequence[str] | None = None,
    ) -> dict[str, Figure]:
        """Builds the figures of these results and, with ``folder``, writes them there.

        Returns the matplotlib figures by file stem (``leg0_q_r``, ..., ``gait_diagram``,
        ``trajectory``, ``averaged_power``, ``energy_breakdown``; see :mod:`hexadyn.plots`).
        ``legs``: the legs of the per-actuator figures (default 0 and 2, as in Section 6.4).
        ``formats``: file formats among png (300 dpi), pdf and svg (default png). The folder
        is written atomically and replaces an existing one: ``results.plot(results.path /
        "plots")`` regenerates the plots of a saved results folder.
        """
        figures = self.figures(legs)
        if folder is not None:
            write_folder(Path(folder), lambda tmp: _save_figures(figures, tmp, formats))
        return figures

    def _write(self, folder: Path) -> None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        from hexadyn import energy

        table = pa.Table.from_pandas(self.timeseries, preserve_index=True)
        extra = json.dumps({"units": self.units, "hexadyn_version": self.metadata.get("hexadyn_version")})
        table = table.replace_schema_metadata({**(table.schema.metadata or {}), b"hexadyn": extra.encode()})
        pq.write_table(table, folder / TIMESERIES_FILE)
        metadata = dict(self.metadata)
        metadata["units"] = self.units
        metadata["columns"] = [self.timeseries.index.name, *map(str, self.timeseries.columns)]
        _write_json(folder / METADATA_FILE, metadata)
        _write_json(folder / SUMMARY_FILE, self.summary)
        write_csv(folder / POWER_FILE, energy.averaged_power(self))
        write_csv(folder / ENERGY_FILE, energy.energy_breakdown(self))

    @classmethod
    def load(cls, folder: str | os.PathLike) -> "Results":
        """Reads a results folder written by :meth:`save`."""
        import pyarrow.parquet as pq

        folder = Path(folder)
        meta_path = folder / METADATA_FILE
        if not meta_path.is_file():
            if not folder.is_dir():
                raise FileNotFoundError(errno.ENOENT, "no such results folder", str(folder))
            raise ValueError(f"{folder}: not a hexadyn results folder (no {METADATA_FILE})")
        metadata = json.loads(meta_path.read_text(encoding="utf-8"))
        if metadata.get("format") != FORMAT:
            raise ValueError(f"{meta_path}: not hexadyn results metadata (format {metadata.get('format')!r}, expected {FORMAT!r})")
        summary = json.loads((folder / SUMMARY_FILE).read_text(encoding="utf-8"))
        frame = pq.read_table(folder / TIMESERIES_FILE).to_pandas()
        metadata.pop("columns", None)
        return cls(frame, metadata.get("units", {}), summary, metadata, path=folder)


def write_folder(target: Path, write: Callable[[Path], None]) -> None:
    """Writes a folder atomically: `write` fills a temporary folder next to `target`, whose
    files are then synced to disk and which is renamed to `target`, replacing an existing
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


def _save_figures(figures: Mapping[str, Figure], folder: Path, formats: Sequence[str] | None) -> None:
    from hexadyn import plots

    plots.save_figures(figures, folder, plots.DEFAULT_FORMATS if formats is None else formats)


def parse_toml(text: str, what: str) -> dict[str, Any]:
    """Parses a TOML text kept with the results (scenario, robot description); `what` names it
    in the ValueError raised for invalid TOML."""
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{what} is not valid TOML: {exc}") from None


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


def _json_safe(value: Any) -> Any:
    """Non-finite floats become None (strict JSON has no NaN or infinity)."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_safe(v) for v in value]
    return value


def _write_json(path: Path, value: Any) -> None:
    with open(path, "w", encoding="utf-8") as f:
        json.dump(_json_safe(value), f, indent=2, allow_nan=False)
        f.write("\n")


def write_csv(path: Path, table: pd.DataFrame) -> None:
    """Writes a table as CSV (floats with 9 significant digits)."""
    with open(path, "w", encoding="utf-8", newline="") as f:
        table.to_csv(f, float_format="%.9g")


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
