"""Input files and results folders (issue 39): every input read only from a regular file of
bounded size (a named pipe refused at once, never waited on), PLY terrains refused from their
header when they declare more than they hold or than a terrain may have, metadata of the wrong
JSON types refused in one line, stale partials of killed saves removed by the next command.

Each refusal of a named pipe runs the command in a subprocess under a timeout: opening a pipe
without a writer used to wait for ever, and a hang is what the timeout catches."""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import hexadyn
from hexadyn import inputs
from hexadyn.results import METADATA_FILE

from conftest import shortened

HEXADYN = [sys.executable, "-m", "hexadyn.cli"]
#: Seconds a refusal may take at most before the command is taken as hung (imports included,
#: on a loaded machine: a refusal itself reads nothing).
HANG_S = 120


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """`hexadyn ARGS` in a subprocess; fails the test if it does not end within HANG_S."""
    try:
        return subprocess.run([*HEXADYN, *args], cwd=cwd, capture_output=True, text=True, timeout=HANG_S)
    except subprocess.TimeoutExpired:
        pytest.fail(f"hexadyn {' '.join(args)} hung (no end within {HANG_S} s)")


def refused(result: subprocess.CompletedProcess, *words: str) -> str:
    """The one line of a refused command (exit status 1), holding each of `words`."""
    assert result.returncode == 1, (result.returncode, result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.stderr
    assert "Traceback" not in result.stderr
    for w in words:
        assert w in lines[0], lines[0]
    return lines[0]


@pytest.fixture
def fifo(tmp_path: Path) -> Path:
    """A named pipe nobody writes to."""
    path = tmp_path / "pipe"
    os.mkfifo(path)
    return path


def pipe_refusal(fifo: Path, limit: str | None = "64 MB") -> tuple[str, str]:
    """The words of the refusal of the named pipe `fifo`: its path, what it is and what is allowed."""
    return str(fifo), "a named pipe (FIFO), not a regular file; allowed: a regular file" + (f" of at most {limit}" if limit else "")


def scenario_with(tmp_path: Path, shipped: str, old: str, new: str, duration: float = 0.1) -> Path:
    """A short copy of a shipped scenario, in `tmp_path`, with `old` replaced by `new`."""
    path = shortened(shipped, tmp_path, duration)
    text = path.read_text()
    assert old in text, old
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.fixture(scope="module")
def saved(tmp_path_factory) -> Path:
    """A results folder of a short walk (the scenario file kept next to it)."""
    folder = tmp_path_factory.mktemp("saved")
    hexadyn.simulate(shortened("validation_tripod_1_5cm", folder, 0.5), folder / "run", progress=False)
    return folder / "run"


def copy_of(folder: Path, into: Path) -> Path:
    target = into / folder.name
    shutil.copytree(folder, target)
    return target


# -- named pipes, one per kind of input ----------------------------------------------------------


def test_a_named_pipe_as_the_scenario_is_refused(fifo: Path):
    refused(run("simulate", str(fifo), "--no-progress"), *pipe_refusal(fifo))


@pytest.mark.parametrize(
    "shipped, old, new, field",
    [
        ("stand_six_legs", 'robot = "amru5"', 'robot = "{fifo}"', "scenario.robot"),
        ("free_gait_rough_spline", 'file = "terrains/rough_ground.ply"', 'file = "{fifo}"', "terrain.file"),
        ("stand_six_legs", "[control]", '[terrain]\nkind = "heightfield"\nfile = "{fifo}"\nspacing_m = 0.1\n\n[control]', "terrain.file"),
        ("validation_tripod_1_5cm", 'kind = "constant"\nvx_m_s = 0.015\nvy_m_s = 0.0\nomega_z_rad_s = 0.0', 'kind = "csv"\nfile = "{fifo}"', "gait.heading.file"),
    ],
    ids=["robot", "ply-terrain", "heightfield-csv", "heading-csv"],
)
def test_a_named_pipe_named_by_a_scenario_is_refused(tmp_path: Path, fifo: Path, shipped: str, old: str, new: str, field: str):
    scenario = scenario_with(tmp_path, shipped, old, new.format(fifo=fifo))
    limit = "1 GB" if shipped == "free_gait_rough_spline" else "64 MB"
    refused(run("simulate", str(scenario), "--no-progress"), f"field `{field}`", *pipe_refusal(fifo, limit))


def test_a_named_pipe_as_a_link_configuration_or_robot_file_is_refused(tmp_path: Path, fifo: Path):
    refused(run("robot", "run", "stand_six_legs", "--link", str(fifo), "--no-progress"), *pipe_refusal(fifo))
    refused(run("urdf", str(fifo)), *pipe_refusal(fifo))
    refused(run("export-urdf", str(fifo), "--out", str(tmp_path / "out.urdf")), *pipe_refusal(fifo))
    urdf = tmp_path / "robot.urdf"
    run("export-urdf", "phantomx", "--out", str(urdf))
    refused(run("import-urdf", str(urdf), "--out", str(tmp_path / "r.toml"), "--drives", str(fifo)), *pipe_refusal(fifo))


@pytest.mark.parametrize("name", ["metadata.json", "summary.json", "timeseries.parquet"])
def test_a_named_pipe_in_a_results_folder_is_refused(saved: Path, tmp_path: Path, name: str):
    folder = copy_of(saved, tmp_path)
    (folder / name).unlink()
    os.mkfifo(folder / name)
    words = pipe_refusal(folder / name, None if name == "timeseries.parquet" else "64 MB")
    refused(run("plot", str(folder)), *words)
    if name != "summary.json":  # the viewer reads no summary
        pytest.importorskip("viser")
        refused(run("view", str(folder), "--html", str(tmp_path / "v.html")), *words)


def test_the_viewer_draws_flat_ground_for_a_terrain_file_that_is_a_named_pipe(saved: Path, tmp_path: Path, fifo: Path):
    """The viewer reads the run's terrain from its scenario file (``scenario_path``): a terrain
    that became a named pipe is not drawn, and the export ends."""
    pytest.importorskip("viser")
    folder = copy_of(saved, tmp_path)
    scenario = scenario_with(tmp_path, "free_gait_rough_spline", 'file = "terrains/rough_ground.ply"', f'file = "{fifo}"')
    metadata = json.loads((folder / METADATA_FILE).read_text())
    metadata["scenario_path"] = str(scenario)
    (folder / METADATA_FILE).write_text(json.dumps(metadata))
    result = run("view", str(folder), "--html", str(tmp_path / "v.html"))
    assert result.returncode == 0 and (tmp_path / "v.html").is_file(), result.stderr


def test_inputs_say_what_a_file_is_and_what_is_allowed(tmp_path: Path):
    with pytest.raises(ValueError, match=rf"^{tmp_path}: a directory, not a file; allowed: a regular file of at most 64 MB$"):
        inputs.check_input(tmp_path)
    with pytest.raises(ValueError, match=r"^/dev/null: a device, not a regular file; allowed: a regular file of at most 64 MB$"):
        inputs.open_input("/dev/null")
    with socket.socket(socket.AF_UNIX) as s:
        s.bind(str(tmp_path / "sock"))
        with pytest.raises(ValueError, match=r"sock: a socket, not a regular file; allowed: a regular file$"):
            inputs.open_input(tmp_path / "sock", limit=None)
    big = tmp_path / "big.json"
    with open(big, "wb") as f:
        f.truncate(inputs.MAX_INPUT_BYTES + 1)
    with pytest.raises(ValueError, match=r"big.json: 67108865 bytes, too large; allowed: a regular file of at most 64 MB$"):
        inputs.read_text(big)
    (tmp_path / "latin1.txt").write_bytes(b"caf\xe9")
    with pytest.raises(ValueError, match=r"latin1.txt: not UTF-8 text \(invalid byte at offset 3\)"):
        inputs.read_text(tmp_path / "latin1.txt")
    with pytest.raises(FileNotFoundError):
        inputs.open_input(tmp_path / "none")


# -- PLY terrains declaring more than they hold or than a terrain may have -----------------------

#: A script that loads a scenario and prints the bytes the process read (``rchar`` of
#: /proc/self/io: every read system call, imports included).
LOAD_AND_COUNT = """
import sys
from hexadyn import _core
try:
    _core.load_scenario(sys.argv[1])
    print("loaded")
except ValueError as e:
    print(e)
print(next(int(l.split()[1]) for l in open("/proc/self/io") if l.startswith("rchar:")))
"""


@pytest.mark.parametrize("vertices, words", [(10**9, "`element vertex 1000000000` of at least 12 bytes each"), (80_000_000, "`element vertex 80000000`: too many; allowed: at most 4000000 (hexadyn's bound on a terrain mesh, MAX_MESH_VERTICES)")])
def test_a_1_gb_ply_declaring_too_much_is_refused_from_its_header(tmp_path: Path, vertices: int, words: str):
    """A 1 GB PLY (sparse: cheap to make) whose header declares more vertices than it holds, or
    than the bound of a terrain: one line from the header, without reading the file (the
    process reads far less than the file)."""
    ply = tmp_path / "big.ply"
    header = f"ply\nformat binary_little_endian 1.0\nelement vertex {vertices}\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    with open(ply, "wb") as f:
        f.write(header.encode())
        f.truncate(2**30)
    scenario = scenario_with(tmp_path, "free_gait_rough_spline", 'file = "terrains/rough_ground.ply"', f'file = "{ply}"')
    out = subprocess.run([sys.executable, "-c", LOAD_AND_COUNT, str(scenario)], capture_output=True, text=True, timeout=HANG_S)
    message, read = out.stdout.strip().splitlines()
    assert f"field `terrain.file` = \"{ply}\": {ply}: header: {words}" in message, message
    assert int(read) < 2**30 // 8, f"read {read} bytes of a 1 GB file"
    refused(run("simulate", str(scenario), "--no-progress"), f"{ply}: header: {words}")


# -- the viewer: robot-run folders, metadata types, decimation, ports ---------------------------


@pytest.fixture(scope="module")
def robot_runs(tmp_path_factory) -> dict[str, Path]:
    """`hexadyn robot run` folders of a walk and of a stand (no gait), emulated in lock-step."""
    folder = tmp_path_factory.mktemp("robot")
    runs = {}
    for name in ("phantomx_tripod", "phantomx_stand"):
        scenario = shortened(name, folder, 2.0)
        result = run("robot", "run", str(scenario), "--link", "loopback", "--emulated", "--out", str(folder / name), "--no-plots", "--no-progress")
        assert result.returncode == 0, result.stderr
        runs[name] = folder / name
    return runs


def test_the_viewer_shows_a_robot_run_with_what_it_recorded(robot_runs: dict[str, Path], tmp_path: Path):
    """A run on the robot has no measured body pose, feet or forces: the body follows the
    controller's reference pose (or stands still without a gait), the feet come from the
    kinematics of the encoder positions, no force is drawn; it exports."""
    pytest.importorskip("viser")
    from hexadyn.view.data import Run

    walk = Run(robot_runs["phantomx_tripod"])
    series = hexadyn.Results.load(robot_runs["phantomx_tripod"]).timeseries
    assert walk.body_source == "reference" and not walk.has_forces and walk.recorded_feet is None and walk.has_phases
    np.testing.assert_array_equal(walk.q[:, :6], series[["X_ref", "Y_ref", "Z_ref", "yaw_ref", "pitch_ref", "roll_ref"]].to_numpy())
    np.testing.assert_array_equal(walk.q[:, 6:9], series[["coxa[0]", "femur[0]", "tibia[0]"]].to_numpy())
    assert np.all(walk.forces == 0.0) and walk.frame(walk.t.size - 1).feet.shape == (6, 3)
    holds = walk.footholds()
    assert len(holds) >= 3 and np.abs(holds[:, 2]).max() < 0.01, holds  # the feet touch down on the ground
    stand = Run(robot_runs["phantomx_stand"])
    assert stand.body_source == "still" and not stand.has_phases and len(stand.footholds()) == 0
    assert np.all(stand.q[:, :2] == 0.0) and abs(stand.frame(0).feet[:, 2].min()) < 1e-12  # the lowest foot on the ground
    result = run("view", str(robot_runs["phantomx_tripod"]), "--html", str(tmp_path / "robot.html"))
    assert result.returncode == 0 and (tmp_path / "robot.html").stat().st_size > 10_000, result.stderr


def test_the_viewer_holds_missed_periods_at_the_last_position():
    from hexadyn.view.data import _held

    values = np.array([[np.nan, 1.0], [1.0, 2.0], [np.nan, 5.0], [np.nan, np.nan], [4.0, 5.0]])
    np.testing.assert_array_equal(_held(values), [[1.0, 2.0], [1.0, 2.0], [1.0, 2.0], [1.0, 2.0], [4.0, 5.0]])


@pytest.mark.parametrize("key, value, words", [("robot", 5, "`robot` = 5: a JSON integer; allowed: a JSON string"), ("scenario_path", 5, "`scenario_path` = 5: a JSON integer; allowed: a JSON string or a JSON null"), ("descriptions", [], "`descriptions` = []: a JSON array; allowed: a JSON object")])
def test_the_viewer_refuses_metadata_of_the_wrong_types_in_one_line(saved: Path, tmp_path: Path, key: str, value: object, words: str):
    pytest.importorskip("viser")
    folder = copy_of(saved, tmp_path)
    metadata = json.loads((folder / METADATA_FILE).read_text())
    metadata[key] = value
    (folder / METADATA_FILE).write_text(json.dumps(metadata))
    refused(run("view", str(folder), "--html", str(tmp_path / "v.html")), f"{folder / METADATA_FILE}: {words}")


def test_the_viewer_decimates_while_reading(saved: Path, tmp_path: Path, monkeypatch):
    """A run is read a row group at a time, keeping at most max_frames instants evenly spread,
    the first and the last included: the same values as the whole run at those instants."""
    pytest.importorskip("viser")
    from hexadyn import results
    from hexadyn.view.data import Run, decimation

    monkeypatch.setattr(results, "ROW_GROUP_BYTES", 8 * 300 * 7)  # 7 rows a group: many groups
    folder = tmp_path / "small-groups"
    loaded = hexadyn.Results.load(saved)
    loaded.timeseries  # read before the folder moves
    folder.mkdir()
    loaded.write(folder)
    whole = Run(folder)
    assert whole.t.size == whole.instants == loaded.shape[0] > 40
    part = Run(folder, max_frames=13)
    rows = decimation(whole.instants, 13)
    assert part.t.size == 13 and rows[0] == 0 and rows[-1] == whole.instants - 1
    np.testing.assert_array_equal(part.t, whole.t[rows])
    np.testing.assert_array_equal(part.q, whole.q[rows])
    np.testing.assert_array_equal(part.read(["Fz[3]"])["Fz[3]"], whole.read(["Fz[3]"])["Fz[3]"][rows])


def test_a_taken_port_is_an_error_and_port_0_takes_a_free_one(saved: Path):
    """`--port P` with P taken: one line, exit 1 (viser used to serve on P + 1 silently);
    `--port 0`: a free port, announced in the URL."""
    pytest.importorskip("viser")
    import re

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        refused(run("view", str(saved), "--port", str(port), "--no-open"), f"--port {port}: taken on 127.0.0.1; allowed: a free port, or 0 for any free one")
    process = subprocess.Popen([*HEXADYN, "view", str(saved), "--port", "0", "--no-open"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        line = process.stdout.readline()
        url = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
        assert url and int(url.group(1)) > 0, line
    finally:
        process.terminate()
        process.wait(timeout=HANG_S)


# -- stale partials of killed saves --------------------------------------------------------------


def test_any_command_removes_the_partials_of_killed_runs_from_the_results_root(tmp_path: Path):
    """SIGKILL while `hexadyn simulate` streams its results into `results/` leaves a
    `.NAME.PID.*.partial`; the next command of any kind (`hexadyn info`) removes it, and keeps
    the partial of a live writer."""
    scenario = shortened("stand_six_legs", tmp_path, 1e4)
    root = tmp_path / "results"
    process = subprocess.Popen([*HEXADYN, "simulate", str(scenario), "--no-progress", "--no-plots"], cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + HANG_S
        while not (root.is_dir() and any(p.name.endswith(".partial") for p in root.iterdir())):
            assert process.poll() is None and time.monotonic() < deadline, "no partial folder appeared"
            time.sleep(0.05)
    finally:
        process.send_signal(signal.SIGKILL)
        process.wait()
    stale = [p.name for p in root.iterdir()]
    assert len(stale) == 1 and stale[0].startswith(f".stand_six_legs.{process.pid}.") and stale[0].endswith(".partial"), stale
    live = root / f".other.{os.getpid()}.abcdefgh.partial"
    live.mkdir()
    result = run("info", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert [p.name for p in root.iterdir()] == [live.name]


def test_the_viewer_names_a_foot_phase_that_is_no_phase_code(saved: Path, tmp_path: Path):
    """Found by test_fuzz_cli.py: `hexadyn view --html` of a time series whose foot phase was
    made NaN wrote its page with numpy's cast warning on stderr. It is refused in one line
    naming the file, the column and the time."""
    pytest.importorskip("viser")
    import pyarrow as pa
    import pyarrow.parquet as pq

    folder = copy_of(saved, tmp_path)
    table = pq.read_table(folder / "timeseries.parquet")
    table = table.set_column(table.column_names.index("phase[1]"), "phase[1]", pa.array([np.nan] * table.num_rows))
    pq.write_table(table, folder / "timeseries.parquet")
    result = run("view", str(folder), "--html", str(tmp_path / "v.html"))
    refused(result, f"{folder / 'timeseries.parquet'}: column `phase[1]` = nan at t = 0 s: not a foot phase; allowed: the codes")
    assert not (tmp_path / "v.html").exists()
