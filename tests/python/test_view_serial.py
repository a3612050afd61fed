"""hexadyn view on a serial robot (the PhantomX Mark II): the kinematics the viewer draws against
an independent forward kinematics of the description's URDF chain, the scene the page receives
(decoded from the HTML export: one node per joint with a link per leg, the feet, no pantograph
parts, every part where the kinematics puts it, moving from frame to frame), the sizes at the
robot's scale, and the real page in headless Chromium (Debian's chromium driven by Playwright;
absent, these tests fail: they do not skip)."""

from __future__ import annotations

import base64
import re
import shutil
import time
import tomllib
from pathlib import Path

import msgspec
import numpy as np
import pytest
import zstandard
from click.testing import CliRunner
from matplotlib.image import imread
from playwright import sync_api as playwright_api

import hexadyn
from hexadyn import _core, report
from hexadyn.view import scene as view_scene
from hexadyn.view.command import view
from hexadyn.view.data import Run
from hexadyn.view.export import frame_indices
from hexadyn.view.measure import HEADLESS_CHROMIUM_ARGS
from test_view import seek_foot_error, wait_for

VIEWPORT = {"width": 1280, "height": 800}
#: The PhantomX's joints (robots/phantomx/phantomx.toml, joints.names).
JOINTS = ["coxa", "femur", "tibia"]
DURATION_S = 3.0


@pytest.fixture(scope="module")
def px_folder(tmp_path_factory) -> Path:
    """A short PhantomX tripod walk as a results folder."""
    results = hexadyn.simulate("phantomx_tripod", progress=False, overrides={"scenario.duration_s": DURATION_S})
    folder = tmp_path_factory.mktemp("view_serial") / "phantomx"
    report.save(results, folder)
    return folder


@pytest.fixture(scope="module")
def browser():
    path = shutil.which("chromium")
    if path is None:
        pytest.fail("chromium not found (make setup installs Debian's chromium package)")
    with playwright_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=path, args=HEADLESS_CHROMIUM_ARGS)
        yield b
        b.close()


# -- an independent forward kinematics of the description (URDF semantics) ----------------------


