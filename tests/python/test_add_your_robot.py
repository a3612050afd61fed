"""docs/add-your-robot.md runs as written: its blocks, in order, in a fresh folder (the shell
commands through the CLI, the TOML block saved as the scenario it names), and the walk it
ends with walks."""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import pandas as pd
from click.testing import CliRunner

from hexadyn.cli import cli

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "add-your-robot.md"


def test_the_walk_through_runs_as_written(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "robots" / "phantomx").mkdir(parents=True)
    (tmp_path / "robots" / "phantomx" / "phantomx.urdf").write_text((ROOT / "robots" / "phantomx" / "phantomx.urdf").read_text())
    blocks = re.findall(r"```(sh|toml)\n(.*?)```", PAGE.read_text(), re.S)
    assert [kind for kind, _ in blocks] == ["sh", "sh", "toml", "sh", "sh"]
    runner = CliRunner()
    for kind, body in blocks:
        if kind == "toml":
            (tmp_path / "my_tripod.toml").write_text(body)
            continue
        for line in body.strip().splitlines():
            args = shlex.split(line)
            assert args[0] == "hexadyn", line
            result = runner.invoke(cli, args[1:])
            assert result.exit_code == 0, (line, result.output)
    summary = json.loads((tmp_path / "results" / "my_tripod" / "summary.json").read_text())
    assert summary["clamped_ik_references"] == 0
    assert summary["reference_distance_m"] > 0.39 and summary["distance_walked_m"] > 0.7 * summary["reference_distance_m"]
    assert abs(summary["energy_balance_error_relative"]) < 1e-3
    columns = pd.read_parquet(tmp_path / "results" / "my_tripod" / "timeseries.parquet", columns=["hip[0]", "thigh[5]", "shank[3]"])
    assert len(columns) == 1001
    assert (tmp_path / "my_hexapod_out.urdf").read_text().startswith("<?xml")
