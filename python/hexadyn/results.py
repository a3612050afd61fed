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

import contextlib
import datetime as _dt
import errno
import functools
import json
import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterator, Mapping, Sequence

from hexadyn import inputs
from hexadyn._core import __version__
from hexadyn.vocabulary import Joints

if TYPE_CHECKING:  # pandas is imported when needed (keeps `import hexadyn` light)
    import pandas as pd
    import pyarrow.parquet as pq

TIMESERIES_FILE = "timeseries.parquet"
METADATA_FILE = "metadata.json"
SUMMARY_FILE = "summary.json"
#: The largest time series kept in memory by :func:`hexadyn.simulate` without a results folder,
#: and analysed in memory by :mod:`hexadyn.report` (the power table and the figures), in bytes
#: of 8-byte floats. INTERPRETATION: a 1000 s walk (about 1e5 instants x 400 columns, 320 MB)
#: still fits, with room for pandas' copies on a machine of a few GB.
IN_MEMORY_LIMIT_BYTES = 400 * 2**20
#: Identifies a hexadyn results folder in metadata.json.
FORMAT = "hexadyn-results"
FORMAT_VERSION = 1
#: The keys of ``metadata.json`` and the JSON types their values may have (None: null); a key
#: may be absent, but for ``format``. The values of ``units`` and ``descriptions`` are strings,
#: as are the items of ``columns``.
METADATA_TYPES: dict[str, tuple[type | None, ...]] = {
    "format": (str,),
    "format_version": (int,),
    "hexadyn_version": (str,),
    "created": (str,),
    "scenario_name": (str, None),
    "scenario_path": (str, None),
    "scenario": (str,),
    "model": (dict,),
    "robot_source": (str, None),
    "robot": (str,),
    "units": (dict,),
    "descriptions": (dict,),
    "columns": (list,),
}
#: The size of a row group of ``timeseries.parquet`` (8-byte values), and so about the memory
#: a streamed run holds before writing. INTERPRETATION: the issue bounds the memory of a run,
#: not the size of a row group. pyarrow's writer keeps about 0.9 kB of footer per column and
#: row group until the file is closed (measured; 53 bytes each once written), 0.2 % of a
#: row group this size: the one part of a streamed run's memory that grows with its duration
#: (1e5 s of standing, 10^7 instants x 282 columns: 170 row groups, 43 MB of footer, against
#: 250 MB with one row group per 10^4 instants). Twice the size halves the footer and doubles
#: the buffer; readers favour row groups of 10^2 MB too.
ROW_GROUP_BYTES = 128 * 2**20
#: The most bytes of a row group read at a time for one row (:meth:`Results.endpoints`).
ROW_READ_BYTES = 2 * 2**20

__all__ = ["Results", "SeriesWriter", "TIMESERIES_FILE", "METADATA_FILE", "SUMMARY_FILE"]


