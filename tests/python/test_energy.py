"""Power and energy per actuator, phase split, specific resistance and the P = α + β V fit
(hexadyn.energy, thesis Section 6.4, Eq. 6.6-6.11)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import hexadyn
from hexadyn import Results, energy, report

from conftest import shortened

ACTUATORS = [f"{j}[{leg}]" for leg in range(6) for j in ("q_r", "q_v", "q_h")]  # AMRU5's joints


def test_power_integrates_to_the_electrical_energy(walk: Results):
    p = energy.power(walk)
    ts = walk.timeseries
    assert list(p.columns) == ACTUATORS
    assert len(p) == len(ts) - 1 and p.index[0] == ts.index[1], "one row per control period, indexed by its end"
    dt = 0.01
    for a in ACTUATORS:
        e_el = ts[f"E_el_{a}"].iloc[-1] - ts[f"E_el_{a}"].iloc[0]
        assert (p[a] * dt).sum() == pytest.approx(e_el, rel=1e-9), a
    assert (p.to_numpy() * dt).sum() == pytest.approx(walk.summary["energy_electrical_j"], rel=1e-9)
    # The sampled u_k i_k (one current sample per period, Eq. 6.7 as the robot measures it)
    # agrees with the integral up to the variation of the current within a period.
    sampled = energy.sampled_power(walk)
    assert sampled.index.equals(p.index)
    assert (sampled.to_numpy() * dt).sum() == pytest.approx(walk.summary["energy_electrical_j"], rel=0.02)
    # u and i of row k belong to the same period as P_k: pairing u_k with i_{k-1} is worse.
    u = ts[[f"u_{a}" for a in ACTUATORS]].to_numpy()
    i = ts[[f"i_{a}" for a in ACTUATORS]].to_numpy()
    aligned = np.abs(u[1:] * i[1:] - p.to_numpy()).mean()
    shifted = np.abs(u[1:] * i[:-1] - p.to_numpy()).mean()
    assert aligned < shifted


def test_phases_are_those_the_period_was_commanded_in(walk: Results):
    phases = energy.foot_phases(walk)
    ts = walk.timeseries
    assert phases.index.equals(energy.power(walk).index)
    for leg in range(6):
        np.testing.assert_array_equal(phases[leg].to_numpy(), ts[f"phase[{leg}]"].to_numpy()[:-1])
    # 24 s of tripod walking: every phase occurs on every leg.
    for leg in range(6):
        assert set(phases[leg].unique()) == {0, 1, 2, 3}, leg
    assert energy.foot_phases(hexadyn.Results(ts.drop(columns=[f"phase[{leg}]" for leg in range(6)]), walk.units, walk.summary, walk.metadata)) is None


def test_averaged_power_split_by_phase_adds_up(walk: Results):
    table = energy.averaged_power(walk)
    assert list(table.index.unique("phase")) == ["all", "support", "swing", "transitions"]
    assert list(table.columns) == ["q_r", "q_v", "q_h", "total"]
    assert list(table.loc["all"].index) == [0, 1, 2, 3, 4, 5, "total"]
    parts = table.loc["support"] + table.loc["swing"] + table.loc["transitions"]
    pd.testing.assert_frame_equal(parts, table.loc["all"], rtol=1e-12, atol=1e-12)
    all_ = table.loc["all"]
    np.testing.assert_allclose(all_.loc["total"].to_numpy(), all_.loc[list(range(6))].sum().to_numpy(), rtol=1e-12)
    np.testing.assert_allclose(all_["total"].to_numpy(), all_[["q_r", "q_v", "q_h"]].sum(axis=1).to_numpy(), rtol=1e-12)
    duration = walk.summary["duration_s"]
    assert all_.loc["total", "total"] * duration == pytest.approx(walk.summary["energy_electrical_j"], rel=1e-9)
    assert walk.summary["average_power_w"] == pytest.approx(all_.loc["total", "total"], rel=1e-9)
    b = energy.energy_breakdown(walk)
    assert all_.loc[2, "q_v"] * duration == pytest.approx(b.loc["q_v[2]", "electrical_j"], rel=1e-9)
    # Section 6.4.2: the vertical actuators draw almost nothing while their foot supports the
    # body (high gearing), most of their energy goes into swing and transitions.
    assert table.loc[("support", "total"), "q_v"] < 0.1 * table.loc[("all", "total"), "q_v"]


def test_energy_breakdown_closes(walk: Results):
    b = energy.energy_breakdown(walk)
    assert list(b.index) == ACTUATORS
    assert list(b.columns) == ["leg", "joint", "electrical_j", "joule_j", "friction_j", "magnetic_j", "mechanical_j"]
    assert b.loc["q_h[3]", "leg"] == 3 and b.loc["q_h[3]", "joint"] == "q_h"
    s = walk.summary
    assert b["electrical_j"].sum() == pytest.approx(s["energy_electrical_j"], rel=1e-12)
    assert b["joule_j"].sum() == pytest.approx(s["energy_joule_j"], rel=1e-12)
    assert b["friction_j"].sum() == pytest.approx(s["energy_friction_j"], rel=1e-12)
    assert (b["magnetic_j"] == 0).all(), "no inductance in the validation case"
    np.testing.assert_allclose(b["electrical_j"], b["joule_j"] + b["friction_j"] + b["mechanical_j"] + b["magnetic_j"], rtol=1e-12, atol=1e-15)
    # The mechanical work and the friction work make up the motor work ∫ τ_m q' dt, which the
    # engine integrates on its own.
    assert (b["mechanical_j"] + b["friction_j"]).sum() == pytest.approx(s["energy_motor_work_j"], rel=1e-6)
    assert b["joule_j"].min() > 0 and b["friction_j"].min() > 0
    assert s["friction_share"] == pytest.approx(s["energy_friction_j"] / s["energy_electrical_j"], rel=1e-12)
    assert s["energy_mechanical_j"] == pytest.approx(b["mechanical_j"].sum(), rel=1e-12)


def test_magnetic_energy_with_inductance(tmp_path: Path):
    path = shortened("leg_sine", tmp_path, 0.1)
    path.write_text(path.read_text().replace('friction = "lugre"', 'friction = "lugre"\ninductance = true'))
    r = hexadyn.simulate(path, progress=False)
    b = energy.energy_breakdown(r)
    i = r.timeseries["i_q_v[1]"]
    assert b.loc["q_v[1]", "magnetic_j"] == pytest.approx(0.5 * 0.09e-3 * (i.iloc[-1] ** 2 - i.iloc[0] ** 2), rel=1e-12)
    assert b.loc["q_v[1]", "magnetic_j"] != 0
    np.testing.assert_allclose(b["electrical_j"], b["joule_j"] + b["friction_j"] + b["mechanical_j"] + b["magnetic_j"], rtol=1e-12, atol=1e-15)
    assert "specific_resistance" not in r.summary, "the robot does not walk"
    assert "phase[0]" not in r.timeseries.columns
    assert list(energy.averaged_power(r).index.unique("phase")) == ["all"]


def test_specific_resistance_by_hand(walk: Results):
    assert energy.specific_resistance(100.0, 10.0, 2.0) == pytest.approx(100.0 / (10.0 * 9.81 * 2.0), rel=1e-15)
    with pytest.raises(ValueError, match="distance = 0"):
        energy.specific_resistance(1.0, 10.0, 0.0)
    with pytest.raises(ValueError, match="mass = -1"):
        energy.specific_resistance(1.0, -1.0, 1.0)
    # The run's ξ: E = total electrical energy, m = the robot mass the engine reports (or
    # inertia.total_mass_kg of the robot description, 34 kg, for results without it), l = the
    # distance walked.
    s = walk.summary
    mass = s["robot_mass_kg"]
    assert mass == pytest.approx(34.447, rel=1e-3), "m_0 + 6 m_leg (robots/amru5.toml)"
    assert energy.robot_mass(walk) == mass
    assert s["distance_walked_m"] == pytest.approx(0.015 * 24, rel=0.01)
    assert s["specific_resistance"] == pytest.approx(s["energy_electrical_j"] / (mass * 9.81 * s["distance_walked_m"]), rel=1e-12)
    assert energy.energy_figures(walk)["specific_resistance"] == pytest.approx(s["specific_resistance"], rel=1e-12)
    older = Results(walk.timeseries, walk.units, {k: v for k, v in s.items() if k != "robot_mass_kg"}, walk.metadata)
    assert energy.robot_mass(older) == 34.0
    assert energy.energy_figures(older)["specific_resistance"] == pytest.approx(s["specific_resistance"] * mass / 34.0, rel=1e-12)
    broken = Results(walk.timeseries, walk.units, older.summary, {**walk.metadata, "robot": "[inertia]\n"})
    with pytest.raises(ValueError, match="total_mass_kg"):
        energy.robot_mass(broken)


def test_power_velocity_fit_recovers_alpha_beta():
    alpha, beta, m = 4.5, 300.0, 34.0
    v = np.array([0.01, 0.015, 0.02, 0.025])
    a, b = energy.fit_power_velocity(v, alpha + beta * v)
    assert a == pytest.approx(alpha, rel=1e-9) and b == pytest.approx(beta, rel=1e-9)
    # Least squares: zero-mean residuals orthogonal to V leave the fit unchanged.
    noise = np.array([0.1, -0.3, 0.3, -0.1])
    assert noise.sum() == 0 and noise @ v == pytest.approx(0, abs=1e-15)
    a, b = energy.fit_power_velocity(v, alpha + beta * v + noise)
    assert a == pytest.approx(alpha, rel=1e-9) and b == pytest.approx(beta, rel=1e-9)
    # Eq. 6.11 is Eq. 6.6 for a run of duration T at velocity V with power P = α + β V.
    xi = energy.specific_resistance_fit(alpha, beta, m, v)
    T = 60.0
    expected = [energy.specific_resistance((alpha + beta * vi) * T, m, vi * T) for vi in v]
    np.testing.assert_allclose(xi, expected, rtol=1e-12)
    assert energy.specific_resistance_fit(alpha, beta, m, 0.015) == pytest.approx(expected[1], rel=1e-12)
    assert xi[-1] < xi[0], "ξ decreases with the velocity (α > 0)"
    with pytest.raises(ValueError, match="two distinct velocities"):
        energy.fit_power_velocity([0.01, 0.01], [1.0, 2.0])
    with pytest.raises(ValueError, match="same length"):
        energy.fit_power_velocity([0.01, 0.02], [1.0])


def test_saved_tables_and_summary(walk: Results, tmp_path: Path):
    folder = report.save(walk, tmp_path / "run")
    power = pd.read_csv(folder / "power.csv", index_col=["phase", "leg"])
    expected = energy.averaged_power(walk)
    np.testing.assert_allclose(power.to_numpy(), expected.to_numpy(), rtol=1e-8)
    assert list(power.columns) == ["q_r", "q_v", "q_h", "total"]
    breakdown = pd.read_csv(folder / "energy.csv", index_col="actuator")
    assert list(breakdown.index) == ACTUATORS
    np.testing.assert_allclose(breakdown["mechanical_j"], energy.energy_breakdown(walk)["mechanical_j"], rtol=1e-8, atol=1e-9)
    summary = json.loads((folder / "summary.json").read_text())
    for key in ["specific_resistance", "average_power_w", "friction_share", "joule_share", "energy_mechanical_j", "robot_mass_kg"]:
        assert summary[key] == walk.summary[key], key
    assert not (folder / "plots").exists(), "plots only on request"
