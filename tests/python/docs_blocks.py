"""The code blocks of the README and of the documentation pages (docs/*.md), read the way
tests/python/test_docs.py runs them and tests/python/test_typing.py type-checks them.

A block is a fenced block (```` ```LANGUAGE ````, at any indentation, closed by a fence at the
same indentation). The HTML comments on the lines right before its opening fence are its
markers, invisible on GitHub and on the site:

- ``<!-- no-run: REASON -->``: the block is not run (a command that rebuilds everything, one
  for the real robot or that waits for it, a long benchmark); REASON says why.
- ``<!-- file: NAME -->``: the block (TOML) is saved as NAME in the page's folder before the
  blocks after it run.
- ``<!-- given: NAME from PATH -->``: a file the reader brings (their URDF, their scenario) is
  NAME in the page's folder; the test brings PATH of the repository in its place.
"""

from __future__ import annotations

import re
import shlex
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: The README and every page of the site, in the order the test runs them.
PAGES: tuple[str, ...] = ("README.md", *sorted(f"docs/{p.name}" for p in (ROOT / "docs").glob("*.md")))

#: The languages a block may have: run (sh, python), parsed (toml), compiled (c), or shown
#: output, layouts and byte dumps (text, never run). A rust block shows a fragment of a
#: controller and must be marked no-run.
LANGUAGES = ("sh", "python", "toml", "c", "rust", "text")

MARKER_KINDS = ("no-run", "file", "given")

_FENCE = re.compile(r"^(?P<indent>[ \t]*)```(?P<language>[^`\s]*)\s*$")
_COMMENT = re.compile(r"^\s*<!--\s*(?P<kind>[\w-]+):\s*(?P<value>.*?)\s*-->\s*$")


@dataclass(frozen=True)
class Block:
    """One fenced block: where it is, its language, its text (unindented) and its markers."""

    page: str
    line: int
    language: str
    body: str
    markers: tuple[tuple[str, str], ...]

    @property
    def where(self) -> str:
        return f"{self.page}:{self.line}"

    def marker(self, kind: str) -> str | None:
        """The value of the block's marker `kind`, or None."""
        return next((value for k, value in self.markers if k == kind), None)

    def givens(self) -> list[tuple[str, str]]:
        """The ``given: NAME from PATH`` markers as (NAME, PATH)."""
        out = []
        for kind, value in self.markers:
            if kind == "given":
                name, sep, path = value.partition(" from ")
                if not sep or not name.strip() or not path.strip():
                    raise ValueError(f"{self.where}: given marker {value!r}: allowed: NAME from PATH")
                out.append((name.strip(), path.strip()))
        return out


def hexadyn_commands(block: Block) -> list[list[str]]:
    """The arguments of the ``hexadyn`` command lines of an ``sh`` block (comments dropped,
    ``\\`` continuations joined); ValueError for a line of another command (a block that runs
    holds hexadyn commands only)."""
    out = []
    for line in block.body.replace("\\\n", " ").splitlines():
        args = shlex.split(line, comments=True)
        if args:
            if args[0] != "hexadyn":
                raise ValueError(f"{block.where}: {line!r}: a runnable sh block holds hexadyn commands only (mark the block no-run, with the reason)")
            out.append(args[1:])
    return out


def blocks(page: str) -> list[Block]:
    """The fenced blocks of `page` (a path relative to the repository), in order; ValueError
    for a block left open or a comment before a fence that is not a marker."""
    lines = (ROOT / page).read_text().splitlines()
    found: list[Block] = []
    i = 0
    while i < len(lines):
        opening = _FENCE.match(lines[i])
        if not opening:
            i += 1
            continue
        indent, language = opening["indent"], opening["language"]
        start = i
        markers: list[tuple[str, str]] = []
        j = i - 1
        while j >= 0 and lines[j].lstrip().startswith("<!--"):
            comment = _COMMENT.match(lines[j])
            if not comment or comment["kind"] not in MARKER_KINDS:
                raise ValueError(f"{page}:{j + 1}: {lines[j].strip()!r} before a block: allowed markers: {', '.join(MARKER_KINDS)}")
            markers.insert(0, (comment["kind"], comment["value"]))
            j -= 1
        body: list[str] = []
        i += 1
        while i < len(lines) and lines[i].rstrip() != f"{indent}```":
            body.append(lines[i][len(indent):] if lines[i].startswith(indent) else lines[i].lstrip())
            i += 1
        if i == len(lines):
            raise ValueError(f"{page}:{start + 1}: block never closed")
        found.append(Block(page, start + 1, language, "\n".join(body) + "\n", tuple(markers)))
        i += 1
    return found


def prose(page: str) -> str:
    """The text of `page` without its fenced blocks (each replaced by an empty line, so that
    paragraphs keep their bounds)."""
    out: list[str] = []
    inside: str | None = None
    for line in (ROOT / page).read_text().splitlines():
        fence = _FENCE.match(line)
        if inside is None and fence:
            inside = fence["indent"]
            out.append("")
        elif inside is not None:
            if line.rstrip() == f"{inside}```":
                inside = None
        else:
            out.append(line)
    return "\n".join(out)
