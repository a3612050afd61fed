"""hexadyn view: the kinematics the viewer draws, its input checks, and the real page in headless
Chromium (Debian's chromium driven by Playwright; WebGL through SwiftShader): the canvas is
drawn, seeking shows the recorded feet, play advances time, the HTML export plays from a plain
static server and from a file:// URL."""

from __future__ import annotations

import functools
import http.server
import io
import json
import os
import shutil
import threading
import time
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from click.testing import CliRunner
from matplotlib.image import imread

from hexadyn import _core, report
from hexadyn.view.command import view
from hexadyn.view.data import FOOT_COLUMNS, Run, ViewError
from hexadyn.view.measure import FRAME_COUNTER_JS, HEADLESS_CHROMIUM_ARGS

pytest.importorskip("viser")
playwright_api = pytest.importorskip("playwright.sync_api")

VIEWPORT = {"width": 1280, "height": 800}


@pytest.fixture(scope="module")
def walk_folder(walk, tmp_path_factory) -> Path:
    """The 24 s validation walk of conftest as a results folder."""
    folder = tmp_path_factory.mktemp("view") / "walk"
    report.save(walk, folder)
    return folder


def chromium_path() -> str:
    """Debian's chromium; absent, a failure in CI (the set-up installs it) and a skip elsewhere."""
    path = shutil.which("chromium")
    if path is None:
        message = "chromium not found (make setup installs Debian's chromium package)"
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip(message)
    return path


@pytest.fixture(scope="module")
def browser():
    with playwright_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=chromium_path(), args=HEADLESS_CHROMIUM_ARGS)
        yield b
        b.close()


def canvas_png(page, path: Path) -> np.ndarray:
    """A screenshot of the WebGL canvas (RGB floats)."""
    page.locator("canvas").first.screenshot(path=path)
    return imread(path)[..., :3]


def link_mask(image: np.ndarray) -> np.ndarray:
    """The pixels in the warm tan/orange of the pantograph links (LINK_COLOURS of
    hexadyn.view.scene, whatever their shading); the grey ground and the GUI have none."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return (r - b > 0.25) & (g > 0.3) & (r > 0.5)


def link_share(image: np.ndarray) -> float:
    return float(np.mean(link_mask(image)))


def link_centre(image: np.ndarray) -> np.ndarray:
    """Where the links are drawn: the centroid (row, column) of their pixels."""
    return np.argwhere(link_mask(image)).mean(axis=0)


def assert_scene_drawn(image: np.ndarray, what: str) -> None:
    """Not blank: many colours, and the robot's links in view."""
    levels = (image * 15).round().astype(np.int32)
    distinct = np.unique(levels[..., 0] * 256 + levels[..., 1] * 16 + levels[..., 2]).size
    assert image.std() > 0.05 and distinct > 30, f"{what}: the canvas looks blank ({distinct} colours)"
    assert link_share(image) > 1e-3, f"{what}: no robot link in view"


def wait_for(predicate, timeout: float = 20.0, what: str = "condition") -> None:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}")


# -- the kinematics and the data the viewer reads ----------------------------------------------


def test_view_kinematics_reproduce_the_recorded_feet(walk_folder):
    """The engine's kinematics of the recorded q put every foot where the simulation recorded it,
    over the whole run (so what the viewer draws is the simulated robot)."""
    run = Run(walk_folder)
    kin = _core.Kinematics(run.metadata["robot"])
    assert len(kin.body_names) == 49 and kin.body_names[0] == "body"
    points = kin.leg_points(run.q)
    assert points.shape == (run.t.size, 6, 8, 3)
    assert np.abs(points[:, :, -1] - run.recorded_feet).max() < 1e-6
    positions, rotations = kin.poses(run.q[::50])
    assert positions.shape == (len(run.q[::50]), 49, 3)
    eye = np.einsum("nbij,nbkj->nbik", rotations, rotations)
    assert np.allclose(eye, np.eye(3), atol=1e-12)
    assert np.allclose(positions[:, 0], run.q[::50, :3])
    with pytest.raises(ValueError, match="24 coordinates"):
        kin.poses(np.zeros((2, 23)))


