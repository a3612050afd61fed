"""Side-by-side benchmark against MuJoCo: the 75 s tripod walk of thesis Section 3.4.1.

hexadyn runs its full model (the shipped scenario ``simulation_time``: 42-DOF multibody model
with the closed pantograph chains, Hertz-Hunt-Crossley ground contact with regularised
Coulomb friction, LuGre joint friction, 18 DC motors with their H-bridges and the digital PI
controllers at 100 Hz, gait controller in the loop). MuJoCo walks an AMRU5 built here from
``robots/amru5.toml`` and replays the joint references of that hexadyn run as position
targets, held over each 10 ms control period, at dt = 1 ms. Both are timed in the same run;
the output gives wall and CPU times (CPU time is what to compare on a loaded machine), the
real-time factors, the ratio, and each one's distance walked and body height, so that a reader
sees they did the same walk. The walks are timed in `--repeats` interleaved pairs (5 by default)
and the medians printed, with the range of the pairs' ratios: on a shared 2-core machine a
single pair's ratio ranged from 2.2 to 3.7.

The MuJoCo model (what it includes is printed with the results):
- bodies and masses of Table B.2: main body, per leg the chassis (hinge q_r about -z, as in
  Eq. 3.64), the three rotors as welded point masses (q_r's on the main body, q_v's and q_h's on
  the chassis, Table B.1), and the four pantograph links lumped into one body;
- the pantograph as its equivalent serial joints: two slides of the foot in the leg plane,
  radial rho and vertical z. The actuator mapping (nut travel -> foot travel) is the affine
  map fitted to the hexadyn run's own references (rho = a + 7.03 q_h, z = c - 6.00 q_v,
  Eq. B.1-B.2), so joint ranges, gains, armature and friction are carried to the slides with
  the same factors;
- position actuators with the stiffness and damping the PI loop and the motor give the joint,
  kp = n k_t K / R, kv = n^2 k_t^2 / R (the PI's proportional part and the back-EMF; the
  integral part is left out), force-limited to the supply voltage n k_t u_supply / R;
- rotor inertia as armature J_r n^2; dry joint friction (Table 5.3, mean of both senses and
  of the six legs) as frictionloss; soft contact with Coulomb friction mu of Table 3.3.

    .venv/bin/python benches/peer_mujoco.py          # or: make bench-peer
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

try:
    import mujoco
except ImportError:  # a benchmark-only dependency
    sys.exit("benches/peer_mujoco.py needs MuJoCo: pip install -c requirements/lock.txt -e '.[bench]'")

from hexadyn import _core

ROOT = Path(__file__).resolve().parent.parent
SCENARIO = ROOT / "python/hexadyn/scenarios/simulation_time.toml"
ROBOT = ROOT / "robots/amru5.toml"
DT = 1e-3
#: Foot sphere radius: half the joint-to-extremity distance h of Table 2.1 (B.1: "foot + h/2").
FOOT_RADIUS = 0.0125

HEXADYN_PHYSICS = (
    "hexadyn: 42-DOF model, closed pantograph chains (dependent parameters), Hertz-Hunt-Crossley "
    "ground contact with regularised Coulomb friction, LuGre joint friction (18 bristle states), "
    "18 DC motors and H-bridges driven by the digital PI controllers at 100 Hz, gait controller "
    "in the loop, adaptive implicit Newmark"
)
MUJOCO_PHYSICS = (
    "MuJoCo: 24-DOF serial equivalent (free body + 6 x hinge q_r + 2 foot slides), lumped "
    "pantograph links, PD position actuators from the PI gain and back-EMF (no integral part), "
    "rotor inertia as armature, dry joint friction as frictionloss, soft contact with Coulomb "
    "friction, replaying hexadyn's joint references; dt = 1 ms, implicitfast"
)


def hexadyn_walk(scenario: Path = SCENARIO) -> tuple[dict, float, float]:
    """Runs a shipped scenario with its time series; returns (columns, wall s, CPU s)."""
    wall, cpu = time.perf_counter(), time.process_time()
    r = _core.run_scenario(scenario, None, None, True)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    return {k: np.asarray(v) for k, v in r["columns"].items()}, wall, cpu


def pantograph_map(c: dict) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per leg, the affine maps (rho, z) of the foot in the leg plane from (q_h, q_v, 1),
    least-squares fitted to the references of the hexadyn run (the gait's foot references and
    the joint references computed from them by hexadyn's inverse kinematics)."""
    maps = []
    for leg in range(6):
        x, y, z = (c[f"foot_ref_{a}[{leg}]"] for a in "xyz")
        a = np.c_[c[f"q_h_ref[{leg}]"], c[f"q_v_ref[{leg}]"], np.ones(len(x))]
        maps.append((np.linalg.lstsq(a, np.hypot(x, y), rcond=None)[0], np.linalg.lstsq(a, z, rcond=None)[0]))
    return maps