def _rot(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation matrix about a unit axis (Rodrigues)."""
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


def _rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """URDF rpy: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    return _rot(np.array([0.0, 0.0, 1.0]), yaw) @ _rot(np.array([0.0, 1.0, 0.0]), pitch) @ _rot(np.array([1.0, 0.0, 0.0]), roll)


def chain_points(robot_text: str, q: np.ndarray) -> np.ndarray:
    """World positions (6, 4, 3) of each leg's joint origins and foot centre for one row q of
    (X, Y, Z, yaw, pitch, roll, then three joints per leg), the body frame being the base
    link's: T = T(X, Y, Z) Rz(yaw) Ry(pitch) Rx(roll), then per joint its origin and its motion."""
    robot = tomllib.loads(robot_text)
    body_r = _rpy(q[5], q[4], q[3])
    out = np.zeros((6, 4, 3))
    for leg, spec in enumerate(robot["legs"]):
        r, p = body_r, q[:3].copy()
        for k, joint in enumerate(spec["joints"]):
            p = p + r @ np.asarray(joint["origin_xyz_m"])
            r = r @ _rpy(*joint["origin_rpy_rad"])
            axis = np.asarray(joint["axis"]) / np.linalg.norm(joint["axis"])
            value = q[6 + 3 * leg + k]
            if joint["kind"] == "revolute":
                r = r @ _rot(axis, value)
            else:
                p = p + r @ (axis * value)
            out[leg, k] = p
        out[leg, 3] = p + r @ np.asarray(spec["foot_m"])
    return out


def test_serial_kinematics_are_the_description_chain_and_the_recorded_feet(px_folder):
    """The viewer's kinematics of a serial robot: its joints' origins and feet, named after the
    robot's joints, are where the description's chain puts them (1e-9 m, every frame), and the
    feet where the simulation recorded them."""
    run = Run(px_folder)
    kin = run.kinematics
    assert kin.leg_mechanism == "serial"
    assert kin.leg_point_names == [*JOINTS, "foot"]
    assert kin.body_names[0] == "base" and "leg0.femur_lf" in kin.body_names and not any("chassis" in n or ".link" in n for n in kin.body_names)
    g = kin.geometry
    assert g["foot_radius"] == 0.01 and g["mass_kg"] == pytest.approx(1.8428, abs=1e-9)
    assert g["leg_joint_names"][0] == ["coxa_lf", "femur_lf", "tibia_lf"] and g["leg_joint_names"][5] == ["coxa_rr", "femur_rr", "tibia_rr"]
    points = kin.leg_points(run.q)
    assert points.shape == (run.t.size, 6, 4, 3)
    oracle = np.array([chain_points(run.metadata["robot"], row) for row in run.q])
    error = np.abs(points - oracle).max()
    print(f"\njoint origins and feet against the description's chain: {error:.1e} m")
    assert error < 1e-9
    # The recorded feet: at the start exactly the kinematics of the recorded q; later they come
    # from the integrator's last evaluation of the step, within a few 1e-8 m of the accepted q.
    assert np.abs(points[0, :, -1] - run.recorded_feet[0]).max() < 1e-12
    assert np.abs(points[:, :, -1] - run.recorded_feet).max() < 1e-6
    # The legs move: the feet of a tripod walk swing by centimetres.
    assert np.ptp(points[:, :, -1, 2], axis=0).max() > 0.01
    # The main body's pose: the base body sits at the base link's centre of mass.
    positions, rotations = kin.poses(run.q[::20])
    com = np.array([0.0, 0.0, 0.00117249])
    assert np.allclose(positions[:, 0], run.q[::20, :3] + rotations[:, 0] @ com, atol=1e-12)


def test_robot_scale_is_one_for_amru5_and_the_phantomx_is_drawn_smaller(px_folder):
    amru5 = _core.Kinematics(_core.shipped_robot_text("amru5")).geometry
    assert view_scene.robot_scale(amru5) == 1.0 and view_scene.force_scale(amru5) == view_scene.FORCE_SCALE_M_PER_N
    px = Run(px_folder).geometry
    scale = view_scene.robot_scale(px)
    assert 0.3 < scale < 0.45, scale
    # The robot's weight on three feet draws arrows as long relative to it as AMRU5's.
    weight = lambda g: g["mass_kg"] * _core.STANDARD_GRAVITY / 3  # noqa: E731
    assert view_scene.force_scale(px) * weight(px) == pytest.approx(scale * view_scene.force_scale(amru5) * weight(amru5), rel=1e-12)


# -- the scene the page receives: the HTML export, decoded ---------------------------------------


def embedded_messages(html: str) -> list[tuple[float, dict]]:
    """The scene messages of a viser HTML export, numpy arrays in place of binary placeholders
    (viser's serializer: base64 of [size][zstd([msgpack length][msgpack][aligned buffers])])."""
    data = base64.b64decode(re.search(r'window\.__VISER_EMBED_DATA__="([^"]+)"', html).group(1))
    inner = zstandard.ZstdDecompressor().decompress(data[8:], max_output_size=int.from_bytes(data[:8], "little"))
    length = int.from_bytes(inner[:8], "little")
    payload = msgspec.msgpack.decode(inner[8 : 8 + length])
    buffers, offset = [], 8 + length
    for size in payload["binaryBufferLengths"]:
        offset += (8 - offset % 8) % 8
        buffers.append(inner[offset : offset + size])
        offset += size

    def resolve(value):
        if isinstance(value, dict):
            if "__binary_index" in value:
                return np.frombuffer(buffers[value["__binary_index"]], dtype=np.dtype(value["dtype"]))
            return {k: resolve(v) for k, v in value.items()}
        if isinstance(value, list):
            return [resolve(v) for v in value]
        return value

    return [(t, resolve(m)) for t, m in payload["messages"]]


def replay(messages: list[tuple[float, dict]], until: float) -> dict[str, dict]:
    """The props of every scene node after the messages up to time `until`."""
    nodes: dict[str, dict] = {}
    for t, m in messages:
        if t > until + 1e-9:
            break
        if "props" in m and m.get("name"):
            nodes[m["name"]] = {"type": m["type"], **m["props"]}
        elif m["type"] == "SceneNodeUpdateMessage":
            nodes[m["name"]].update(m["updates"])
    return nodes


@pytest.fixture(scope="module")
def px_export(px_folder, tmp_path_factory) -> Path:
    file = tmp_path_factory.mktemp("view_serial_export") / "phantomx.html"
    result = CliRunner().invoke(view, [str(px_folder), "--html", str(file)])
    assert result.exit_code == 0, result.output
    return file


def test_serial_export_holds_the_robots_links_where_the_kinematics_puts_them(px_folder, px_export):
    run = Run(px_folder)
    messages = embedded_messages(px_export.read_text())
    indices = frame_indices(run)
    assert len(indices) > 10
    first = replay(messages, 0.0)
    # One batched node per joint of the robot with a link per leg, the feet; no pantograph part.
    batched = {name for name, node in first.items() if node["type"] == "BatchedMeshesMessage"}
    assert batched == {f"/legs/{j}" for j in JOINTS} | {"/legs/feet"}, batched
    assert not any(n.startswith(("/legs/chassis", "/legs/links")) for n in first)
    for name in batched:
        assert first[name]["batched_positions"].reshape(-1, 3).shape == (6, 3), name
    # The feet at the description's radius; the links as wide as AMRU5's at the robot's scale.
    foot_vertices = first["/legs/feet"]["vertices"].reshape(-1, 3)
    assert np.allclose(np.linalg.norm(foot_vertices, axis=1), 0.01, atol=1e-6)
    scale = view_scene.robot_scale(run.geometry)
    widths = first["/legs/femur"]["batched_scales"].reshape(6, 3)[:, 1:]
    assert np.allclose(widths, scale * view_scene.LINK_WIDTH, rtol=1e-6)

    points = run.kinematics.leg_points(run.q[indices])
    previous = None
    for i, index in enumerate(indices):
        nodes = replay(messages, float(run.t[index] - run.t[0]))
        feet = nodes["/legs/feet"]["batched_positions"].reshape(6, 3)
        # float32 in the page: a few 1e-8 m at these distances.
        assert np.abs(feet - run.recorded_feet[index]).max() < 1e-6, (index, feet, run.recorded_feet[index])
        state = []
        for k, joint in enumerate(JOINTS):
            node = nodes[f"/legs/{joint}"]
            start = node["batched_positions"].reshape(6, 3)
            wxyz = node["batched_wxyzs"].reshape(6, 4).astype(np.float64)
            length = node["batched_scales"].reshape(6, 3)[:, 0]
            x_axis = np.array([view_scene.tf.SO3(w).as_matrix()[:, 0] for w in wxyz])
            # Each link from its joint's origin to the next joint's origin (the last: the foot).
            assert np.abs(start - points[i, :, k]).max() < 1e-6, (joint, index)
            assert np.abs(start + x_axis * length[:, None] - points[i, :, k + 1]).max() < 1e-6, (joint, index)
            state.append(start)
        state.append(feet)
        if previous is not None:
            moved = np.abs(np.array(state) - previous).max()
            assert moved > 0.0, f"nothing moved at frame {index}"
        previous = np.array(state)
    # Over the run the legs swing: the femur's far end and the feet move by centimetres.
    start_pose = replay(messages, 0.0)["/legs/tibia"]["batched_positions"].reshape(6, 3)
    end_pose = replay(messages, float(run.t[indices[-1]] - run.t[0]))["/legs/tibia"]["batched_positions"].reshape(6, 3)
    assert np.abs(end_pose - start_pose).max() > 0.01


# -- the page in a real browser ------------------------------------------------------------------


def canvas_png(page, path: Path) -> np.ndarray:
    page.locator("canvas").first.screenshot(path=path)
    return imread(path)[..., :3]


def link_mask(image: np.ndarray) -> np.ndarray:
    """The pixels in the warm tan/orange of the links (SERIAL_LINK_COLOURS, whatever their
    shading); the ground, the body plate, the paths, the feet and the GUI have none."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return (r - b > 0.25) & (g > 0.3) & (r > 0.5)


def test_serial_page_draws_the_legs_and_seeks_to_the_recorded_feet(px_folder, browser, tmp_path):
    from hexadyn.view.server import start

    running = start(px_folder)
    try:
        page = browser.new_page(viewport=VIEWPORT)
        page.goto(running.url)
        page.wait_for_selector("#hexadyn-state", state="attached", timeout=30000)
        time.sleep(2.0)
        before = canvas_png(page, tmp_path / "start.png")
        share = float(np.mean(link_mask(before)))
        print(f"\nlink pixels at the start: {share:.4f}")
        assert share > 1e-3, "no leg link in view"

        assert seek_foot_error(page, px_folder, 1.73) < 1e-6
        time.sleep(1.0)
        after = canvas_png(page, tmp_path / "later.png")
        assert float(np.mean(link_mask(after))) > 1e-3
        # The legs moved on the screen.
        changed = np.mean(np.any(np.abs(after - before) > 0.1, axis=-1))
        assert changed > 1e-3, changed
        page.close()
    finally:
        running.stop()


def test_serial_export_plays_in_the_browser(px_export, browser, tmp_path):
    page = browser.new_page(viewport=VIEWPORT)
    page.goto(px_export.as_uri())
    page.wait_for_selector("canvas", timeout=30000)
    time_box = page.locator("input[type=text]").first
    wait_for(lambda: time_box.count() and float(time_box.input_value() or 0) > 0.5, what="the export to play")
    image = canvas_png(page, tmp_path / "export.png")
    assert image.std() > 0.05
    assert float(np.mean(link_mask(image))) > 1e-3, "no leg link in view"
    page.close()