class Results:
    """The results of one simulation.

    Attributes:
        timeseries: pandas DataFrame indexed by ``t`` (s), one column per recorded quantity
            (``Z``, ``q_v[2]``, ``i_q_v[2]``, ``tau_f_q_v[2]``, ``Fz[2]``, ...). Results saved to
            or loaded from a folder read it from ``timeseries.parquet`` on first access; for
            a long run that may not fit in memory, read a few columns with
            :meth:`read_columns` or the file row group by row group with pyarrow.
        units: column name -> SI unit (``"t"`` included).
        summary: totals and diagnostics (names carry their unit as a suffix); ``warnings`` lists
            the failed health checks of the run (:mod:`hexadyn.health`).
        metadata: ``scenario`` and ``robot`` (TOML texts), ``model`` (the ``[model]`` flags
            as the engine read them), ``scenario_name``, ``scenario_path``, ``robot_source``,
            ``hexadyn_version``, ``created``, ``units``, ``descriptions``.
        path: the folder the results were saved to (:func:`hexadyn.report.save`) or loaded
            from, if any.
    """

    def __init__(
        self,
        timeseries: pd.DataFrame | None,
        units: Mapping[str, str],
        summary: Mapping[str, Any],
        metadata: Mapping[str, Any],
        path: Path | None = None,
    ) -> None:
        self._timeseries = timeseries
        self.units = dict(units)
        self.summary = dict(summary)
        self.metadata = dict(metadata)
        self.path = path

    # -----------------------------------------------------------------------------------------
    # Construction
    # -----------------------------------------------------------------------------------------

    @classmethod
    def from_engine(cls, raw: Mapping[str, Any], scenario_path: str | os.PathLike | None = None, timeseries: pd.DataFrame | None = None) -> "Results":
        """Builds the results from the dict returned by ``hexadyn._core.run_scenario``, with
        the engine's summary as it is (:func:`hexadyn.simulate` adds the key figures of the
        power analysis, :func:`hexadyn.energy.add_energy_figures`). `timeseries` replaces the
        ``columns`` of a run whose series was handed out in chunks (None: read from ``path``)."""
        import pandas as pd

        if timeseries is None and raw["columns"]:
            timeseries = pd.DataFrame(dict(raw["columns"])).set_index("t")
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
            "model": dict(raw.get("model", {})),
            "robot_source": raw.get("robot_source"),
            "robot": raw["robot"],
            "units": units,
            "descriptions": descriptions,
        }
        return cls(timeseries, units, summary, metadata)

    # -----------------------------------------------------------------------------------------
    # Access
    # -----------------------------------------------------------------------------------------

    @property
    def timeseries(self) -> pd.DataFrame:
        if self._timeseries is None:
            self._timeseries = _read_parquet(self._series_file())
        return self._timeseries

    @timeseries.setter
    def timeseries(self, frame: pd.DataFrame) -> None:
        self._timeseries = frame

    @property
    def shape(self) -> tuple[int, int]:
        """(instants, columns) of the time series, without reading it."""
        if self._timeseries is not None:
            return self._timeseries.shape
        with open_series(self._series_file()) as file:
            meta = file.metadata
        return meta.num_rows, meta.num_columns - 1  # t is the index

    @property
    def series_bytes(self) -> int:
        """The size of the time series in memory (8-byte floats)."""
        rows, columns = self.shape
        return 8 * rows * (columns + 1)

    def read_columns(self, columns: Sequence[str]) -> pd.DataFrame:
        """Some columns of the time series (indexed by ``t``), read from the file if the series is
        not in memory: the way into a series too long for memory."""
        if self._timeseries is not None:
            return self._timeseries[list(columns)]
        return _read_parquet(self._series_file(), columns=list(columns))

    def iter_chunks(self, columns: Sequence[str], rows: int = 10_000) -> Iterator[pd.DataFrame]:
        """Some columns of the time series (indexed by ``t``), `rows` instants at a time, read
        from the file batch by batch if the series is not in memory: the way through a series
        too long for memory."""
        if self._timeseries is not None:
            frame = self._timeseries[list(columns)]
            for start in range(0, len(frame), rows):
                yield frame.iloc[start : start + rows]
            return
        import pyarrow.parquet as pq

        file = pq.ParquetFile(self._series_file())
        for batch in file.iter_batches(batch_size=rows, columns=list(columns), use_pandas_metadata=True, use_threads=False):
            yield batch.to_pandas()

    def endpoints(self) -> pd.DataFrame:
        """The first and the last instant of the time series (two rows), read from the file if
        the series is not in memory (:func:`_read_row`: a few columns at a time)."""
        if self._timeseries is not None:
            return self._timeseries.iloc[[0, -1]]
        import pyarrow as pa

        with open_series(self._series_file()) as file:
            ends = pa.concat_tables([_read_row(file, 0, 0), _read_row(file, file.num_row_groups - 1, -1)])
        return ends.to_pandas()

    def _series_file(self) -> Path:
        if self.path is None:
            raise ValueError("these results hold no time series (not in memory, no results folder)")
        return self.path / TIMESERIES_FILE

    @functools.cached_property
    def joints(self) -> Joints:
        """The names and kinds of the robot's leg joints (:class:`hexadyn.vocabulary.Joints`),
        read once from the robot description stored with the results."""
        return Joints.of(self)

    @property
    def descriptions(self) -> dict[str, str]:
        """Column name -> one-line description."""
        return dict(self.metadata.get("descriptions", {}))

    def unit(self, column: str) -> str:
        """The unit of a column (KeyError if there is no such column)."""
        return self.units[column]

    def __repr__(self) -> str:
        rows, cols = self.shape
        name = self.metadata.get("scenario_name")
        where = f", path={str(self.path)!r}" if self.path else ""
        return f"<Results {name!r}: {rows} instants x {cols} columns{where}>"

    # -----------------------------------------------------------------------------------------
    # Writing and loading
    # -----------------------------------------------------------------------------------------

    def write(self, folder: Path) -> None:
        """Writes the files :meth:`load` reads (``timeseries.parquet``, ``metadata.json``,
        ``summary.json``) into the existing `folder`, as they are: not atomically, and
        without the power tables and figures (the time series is kept if it was streamed
        there). :func:`hexadyn.report.save` writes a complete results folder atomically."""
        target = folder / TIMESERIES_FILE
        if self.path is None or self._series_file().resolve() != target.resolve():
            frame = self.timeseries
            with SeriesWriter(target, self.units) as writer:
                writer.write_frame(frame)
        metadata = dict(self.metadata)
        metadata["units"] = self.units
        metadata["columns"] = list(self.units)
        _write_json(folder / METADATA_FILE, metadata)
        _write_json(folder / SUMMARY_FILE, self.summary)

    @classmethod
    def load(cls, folder: str | os.PathLike) -> "Results":
        """Reads a results folder (written by :func:`hexadyn.report.save`); the time series is
        read on first access. Raises ValueError naming the file for a broken folder, or for a
        time series without a column its metadata lists (the analyses go by the metadata)."""
        folder = Path(folder)
        metadata = read_metadata(folder)
        summary = _read_json_object(folder / SUMMARY_FILE, "the run's summary")
        units = metadata.get("units", {})
        with open_series(folder / TIMESERIES_FILE) as file:
            held = set(file.schema_arrow.names)
        missing = [c for c in units if c not in held]
        if missing:
            raise ValueError(f"{folder / TIMESERIES_FILE}: no column `{missing[0]}`{f' (and {len(missing) - 1} more)' if len(missing) > 1 else ''}, which {METADATA_FILE} lists; allowed: a time series of the columns of its metadata")
        metadata.pop("columns", None)
        return cls(None, units, summary, metadata, path=folder)


