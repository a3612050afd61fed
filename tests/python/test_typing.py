"""The public API is typed: the stub of the compiled module matches the module (mypy's
stubtest), the public modules pass mypy (pyproject's [tool.mypy]), and a user's script is
checked against the package as installed (its py.typed marker): right uses pass, wrong ones are
reported."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from docs_blocks import PAGES, blocks

import hexadyn

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = Path(hexadyn.__file__).resolve().parent


@pytest.fixture(scope="module")
def mypy(tmp_path_factory):
    """Runs ``python -m <module> args`` with one mypy cache for the module's tests; fails
    (never skips) without mypy, which the test extra installs."""
    if importlib.util.find_spec("mypy") is None:
        pytest.fail("mypy is not installed: it is in the test extra (make setup, or pip install -c requirements/lock.txt -e '.[test]')")
    cache = tmp_path_factory.mktemp("mypy_cache")

    def run(module: str, *args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
        env = {**os.environ, "MYPY_CACHE_DIR": str(cache)}
        return subprocess.run([sys.executable, "-m", module, *args], cwd=cwd, env=env, capture_output=True, text=True)

    return run


def test_the_package_ships_its_types():
    assert (PACKAGE / "py.typed").is_file()
    assert (PACKAGE / "_core.pyi").is_file()


def test_core_stub_matches_the_compiled_module(mypy):
    """Every class, function, parameter and default of hexadyn._core is in _core.pyi, and
    nothing else (a binding added or changed in Rust fails here until the stub follows)."""
    out = mypy("mypy.stubtest", "hexadyn._core", cwd=PACKAGE.parent)
    assert out.returncode == 0, out.stdout + out.stderr


def test_public_modules_type_check(mypy):
    out = mypy("mypy", cwd=ROOT)
    assert out.returncode == 0, out.stdout + out.stderr


USER_SCRIPT = """
    from pathlib import Path

    import hexadyn
    from hexadyn import Results, Scenario, report

    names: list[str] = hexadyn.list_scenarios()
    files: list[Path] = hexadyn.scenario_files()
    s: Scenario = Scenario.load(names[0]).set("gait.period_s", 1.2).rename("mine", "my walk")
    text: str = s.to_toml()
    results: Results = s.simulate(progress=False, save=True)
    folder: Path | None = results.path
    again: Results = hexadyn.simulate("stand_six_legs", overrides={"model.friction": "none"})
    saved: Path = report.save(again, "results/stand")
    info = hexadyn._core.load_scenario(str(files[0]))
"""

WRONG_USES = {
    "hexadyn.simulate(42)": 'Argument 1 to "simulate" has incompatible type "int"',
    'hexadyn.Scenario.load("walk").set(1, 2)': 'Argument 1 to "set" of "Scenario" has incompatible type "int"',
    "n: int = hexadyn.list_scenarios()": 'Incompatible types in assignment (expression has type "list[str]"',
    'hexadyn.Scenario.load("walk").rename("only a name")': 'Missing positional argument "description" in call to "rename"',
    'hexadyn._core.load_scenario("x.toml", overrides=[1])': 'Argument "overrides" to "load_scenario" has incompatible type',
}


def test_a_users_script_type_checks_against_the_package(mypy, tmp_path: Path):
    script = tmp_path / "user.py"
    script.write_text(textwrap.dedent(USER_SCRIPT))
    out = mypy("mypy", "--strict", str(script), cwd=tmp_path)
    assert out.returncode == 0, out.stdout + out.stderr


def test_the_documented_python_examples_use_the_real_api(mypy, tmp_path: Path):
    """The Python blocks of the README and of docs/*.md, one script per page in their order (a
    block may use an earlier one's names, as tests/python/test_docs.py runs them), against the
    package's types."""
    scripts = []
    for page in PAGES:
        code = [block.body for block in blocks(page) if block.language == "python" and block.marker("no-run") is None]
        if code:
            script = tmp_path / (page.replace("/", "_").replace("-", "_").removesuffix(".md") + ".py")
            script.write_text("\n".join(code))
            scripts.append(str(script))
    assert len(scripts) >= 4 and any("hexadyn.Scenario.load" in Path(s).read_text() for s in scripts)
    out = mypy("mypy", *scripts, cwd=tmp_path)
    assert out.returncode == 0, out.stdout + out.stderr


def test_wrong_uses_of_the_api_are_reported(mypy, tmp_path: Path):
    script = tmp_path / "wrong.py"
    script.write_text("import hexadyn\n" + "\n".join(WRONG_USES) + "\n")
    out = mypy("mypy", str(script), cwd=tmp_path)
    assert out.returncode == 1, out.stdout + out.stderr
    for line, (use, error) in enumerate(WRONG_USES.items(), start=2):
        assert f"wrong.py:{line}: error: {error}" in out.stdout, f"{use}:\n{out.stdout}"
