"""Regenerates the ``hexadyn view`` screenshots of the README (docs/view_*.png) in headless
Chromium: the validation walk, the spline path of Section 7.5.3 with its reference, and a walk
onto a step of the [terrain] table.

    .venv/bin/python docs/view_screenshots.py [--results DIR] [--only FILE ...]   # simulates the runs into DIR
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
from PIL import Image

import hexadyn
from hexadyn.view.server import start

DOCS = Path(__file__).resolve().parent
#: (scenario, file, time shown (s), camera position and target relative to the start of the body path)
SHOTS = [
    ("validation_tripod_1_5cm", "view_validation_walk.png", 33.0, (-0.35, -1.25, 0.95), (0.5, 0.0, 0.2)),
    ("path_spline", "view_path_spline.png", 120.0, (0.45, -2.2, 2.0), (0.8, -0.6, 0.0)),
    ("tripod_low_step", "view_low_step.png", 42.0, (0.05, -1.1, 0.35), (0.6, 0.0, 0.1)),
]


def screenshot(folder: Path, png: Path, t: float, eye: tuple, target: tuple, browser) -> None:
    running = start(folder)
    try:
        page = browser.new_page(viewport={"width": 1280, "height": 760})
        page.goto(running.url)
        page.wait_for_selector("#hexadyn-state", state="attached", timeout=30000)
        running.viewer.seek(t)
        origin = running.viewer.run.q[0, :3] * np.array([1.0, 1.0, 0.0])
        for client in running.server.get_clients().values():
            client.camera.position = origin + np.array(eye)
            time.sleep(0.5)
            client.camera.look_at = origin + np.array(target)
        for close in page.locator("button.mantine-Notification-closeButton").all():
            close.click()
        time.sleep(4.0)
        page.screenshot(path=png)
        page.close()
    finally:
        running.stop()
    Image.open(png).convert("RGB").quantize(colors=128).save(png, optimize=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", type=Path, default=None, help="folder for the simulated runs (default: a temporary one)")
    parser.add_argument("--only", action="append", default=[], metavar="FILE", help="regenerate only this screenshot (repeatable), e.g. view_low_step.png")
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    results = args.results or Path(tempfile.mkdtemp(prefix="hexadyn-shots-"))
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=shutil.which("chromium"), args=["--use-angle=swiftshader", "--enable-unsafe-swiftshader"])
            for scenario, name, t, eye, target in SHOTS:
                if args.only and name not in args.only:
                    continue
                folder = results / scenario
                if not folder.exists():
                    hexadyn.simulate(scenario, out=folder, progress=False)
                screenshot(folder, DOCS / name, t, eye, target, browser)
                print(f"wrote {DOCS / name}")
            browser.close()
    finally:
        if args.results is None:
            shutil.rmtree(results, ignore_errors=True)


if __name__ == "__main__":
    main()