def _vec(v) -> str:
    return " ".join(f"{x:.9g}" for x in v)


def amru5_mjcf(d: dict, maps: list[tuple[np.ndarray, np.ndarray]]) -> tuple[str, list[tuple[float, float]]]:
    """The MJCF of the AMRU5 from the robot file ``d`` (thesis units, see robots/amru5.toml)
    and the pantograph maps; returns it with the slide origins (rho_0, z_0) of each leg."""
    geo, ine, act = d["geometry"], d["inertia"], d["geometry"]["actuators"]
    ch = geo["chassis"]
    rotor = ine["rotor"]
    r_total = d["motor"]["resistance_ohm"] + d["driver"]["mosfet_resistance_ohm"] * d["driver"]["mosfets_in_series"]
    k_t, j_r = d["motor"]["torque_constant_nm_per_a"], d["motor"]["rotor_inertia_g_cm2"] * 1e-7
    u_supply = d["driver"]["supply_voltage_v"]
    red = d["reductions"]
    ranges = d["joint_ranges"]
    ctl = d["controller"]
    fr = d["friction"]

    def dry(joint: str, unit: str) -> float:
        plus, minus = fr[joint][f"tau_f_d_plus_{unit}"]["mu"], fr[joint][f"tau_f_d_minus_{unit}"]["mu"]
        return float(np.mean(np.abs(plus)) + np.mean(np.abs(minus))) / 2.0

    def actuator(n: float, k: float, ratio: float) -> dict:
        """Joint-side PD, armature, force limit from the motor (Eq. 4.4) and the PI gain K
        (Table 4.1), carried to a coordinate that moves `ratio` times the joint."""
        s = ratio * ratio
        return {"kp": n * k_t * k / r_total / s, "kv": (n * k_t) ** 2 / r_total / s, "armature": j_r * n * n / s, "force": n * k_t * u_supply / r_total / abs(ratio)}

    # Transmission ratios (foot per nut) averaged over the legs.
    a_h = float(np.mean([m[0][0] for m in maps]))
    a_v = float(np.mean([m[1][1] for m in maps]))
    joints = {
        "r": actuator(red["n_r"], ctl["q_r"]["k_v_per_rad"], 1.0) | {"friction": dry("q_r", "nm")},
        "rho": actuator(red["n_h_rad_per_m"], ctl["q_h"]["k_v_per_m"], a_h) | {"friction": dry("q_h", "n") / abs(a_h)},
        "z": actuator(red["n_v_rad_per_m"], ctl["q_v"]["k_v_per_m"], a_v) | {"friction": dry("q_v", "n") / abs(a_v)},
    }
    q_v, q_h = ranges["q_v_m"], ranges["q_h_m"]
    c_star = np.array([ch["l_x1_m"] + ch["l_xc_m"], ch["l_y1_m"] + ch["l_yc_m"], ch["l_z1_m"] + ch["l_zc_m"]])
    links = [ine[k] for k in ("pantograph_upper", "pantograph_left", "pantograph_lower", "pantograph_leg")]
    link_mass = sum(x["mass_kg"] for x in links)
    link_inertia = [sum(x[f"i_{a}_kg_m2"] for x in links) for a in ("xx", "yy", "zz")]
    rotor_inertia = [rotor["i_equatorial_kg_m2"], rotor["i_equatorial_kg_m2"], rotor["i_axial_kg_m2"]]
    mb = ine["main_body"]

    def rotor_body(name: str, pos) -> str:
        return f'<body name="{name}" pos="{_vec(pos)}"><inertial pos="0 0 0" mass="{rotor["mass_kg"]}" diaginertia="{_vec(rotor_inertia)}"/></body>'

    legs, actuators, origins = [], [], []
    for leg, spec in enumerate(d["legs"]):
        alpha = math.radians(spec["angle_deg"])
        r_rot = geo["body"]["r_rot_m"]
        (rho_map, z_map) = maps[leg]
        mid_h, mid_v = (q_h["min"] + q_h["max"]) / 2, (q_v["min"] + q_v["max"]) / 2
        rho0 = float(rho_map @ [mid_h, mid_v, 1.0])
        z0 = float(z_map @ [mid_h, mid_v, 1.0])
        origins.append((rho0, z0))
        rho_range = sorted((a_h * (q_h["min"] - mid_h), a_h * (q_h["max"] - mid_h)))
        z_range = sorted((a_v * (q_v["min"] - mid_v), a_v * (q_v["max"] - mid_v)))
        lumped_com = (c_star - np.array([rho0, 0.0, z0])) / 2.0

        def joint(name: str, kind: str, axis: str, rng, j: dict) -> str:
            return f'<joint name="{name}{leg}" type="{kind}" axis="{axis}" range="{_vec(rng)}" limited="true" armature="{j["armature"]:.9g}" frictionloss="{j["friction"]:.9g}"/>'

        legs.append(
            f'<body name="chassis{leg}" pos="{_vec([r_rot * math.cos(alpha), r_rot * math.sin(alpha), 0.0])}" euler="0 0 {alpha:.12g}">'
            + joint("q_r", "hinge", "0 0 -1", [math.radians(ranges["q_r_deg"]["min"]), math.radians(ranges["q_r_deg"]["max"])], joints["r"])
            + f'<inertial pos="{_vec([ch["l_x1_m"], ch["l_y1_m"], ch["l_z1_m"]])}" mass="{ine["chassis"]["mass_kg"]}" diaginertia="{_vec([ine["chassis"][f"i_{a}_kg_m2"] for a in ("xx", "yy", "zz")])}"/>'
            + rotor_body(f"rotor_v{leg}", c_star + [act["l_x7_m"], act["l_y7_m"], act["l_z7_m"]])
            + rotor_body(f"rotor_h{leg}", c_star + [act["l_x8_m"], act["l_y8_m"], act["l_z8_m"]])
            + f'<body name="pantograph{leg}" pos="{_vec([rho0, 0.0, z0])}">'
            + joint("rho", "slide", "1 0 0", rho_range, joints["rho"])
            + joint("z", "slide", "0 0 1", z_range, joints["z"])
            + f'<inertial pos="{_vec(lumped_com)}" mass="{link_mass:.9g}" diaginertia="{_vec(link_inertia)}"/>'
            + f'<geom name="foot{leg}" type="sphere" size="{FOOT_RADIUS}" pos="0 0 {FOOT_RADIUS}" contype="1" conaffinity="1" condim="3" mass="0"/>'
            + "</body></body>"
        )
        for name, j in (("q_r", joints["r"]), ("rho", joints["rho"]), ("z", joints["z"])):
            actuators.append(f'<position joint="{name}{leg}" kp="{j["kp"]:.9g}" kv="{j["kv"]:.9g}" forcelimited="true" forcerange="{-j["force"]:.9g} {j["force"]:.9g}"/>')
    main_rotors = "".join(
        rotor_body(f"rotor_r{leg}", [act["l_x6_m"] * math.cos(math.radians(s["angle_deg"])), act["l_x6_m"] * math.sin(math.radians(s["angle_deg"])), 0.0])
        for leg, s in enumerate(d["legs"])
    )
    mu = d["ground"]["mu"]
    xml = f"""<mujoco model="amru5">
  <compiler angle="radian"/>
  <option timestep="{DT}" integrator="implicitfast" gravity="0 0 -9.81"/>
  <worldbody>
    <geom name="ground" type="plane" size="50 50 0.1" contype="1" conaffinity="1" friction="{mu} 0.005 0.0001"/>
    <body name="main_body" pos="0 0 0.5">
      <freejoint name="root"/>
      <inertial pos="0 0 0" mass="{mb["mass_kg"]}" diaginertia="{_vec([mb["i_xx_kg_m2"], mb["i_yy_kg_m2"], mb["i_zz_kg_m2"]])}"/>
      {main_rotors}
      {"".join(legs)}
    </body>
  </worldbody>
  <actuator>{"".join(actuators)}</actuator>
</mujoco>"""
    return xml, origins


