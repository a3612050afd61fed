"""Benchmark of the memory of long runs: the time series is streamed to disk (issue 17).

Runs the standing scenario (stand_six_legs) for a baseline duration and for 10 times longer
(default 1e4 s and 1e5 s: 10^6 and 10^7 instants), each in its own process through
``hexadyn.simulate(..., out=...)`` (the path of ``hexadyn simulate``; both without the
in-memory analysis, which such series are too large for), the two at once, and prints each
run's peak resident memory (``resource.getrusage``: ru_maxrss), wall time and Parquet size, and
the ratio of the peaks: a memory bounded by a constant gives a ratio near 1 (it was 100: 2.5 GB
at 11 % of 1e5 s before the series was streamed; then 650 MB at 1e5 s, growing with the
Parquet footer of one row group per 10^4 instants). What remains of the growth is the footer
of the row groups (:class:`hexadyn.results.SeriesWriter`), printed as MB per 10^6 instants.
The long run's Parquet file is then read back whole, row group by row group, in another
process (its peak memory printed too): every instant is there (t = 0, Δt, ..., the duration)
with every column.

    .venv/bin/python benches/memory.py                  # 1e4 s and 1e5 s (about 1 h on a loaded 2-core machine)
    .venv/bin/python benches/memory.py --duration 1e4   # 1e3 s and 1e4 s (a few minutes)
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import hexadyn

#: The issue's bound on the peak memory of a 1e5 s standing run.
LIMIT_MB = 500.0

RUN = """
import json, resource, sys, time
import hexadyn
from hexadyn import report
report.IN_MEMORY_LIMIT_BYTES = 0  # the baseline is not analysed in memory either: like with like
start = time.perf_counter()
r = hexadyn.simulate(sys.argv[1], sys.argv[2], progress=False)
print(json.dumps({"wall_s": time.perf_counter() - start, "rows": r.shape[0], "columns": r.shape[1],
                  "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, "warnings": r.summary["warnings"]}))
"""

READ_BACK = """
import json, resource, sys
import numpy as np
import pyarrow.parquet as pq
file = pq.ParquetFile(sys.argv[1])
rows, last, monotone = 0, None, True
for group in range(file.num_row_groups):
    batch = file.read_row_group(group)
    t = batch.column("t").to_numpy()
    monotone &= bool(np.all(np.diff(t) > 0) and (last is None or t[0] > last))
    rows += batch.num_rows
    last = float(t[-1])
print(json.dumps({"rows": rows, "columns": file.metadata.num_columns, "last_t": last, "monotone": monotone,
                  "row_groups": file.num_row_groups, "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def scenario(folder: Path, duration: float) -> Path:
    text = (hexadyn.SCENARIOS_DIR / "stand_six_legs.toml").read_text()
    text, n = re.subn(r"(?m)^duration_s = .*$", f"duration_s = {duration:g}", text)
    assert n == 1
    path = folder / f"stand_{duration:g}.toml"
    path.write_text(text)
    return path


def start_child(code: str, *args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-c", code, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def finish_child(child: subprocess.Popen) -> dict:
    out, err = child.communicate()
    if child.returncode != 0:
        sys.exit(f"the child failed ({child.returncode}): {err.strip()}")
    return json.loads(out.strip().splitlines()[-1])


def child(code: str, *args: str) -> dict:
    return finish_child(start_child(code, *args))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--duration", type=float, default=1e5, help="simulated time of the long run (s); the baseline is 10 times shorter")
    parser.add_argument("--dir", type=Path, default=None, help="where to write the results (default: a temporary folder; needs about 26 GB for 1e4 s and 1e5 s)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="hexadyn-bench-memory-", dir=args.dir) as tmp:
        tmp = Path(tmp)
        durations = (args.duration / 10, args.duration)
        print(f"standing {durations[0]:g} s and {durations[1]:g} s, each in its own process, at once ...", flush=True)
        children = {d: start_child(RUN, str(scenario(tmp, d)), str(tmp / f"out_{d:g}")) for d in durations}
        measured = {d: finish_child(child) for d, child in children.items()}
        for duration, m in measured.items():
            m["parquet_mb"] = (tmp / f"out_{duration:g}" / "timeseries.parquet").stat().st_size / 2**20
            print(f"  {duration:g} s: {m['rows']} instants x {m['columns']} columns in {m['wall_s']:.0f} s wall; peak memory {m['peak_mb']:.0f} MB; "
                  f"Parquet {m['parquet_mb']:.0f} MB; warnings {m['warnings']}", flush=True)
        short, long = measured[durations[0]], measured[durations[1]]
        growth = (long["peak_mb"] - short["peak_mb"]) / ((long["rows"] - short["rows"]) / 1e6)
        print(f"peak memory ratio long/baseline (10x the duration): {long['peak_mb'] / short['peak_mb']:.2f}; growth {growth:.1f} MB per 10^6 instants")
        start = time.perf_counter()
        back = child(READ_BACK, str(tmp / f"out_{args.duration:g}" / "timeseries.parquet"))
        expected = round(args.duration / 0.01) + 1
        # The engine's t accumulates the period's rounding: over 10^7 periods the last t is off the
        # duration by about 1e-5 s; it is that instant if within half a period of it.
        whole = back["rows"] == long["rows"] == expected and back["monotone"] and abs(back["last_t"] - args.duration) < 0.5 * 0.01 and back["columns"] == long["columns"] + 1
        print(f"read back: {back['rows']} rows (expected {expected}) x {back['columns']} columns in {back['row_groups']} row groups, "
              f"last t = {back['last_t']!r} s, increasing: {back['monotone']}, in {time.perf_counter() - start:.0f} s, peak memory {back['peak_mb']:.0f} MB: "
              f"{'whole' if whole else 'NOT WHOLE'}")
        if args.duration >= 1e5 and long["peak_mb"] > LIMIT_MB:
            sys.exit(f"peak memory {long['peak_mb']:.0f} MB over the {LIMIT_MB:g} MB bound")
        if not whole:
            sys.exit("the Parquet file does not read back whole")


if __name__ == "__main__":
    main()
