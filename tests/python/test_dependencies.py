"""The package declares what it imports: every third-party module that python/hexadyn imports
comes from a runtime dependency of pyproject.toml, or, for an optional feature, from the extra
that installs that feature (`pip install .` then runs every command but `hexadyn view` and
`--ray`, which say which extra they need)."""

from __future__ import annotations

import ast
import importlib.metadata
import re
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "python" / "hexadyn"

#: The optional features: the modules (paths under python/hexadyn, a folder ending in /) whose
#: imports may come from the extra instead of the runtime dependencies.
OPTIONAL = {"view/": "view", "montecarlo/execution.py": "ray"}


def canonical(name: str) -> str:
    """A distribution name as PEP 503 compares them."""
    return re.sub(r"[-_.]+", "-", name).lower()


def requirement_name(requirement: str) -> str:
    """The distribution a requirement string names (``ray[client]; python_version < "4"`` -> ray)."""
    match = re.match(r"\s*([A-Za-z0-9][A-Za-z0-9._-]*)", requirement)
    assert match, f"not a requirement: {requirement!r}"
    return canonical(match.group(1))


def declared() -> tuple[set[str], dict[str, set[str]]]:
    """The runtime dependencies and the distributions of each extra, from pyproject.toml."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    runtime = {requirement_name(r) for r in project["dependencies"]}
    extras = {extra: {requirement_name(r) for r in requirements} for extra, requirements in project["optional-dependencies"].items()}
    return runtime, extras


def top_level_imports(path: Path) -> list[tuple[int, str]]:
    """(line, top-level module) of every absolute import of a source file, at any depth (an
    import inside a function is still needed when the function runs)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name.split(".")[0]) for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.append((node.lineno, node.module.split(".")[0]))
    return found


def third_party_imports() -> list[tuple[str, int, str]]:
    """(file relative to python/hexadyn, line, module) of the imports of neither the standard
    library nor hexadyn."""
    return [
        (path.relative_to(PACKAGE).as_posix(), line, module)
        for path in sorted(PACKAGE.rglob("*.py"))
        for line, module in top_level_imports(path)
        if module not in sys.stdlib_module_names and module != "hexadyn"
    ]


def test_every_third_party_import_is_declared():
    runtime, extras = declared()
    distributions = importlib.metadata.packages_distributions()
    imports = third_party_imports()
    # The scan sees the imports this test is about (scipy: hexadyn identify).
    assert {"numpy", "scipy", "viser", "ray"} <= {module for _, _, module in imports}
    undeclared = []
    for file, line, module in imports:
        extra = next((e for prefix, e in OPTIONAL.items() if file == prefix or (prefix.endswith("/") and file.startswith(prefix))), None)
        allowed = runtime | (extras[extra] if extra else set())
        names = {canonical(d) for d in distributions.get(module, [])}
        if not names & allowed:
            where = f"the dependencies or the {extra} extra" if extra else "the dependencies"
            undeclared.append(f"python/hexadyn/{file}:{line}: import {module} (distribution {', '.join(sorted(names)) or 'not installed'}) is not in {where}")
    assert not undeclared, "\n".join(undeclared)


def test_extras_exist_and_the_test_extra_installs_the_optional_features():
    runtime, extras = declared()
    assert set(OPTIONAL.values()) <= set(extras)
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    # The tests exercise the view, Ray and the docs site: the test extra pulls in those extras.
    assert "hexadyn[ray,view,docs]" in project["optional-dependencies"]["test"]
    # `--ray ray://head:10001` (README) connects through Ray's client.
    assert "ray[client]" in project["optional-dependencies"]["ray"]


def test_lock_pins_every_declared_distribution():
    runtime, extras = declared()
    pinned = {canonical(line.split("==")[0]) for line in (ROOT / "requirements" / "lock.txt").read_text().splitlines() if line and not line.startswith("#")}
    wanted = (runtime | set().union(*extras.values())) - {"hexadyn"}
    assert wanted - pinned == set()
