"""Simulation results: time series with units, a summary and metadata.

:meth:`Results.write` writes, and :meth:`Results.load` reads, these files of a results folder:

- ``timeseries.parquet``: one row per control instant, indexed by ``t`` (s); the units are also
  in the Parquet schema metadata (key ``hexadyn``);
- ``metadata.json``: the scenario and robot description texts, the hexadyn version, the units
  and a one-line description of every column;
- ``summary.json``: totals and diagnostics of the run (energies, integration statistics, body
  height change, saturation, tracking errors, robot mass, specific resistance) and, for
  :func:`hexadyn.simulate`, the key figures of the power analysis
  (:func:`hexadyn.energy.energy_figures`).

A complete results folder, with the power tables and the figures, is written atomically by
:func:`hexadyn.report.save`. This module is the bottom of the package's analysis layers
(results -> energy -> plots -> report): it imports none of them.
"""

from __future__ import annotations

import datetime as _dt
import errno
import json
import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping

from hexadyn._core import __version__

if TYPE_CHECKING:  # pandas is imported when needed (keeps `import hexadyn` light)
    import pandas as pd

TIMESERIES_FILE = "timeseries.parquet"
METADATA_FILE = "metadata.json"
SUMMARY_FILE = "summary.json"
#: Identifies a hexadyn results folder in metadata.json.
FORMAT = "hexadyn-results"
FORMAT_VERSION = 1

__all__ = ["Results", "TIMESERIES_FILE", "METADATA_FILE", "SUMMARY_FILE"]


class Results:
    """The results of one simulation.

    Attributes:
        timeseries: pandas DataFrame indexed by ``t`` (s), one column per recorded quantity
            (``Z``, ``q_v[2]``, ``i_q_v[2]``, ``tau_f_q_v[2]``, ``Fz[2]``, ...).
        units: column name -> SI unit (``"t"`` included).
        summary: totals and diagnostics (names carry their unit as a suffix).
        metadata: ``scenario`` and ``robot`` (TOML texts), ``scenario_name``, ``scenario_path``,
            ``robot_source``, ``hexadyn_version``, ``created``, ``units``, ``descriptions``.
        path: the folder the results were saved to (:func:`hexadyn.report.save`) or loaded
            from, if any.
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
        """Builds the results from the dict returned by ``hexadyn._core.run_scenario``, with
        the engine's summary as it is (:func:`hexadyn.simulate` adds the key figures of the
        power analysis, :func:`hexadyn.energy.add_energy_figures`)."""
        import pandas as pd

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
        return cls(frame, units, summary, metadata)

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
    # Writing and loading
    # -----------------------------------------------------------------------------------------

    def write(self, folder: Path) -> None:
        """Writes the files :meth:`load` reads (``timeseries.parquet``, ``metadata.json``,
        ``summary.json``) into the existing `folder`, as they are: not atomically, and
        without the power tables and figures. :func:`hexadyn.report.save` writes a complete
        results folder atomically."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.Table.from_pandas(self.timeseries, preserve_index=True)
        extra = json.dumps({"units": self.units, "hexadyn_version": self.metadata.get("hexadyn_version")})
        table = table.replace_schema_metadata({**(table.schema.metadata or {}), b"hexadyn": extra.encode()})
        pq.write_table(table, folder / TIMESERIES_FILE)
        metadata = dict(self.metadata)
        metadata["units"] = self.units
        metadata["columns"] = [self.timeseries.index.name, *map(str, self.timeseries.columns)]
        _write_json(folder / METADATA_FILE, metadata)
        _write_json(folder / SUMMARY_FILE, self.summary)

    @classmethod
    def load(cls, folder: str | os.PathLike) -> "Results":
        """Reads a results folder (written by :func:`hexadyn.report.save`)."""
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
