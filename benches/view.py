"""Benchmark of ``hexadyn view``: frames per second of the page in headless Chromium, and the
cost of a long run (a 1000 s walk, 10^5 recorded instants) for the viewer.

Measures, on the validation walk (or FOLDER):

- the rendered frames per second of the live page while it plays at 1x (frames in which the
  page issued WebGL draw calls, counted in the page), and of the HTML export while it plays;
- with ``--long``: the time to open a 1000 s walk (simulated first, about 20 s), to compute one
  frame's kinematics, to seek, and the export's size and time.

Software WebGL (SwiftShader: no GPU here) on a shared 2-core machine is the worst case; a
desktop browser with a GPU renders at its display rate.

    .venv/bin/python benches/view.py [FOLDER] [--seconds 5] [--speed 1] [--long] [--chromium-arg=...]
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path

import hexadyn
from hexadyn.view.data import Run
from hexadyn.view.export import export_html
from hexadyn.view.measure import FRAME_COUNTER_JS, HEADLESS_CHROMIUM_ARGS
from hexadyn.view.server import start



def frames_per_second(browser, url: str, seconds: float, start_playing=None) -> float:
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    page.add_init_script(FRAME_COUNTER_JS)
    page.goto(url)
    page.wait_for_selector("canvas", timeout=60000)
    time.sleep(3.0)
    if start_playing is not None:
        start_playing()
        time.sleep(1.0)
    f0, t0 = page.evaluate("window.__frames"), time.monotonic()
    time.sleep(seconds)
    fps = (page.evaluate("window.__frames") - f0) / (time.monotonic() - t0)
    page.close()
    return fps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", nargs="?", type=Path, help="a results folder (default: the validation walk, simulated)")
    parser.add_argument("--seconds", type=float, default=5.0, help="measuring time per page")
    parser.add_argument("--speed", default="1", help="playback speed of the live page")
    parser.add_argument("--long", action="store_true", help="also open, seek and export a 1000 s walk")
    parser.add_argument("--chromium-arg", action="append", default=[], help="extra Chromium flag (repeatable)")
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    work = Path(tempfile.mkdtemp(prefix="hexadyn-view-bench-"))
    try:
        folder = args.folder
        if folder is None:
            folder = work / "walk"
            hexadyn.simulate("validation_tripod_1_5cm", out=folder, progress=False)
        export = export_html(folder, work / "walk.html")
        running = start(folder)
        try:
            with sync_playwright() as p:
                browser = p.chromium.launch(executable_path=shutil.which("chromium"), args=HEADLESS_CHROMIUM_ARGS + args.chromium_arg)

                def play() -> None:
                    running.viewer.speed.value = args.speed
                    running.viewer.play()

                live = frames_per_second(browser, running.url, args.seconds, play)
                exported = frames_per_second(browser, export.as_uri(), args.seconds)
                browser.close()
        finally:
            running.stop()
        print(f"{folder}: live page playing at {args.speed}x: {live:.1f} frames/s; HTML export ({export.stat().st_size / 1e6:.1f} MB) playing: {exported:.1f} frames/s")
        print(f"  (headless Chromium, software WebGL, 1280 x 800, flags {' '.join(HEADLESS_CHROMIUM_ARGS + args.chromium_arg)})")
        if args.long:
            long_run(work)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def long_run(work: Path) -> None:
    """A 1000 s walk (10^5 instants): open, one frame, seek, export."""
    folder = work / "long"
    t0 = time.perf_counter()
    hexadyn.simulate("validation_tripod_1_5cm", out=folder, overrides={"scenario.duration_s": 1000.0}, progress=False)
    simulated = time.perf_counter() - t0
    t0 = time.perf_counter()
    run = Run(folder)
    opened = time.perf_counter() - t0
    t0 = time.perf_counter()
    for index in range(0, run.t.size, run.t.size // 200):
        run.frame(index)
    per_frame = (time.perf_counter() - t0) / 200
    running = start(folder)
    t0 = time.perf_counter()
    for t in (10.0, 500.0, 999.0, 250.0):
        running.viewer.seek(t)
    seek = (time.perf_counter() - t0) / 4
    running.stop()
    t0 = time.perf_counter()
    export = export_html(folder, work / "long.html")
    exported = time.perf_counter() - t0
    print(f"1000 s walk ({run.t.size} instants, simulated in {simulated:.0f} s, Parquet {(folder / 'timeseries.parquet').stat().st_size / 1e6:.0f} MB):")
    print(f"  open {opened:.2f} s, one frame's kinematics {per_frame * 1e3:.2f} ms, seek (scene, read-out, chart cursors) {seek * 1e3:.0f} ms")
    print(f"  HTML export: {export.stat().st_size / 1e6:.1f} MB in {exported:.1f} s")


if __name__ == "__main__":
    main()
