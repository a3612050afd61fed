"""Benchmark of a Monte Carlo campaign (thesis Section 6.5) on every local core, or on Ray.

Runs a campaign (default: the full one of the robot's ``[monte_carlo]``, 1000 runs x 4
velocities x 2 friction variants of the validation walk) and a single-worker baseline on a few
runs in the same command, and prints the wall time, simulations per second, the real-time
factor, the ratio against the thesis' cost (260 s of computation per 75 s simulated, Table 3.2),
the parallel speed-up over the baseline and the parallel efficiency of issue 16 (the walks' own
times shared over the workers, against the campaign's wall time).

The efficiency is then taken apart from timestamps of every walk (start and end in its worker,
arrival in the parent): start-up (the campaign started, no walk yet: the pool or Ray), the
work of a worker around each walk (reading the scenario, the summary), the gaps between a
worker's walks (dispatch, result transfer), the tail (workers idle while the last walks end)
and the end (Table 6.8 and Fig. 6.20). The fixed parts (start-up, tail, end) weigh less the more
walks there are: the efficiency of the full campaign is projected from the parts. On a loaded
machine every part stretches alike; the parts, not one wall-clock ratio, say what is lost.

    .venv/bin/python benches/montecarlo.py --runs 50          # or: make bench-montecarlo MC_ARGS="--runs 50"
    .venv/bin/python benches/montecarlo.py --runs 4 --variants dry_viscous --workers 2 --ray   # Ray, 2 local workers
    make bench-montecarlo MC_ARGS="--runs 1000 --variants dry_viscous"   # the 4000-walk campaign
"""

from __future__ import annotations

import argparse
import os
import sqlite3
import sys
import tempfile
import time
from pathlib import Path

from hexadyn.montecarlo import DEFAULT_SCENARIO, Campaign, execution
from hexadyn.montecarlo.storage import DATABASE_FILE, CampaignStore

#: Table 3.2, last row: 4 min 20 s of computation for 75 s of walking (tripod, 2 cm/s, LuGre).
THESIS_WALL_PER_SIMULATED_S = 260.0 / 75.0


def timed_simulate_run(scenario, overrides):
    """:func:`hexadyn.montecarlo.execution.simulate_run` with the walk's start and end (time.time()
    in the worker) and the worker's process id in its outcome."""
    start = time.time()
    outcome = _simulate_run(scenario, overrides)
    return {**outcome, "timing": (os.getpid(), start, time.time())}


_simulate_run = execution.simulate_run
_store_add = CampaignStore.add


def timed_campaign(campaign: Campaign, out: Path, workers: int, progress: bool, ray: str | None = None):
    """Runs ``campaign`` into the new folder ``out``; returns (Table 6.8, wall time, simulated
    time, summed per-simulation wall time, simulations, timeline). The timeline: the start and
    the end of the run (time.time()), (pid, start, end, engine seconds) of every walk in its
    worker, and (arrival, seconds spent storing) of every outcome in the parent."""
    walks, arrivals = [], []

    def add(store, key, velocity, parameters, outcome):
        arrived = time.time()
        if "timing" in outcome:
            walks.append((*outcome["timing"], outcome.get("summary", {}).get("wall_time_s", 0.0)))
        _store_add(store, key, velocity, parameters, outcome)
        arrivals.append((arrived, time.time() - arrived))

    execution.simulate_run, CampaignStore.add = timed_simulate_run, add
    try:
        began, start = time.time(), time.perf_counter()
        table = campaign.run(out, workers=workers, ray=ray, progress=progress)
        wall, ended = time.perf_counter() - start, time.time()
    finally:
        execution.simulate_run, CampaignStore.add = _simulate_run, _store_add
    with sqlite3.connect(out / DATABASE_FILE) as db:
        simulated, engine, n = db.execute("SELECT sum(duration_s), sum(wall_time_s), count(*) FROM runs WHERE status = 'ok'").fetchone()
    return table, wall, simulated, engine, n, (began, ended, walks, arrivals)


