"""The campaign folder: ``campaign.json`` (the configuration) and ``runs.sqlite`` (the runs).

:class:`RunStore` keeps such a folder for any :class:`Layout` of runs (a design study's too,
:mod:`hexadyn.study`); :class:`CampaignStore` is a campaign's.

``campaign.json`` holds the configuration of the campaign (scenario text, velocities, runs,
variants, seed, distributions) and the hexadyn version; a folder is resumed only with the same
configuration. ``runs.sqlite`` has one row per finished simulation in the table ``runs``, keyed
by (variant, velocity_index, run_index), written by the parent process in one transaction per
run: an interrupted campaign loses at most the runs that were still being simulated, and the
primary key forbids duplicates. Failed simulations are stored too (status ``failed`` and the
error message), so a resumed campaign does not retry them. A campaign's run keeps its failed
health checks (``warnings``, a JSON list; NULL for a run stored before hexadyn recorded them).

``campaign.json`` is written atomically (:func:`hexadyn.atomic.write_file`), the output files
(table and figures) as one set (:func:`hexadyn.montecarlo.tables.write_results`). A
``runs.sqlite`` that SQLite cannot read (truncated, not a database, another table) is refused
with one line naming it.
"""

from __future__ import annotations

import json
import os
import sqlite3
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, NamedTuple, Sequence

from hexadyn import atomic

__all__ = ["CAMPAIGN_FILE", "DATABASE_FILE", "WARNINGS_COLUMN", "SUMMARY_COLUMNS", "CampaignStore", "Layout", "RunKey", "RunStore", "campaign_layout", "per_joint_columns", "summary_columns"]

CAMPAIGN_FILE = "campaign.json"
DATABASE_FILE = "runs.sqlite"
#: Identifies a hexadyn Monte Carlo folder in campaign.json.
FORMAT = "hexadyn-montecarlo"
#: The column of a campaign's runs holding their failed health checks (JSON list).
WARNINGS_COLUMN = "warnings"

#: The joints of AMRU5's legs, whose names the per-joint columns of its campaigns carry.
AMRU5_JOINTS = ("q_r", "q_v", "q_h")


def per_joint_columns(joints: Sequence[str] = AMRU5_JOINTS) -> tuple[str, ...]:
    """The database columns of the split of E per joint of a leg, in the robot's joint order:
    the summary entries ``energy_electrical_{name}_j`` of the robot's joints (AMRU5's
    ``energy_electrical_q_r_j``..., the PhantomX's ``energy_electrical_coxa_j``...)."""
    return tuple(f"energy_electrical_{name}_j" for name in joints)


def summary_columns(joints: Sequence[str] = AMRU5_JOINTS) -> tuple[str, ...]:
    """Summary entries of a run kept in the database (``_core.run_scenario(...)["summary"]``):
    ξ (Eq. 6.6), E and its split per joint (:func:`per_joint_columns`), distance, mass,
    averaged power, Joule and friction losses, the energy balance error, the simulated and the
    wall time."""
    return (
        "specific_resistance",
        "energy_electrical_j",
        *per_joint_columns(joints),
        "energy_joule_j",
        "energy_friction_j",
        "energy_balance_error_relative",
        "robot_mass_kg",
        "distance_walked_m",
        "average_power_w",
        "duration_s",
        "wall_time_s",
    )


#: AMRU5's per-joint columns and summary columns.
PER_JOINT_COLUMNS = per_joint_columns()
SUMMARY_COLUMNS = summary_columns()


@dataclass(frozen=True)
class Layout:
    """What a folder of runs holds: ``config_file`` (its configuration, ``{"format": format,
    "configuration": {...}}``) and the table ``runs`` of :data:`DATABASE_FILE`, keyed by the
    ``keys`` columns, with the ``columns`` besides (name -> SQL type: INTEGER, REAL, TEXT).
    ``what`` names such a folder in messages ("Monte Carlo campaign", "design study")."""

    what: str
    format: str
    config_file: str
    keys: Mapping[str, str]
    columns: Mapping[str, str]

    def schema(self) -> str:
        columns = [f"{_quoted(c)} {t} NOT NULL" for c, t in self.keys.items()]
        columns += [f"{_quoted(c)} {t}" for c, t in self.columns.items()]
        columns[len(self.keys) :] = ["status TEXT NOT NULL CHECK (status IN ('ok', 'failed'))", "error TEXT", *columns[len(self.keys) :]]
        return f"CREATE TABLE IF NOT EXISTS runs ({', '.join(columns)}, PRIMARY KEY ({', '.join(map(_quoted, self.keys))}))"


