"""Benchmark of the friction identification (thesis Chapter 5, `hexadyn identify`).

1. Simulates the three Table 5.2 campaigns (identification_q_r, _q_v, _q_h: six joints each,
   16 velocities) and times the identification of all eighteen joints from them, against the
   issue's budget of one minute on 2 cores, and the simulations themselves as the baseline
   measured in the same run.
2. Repeats the identification of the q_v campaign under the real robot's sensor model (1.5 %
   current noise, 30 Hz + 3 Hz filters, 500-count encoders) with `--repetitions` seeds
   (default 200) and prints the share of the 95 % intervals (Jacobian and bootstrap) that hold
   the truth, and the largest errors of tau_f,d and f_v.

    .venv/bin/python benches/identify.py                  # 200 repetitions (about 15 min)
    .venv/bin/python benches/identify.py --repetitions 20
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import hexadyn
from hexadyn.identify import identify, load_log
from hexadyn.identify.sensors import SensorModel, measure
from hexadyn.identify.torques import leg_model


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repetitions", type=int, default=200)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        logs = {}
        started = time.perf_counter()
        for joint in ("q_r", "q_v", "q_h"):
            logs[joint] = hexadyn.simulate(f"identification_{joint}", out=Path(tmp) / joint, progress=False).path
        simulated = time.perf_counter() - started
        started = time.perf_counter()
        ident = identify([load_log(p) for p in logs.values()])
        identified = time.perf_counter() - started
        print(f"simulating the three campaigns: {simulated:.1f} s (baseline)")
        print(f"identifying all 18 joints ({len(ident.fits)} fits): {identified:.1f} s = {identified / simulated:.2f} x the simulations, {identified / 60:.2f} of the 1 min budget")
        base = load_log(logs["q_v"])
        jac = boot = total = 0
        worst = {"tau_f_d": 0.0, "f_v": 0.0}
        for seed in range(args.repetitions):
            noisy = identify([measure(base, SensorModel(noise_percent=1.5, seed=seed))])
            for _, f in noisy.fits:
                sense = "plus" if f.direction > 0 else "minus"
                t = leg_model(None).joint(f.leg, "q_v")
                for name, e in (("tau_f_d", f.tau_f_d), ("f_v", f.f_v)):
                    true = t[f"{name}_{sense}"]
                    jac += e.ci_low <= true <= e.ci_high
                    boot += e.boot_low <= true <= e.boot_high
                    total += 1
                    worst[name] = max(worst[name], abs(e.value - true) / abs(true))
        print(f"{args.repetitions} noisy repetitions, {total} intervals: Jacobian coverage {jac / total:.3f}, bootstrap coverage {boot / total:.3f} (target >= 0.90)")
        print(f"largest errors of a single campaign: tau_f,d {100 * worst['tau_f_d']:.2f} %, f_v {100 * worst['f_v']:.2f} %")


if __name__ == "__main__":
    main()
