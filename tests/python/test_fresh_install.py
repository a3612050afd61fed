"""A plain install runs every command (issue 38): in a fresh venv, hexadyn's wheel installed
without extras, with nothing but the runtime dependencies pip resolves from its metadata, runs
the documented example of every command of `hexadyn --help` (docs/cli.md's ``sh`` blocks).

Offline and cheap, yet pip's own resolution: the wheel is maturin's (``maturin build
--release``, which reuses the engine that `make setup` built into target/), and pip installs
it with ``--no-index`` from a wheelhouse of the distributions of this test environment (the
ones requirements/lock.txt pins, packed back into wheels). The wheelhouse holds more than the
dependencies need; pip takes only what hexadyn's metadata asks for, so a module that the
package imports but that only an extra (the test one, say) installs is missing in the fresh venv
and its command fails here. Commands that need an extra (`hexadyn view`) must say which, in one
line.
"""

from __future__ import annotations

import importlib.metadata
import json
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path
from typing import Iterator

import pytest
from docs_blocks import ROOT, blocks, hexadyn_commands
from packaging.requirements import Requirement
from packaging.tags import sys_tags
from test_dependencies import canonical, declared

LOCK = ROOT / "requirements" / "lock.txt"
#: The page whose ``sh`` blocks are the commands' documented examples (run ones and no-run).
EXAMPLES = "docs/cli.md"
#: Commands a plain install cannot run, and the extra their one-line error names (the optional
#: features of tests/python/test_dependencies.py).
NEEDS_EXTRA = {"view": "view"}
#: Python modules of the optional features (under python/hexadyn): they may import their extra.
OPTIONAL_MODULES = ("hexadyn.view.",)


@pytest.fixture(scope="module")
def fresh(tmp_path_factory) -> Iterator[Path]:
    """The bin/ folder of a fresh venv holding hexadyn's wheel and its runtime dependencies
    (about 1 GB with the wheelhouse: both are removed once used)."""
    folder = tmp_path_factory.mktemp("fresh_install")
    wheel = build_wheel(folder / "dist")
    wheelhouse = folder / "wheelhouse"
    runtime, _ = declared()
    for name in sorted(closure(runtime)):
        pack_wheel(importlib.metadata.distribution(name), wheelhouse)
    run([sys.executable, "-m", "venv", str(folder / "venv")])
    bin_dir = folder / "venv" / "bin"
    run([str(bin_dir / "python"), "-m", "pip", "install", "--quiet", "--no-index", "--no-compile", "--find-links", str(wheelhouse), "-c", str(LOCK), str(wheel)])
    shutil.rmtree(wheelhouse)
    yield bin_dir
    shutil.rmtree(folder)


def run(args: list[str], cwd: Path | None = None, check: bool = True) -> subprocess.CompletedProcess:
    """`args` in `cwd`, outside this test's environment (no PYTHONPATH to the source tree)."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "HEXADYN_DEBUG")}
    done = subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True, stdin=subprocess.DEVNULL)
    if check and done.returncode != 0:
        pytest.fail(f"{' '.join(args)}: exit status {done.returncode}\n{done.stdout}{done.stderr}")
    return done


def build_wheel(out: Path) -> Path:
    """hexadyn's wheel as `pip install .` builds it (maturin, the build backend), into `out`."""
    maturin = Path(sys.executable).with_name("maturin")
    if not maturin.is_file():
        pytest.fail(f"{maturin}: no maturin beside the test's Python; `make setup` installs it (pinned by requirements/lock.txt)")
    run([str(maturin), "build", "--release", "--interpreter", sys.executable, "--out", str(out)], cwd=ROOT)
    (wheel,) = out.glob("hexadyn-*.whl")
    return wheel


def closure(names: set[str]) -> set[str]:
    """The installed distributions `names` need, with their own runtime dependencies (no
    extras), transitively, by canonical name."""
    found: set[str] = set()
    todo = sorted(names)
    while todo:
        name = todo.pop()
        if name in found:
            continue
        found.add(name)
        for text in importlib.metadata.distribution(name).requires or []:
            requirement = Requirement(text)
            if requirement.marker is None or requirement.marker.evaluate({"extra": ""}):
                todo.append(canonical(requirement.name))
    return found