def test_view_draws_the_robot_of_the_description(walk_folder):
    """The geometry comes from the robot description: another R_rot moves the hips."""
    run = Run(walk_folder)
    text = run.metadata["robot"]
    assert "r_rot_m = 0.175" in text
    for r_rot in (0.175, 0.21):
        kin = _core.Kinematics(text.replace("r_rot_m = 0.175", f"r_rot_m = {r_rot}"))
        assert kin.geometry["r_rot"] == r_rot
        hips = kin.leg_points(run.q[:1])[0, :, 0]
        assert np.allclose(np.linalg.norm(hips[:, :2] - run.q[0, :2], axis=1), r_rot, atol=1e-3)


def test_view_command_serves_on_loopback_and_prints_the_url(walk_folder):
    """`hexadyn view FOLDER --no-open` serves the page on 127.0.0.1 and prints its URL."""
    import re
    import subprocess
    import sys
    import urllib.request

    hexadyn_script = Path(sys.executable).with_name("hexadyn")  # the console script of the install
    process = subprocess.Popen([str(hexadyn_script), "view", str(walk_folder), "--no-open"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        line = process.stdout.readline()
        url = re.search(r"http://127\.0\.0\.1:\d+/", line)
        assert url, line
        with urllib.request.urlopen(url.group(0), timeout=20) as response:
            assert response.status == 200 and b"<html" in response.read(2000).lower()
    finally:
        process.terminate()
        process.wait(timeout=20)


def test_view_rejects_what_is_not_a_results_folder(walk_folder, tmp_path):
    with pytest.raises(ViewError, match="no such results folder"):
        Run(tmp_path / "missing")
    with pytest.raises(ViewError, match="not a hexadyn results folder"):
        Run(tmp_path)
    broken = tmp_path / "broken"
    shutil.copytree(walk_folder, broken)
    table = pq.read_table(broken / "timeseries.parquet")
    pq.write_table(table.drop(["foot_x[2]"]), broken / "timeseries.parquet")
    with pytest.raises(ViewError, match=r"timeseries\.parquet: missing column foot_x\[2\]"):
        Run(broken)
    result = CliRunner().invoke(view, [str(broken), "--no-open"])
    assert result.exit_code == 1 and "missing column foot_x[2]" in result.output


def test_view_footholds_and_decimation(walk_folder):
    run = Run(walk_folder)
    holds = run.footholds()
    # Two 12 s tripod steps: every foot touches down at least once after its first swing.
    assert len(holds) >= 6 and np.all(np.abs(holds[:, 2]) < 0.01)
    from hexadyn.view.export import frame_indices

    frames = frame_indices(run, fps=25.0, max_frames=100)
    assert frames[0] == 0 and frames[-1] == run.t.size - 1 and len(frames) <= 100


# -- the page in a real browser ------------------------------------------------------------------


@pytest.fixture(scope="module")
def live(walk_folder):
    from hexadyn.view.server import start

    running = start(walk_folder)
    yield running
    running.stop()


def state(page) -> dict:
    el = page.locator("#hexadyn-state")
    return {"t": float(el.get_attribute("data-t")), "feet": np.array(json.loads(el.get_attribute("data-feet")))}


def seek_foot_error(page, folder: Path, t: float) -> float:
    """Seeks the page to `t` with its own time input, as a user types a time, and returns the
    largest distance (m) between the feet it shows and those recorded in `folder` at `t`."""
    box = page.locator("input.mantine-NumberInput-input").first  # the number box of the time slider
    box.fill(str(t))
    box.press("Enter")
    wait_for(lambda: abs(state(page)["t"] - t) < 1e-9, what=f"the page to show t = {t}")
    table = pq.read_table(folder / "timeseries.parquet", columns=["t", *FOOT_COLUMNS])
    row = int(np.argmin(np.abs(table.column("t").to_numpy() - t)))
    recorded = np.array([table.column(c)[row].as_py() for c in FOOT_COLUMNS]).reshape(6, 3)
    return float(np.abs(state(page)["feet"] - recorded).max())


def test_view_page_draws_seeks_to_the_recorded_feet_and_plays(live, walk_folder, browser, tmp_path):
    page = browser.new_page(viewport=VIEWPORT)
    page.add_init_script(FRAME_COUNTER_JS)
    page.goto(live.url)
    page.wait_for_selector("#hexadyn-state", state="attached", timeout=30000)
    assert state(page)["t"] == 0.0
    time.sleep(2.0)
    assert_scene_drawn(canvas_png(page, tmp_path / "live.png"), "live page")

    t = 13.37
    error = seek_foot_error(page, walk_folder, t)
    print(f"\nfoot position error at t = {t} s: {error:.2e} m")
    assert error < 1e-6

    # Play advances the time and draws new frames (their rate is reported, not asserted: it
    # depends on the machine; benches/view.py measures it).
    frames, start = page.evaluate("window.__frames"), time.monotonic()
    page.get_by_role("button", name="Play").click()
    wait_for(lambda: state(page)["t"] > t + 1.0, what="playback to advance")
    drawn = page.evaluate("window.__frames") - frames
    print(f"frames drawn while playing: {drawn / (time.monotonic() - start):.1f} per second")
    assert drawn > 0
    page.get_by_role("button", name="Pause").click()
    wait_for(lambda: not live.viewer.playing, what="pause")
    paused = live.viewer.frame.t
    wait_for(lambda: state(page)["t"] == paused, what="the page to show the paused frame")
    time.sleep(0.5)
    assert state(page)["t"] == paused

    # Follow the body: the camera keeps its offset and looks at the body as time moves.
    page.get_by_label("Follow body").check()
    wait_for(lambda: live.viewer.follow.value, what="the follow box to reach the viewer")
    box = page.locator("input.mantine-NumberInput-input").first
    box.fill("5")
    box.press("Enter")
    wait_for(lambda: abs(state(page)["t"] - 5.0) < 1e-9, what="the page to show t = 5")
    client = next(iter(live.server.get_clients().values()))
    wait_for(lambda: np.allclose(client.camera.look_at, live.viewer.frame.body_position, atol=1e-4), what="the camera to look at the body")

    # Another signal group and leg: the charts are rebuilt with their series.
    live.viewer.group.value = "Currents"
    live.viewer.leg.value = "3"
    page.get_by_text("Currents: i_q_h[3] (A)").wait_for(timeout=20000)
    page.close()


def test_view_html_export_plays_from_a_static_server_and_a_file_url(walk_folder, live, browser, tmp_path):
    export = tmp_path / "site" / "walk.html"
    result = CliRunner().invoke(view, [str(walk_folder), "--html", str(export)])
    assert result.exit_code == 0, result.output
    assert export.is_file() and "__VISER_EMBED_DATA__" in export.read_text()

    # The live page at the start, seen from the same initial camera, for comparison.
    live.viewer.seek(0.0)
    page = browser.new_page(viewport=VIEWPORT)
    page.goto(live.url)
    page.wait_for_selector("#hexadyn-state", state="attached", timeout=30000)
    time.sleep(2.0)
    live_links = link_centre(canvas_png(page, tmp_path / "live.png"))
    page.close()

    handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=str(export.parent))
    handler.log_message = lambda *a: None  # type: ignore[attr-defined]
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    try:
        for url in (f"http://127.0.0.1:{httpd.server_address[1]}/walk.html", export.as_uri()):
            page = browser.new_page(viewport=VIEWPORT)
            page.goto(url)
            page.wait_for_selector("canvas", timeout=30000)
            time_box = page.locator("input[type=text]").first
            wait_for(lambda: time_box.count() and float(time_box.input_value() or 0) > 0.5, what=f"{url} to play")
            image = canvas_png(page, tmp_path / "export.png")
            assert_scene_drawn(image, url)
            # The same scene: the robot where the live page draws it (it walks 1.5 cm/s).
            assert np.abs(link_centre(image) - live_links).max() < 60, (link_centre(image), live_links)
            page.close()
    finally:
        httpd.shutdown()