def _quoted(name: str) -> str:
    """A column name in SQL: a plain identifier as it is (SQLite would take a quoted name that
    is no column for a string), a dotted scenario field quoted (``"gait.period_s"``)."""
    return name if name.isidentifier() else '"' + name.replace('"', '""') + '"'


def campaign_layout(joints: Sequence[str] = AMRU5_JOINTS) -> Layout:
    """A Monte Carlo campaign's folder: runs keyed by (variant, velocity_index, run_index), with
    the velocity, the drawn friction (JSON), the :func:`summary_columns` of the robot's joints
    and the failed health checks (:data:`WARNINGS_COLUMN`)."""
    keys = {"variant": "TEXT", "velocity_index": "INTEGER", "run_index": "INTEGER"}
    columns = {"velocity_m_s": "REAL NOT NULL", "parameters": "TEXT NOT NULL", **{c: "REAL" for c in summary_columns(joints)}, WARNINGS_COLUMN: "TEXT"}
    return Layout("Monte Carlo campaign", FORMAT, CAMPAIGN_FILE, keys, columns)


class RunKey(NamedTuple):
    """One simulation of a campaign: a friction variant, a velocity (index) and a run index."""

    variant: str
    velocity_index: int
    run_index: int


class RunStore:
    """A folder of runs (a campaign's, a study's), created or reopened with :meth:`open`."""

    def __init__(self, folder: Path, connection: sqlite3.Connection, layout: Layout) -> None:
        self.folder = folder
        self._db = connection
        self.layout = layout

    @classmethod
    def open(cls, folder: str | os.PathLike, configuration: Mapping[str, Any], layout: Layout):
        """Creates the folder, or reopens it if it holds the same configuration.

        Raises ValueError if ``folder`` holds something else than such a folder, or one with
        another configuration (naming the first differing field).
        """
        folder = Path(folder)
        config_file = folder / layout.config_file
        if config_file.is_file():
            _check_same_configuration(config_file, configuration, layout)
        elif folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
            raise ValueError(f"{folder}: not a {layout.what} folder (no {layout.config_file}); choose an empty or new folder")
        else:
            folder.mkdir(parents=True, exist_ok=True)
            text = json.dumps({"format": layout.format, "configuration": dict(configuration)}, indent=2) + "\n"
            atomic.write_file(config_file, lambda tmp: tmp.write_text(text))
        connection = sqlite3.connect(folder / DATABASE_FILE, timeout=60.0)
        try:
            with _readable(folder / DATABASE_FILE, layout), connection:
                connection.execute(layout.schema())
                _add_new_columns(connection, layout)
        except BaseException:
            connection.close()
            raise
        return cls(folder, connection, layout)

    def close(self) -> None:
        self._db.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def finished(self) -> set[tuple]:
        """The keys of the runs stored so far (succeeded or failed)."""
        with _readable(self.folder / DATABASE_FILE, self.layout):
            return set(self._db.execute(f"SELECT {', '.join(map(_quoted, self.layout.keys))} FROM runs"))

    def add_rows(self, rows: Sequence[Mapping[str, Any]]) -> None:
        """Stores finished runs in one transaction: each row maps the key columns, ``status``
        (``ok`` or ``failed``), ``error`` and any of the other columns (missing: NULL). A run
        already stored is an error (sqlite3.IntegrityError)."""
        columns = (*self.layout.keys, "status", "error", *self.layout.columns)
        statement = f"INSERT INTO runs ({', '.join(map(_quoted, columns))}) VALUES ({', '.join('?' * len(columns))})"
        with _readable(self.folder / DATABASE_FILE, self.layout), self._db:
            self._db.executemany(statement, [tuple(row.get(c) for c in columns) for row in rows])

    def runs(self):
        """Every stored run as a pandas DataFrame sorted by its key (the order makes aggregates
        independent of the order the runs finished in)."""
        import pandas as pd

        with _readable(self.folder / DATABASE_FILE, self.layout, pd.errors.DatabaseError):
            return pd.read_sql_query(f"SELECT * FROM runs ORDER BY {', '.join(map(_quoted, self.layout.keys))}", self._db)