def pack_wheel(dist: importlib.metadata.Distribution, folder: Path) -> Path:
    """Packs an installed distribution back into a wheel in `folder`: the files of its RECORD
    inside site-packages (its scripts, outside, pip makes again from its entry points), under
    the first tag of its WHEEL file that this interpreter supports."""
    tags = [line.split(":", 1)[1].strip() for line in (dist.read_text("WHEEL") or "").splitlines() if line.startswith("Tag:")]
    supported = {str(t) for t in sys_tags()}
    tag = next(t for t in tags if t in supported)
    name = re.sub(r"[-_.]+", "_", dist.metadata["Name"])
    path = folder / f"{name}-{dist.version}-{tag}.whl"
    folder.mkdir(exist_ok=True)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as wheel:
        for file in dist.files or []:
            if file.parts[0] != ".." and "__pycache__" not in file.parts:
                wheel.write(Path(dist.locate_file(file)), file.as_posix())
    return path


def test_a_plain_install_holds_the_runtime_dependencies_and_no_extra(fresh: Path):
    installed = {canonical(d["name"]) for d in json.loads(run([str(fresh / "python"), "-m", "pip", "list", "--format", "json"]).stdout)}
    runtime, extras = declared()
    assert runtime | {"hexadyn"} <= installed
    extra_only = set().union(*extras.values()) - closure(runtime) - {"hexadyn"}
    assert {"pytest", "viser", "ray", "mypy"} <= extra_only
    assert installed & extra_only == set()


def test_every_module_imports_without_the_extras(fresh: Path):
    """Every module of the package imports in the plain install, but those of an optional
    feature, which may only miss their extra's modules."""
    script = """
import importlib, json, pkgutil, hexadyn
failed = {}
for module in pkgutil.walk_packages(hexadyn.__path__, "hexadyn."):
    try:
        importlib.import_module(module.name)
    except ImportError as exc:
        failed[module.name] = [type(exc).__name__, exc.name]
print(json.dumps(failed))
"""
    failed = json.loads(run([str(fresh / "python"), "-c", script]).stdout)
    _, extras = declared()
    for module, (kind, missing) in failed.items():
        assert module.startswith(OPTIONAL_MODULES) and kind == "ModuleNotFoundError", (module, kind, missing)
        assert canonical(missing) in extras["view"], (module, missing)


def test_every_command_runs_its_documented_example(fresh: Path, tmp_path: Path):
    listed = json.loads(run([str(fresh / "python"), "-c", COMMANDS]).stdout)
    documented: set[str] = set()
    for block in blocks(EXAMPLES):
        if block.language != "sh":
            continue
        skipped = block.marker("no-run") is not None
        for name, source in block.givens():
            shutil.copyfile(ROOT / source, tmp_path / name)
        for args in hexadyn_commands(block):
            command = next((c for c in sorted(listed, key=len, reverse=True) if args[: len(c.split())] == c.split()), None)
            if command is None:
                assert args[0].startswith("-"), f"{block.where}: hexadyn {' '.join(args)}: not a command of hexadyn --help"
                run([str(fresh / "hexadyn"), *args], cwd=tmp_path)
                continue
            documented.add(command)
            if skipped:  # not run here: its help at least (the modules it imports load above)
                run([str(fresh / "hexadyn"), *command.split(), "--help"], cwd=tmp_path)
            elif command in NEEDS_EXTRA:
                done = run([str(fresh / "hexadyn"), *args], cwd=tmp_path, check=False)
                assert done.returncode == 1 and done.stderr.count("\n") == 1, (args, done.stdout, done.stderr)
                assert f"pip install 'hexadyn[{NEEDS_EXTRA[command]}]'" in done.stderr, done.stderr
            else:
                run([str(fresh / "hexadyn"), *args], cwd=tmp_path)
    assert sorted(set(listed) - documented) == [], f"commands of hexadyn --help without an example in {EXAMPLES}"


#: Prints the commands of `hexadyn --help` ("simulate", "robot run"...) as a JSON list.
COMMANDS = """
import json, click
from hexadyn.cli import cli
def names(group, prefix=()):
    for name, command in group.commands.items():
        if isinstance(command, click.Group):
            yield from names(command, (*prefix, name))
        else:
            yield " ".join((*prefix, name))
print(json.dumps(sorted(names(cli))))
"""
