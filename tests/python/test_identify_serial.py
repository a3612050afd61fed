"""Friction identification on serial legs (thesis Section 5.2 on the PhantomX, `hexadyn
identify`): the shipped campaigns `phantomx_identification_<joint>` simulated with known
friction and identified back.

Each campaign runs six joints of one kind on the stand, cut to four velocities (0.1 to 0.4
rad/s) to stay fast. The truth is the friction the simulation used: the robot's AX-12A gear
friction (tau_f_d = 0.59 Nm, f_v = 0, read back through `_core.LegModel.joint`) or
`[model.joint_friction.<joint>]` values.

Tolerances (docs/identification.md, "Measured accuracy"): tau_f_d within 1.5 % and f_v within
0.02 Nm s/rad. The servos take a new goal every control period, a step of v dt; the motor
current jumps with it and relaxes within the period, and the current sensor's 30 Hz filter
sampled at the control instants reads below the period's mean by an amount that grows with the
velocity: -0.01 to -0.015 Nm s/rad on the viscous slope, up to 0.5 % on the dry friction.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import hexadyn
from hexadyn import _core
from hexadyn.cli import cli
from hexadyn.identify import identify, load_log
from hexadyn.identify import torques

#: The campaigns' sweeps (rad) and the standing posture each starts from (the shipped files).
SWEEPS = {"coxa": (-0.7, 0.7), "femur": (-0.5, 0.9), "tibia": (-2.4, -1.0)}
#: Four velocities: start, step, end (rad/s).
SPEEDS = (0.1, 0.1, 0.4)
#: Changed friction, the same in both senses (a serial drive's keys).
CHANGED = {"tau_f_d": 0.4, "f_v": 0.1}
TAU_RELATIVE = 0.015
F_V_ABSOLUTE = 0.02
PHANTOMX = Path(__file__).resolve().parents[2] / "robots" / "phantomx" / "phantomx.toml"


def campaign(joint: str, out: Path, friction: dict | None = None) -> Path:
    """The shipped campaign of `joint` at four velocities; returns the results folder."""
    start, step, end = SPEEDS
    lo, hi = SWEEPS[joint]
    count = int(round((end - start) / step)) + 1
    duration = sum(2 * (hi - lo) / (start + k * step) for k in range(count)) + 1.0
    motion = [{"leg": leg, "joint": joint, "kind": "sawtooth", "min": lo, "max": hi, "speed": start, "speed_step": step, "speed_max": end} for leg in range(6)]
    overrides = {"scenario.duration_s": round(duration, 2), "control.motion": motion}
    overrides.update({f"model.joint_friction.{joint}.{k}": v for k, v in (friction or {}).items()})
    hexadyn.simulate(f"phantomx_identification_{joint}", out=out, progress=False, overrides=overrides)
    return out


def truth(joint: str, leg: int, friction: dict | None) -> dict[str, float]:
    values = dict(torques.leg_model(_core.shipped_robot_text("phantomx")).joint(leg, joint))
    if friction:
        values.update(tau_f_d_plus=friction["tau_f_d"], tau_f_d_minus=-friction["tau_f_d"], f_v_plus=friction["f_v"], f_v_minus=friction["f_v"])
    return values


def assert_recovered(ident, joint: str, friction: dict | None) -> None:
    assert len(ident.fits) == 12
    for _, f in ident.fits:
        sense = "plus" if f.direction > 0 else "minus"
        t = truth(joint, f.leg, friction)
        tau, f_v = t[f"tau_f_d_{sense}"], t[f"f_v_{sense}"]
        assert abs(f.tau_f_d.value - tau) < TAU_RELATIVE * abs(tau), f"{joint}[{f.leg}] tau_f_d_{sense} = {f.tau_f_d.value} vs {tau}"
        assert abs(f.f_v.value - f_v) < F_V_ABSOLUTE, f"{joint}[{f.leg}] f_v_{sense} = {f.f_v.value} vs {f_v}"


@pytest.fixture(scope="module")
def logs(tmp_path_factory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("phantomx_identification")
    runs = {f"{joint} robot": campaign(joint, root / joint) for joint in SWEEPS}
    runs["femur changed"] = campaign("femur", root / "femur_changed", CHANGED)
    return runs


def test_leg_model_gives_the_servos_constants():
    """n k_t, the servo's position sensor (1024 counts over 300 deg), the winding resistance,
    the range and the drive's friction, the same in both senses, as the simulation uses them."""
    model = torques.leg_model(_core.shipped_robot_text("phantomx"))
    c = dict(model.joint(3, "femur"))
    assert c["torque_per_ampere"] == pytest.approx(254.0 * 5.48677e-3, rel=1e-12)
    assert c["encoder_resolution"] == pytest.approx(np.radians(300.0) / 1024, rel=1e-12)
    assert c["resistance"] == 8.0
    assert (c["lower"], c["upper"]) == (-1.832596, 1.727876)
    assert (c["tau_f_d_plus"], c["tau_f_d_minus"], c["f_v_plus"], c["f_v_minus"]) == (0.59, -0.59, 0.0, 0.0)
    assert not any(k.startswith(("tau_f_s", "a_")) for k in c)
    with pytest.raises(ValueError, match=r'^joint = "q_v": allowed "coxa", "femur", "tibia"$'):
        model.joint(0, "q_v")


