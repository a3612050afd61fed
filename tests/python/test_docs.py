"""The README and the documentation pages (docs/*.md, the mkdocs site) stay true.

- Every code block runs, in order, each page in a fresh temporary folder (its own `results/`):
  ``sh`` lines through the ``hexadyn`` command line (in this process, as ``hexadyn`` would run
  them; a runnable ``sh`` block holds ``hexadyn`` commands only), ``python`` blocks as one
  script per page (a block may use an earlier one's names), ``toml`` blocks parsed (and saved
  where a ``file:`` marker names them), ``c`` blocks compiled. The markers and the languages are
  described in docs_blocks.py; a block that must not run says why (``no-run: REASON``), and
  each page's count of those is held here, so that one more is a decision, not a slip.
- The site builds with ``mkdocs build --strict`` (any warning, a broken link first, fails).
- No placeholder is left, and a measured figure carries its date, machine (cores and CPU
  model) and commit.
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import matplotlib
import pandas as pd
import pytest
from click.testing import CliRunner
from docs_blocks import LANGUAGES, PAGES, ROOT, Block, blocks, hexadyn_commands, prose

from hexadyn.cli import cli

matplotlib.use("Agg")  # pandas' .plot() in the Python blocks draws without a display

#: The blocks each page does not run (no-run marker); a page not listed runs all of its blocks.
NO_RUN = {
    "README.md": 1,  # make run, make test
    "docs/benchmarks.md": 2,  # make bench..., cargo run
    "docs/cli.md": 1,  # the live viewer, a 606 s ground detection run
    "docs/ground-detection.md": 1,  # a Rust fragment
    "docs/install.md": 2,  # pip install
    "docs/monte-carlo.md": 1,  # full campaigns, a Ray cluster
    "docs/robot-link.md": 1,  # master and emulator in real time, two terminals
    "docs/studies.md": 4,  # the shipped studies: 6144 walks, from the CLI and from Python; the efficiency study with its comparison; the AMRU5 bis studies, once per robot
}


@pytest.mark.parametrize("page", PAGES)
def test_the_page_runs_as_written(page: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    namespace: dict[str, object] = {"__name__": "__docs__"}
    for block in blocks(page):
        if block.marker("no-run") is not None:
            continue
        for name, source in block.givens():
            target = tmp_path / name
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(ROOT / source, target)
        run_block(block, tmp_path, namespace)
    if check := AFTER_PAGE.get(page):
        check(tmp_path)


def the_walk_through_walks(folder: Path) -> None:
    """docs/add-your-robot.md ends with a walk of the imported robot: it walks."""
    summary = json.loads((folder / "results" / "my_tripod" / "summary.json").read_text())
    assert summary["clamped_ik_references"] == 0
    assert summary["reference_distance_m"] > 0.39 and summary["distance_walked_m"] > 0.7 * summary["reference_distance_m"]
    assert abs(summary["energy_balance_error_relative"]) < 1e-3
    columns = pd.read_parquet(folder / "results" / "my_tripod" / "timeseries.parquet", columns=["hip[0]", "thigh[5]", "shank[3]"])
    assert len(columns) == 1001
    assert (folder / "my_hexapod_out.urdf").read_text().startswith("<?xml")


#: What a page's run must have produced, beyond every command succeeding.
AFTER_PAGE = {"docs/add-your-robot.md": the_walk_through_walks}


def run_block(block: Block, folder: Path, namespace: dict[str, object]) -> None:
    """Runs one block in `folder` (the current directory); `namespace` is the page's script."""
    if block.language == "sh":
        for command in hexadyn_commands(block):
            run_hexadyn(block, command)
    elif block.language == "python":
        exec(compile(block.body, block.where, "exec"), namespace)
    elif block.language == "toml":
        try:
            tomllib.loads(block.body)
        except tomllib.TOMLDecodeError as exc:
            pytest.fail(f"{block.where}: not TOML: {exc}")
        if name := block.marker("file"):
            (folder / name).write_text(block.body)
    elif block.language == "c":
        compiled = subprocess.run(
            ["cc", "-std=c99", "-Wall", "-Werror", "-fsyntax-only", "-include", "stdint.h", "-include", "stddef.h", "-x", "c", "-"],
            input=block.body, capture_output=True, text=True, cwd=folder,
        )
        assert compiled.returncode == 0, f"{block.where}: does not compile:\n{compiled.stderr}"
    elif block.language == "rust":
        pytest.fail(f"{block.where}: a rust block shows a fragment: mark it no-run with the test that compiles the same calls")


def run_hexadyn(block: Block, args: list[str]) -> None:
    result = CliRunner().invoke(cli, args)
    if result.exit_code != 0:
        detail = "" if result.exception is None or isinstance(result.exception, SystemExit) else f"\n{result.exception!r}"
        pytest.fail(f"{block.where}: hexadyn {shlex.join(args)}: exit status {result.exit_code}\n{result.output}{detail}")


