"""Shared helpers and fixtures of the Python tests."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import hexadyn
from hexadyn import Results


def shortened(name: str, folder: Path, duration: float = 0.2) -> Path:
    """A copy of a shipped scenario with duration_s replaced (keeps the tests fast)."""
    text = (hexadyn.SCENARIOS_DIR / f"{name}.toml").read_text()
    text, n = re.subn(r"(?m)^duration_s = .*$", f"duration_s = {duration}", text)
    assert n == 1
    path = folder / f"{name}.toml"
    path.write_text(text)
    return path


@pytest.fixture(scope="session")
def walk_file(tmp_path_factory) -> Path:
    """The validation walk of Table 6.2 at 1.5 cm/s cut to 24 s: two 12 s steps, every phase."""
    return shortened("validation_tripod_1_5cm", tmp_path_factory.mktemp("walk"), 24.0)


@pytest.fixture(scope="session")
def walk(walk_file: Path) -> Results:
    return hexadyn.simulate(walk_file, progress=False)
