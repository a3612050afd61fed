"""The campaign folder: ``campaign.json`` (the configuration) and ``runs.sqlite`` (the runs).

``campaign.json`` holds the configuration of the campaign (scenario text, velocities, runs,
variants, seed, distributions) and the hexadyn version; a folder is resumed only with the same
configuration. ``runs.sqlite`` has one row per finished simulation in the table ``runs``, keyed
by (variant, velocity_index, run_index), written by the parent process in one transaction per
run: an interrupted campaign loses at most the runs that were still being simulated, and the
primary key forbids duplicates. Failed simulations are stored too (status ``failed`` and the
error message), so a resumed campaign does not retry them.

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
from pathlib import Path
from typing import Any, Mapping, NamedTuple, Sequence

from hexadyn import atomic

__all__ = ["CAMPAIGN_FILE", "DATABASE_FILE", "SUMMARY_COLUMNS", "CampaignStore", "RunKey", "per_joint_columns", "summary_columns"]

CAMPAIGN_FILE = "campaign.json"
DATABASE_FILE = "runs.sqlite"
#: Identifies a hexadyn Monte Carlo folder in campaign.json.
FORMAT = "hexadyn-montecarlo"

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


def _schema(columns: Sequence[str]) -> str:
    return f"""
CREATE TABLE IF NOT EXISTS runs (
    variant TEXT NOT NULL,
    velocity_index INTEGER NOT NULL,
    run_index INTEGER NOT NULL,
    velocity_m_s REAL NOT NULL,
    status TEXT NOT NULL CHECK (status IN ('ok', 'failed')),
    error TEXT,
    parameters TEXT NOT NULL,
    {", ".join(f"{c} REAL" for c in columns)},
    PRIMARY KEY (variant, velocity_index, run_index)
)
"""


class RunKey(NamedTuple):
    """One simulation of a campaign: a friction variant, a velocity (index) and a run index."""

    variant: str
    velocity_index: int
    run_index: int


class CampaignStore:
    """A campaign folder, created or reopened with :meth:`open`."""

    def __init__(self, folder: Path, connection: sqlite3.Connection, joints: Sequence[str] = AMRU5_JOINTS) -> None:
        self.folder = folder
        self._db = connection
        self.columns = summary_columns(joints)

    @classmethod
    def open(cls, folder: str | os.PathLike, configuration: Mapping[str, Any], joints: Sequence[str] = AMRU5_JOINTS) -> CampaignStore:
        """Creates the campaign folder, or reopens it if it holds the same configuration.
        ``joints``: the robot's joint names, for the per-joint columns.

        Raises ValueError if ``folder`` holds something else than a campaign, or a campaign
        with another configuration (naming the first differing field).
        """
        folder = Path(folder)
        config_file = folder / CAMPAIGN_FILE
        if config_file.is_file():
            _check_same_configuration(config_file, configuration)
        elif folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
            raise ValueError(f"{folder}: not a Monte Carlo campaign folder (no {CAMPAIGN_FILE}); choose an empty or new folder")
        else:
            folder.mkdir(parents=True, exist_ok=True)
            text = json.dumps({"format": FORMAT, "configuration": dict(configuration)}, indent=2) + "\n"
            atomic.write_file(config_file, lambda tmp: tmp.write_text(text))
        connection = sqlite3.connect(folder / DATABASE_FILE, timeout=60.0)
        try:
            with _readable(folder / DATABASE_FILE), connection:
                connection.execute(_schema(summary_columns(joints)))
        except BaseException:
            connection.close()
            raise
        return cls(folder, connection, joints)

    def close(self) -> None:
        self._db.close()

    def __enter__(self) -> CampaignStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def finished(self) -> set[RunKey]:
        """The runs stored so far (succeeded or failed)."""
        with _readable(self.folder / DATABASE_FILE):
            rows = self._db.execute("SELECT variant, velocity_index, run_index FROM runs")
            return {RunKey(*row) for row in rows}

    def add(self, key: RunKey, velocity_m_s: float, parameters: Mapping[str, Any], outcome: Mapping[str, Any]) -> None:
        """Stores one finished run in its own transaction.

        ``outcome`` is ``{"status": "ok", "summary": {...}}`` or ``{"status": "failed",
        "error": message}``. A run already stored is an error (sqlite3.IntegrityError).
        """
        summary = outcome.get("summary", {})
        columns = ("variant", "velocity_index", "run_index", "velocity_m_s", "status", "error", "parameters", *self.columns)
        values = (*key, velocity_m_s, outcome["status"], outcome.get("error"), json.dumps(dict(parameters)), *(summary.get(c) for c in self.columns))
        with _readable(self.folder / DATABASE_FILE), self._db:
            self._db.execute(f"INSERT INTO runs ({', '.join(columns)}) VALUES ({', '.join('?' * len(columns))})", values)

    def runs(self):
        """Every stored run as a pandas DataFrame sorted by (variant, velocity_index, run_index)
        (the order makes aggregates independent of the order the runs finished in)."""
        import pandas as pd

        with _readable(self.folder / DATABASE_FILE, pd.errors.DatabaseError):
            return pd.read_sql_query("SELECT * FROM runs ORDER BY variant, velocity_index, run_index", self._db)


@contextmanager
def _readable(database: Path, *wrapped: type[Exception]):
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
        raise ValueError(f"{database}: not a readable campaign database ({' '.join(str(cause).split())}); restore it, or move it away to start the campaign again") from exc


def _check_same_configuration(config_file: Path, configuration: Mapping[str, Any]) -> None:
    try:
        stored = json.loads(config_file.read_text())
    except ValueError as exc:
        raise ValueError(f"{config_file}: not a campaign file ({exc})") from exc
    if not isinstance(stored, dict) or stored.get("format") != FORMAT:
        raise ValueError(f"{config_file}: not a hexadyn Monte Carlo campaign file")
    # JSON round trip: tuples become lists, as in the stored file.
    wanted = json.loads(json.dumps(dict(configuration)))
    old = stored.get("configuration", {})
    for field in sorted(set(wanted) | set(old)):
        if wanted.get(field) != old.get(field):
            raise ValueError(
                f"{config_file.parent}: the campaign there has another {field} "
                f"({_short(old.get(field))} there, {_short(wanted.get(field))} now); "
                "rerun with its configuration to resume it, or choose another folder"
            )


def _short(value: Any) -> str:
    text = json.dumps(value)
    return text if len(text) <= 60 else text[:57] + "..."
