"""Shared helpers and fixtures of the Python tests."""

from __future__ import annotations

import re
import signal
from pathlib import Path
from typing import Sequence

import numpy as np
import pytest
from matplotlib.colors import to_rgb
from matplotlib.image import imread

import hexadyn
from hexadyn import Results


def sigint_as_in_a_terminal() -> None:
    """``preexec_fn`` of a command that a test interrupts with SIGINT: it gets the default
    disposition a command started from a terminal has. A test session started in the background
    of a non-interactive shell (``&``, nohup) inherits SIGINT ignored, which its children keep
    through exec, and Python then never raises KeyboardInterrupt."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def assert_one_line_error(result, *words: str) -> str:
    """A CLI result (click's CliRunner) of a refused command: exit status 1 and one line
    `Error: ...` on stderr holding each of `words`, no traceback; returns the line."""
    assert result.exit_code == 1, (result.exit_code, result.output, result.exception)
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])
    return lines[0]


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


def assert_drawn(png: Path, colours: Sequence[str] = (), width_in: float = 6.3) -> None:
    """The PNG is a 300 dpi figure `width_in` wide with a substantial drawn part and several
    colours, and each of `colours` (data series) covers a visible number of pixels."""
    image = imread(png)[..., :3]
    width = image.shape[1]
    assert width >= width_in * 300 * 0.95, f"{png.name}: {width} px wide, not 300 dpi"
    pixels = image.reshape(-1, 3)
    background = np.all(pixels > 0.99, axis=1)
    assert background.mean() < 0.97, f"{png.name}: {100 * (1 - background.mean()):.1f} % drawn"
    assert (~background).sum() > 20000, png.name
    levels = (pixels * 15).round().astype(np.int32)
    distinct = np.unique(levels[:, 0] * 256 + levels[:, 1] * 16 + levels[:, 2]).size
    assert distinct >= 8, f"{png.name}: only {distinct} colours"
    for colour in colours:
        near = np.all(np.abs(pixels - np.array(to_rgb(colour))) < 0.04, axis=1)
        assert near.sum() > 500, f"{png.name}: {near.sum()} pixels of {colour}"