def targets(c: dict, maps, origins) -> np.ndarray:
    """MuJoCo position targets per control instant (rows) and actuator (q_r, rho, z per leg):
    hexadyn's joint references through the pantograph maps."""
    cols = []
    for leg in range(6):
        rho_map, z_map = maps[leg]
        a = np.c_[c[f"q_h_ref[{leg}]"], c[f"q_v_ref[{leg}]"], np.ones(len(c["t"]))]
        rho0, z0 = origins[leg]
        cols += [c[f"q_r_ref[{leg}]"], a @ rho_map - rho0, a @ z_map - z0]
    return np.stack(cols, axis=1)


def ypr_quaternion(yaw: float, pitch: float, roll: float) -> np.ndarray:
    """Unit quaternion (w, x, y, z) of R_z(yaw) R_y(pitch) R_x(roll)."""
    cy, sy, cp, sp, cr, sr = (f(a / 2) for a in (yaw, pitch, roll) for f in (math.cos, math.sin))
    return np.array([cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy])


def mujoco_walk(model, c: dict, ctrl: np.ndarray, settle_s: float = 2.0):
    """Starts from hexadyn's initial pose and joints, settles under the first targets (not
    timed), then replays the targets with a zero-order hold over each control period. Returns
    (X, Z of the body at each control instant, wall s, CPU s)."""
    data = mujoco.MjData(model)
    data.qpos[:3] = [c["X"][0], c["Y"][0], c["Z"][0] + 0.005]
    data.qpos[3:7] = ypr_quaternion(c["yaw"][0], c["pitch"][0], c["roll"][0])
    data.qpos[7:] = ctrl[0]
    data.ctrl[:] = ctrl[0]
    mujoco.mj_step(model, data, nstep=int(round(settle_s / DT)))
    per_period = int(round((c["t"][1] - c["t"][0]) / DT))
    x, z = np.empty(len(ctrl)), np.empty(len(ctrl))
    wall, cpu = time.perf_counter(), time.process_time()
    for i, u in enumerate(ctrl):
        x[i], z[i] = data.qpos[0], data.qpos[2]
        if i + 1 < len(ctrl):
            data.ctrl[:] = u
            mujoco.mj_step(model, data, nstep=per_period)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    return x, z, wall, cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--xml", type=Path, help="also write the generated MJCF to this file")
    parser.add_argument(
        "--repeats",
        type=int,
        default=5,
        help="timed pairs of walks, hexadyn then MuJoCo, interleaved; the medians are printed (default 5: "
        "on a shared machine single runs vary by tens of percent)",
    )
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error(f"--repeats {args.repeats}: must be at least 1")
    with open(ROBOT, "rb") as f:
        robot = tomllib.load(f)
    c, hx_wall, hx_cpu = hexadyn_walk()
    maps = pantograph_map(c)
    xml, origins = amru5_mjcf(robot, maps)
    if args.xml:
        args.xml.write_text(xml)
    model = mujoco.MjModel.from_xml_string(xml)
    ctrl = targets(c, maps, origins)
    x, z, mj_wall, mj_cpu = mujoco_walk(model, c, ctrl)
    # (hexadyn wall, CPU, MuJoCo wall, CPU) of each pair; the first pair is the one above.
    pairs = [(hx_wall, hx_cpu, mj_wall, mj_cpu)]
    for _ in range(args.repeats - 1):
        _, hw, hc = hexadyn_walk()
        _, _, mw, mc = mujoco_walk(model, c, ctrl)
        pairs.append((hw, hc, mw, mc))
    hx_wall, hx_cpu, mj_wall, mj_cpu = (float(np.median(column)) for column in zip(*pairs))
    ratios = [mc / hc for _, hc, _, mc in pairs]
    duration = float(c["t"][-1] - c["t"][0])
    load = os.getloadavg()[0]
    print(f"75 s tripod walk of Section 3.4.1 (T = 15 s, 2 cm/s), one core; load average {load:.1f} on {os.cpu_count()} cores")
    print(f"MuJoCo {mujoco.__version__}, {model.nbody - 1} bodies, {model.nv} DOF, {model.nu} position actuators, dt = {DT * 1e3:g} ms")
    print(f"medians of {args.repeats} interleaved pairs")
    print(f"{'':<10} {'wall s':>8} {'CPU s':>8} {'RTF(CPU)':>9} {'walked m':>9} {'height m':>9}")
    hx_rows = (hx_wall, hx_cpu, c["X"][-1] - c["X"][0], float(np.mean(c["Z"])))
    mj_rows = (mj_wall, mj_cpu, x[-1] - x[0], float(np.mean(z)))
    for name, (w, p, walked, height) in (("hexadyn", hx_rows), ("MuJoCo", mj_rows)):
        print(f"{name:<10} {w:>8.3f} {p:>8.3f} {duration / p:>9.0f} {walked:>9.3f} {height:>9.3f}")
    print(
        f"ratio MuJoCo / hexadyn: {float(np.median(ratios)):.2f} (median of the pairs' CPU ratios; "
        f"{min(ratios):.2f}-{max(ratios):.2f}), {mj_wall / hx_wall:.2f} (median wall times)"
    )
    print("physics included:")
    print(f"  {HEXADYN_PHYSICS}")
    print(f"  {MUJOCO_PHYSICS}")


if __name__ == "__main__":
    main()
