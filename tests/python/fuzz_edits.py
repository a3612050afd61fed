"""Damage to a file's bytes, shared by the fuzz suites (``test_fuzz``, ``test_fuzz_cli``): one
edit drawn with hypothesis's ``draw``."""

from __future__ import annotations

from typing import Any, Callable

#: The edits of :func:`byte_edit`: a byte replaced, a line deleted or doubled, the file cut, a
#: UTF-8 byte order mark put in front.
BYTE_EDITS = ("flip", "delete_line", "duplicate_line", "truncate", "bom")


def byte_edit(draw: Callable[[Any], Any], text: bytes, edit: str) -> bytes:
    """`text` with one edit of :data:`BYTE_EDITS` (a flip of an empty text leaves it)."""
    from hypothesis import strategies as st

    lines = text.split(b"\n")
    if edit == "flip" and text:
        i = draw(st.integers(0, len(text) - 1))
        return text[:i] + bytes([draw(st.integers(0, 255))]) + text[i + 1 :]
    if edit == "delete_line":
        del lines[draw(st.integers(0, len(lines) - 1))]
        return b"\n".join(lines)
    if edit == "duplicate_line":
        i = draw(st.integers(0, len(lines) - 1))
        lines.insert(i, lines[i])
        return b"\n".join(lines)
    if edit == "truncate":
        return text[: draw(st.integers(0, len(text)))]
    if edit == "bom":
        return b"\xef\xbb\xbf" + text
    return text