class CampaignStore(RunStore):
    """A campaign folder, created or reopened with :meth:`open`."""

    @classmethod
    def open(cls, folder: str | os.PathLike, configuration: Mapping[str, Any], joints: Sequence[str] = AMRU5_JOINTS) -> CampaignStore:  # type: ignore[override]
        """Creates the campaign folder, or reopens it if it holds the same configuration.
        ``joints``: the robot's joint names, for the per-joint columns.

        Raises ValueError if ``folder`` holds something else than a campaign, or a campaign
        with another configuration (naming the first differing field).
        """
        return super().open(folder, configuration, campaign_layout(joints))

    @property
    def columns(self) -> tuple[str, ...]:
        """The summary columns of the runs (between the drawn friction and the warnings)."""
        return tuple(self.layout.columns)[2:-1]

    def finished(self) -> set[RunKey]:  # type: ignore[override]
        """The runs stored so far (succeeded or failed)."""
        return {RunKey(*key) for key in super().finished()}

    def add(self, key: RunKey, velocity_m_s: float, parameters: Mapping[str, Any], outcome: Mapping[str, Any]) -> None:
        """Stores one finished run in its own transaction.

        ``outcome`` is ``{"status": "ok", "summary": {...}, "warnings": [...]}`` or ``{"status":
        "failed", "error": message}``. A run already stored is an error (sqlite3.IntegrityError).
        """
        row = {**outcome.get("summary", {}), **key._asdict(), "velocity_m_s": velocity_m_s, "parameters": json.dumps(dict(parameters))}
        if "warnings" in outcome:
            row[WARNINGS_COLUMN] = json.dumps(list(outcome["warnings"]))
        self.add_rows([{**row, "status": outcome["status"], "error": outcome.get("error")}])


def _add_new_columns(connection: sqlite3.Connection, layout: Layout) -> None:
    """Adds to a ``runs`` table stored by an earlier hexadyn the nullable columns of `layout` it
    lacks (its runs get NULL there), so that its campaign resumes; a table without the key
    columns is not one of ours and is left to fail on use."""
    present = {row[1] for row in connection.execute("PRAGMA table_info(runs)")}
    if not set(layout.keys) <= present:
        return
    for column, kind in layout.columns.items():
        if column not in present and "NOT NULL" not in kind:
            connection.execute(f"ALTER TABLE runs ADD COLUMN {_quoted(column)} {kind}")


@contextmanager
def _readable(database: Path, layout: Layout, *wrapped: type[Exception]):
    """Turns an error of the SQLite file `database` (truncated, not a database, another table,
    locked beyond the timeout) into a ValueError of one line naming it; `wrapped`: the errors a
    reader wraps SQLite's in (pandas'). A run stored twice (sqlite3.IntegrityError) is a bug,
    not bad input: it is left as it is."""
    try:
        yield
    except sqlite3.IntegrityError:
        raise
    except (sqlite3.DatabaseError, *wrapped) as exc:
        cause = exc.__cause__ if isinstance(exc.__cause__, sqlite3.Error) else exc
        noun = layout.what.split()[-1]  # campaign, study
        raise ValueError(f"{database}: not a readable {noun} database ({' '.join(str(cause).split())}); restore it, or move it away to start the {noun} again") from exc


def _check_same_configuration(config_file: Path, configuration: Mapping[str, Any], layout: Layout) -> None:
    noun = layout.what.split()[-1]
    try:
        stored = json.loads(config_file.read_text())
    except ValueError as exc:
        raise ValueError(f"{config_file}: not a {noun} file ({exc})") from exc
    if not isinstance(stored, dict) or stored.get("format") != layout.format:
        raise ValueError(f"{config_file}: not a hexadyn {layout.what} file")
    # JSON round trip: tuples become lists, as in the stored file.
    wanted = json.loads(json.dumps(dict(configuration)))
    old = stored.get("configuration", {})
    for field in sorted(set(wanted) | set(old)):
        if wanted.get(field) != old.get(field):
            raise ValueError(
                f"{config_file.parent}: the {noun} there has another {field} "
                f"({_short(old.get(field))} there, {_short(wanted.get(field))} now); "
                "rerun with its configuration to resume it, or choose another folder"
            )


def _short(value: Any) -> str:
    text = json.dumps(value)
    return text if len(text) <= 60 else text[:57] + "..."