@pytest.mark.parametrize("name", ["coxa robot", "femur robot", "tibia robot", "femur changed"])
def test_friction_recovered(logs, name):
    joint = name.split()[0]
    assert_recovered(identify([load_log(logs[name])]), joint, CHANGED if name.endswith("changed") else None)


def test_gravity_is_removed(logs, monkeypatch):
    """The femur lifts the femur and tibia links: gravity adds the same torque to both senses,
    about 0.05 Nm along the sweep. Removed by the leg model, the two dry frictions are opposite
    within 0.003 Nm; with a leg model that leaves gravity in (zero torques), the friction is
    off by more than 5 % and the test of the identified values fails."""
    log = load_log(logs["femur robot"])
    ident = identify([log])
    for leg in range(6):
        plus, minus = (ident.unloaded("femur", leg, d)[0].tau_f_d.value for d in (1, -1))
        assert abs(plus + minus) / 2 < 0.003, (leg, plus, minus)

    real = torques.leg_model(log.robot_text)

    class WithoutGravity:
        def joint(self, leg, joint):
            return real.joint(leg, joint)

        def joint_torques(self, leg, q, qd, qdd, foot_force=(0.0, 0.0, 0.0)):
            return np.zeros_like(q)

    monkeypatch.setattr(torques, "leg_model", lambda _text: WithoutGravity())
    wrong = identify([log])
    worst = max(abs(f.tau_f_d.value - truth("femur", f.leg, None)[f"tau_f_d_{'plus' if f.direction > 0 else 'minus'}"]) for _, f in wrong.fits)
    assert worst > 0.05 * 0.59, worst
    with pytest.raises(AssertionError):
        assert_recovered(wrong, "femur", None)


def test_command_on_results_and_csv_logs(logs, tmp_path):
    """`hexadyn identify` on a results folder writes the PhantomX's table, figure and a
    fragment with the serial drive's keys that a PhantomX scenario accepts; on a CSV log of one
    leg with `--robot robots/phantomx/phantomx.toml` it gives the same friction."""
    out = tmp_path / "ident"
    result = CliRunner().invoke(cli, ["identify", str(logs["femur changed"]), "--out", str(out)])
    assert result.exit_code == 0, result.output
    for name in ("table_5_3_femur.csv", "table_5_3_femur.md", "estimates.csv", "sections.csv", "figure_friction_femur.png", "joint_friction.toml", "friction_stats.toml"):
        assert (out / name).is_file(), name
    fragment = tomllib.loads((out / "joint_friction.toml").read_text())["model"]["joint_friction"]
    assert set(fragment) == {"femur"} and set(fragment["femur"]) == {"tau_f_d", "f_v"}
    assert fragment["femur"]["tau_f_d"] == pytest.approx(CHANGED["tau_f_d"], rel=TAU_RELATIVE)
    assert fragment["femur"]["f_v"] == pytest.approx(CHANGED["f_v"], abs=F_V_ABSOLUTE)
    overrides = {f"model.joint_friction.femur.{k}": v for k, v in fragment["femur"].items()}
    _core.load_scenario(str(hexadyn.SCENARIOS_DIR / "phantomx_tripod.toml"), overrides)

    ts = load_log(logs["femur changed"]).frame
    columns = ["femur[2]", "i_meas_femur[2]", "coxa[2]", "tibia[2]"]
    csv = tmp_path / "phantomx.csv"
    pd.DataFrame({"t": ts.index, **{c: ts[c].to_numpy() for c in columns}}).to_csv(csv, index=False)
    result = CliRunner().invoke(cli, ["identify", str(csv), "--robot", str(PHANTOMX), "--joint", "femur", "--out", str(tmp_path / "csv")])
    assert result.exit_code == 0, result.output
    estimates = pd.read_csv(tmp_path / "csv" / "estimates.csv")
    assert set(estimates["leg"]) == {2}
    for _, row in estimates.iterrows():
        true = CHANGED[row["parameter"]] * (-1 if row["parameter"] == "tau_f_d" and row["direction"] == "minus" else 1)
        tolerance = TAU_RELATIVE * CHANGED["tau_f_d"] if row["parameter"] == "tau_f_d" else F_V_ABSOLUTE
        assert abs(row["value"] - true) < tolerance, row.to_dict()
    # A joint the robot does not have: one line naming the file and the robot's joints.
    result = CliRunner().invoke(cli, ["identify", str(csv), "--robot", str(PHANTOMX), "--joint", "q_v", "--out", str(tmp_path / "bad")])
    errors = [line for line in result.output.splitlines() if line.startswith("Error:")]
    assert result.exit_code == 1 and len(errors) == 1, result.output
    assert str(csv) in errors[0] and "joint = 'q_v': allowed the robot's joints coxa, femur, tibia" in errors[0]