def efficiency_parts(timeline, workers: int, full_walks: int) -> None:
    """Prints where the campaign time went, as fractions of workers x campaign time (they add up
    to 100 %), and the efficiency projected for `full_walks` walks."""
    began, ended, walks, arrivals = timeline
    if not walks:
        return
    total = workers * (ended - began)
    first_start = min(w[1] for w in walks)
    last_end = max(w[2] for w in walks)
    by_worker: dict[int, list] = {}
    for w in sorted(walks, key=lambda w: w[1]):
        by_worker.setdefault(w[0], []).append(w)
    engine = sum(w[3] for w in walks)
    around = sum(w[2] - w[1] - w[3] for w in walks)  # in the worker, outside the engine's own time
    gaps = sum(b[1] - a[2] for ws in by_worker.values() for a, b in zip(ws, ws[1:]))
    # Worker slots with no walk at all (fewer processes than workers) idle from the first start.
    starts = sum(ws[0][1] - first_start for ws in by_worker.values()) + (workers - len(by_worker)) * (last_end - first_start)
    tail = sum(last_end - ws[-1][2] for ws in by_worker.values())
    start_up, end = workers * (first_start - began), workers * (ended - last_end)
    parts = {
        "walks (engine)": engine,
        "around each walk in the worker": around,
        "gaps between a worker's walks": gaps,
        "start-up (no walk yet)": start_up + starts,
        "tail (workers idle at the end)": tail,
        "end (last walk to Table 6.8, Fig. 6.20)": end,
    }
    store = sum(a[1] for a in arrivals)
    print(f"\nwhere the {workers} x {ended - began:.1f} s went ({len(walks)} walks on {len(by_worker)} worker processes):")
    for name, seconds in parts.items():
        print(f"  {name:42s} {seconds:8.2f} s  {seconds / total:6.1%}")
    print(f"  {'(rest: rounding of the clocks)':42s} {total - sum(parts.values()):8.2f} s")
    print(f"  parent: {1e3 * store / len(arrivals):.1f} ms per stored walk (concurrent with the workers)")
    n = len(walks)
    per_walk = (engine + around + gaps) / n
    fixed = start_up + starts + tail + end
    print(f"  efficiency without the fixed parts (start-up, tail, end): {engine / (engine + around + gaps):.1%}; "
          f"projected for {full_walks} walks: {full_walks * engine / n / (full_walks * per_walk + fixed):.1%}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scenario", default=DEFAULT_SCENARIO)
    parser.add_argument("--runs", type=int, default=None, help="runs per velocity (default: the robot's, 1000)")
    parser.add_argument("--variants", default=None, help="comma-separated friction variants (default: both, dry_viscous,dry_viscous_load)")
    parser.add_argument("--baseline-runs", type=int, default=5, help="runs per velocity of the single-worker baseline (default 5: the worker start-up, about 1 s, is in its time)")
    parser.add_argument("--workers", type=int, default=os.cpu_count(), help="parallel workers (default: every core)")
    parser.add_argument("--out", type=Path, default=None, help="keep the campaign in this new folder (default: a temporary one)")
    parser.add_argument("--ray", action="store_true", help="run the campaign on Ray (a local instance with --workers CPUs) instead of the process pool")
    args = parser.parse_args()
    if args.out is not None and args.out.exists():
        sys.exit(f"{args.out}: exists; the benchmark needs a new folder (an existing campaign would be resumed, not timed)")

    variants = None if args.variants is None else [v.strip() for v in args.variants.split(",")]
    campaign = Campaign.create(args.scenario, runs_per_velocity=args.runs, variants=variants)
    baseline = Campaign.create(args.scenario, runs_per_velocity=args.baseline_runs, variants=variants)
    with tempfile.TemporaryDirectory(prefix="hexadyn-bench-mc-") as tmp:
        print(f"baseline: {len(baseline.keys())} simulations on 1 worker ...", flush=True)
        _, b_wall, _, _, b_n, _ = timed_campaign(baseline, Path(tmp) / "baseline", 1, progress=False)
        out = args.out or Path(tmp) / "campaign"
        print(f"campaign: {len(campaign.keys())} simulations on {args.workers} workers{' (Ray)' if args.ray else ''} ...", flush=True)
        table, wall, simulated, engine, n, timeline = timed_campaign(campaign, out, args.workers, progress=True, ray="local" if args.ray else None)

    serial_rate, rate = b_n / b_wall, n / wall
    full = Campaign.create(args.scenario)
    print(f"\nMonte Carlo campaign: {campaign.scenario_name}, {campaign.runs_per_velocity} runs x {len(campaign.velocities_m_per_s)} velocities x {len(campaign.variants)} variants")
    print(f"  wall time              {wall:10.1f} s for {n} simulations ({simulated:.0f} s simulated)")
    print(f"  throughput             {rate:10.3f} simulations/s ({args.workers} workers)")
    print(f"  real-time factor       {simulated / wall:10.1f} x (campaign), {simulated / engine:.1f} x per simulation")
    print(f"  vs thesis (Table 3.2)  {simulated * THESIS_WALL_PER_SIMULATED_S / wall:10.0f} x faster than 260 s per 75 s sequentially")
    print(f"  single-worker baseline {serial_rate:10.3f} simulations/s ({b_n} simulations in {b_wall:.1f} s)")
    print(f"  parallel speed-up      {rate / serial_rate:10.2f} x on {args.workers} workers")
    # Issue 16's measure: the walks' own (engine) times shared over the workers, against the
    # campaign's wall time; what is lost is process start-up, scenario parsing, result storage
    # and the tail of the last walks. On a loaded machine both sides stretch: a rough figure.
    print(f"  parallel efficiency    {engine / args.workers / wall:10.1%} (sum of single-walk times / {args.workers} workers / campaign time; load average {os.getloadavg()[0]:.1f})")
    print(f"  full campaign          {len(full.keys()) / rate / 3600:10.2f} h projected for {len(full.keys())} simulations at this throughput")
    efficiency_parts(timeline, args.workers, 4000)
    print("\nTable 6.8:")
    print(table.to_string(index=False, float_format=lambda x: f"{x:.4g}"))


if __name__ == "__main__":
    main()