def test_every_block_has_a_language_and_every_no_run_a_reason() -> None:
    counts = {}
    for page in PAGES:
        for block in blocks(page):
            assert block.language in LANGUAGES, f"{block.where}: block language {block.language!r}: allowed: {', '.join(LANGUAGES)} (text: shown output, not run)"
            reason = block.marker("no-run")
            if reason is not None:
                assert len(reason.split()) >= 3, f"{block.where}: no-run {reason!r}: say why the block does not run"
                counts[page] = counts.get(page, 0) + 1
            else:
                block.givens()  # a malformed given marker fails here, run or not
                for name, source in block.givens():
                    assert (ROOT / source).is_file(), f"{block.where}: given {name} from {source}: no such file in the repository"
    assert counts == NO_RUN, "the no-run blocks per page changed: update NO_RUN if each has its reason"


#: Left-over placeholders: a FIGURE token to fill in, TODO, TBD, FIXME.
PLACEHOLDER = re.compile(r"\b[A-Z][A-Z0-9]*(?:_[A-Z0-9]+)*_FIGURE\b|\bTODO\b|\bTBD\b|\bFIXME\b")


@pytest.mark.parametrize("page", PAGES)
def test_no_placeholder_is_left(page: str) -> None:
    for number, line in enumerate((ROOT / page).read_text().splitlines(), start=1):
        assert not PLACEHOLDER.search(line), f"{page}:{number}: placeholder: {line.strip()}"


#: What makes a paragraph a measured figure: a time of wall clock, CPU or user, a rate of
#: frames or simulations, a load average or real-time factor with its number, a paragraph that
#: says "Measured", a screenshot.
MEASURED = re.compile(
    r"\d\s*(?:s|ms|µs|min)\b[^.;]{0,25}\b(?:wall|CPU|user)\b|\b(?:wall|CPU|user) time[^.;]{0,15}\d"
    r"|\d\s*(?:frames|simulations)/s|load average \d|real-time factor \d|\bMeasured\b|!\["
)
DATE = re.compile(r"\b20\d\d-\d\d-\d\d\b")
COMMIT = re.compile(r"\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}\b")
MACHINE = re.compile(r"\b\d+[- ]cores?\b")
#: The machine's CPU: its model (`lscpu`'s "Model name"), or, for a figure measured before the
#: stamps named it, that it was not recorded.
CPU = re.compile(r"\b(?:AMD EPYC|AMD Ryzen|Intel|Apple M\d|Graviton|Ampere)\b|\bCPU model not recorded\b")


def figure_paragraphs(page: str) -> list[tuple[str, str]]:
    """The paragraphs of `page` that give a measured figure, each with where its stamp may
    also be: the heading of its section (a stamp there covers the section) and the paragraph
    before it (the sentence that introduces a table or a list)."""
    out = []
    heading = previous = ""
    for paragraph in re.split(r"\n\s*\n", prose(page)):
        if paragraph.lstrip().startswith("#"):
            heading, previous = paragraph.strip().splitlines()[0], ""
            continue
        if MEASURED.search(paragraph):
            out.append((heading + "\n" + previous, paragraph.strip()))
        previous = paragraph
    return out


@pytest.mark.parametrize("page", PAGES)
def test_measured_figures_carry_their_date_machine_and_commit(page: str) -> None:
    missing = []
    for around, paragraph in figure_paragraphs(page):
        stamps = (("date", DATE), ("machine (N-core)", MACHINE), ("CPU model (or 'CPU model not recorded')", CPU), ("commit", COMMIT))
        lacks = [what for what, stamp in stamps if not (stamp.search(paragraph) or stamp.search(around))]
        if lacks:
            missing.append(f"{', '.join(lacks)}: {paragraph[:100]!r}")
    assert not missing, f"{page}: figures without " + "\n".join(missing)


def test_the_readme_links_resolve() -> None:
    for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", (ROOT / "README.md").read_text()):
        if not re.match(r"[a-z]+://", target):
            assert (ROOT / target).exists(), f"README.md: link to {target}: no such file"


def test_the_site_builds_without_a_warning(tmp_path: Path) -> None:
    """`make docs`' build, strict: a broken link, an anchor that is not there or a page left
    out of the nav fails. Fails (never skips) without mkdocs-material, a test dependency."""
    if importlib.util.find_spec("material") is None:
        pytest.fail("mkdocs-material is not installed: it is in the docs and test extras (make setup, or pip install -c requirements/lock.txt -e '.[test]')")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    built = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")], cwd=ROOT, env=env, capture_output=True, text=True)
    assert built.returncode == 0, built.stdout + built.stderr
    assert (tmp_path / "site" / "index.html").is_file()
