"""The engine's schema as the Python package sees it (``_core`` constants and functions,
hexadyn.vocabulary): the same names, codes and figures as the engine's own outputs."""

from __future__ import annotations

from pathlib import Path

import pytest

from hexadyn import Results, _core, vocabulary

ROOT = Path(__file__).resolve().parents[2]


def test_vocabulary_matches_the_recorded_columns(walk: Results):
    joints = walk.joints
    assert joints == vocabulary.Joints(("q_r", "q_v", "q_h"), ("revolute", "prismatic", "prismatic"))
    assert vocabulary.LEGS == (0, 1, 2, 3, 4, 5)
    assert len(joints.actuators) == 18 and joints.actuators[:4] == ("q_r[0]", "q_v[0]", "q_h[0]", "q_r[1]")
    columns = set(walk.timeseries.columns)
    for a in joints.actuators:
        assert {a, *(vocabulary.actuator_column(q, a) for q in ("u", "i", "E_el", "E_joule", "E_fric"))} <= columns, a
    # The phase codes are those the engine describes its phase columns with.
    description = walk.descriptions[vocabulary.leg_column("phase", 0)]
    assert vocabulary.PHASE_CODES == {"support": 0, "takeoff": 1, "swing": 2, "landing": 3, "failed": 4}
    for name, code in vocabulary.PHASE_CODES.items():
        assert f"{code} {name}" in description, (name, description)


def test_robot_properties(walk: Results):
    props = _core.robot_properties((ROOT / "robots" / "amru5.toml").read_text())
    assert props["mass_kg"] == pytest.approx(walk.summary["robot_mass_kg"], rel=1e-12), "m_0 + 6 m_leg, summed in another order"
    assert props["stated_mass_kg"] == 34.0
    assert props["inductance_h"] == pytest.approx((0.09e-3,) * 3, rel=1e-12)
    assert props["joints"] == (("q_r", "revolute"), ("q_v", "prismatic"), ("q_h", "prismatic"))
    assert _core.robot_properties(walk.metadata["robot"]) == props
    with pytest.raises(ValueError, match=r"^my robot:.*inertia\.leg_mass_kg"):
        _core.robot_properties("[inertia]\n", "my robot")


def test_specific_resistance_is_the_summarys(walk: Results):
    s = walk.summary
    assert _core.specific_resistance(s["energy_electrical_j"], s["robot_mass_kg"], s["distance_walked_m"]) == s["specific_resistance"]
    assert _core.specific_resistance(1.0, 1.0, 0.0) != _core.specific_resistance(1.0, 1.0, 0.0), "NaN without a distance"
