"""Property-based abuse of the input files (issue 17): the shipped scenarios and the robot
description mutated the ways files get broken (byte flips, deleted or duplicated lines, values
replaced by extremes or wrong types, a byte order mark, non-UTF-8 bytes, truncation). Every case
ends with either a clean one-line ValueError naming the file, or a valid scenario; a sample of
the valid ones is run for a few control periods and must end healthy or with its health
warnings (never a panic, a traceback, a hang or a silent NaN)."""

from __future__ import annotations

import math
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import hexadyn
from hexadyn import _core, health

from fuzz_edits import BYTE_EDITS, byte_edit

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = {p.name: p.read_bytes() for p in hexadyn.scenario_files()}
ROBOT = (ROOT / "robots" / "amru5.toml").read_bytes()
#: The scenario that names the mutated robot file.
ROBOT_USER = b'[scenario]\nname = "robot_fuzz"\nduration_s = 1.0\nrobot = "robot.toml"\n[control]\nmode = "pi"\n'
#: Cases per suite run (the issue asks for at least 1e4).
CASES = 10_000
#: Values written in place of a value: extremes, wrong types, paths.
EXTREMES = [
    b"0", b"-1", b"1e308", b"-1e308", b"1e-320", b"nan", b"inf", b"-inf", b"9223372036854775807", b"-9223372036854775808",
    b"99999999999999999999", b"1e9", b"-1e9", b'""', b'"x"', b"[]", b"[1e308]", b"{}", b"true", b"1979-05-27", b'"/dev/zero"', b'"../../x"', b'"/"',
]


def lines_of(text: bytes) -> list[bytes]:
    return text.split(b"\n")


@st.composite
def mutated(draw) -> tuple[str, bytes]:
    """(name, bytes) of a mutated file: a shipped scenario, or (one case in ten) the robot file."""
    if draw(st.integers(0, 9)) == 0:
        name, text = "robot.toml", ROBOT
    else:
        name = draw(st.sampled_from(sorted(SCENARIOS)))
        text = SCENARIOS[name]
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["flip", "delete_line", "duplicate_line", "replace_value", "extreme_number", "bom", "non_utf8", "truncate"]))
        lines = lines_of(text)
        if kind in BYTE_EDITS:
            text = byte_edit(draw, text, kind)
        elif kind in ("replace_value", "extreme_number"):
            assignments = [i for i, line in enumerate(lines) if b"=" in line and not line.lstrip().startswith(b"#")]
            if assignments:
                i = draw(st.sampled_from(assignments))
                key = lines[i].split(b"=", 1)[0]
                if kind == "replace_value":
                    value = draw(st.sampled_from(EXTREMES))
                else:
                    value = repr(draw(st.floats(allow_nan=True, allow_infinity=True))).encode()  # 'nan', 'inf', '1e+308': TOML floats
                lines[i] = key + b"= " + value
                text = b"\n".join(lines)
        elif kind == "non_utf8":
            i = draw(st.integers(0, len(text)))
            text = text[:i] + draw(st.sampled_from([b"\xff", b"\xc3", b"\xe9", b"\x80\x80", b"\x00"])) + text[i:]
    return name, text


def assert_clean_error(exc: BaseException, folder: Path) -> None:
    """A ValueError of one line naming the scenario or the robot file."""
    message = str(exc)
    assert type(exc) is ValueError, f"{type(exc).__name__}: {message}"
    assert message and "\n" not in message, repr(message)
    assert str(folder) in message, message


def test_mutated_inputs_give_one_line_errors_or_healthy_runs(tmp_path: Path):
    scenario = tmp_path / "scenario.toml"
    robot = tmp_path / "robot.toml"
    outcomes = {"error": 0, "valid": 0, "run": 0}

    @settings(max_examples=CASES, deadline=None, database=None, suppress_health_check=list(HealthCheck))
    @given(case=mutated(), run=st.integers(0, 249))
    def check(case: tuple[str, bytes], run: int) -> None:
        name, text = case
        if name == "robot.toml":
            robot.write_bytes(text)
            scenario.write_bytes(ROBOT_USER)
        else:
            scenario.write_bytes(text)
        try:
            info = _core.load_scenario(str(scenario))
        except BaseException as exc:  # noqa: BLE001 - the type is what is checked
            assert_clean_error(exc, tmp_path)
            outcomes["error"] += 1
            return
        outcomes["valid"] += 1
        assert info["duration_s"] > 0 and math.isfinite(info["duration_s"])
        if run:  # one valid case in 250 runs a few control periods (settling costs ~0.1 s)
            return
        try:
            short = min(info["duration_s"], 5 * info["period_s"])
            raw = _core.run_scenario(str(scenario), overrides={"scenario.duration_s": short}, timeseries=False)
        except BaseException as exc:  # noqa: BLE001
            assert_clean_error(exc, tmp_path)
            return
        outcomes["run"] += 1
        summary = raw["summary"]
        nonfinite = [k for k, v in summary.items() if isinstance(v, float) and not math.isfinite(v) and k not in health.RATIOS]
        assert not nonfinite or health.check(summary), f"silent non-finite figures {nonfinite}"

    check()
    assert sum(outcomes.values()) >= CASES and outcomes["error"] > CASES / 10 and outcomes["valid"] > CASES / 10 and outcomes["run"] > 0, outcomes