class SeriesWriter:
    """Writes a time series to ``timeseries.parquet`` as it is recorded, in row groups of
    about :data:`ROW_GROUP_BYTES` (pyarrow's ParquetWriter): a long run is streamed to disk as
    it goes. The file is read back by :meth:`Results.load` as a DataFrame indexed by ``t``;
    the units are in the schema metadata (key ``hexadyn``).

    Memory: the chunks handed to :meth:`write_columns` are kept (without a copy) until they make
    a row group, which is then written and dropped; the writer itself keeps the file footer
    (see :data:`ROW_GROUP_BYTES`; statistics are written for ``t`` only, the column a reader
    selects rows by)."""

    def __init__(self, path: Path, units: Mapping[str, str] | None = None) -> None:
        self.path = path
        self.units = dict(units or {})
        self.rows = 0
        self._writer: Any = None  # pyarrow.parquet.ParquetWriter once opened
        self._schema: Any = None  # pyarrow.Schema once opened
        self._pending: list[list[Any]] = []  # chunks not written yet: one list of arrays per chunk, in schema order
        self._pending_rows = 0
        self._group_rows = 1  # rows of a row group, from the number of columns (:meth:`_open`)

    def write_columns(self, columns: Mapping[str, Any]) -> None:
        """Appends a chunk: column name -> 1-D array, ``t`` among them. The arrays are kept as
        they are (not copied) until a row group is full."""
        if self._schema is None:
            import pandas as pd

            self._open(pd.DataFrame({name: values[:1] for name, values in columns.items()}).set_index("t"))
        self._pending.append([columns[name] for name in self._schema.names])
        self._pending_rows += len(columns["t"])
        self.rows += len(columns["t"])
        if self._pending_rows >= self._group_rows:
            self._flush()

    def write_frame(self, frame: pd.DataFrame) -> None:
        """Appends a chunk indexed by ``t`` (a series already in memory), in row groups of
        about :data:`ROW_GROUP_BYTES`."""
        import pyarrow as pa

        if self._schema is None:
            self._open(frame)
        self._flush()
        self._writer.write_table(pa.Table.from_pandas(frame, schema=self._schema, preserve_index=True), row_group_size=self._group_rows)
        self.rows += len(frame)

    def _open(self, frame: pd.DataFrame) -> None:
        """Opens the file with the schema of `frame` (its pandas metadata makes ``t`` the index
        when read back) and the units."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        schema = pa.Schema.from_pandas(frame, preserve_index=True)
        extra = json.dumps({"units": self.units, "hexadyn_version": __version__})
        self._schema = schema.with_metadata({**(schema.metadata or {}), b"hexadyn": extra.encode()})
        self._group_rows = max(1, ROW_GROUP_BYTES // (8 * len(self._schema)))
        self._writer = pq.ParquetWriter(self.path, self._schema, write_statistics=["t"])

    def _flush(self) -> None:
        """Writes the pending chunks as one row group."""
        if not self._pending:
            return
        import pyarrow as pa

        arrays = [pa.chunked_array([chunk[i] for chunk in self._pending], type=field.type) for i, field in enumerate(self._schema)]
        rows, self._pending, self._pending_rows = self._pending_rows, [], 0
        self._writer.write_table(pa.Table.from_arrays(arrays, schema=self._schema), row_group_size=rows)

    def close(self) -> None:
        """Writes what is pending and the footer."""
        if self._writer is not None:
            self._flush()
            self._writer.close()
            self._writer = None

    def __enter__(self) -> "SeriesWriter":
        return self

    def __exit__(self, exc_type: object, *exc: object) -> None:
        if exc_type is not None:  # the run failed: its file is discarded, what is pending with it
            self._pending = []
        self.close()


def _read_row(file: Any, group: int, index: int) -> Any:
    """Row `index` (negative: from the end) of row group `group` of a ParquetFile, as a
    one-row pyarrow Table with the file's schema, read a block of columns at a time so that
    at most about :data:`ROW_READ_BYTES` are decoded at once."""
    import pyarrow as pa

    names = file.schema_arrow.names
    rows = file.metadata.row_group(group).num_rows
    step = max(1, ROW_READ_BYTES // (8 * rows))
    row: dict[str, list[Any]] = {}
    for k in range(0, len(names), step):
        block = file.read_row_group(group, columns=names[k : k + step], use_threads=False)
        row.update((name, [block.column(name)[index % rows].as_py()]) for name in block.column_names)  # copies: a slice would keep the block
    return pa.Table.from_pydict(row, schema=file.schema_arrow)


def read_metadata(folder: str | os.PathLike) -> dict[str, Any]:
    """The ``metadata.json`` of a results folder, every known key of the type
    :data:`METADATA_TYPES` gives it; ValueError naming the file, the key, the value and what is
    allowed otherwise (FileNotFoundError if there is no such folder)."""
    folder = Path(folder)
    path = folder / METADATA_FILE
    if not os.path.lexists(path):
        if not folder.is_dir():
            raise FileNotFoundError(errno.ENOENT, "no such results folder", str(folder))
        raise ValueError(f"{folder}: not a hexadyn results folder (no {METADATA_FILE})")
    metadata = _read_json_object(path, "hexadyn results metadata")
    if metadata.get("format") != FORMAT:
        raise ValueError(f"{path}: not hexadyn results metadata (format {metadata.get('format')!r}, expected {FORMAT!r})")
    for key, kinds in METADATA_TYPES.items():
        if key in metadata and not any(_is_json(metadata[key], kind) for kind in kinds):
            raise ValueError(f"{path}: `{key}` = {_shown(metadata[key])}: a JSON {_json_kind(metadata[key])}; allowed: {' or '.join(f'a JSON {_JSON_NAMES[k]}' for k in kinds)}")
    for key, what in (("units", "values"), ("descriptions", "values"), ("columns", "items")):
        items = metadata.get(key, ())
        for item in items.values() if isinstance(items, dict) else items:
            if not isinstance(item, str):
                raise ValueError(f"{path}: `{key}` holds {_shown(item)}, a JSON {_json_kind(item)}; allowed: strings as its {what}")
    return metadata


@contextlib.contextmanager
def open_series(path: Path) -> Iterator["pq.ParquetFile"]:
    """The Parquet file of a time series, opened as an input file
    (:func:`hexadyn.inputs.open_input`) and closed on leaving; ValueError naming it if it is
    missing, not a Parquet file, holds a column twice (a column would then be a table) or a
    column of other values than numbers."""
    import collections

    import pyarrow as pa
    import pyarrow.parquet as pq

    with inputs.open_input(_existing(path, "the Parquet file of the time series"), limit=None) as source:
        try:
            file = pq.ParquetFile(source)
        except (pa.ArrowException, OSError) as exc:
            raise ValueError(f"{path}: not a readable time series: {exc}") from None
        repeated = [(name, n) for name, n in collections.Counter(file.schema_arrow.names).items() if n > 1]
        if repeated:
            raise ValueError(f"{path}: column `{repeated[0][0]}` appears {repeated[0][1]} times; allowed: a time series of distinct columns")
        other = next((f for f in file.schema_arrow if not (pa.types.is_floating(f.type) or pa.types.is_integer(f.type))), None)
        if other is not None:
            raise ValueError(f"{path}: column `{other.name}` holds {other.type} values; allowed: a time series of numbers")
        yield file


def _existing(path: Path, what: str) -> Path:
    """`path`, ValueError saying `what` is missing if there is nothing there."""
    if not os.path.lexists(path):
        raise ValueError(f"{path}: missing; expected {what}")
    return path


def _read_parquet(path: Path, columns: list[str] | None = None) -> pd.DataFrame:
    import pyarrow as pa

    with open_series(path) as file:
        try:
            return file.read(columns=columns).to_pandas()
        except (pa.ArrowException, OSError) as exc:
            raise ValueError(f"{path}: not a readable time series: {exc}") from None


def _read_json_object(path: Path, what: str) -> dict[str, Any]:
    """A JSON file holding an object (an input file, :func:`hexadyn.inputs.read_text`);
    ValueError naming the file otherwise."""
    try:
        value = json.loads(inputs.read_text(_existing(path, f"{what} ({path.name})")))
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path}: not valid JSON ({what}): {exc}") from None
    if not isinstance(value, dict):
        raise ValueError(f"{path}: a JSON {_json_kind(value)}; expected an object ({what})")
    return value


#: JSON type names of the Python types :mod:`json` reads.
_JSON_NAMES: dict[type | None, str] = {dict: "object", list: "array", str: "string", int: "integer", float: "number", bool: "boolean", None: "null"}


def _is_json(value: Any, kind: type | None) -> bool:
    """Whether `value` read from JSON is of `kind` (None: null; a boolean is not an integer)."""
    if kind is None:
        return value is None
    return isinstance(value, kind) and not (kind is int and isinstance(value, bool))


def _json_kind(value: Any) -> str:
    """The JSON type name of a value read from JSON."""
    return _JSON_NAMES[None] if value is None else _JSON_NAMES.get(type(value), type(value).__name__)


def _shown(value: Any) -> str:
    """A JSON value on one line, at most 60 characters."""
    text = json.dumps(value)
    return text if len(text) <= 60 else text[:57] + "..."


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
