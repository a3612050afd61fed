"""The package installs, its extension imports and the CLI answers."""

from __future__ import annotations

import importlib.metadata
import re
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

import hexadyn
from hexadyn import _core
from hexadyn.cli import cli

ROOT = Path(__file__).resolve().parents[2]


def cargo_workspace_version() -> str:
    """[workspace.package] version of the root Cargo.toml."""
    text = (ROOT / "Cargo.toml").read_text()
    section = re.search(r"^\[workspace\.package\]\s*$(.*?)(?=^\[|\Z)", text, re.M | re.S)
    assert section, "root Cargo.toml has no [workspace.package]"
    version = re.search(r'^version\s*=\s*"([^"]+)"', section.group(1), re.M)
    assert version, "[workspace.package] has no version"
    return version.group(1)


def test_extension_imports():
    assert _core.__name__ == "hexadyn._core"
    assert hexadyn.__version__ == _core.__version__


def test_version_matches_cargo_workspace():
    expected = cargo_workspace_version()
    assert hexadyn.__version__ == expected
    assert importlib.metadata.version("hexadyn") == expected


def test_cli_version():
    result = CliRunner().invoke(cli, ["--version"], prog_name="hexadyn")
    assert result.exit_code == 0, result.output
    assert result.output.strip() == f"hexadyn {cargo_workspace_version()}"


def test_cli_info():
    result = CliRunner().invoke(cli, ["info"], prog_name="hexadyn")
    assert result.exit_code == 0, result.output
    assert f"engine: {_core.__version__}" in result.output
    assert "default robot: amru5" in result.output
    assert "phantomx  serial legs, 1.843 kg, joints coxa (revolute), femur (revolute), tibia (revolute)" in result.output
    assert "amru5     pantograph legs" in result.output


def test_user_errors_are_one_line(monkeypatch):
    @cli.command("_fail")
    def fail():
        raise FileNotFoundError(2, "No such file or directory", "missing.toml")

    try:
        monkeypatch.delenv("HEXADYN_DEBUG", raising=False)
        result = CliRunner().invoke(cli, ["_fail"], prog_name="hexadyn")
    finally:
        del cli.commands["_fail"]
    assert result.exit_code == 1
    assert result.output == "Error: missing.toml: No such file or directory\n"


def test_unknown_command_is_a_usage_error():
    result = CliRunner().invoke(cli, ["no-such-command"], prog_name="hexadyn")
    assert result.exit_code == 2
    assert "Traceback" not in result.output
    assert "No such command" in result.output


def test_console_script():
    script = Path(sys.executable).with_name("hexadyn")
    if not script.exists():
        pytest.skip("the hexadyn console script is not installed next to this interpreter")
    out = subprocess.run([str(script), "--version"], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == f"hexadyn {hexadyn.__version__}"
