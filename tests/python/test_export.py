"""`hexadyn export`: the time series of a results folder as CSV and as MCAP (Foxglove Studio's
JSON channels), read back and compared with the series value by value."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner
from conftest import shortened
from mcap.reader import make_reader
from scipy.spatial.transform import Rotation

import hexadyn
from hexadyn import export
from hexadyn.cli import cli
from hexadyn.vocabulary import LEGS

#: A short walk of each leg mechanism: every channel has moving values.
WALKS = {"amru5": "validation_tripod_1_5cm", "phantomx": "phantomx_tripod"}


@pytest.fixture(scope="module", params=sorted(WALKS))
def run(request, tmp_path_factory) -> hexadyn.Results:
    folder = tmp_path_factory.mktemp(f"export_{request.param}")
    hexadyn.simulate(shortened(WALKS[request.param], folder, 1.0), folder / "run", progress=False)
    return hexadyn.Results.load(folder / "run")  # read from the folder, as the command does


def invoke(*args: str):
    return CliRunner().invoke(cli, list(args), prog_name="hexadyn")


def read_mcap(path: Path) -> tuple[dict[str, list[tuple[int, dict]]], dict[str, dict], dict[str, dict[str, str]]]:
    """topic -> [(log time, message)], topic -> its schema, metadata records."""
    messages: dict[str, list[tuple[int, dict]]] = {}
    schemas: dict[str, dict] = {}
    with open(path, "rb") as f:
        reader = make_reader(f)
        for schema, channel, message in reader.iter_messages(log_time_order=True):
            assert schema.encoding == "jsonschema" and channel.message_encoding == "json"
            assert message.publish_time == message.log_time
            schemas[channel.topic] = json.loads(schema.data) | {"name": schema.name}
            messages.setdefault(channel.topic, []).append((message.log_time, json.loads(message.data)))
        metadata = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
    return messages, schemas, metadata


def test_mcap_channels_hold_the_time_series(run, tmp_path):
    out = tmp_path / "run.mcap"
    result = invoke("export", str(run.path), "--format", "mcap", "--out", str(out))
    assert result.exit_code == 0, result.output
    messages, schemas, metadata = read_mcap(out)
    ts = run.timeseries
    t = ts.index.to_numpy()
    assert t[0] == 0.0 and t[-1] == pytest.approx(run.summary["duration_s"])
    assert sorted(messages) == sorted(c.topic for c in export.CHANNELS)
    assert schemas["/body_pose"]["name"] == "foxglove.PoseInFrame"
    for topic, logged in messages.items():
        # One message per instant, logged at the instant's time: the run's whole duration.
        assert len(logged) == len(ts), topic
        times = np.array([time for time, _ in logged])
        assert np.array_equal(times, np.round(t * 1e9).astype(np.int64)), topic
        stamps = np.array([m["timestamp"]["sec"] * 10**9 + m["timestamp"]["nsec"] for _, m in logged])
        assert np.array_equal(stamps, times), topic

    def values(topic: str, field: str, key: str) -> np.ndarray:
        """(instants, entries) of one field of the entries of a channel's array `field`."""
        return np.array([[entry[key] for entry in m[field]] for _, m in messages[topic]], dtype=float)

    joints = run.joints
    actuators = list(joints.actuators)
    first = messages["/joint_states"][0][1]["joints"]
    assert [j["name"] for j in first] == actuators and {j["joint"] for j in first} == set(joints.names)
    assert [j["leg"] for j in first] == [leg for leg in LEGS for _ in joints.names]
    np.testing.assert_array_equal(values("/joint_states", "joints", "position"), ts[actuators].to_numpy())
    np.testing.assert_array_equal(values("/joint_states", "joints", "velocity"), ts[[f"{j}_dot[{leg}]" for leg in LEGS for j in joints.names]].to_numpy())
    np.testing.assert_array_equal(values("/joint_states", "joints", "effort"), ts[[f"tau_m_{a}" for a in actuators]].to_numpy())
    np.testing.assert_array_equal(values("/motor_currents", "motors", "current"), ts[[f"i_{a}" for a in actuators]].to_numpy())
    np.testing.assert_array_equal(values("/motor_currents", "motors", "voltage"), ts[[f"u_{a}" for a in actuators]].to_numpy())
    for key, column in {"x": "Fx", "y": "Fy", "z": "Fz", "normal": "Fn"}.items():
        np.testing.assert_array_equal(values("/foot_forces", "feet", key), ts[[f"{column}[{leg}]" for leg in LEGS]].to_numpy())
    assert np.abs(ts[[f"Fz[{leg}]" for leg in LEGS]].to_numpy()).max() > 1.0  # the values compared are forces, not zeros

    poses = [m["pose"] for _, m in messages["/body_pose"]]
    assert {m["frame_id"] for _, m in messages["/body_pose"]} == {"world"}
    position = np.array([[p["position"][k] for k in "xyz"] for p in poses])
    np.testing.assert_array_equal(position, ts[["X", "Y", "Z"]].to_numpy())
    quaternion = np.array([[p["orientation"][k] for k in "xyzw"] for p in poses])
    expected = Rotation.from_euler("ZYX", ts[["yaw", "pitch", "roll"]].to_numpy()).as_matrix()  # R_z R_y R_x, Eq. 3.52
    np.testing.assert_allclose(Rotation.from_quat(quaternion).as_matrix(), expected, atol=1e-12)
    assert np.ptp(ts["yaw"]) + np.ptp(ts["pitch"]) + np.ptp(ts["roll"]) > 0  # a moving body

    record = metadata["hexadyn"]
    assert record["hexadyn_version"] == hexadyn.__version__ and record["scenario"] == run.metadata["scenario_name"]
    assert json.loads(record["units"])["Fz[0]"] == "N"


def test_csv_holds_every_column_exactly(run, tmp_path):
    result = invoke("export", str(run.path), "--format", "csv")
    assert result.exit_code == 0, result.output
    path = run.path / "timeseries.csv"
    assert f"Export: {path}" in result.stdout
    table = pd.read_csv(path, index_col="t")
    pd.testing.assert_frame_equal(table, run.timeseries, check_dtype=False, check_exact=True)
    # An existing file is refused without --overwrite, in one line, and replaced with it.
    again = invoke("export", str(run.path), "--format", "csv")
    assert again.exit_code == 1 and again.stderr.count("\n") == 1 and "exists" in again.stderr, again.output
    assert invoke("export", str(run.path), "--format", "csv", "--overwrite").exit_code == 0


def test_a_long_series_is_exported_block_by_block(run, tmp_path, monkeypatch):
    """With blocks of 7 instants the files are the same (the series is read from the file)."""
    whole = export.export(run, tmp_path / "whole.mcap", "mcap")
    monkeypatch.setattr(export, "CHUNK_ROWS", 7)
    blocks = export.export(hexadyn.Results.load(run.path), tmp_path / "blocks.mcap", "mcap")
    assert read_mcap(whole)[0] == read_mcap(blocks)[0]
    csv = export.export(hexadyn.Results.load(run.path), tmp_path / "blocks.csv", "csv")
    pd.testing.assert_frame_equal(pd.read_csv(csv, index_col="t"), run.timeseries, check_dtype=False, check_exact=True)


def test_channels_without_their_columns_are_left_out(run, tmp_path):
    """Results without a body pose (a run on the robot) export the other channels."""
    short = hexadyn.Results(run.timeseries.drop(columns=["X", "Y", "Z"]), {k: v for k, v in run.units.items() if k not in "XYZ"}, run.summary, run.metadata)
    assert [c.topic for c in export.channels(short)] == ["/joint_states", "/foot_forces", "/motor_currents"]
    messages, _, _ = read_mcap(export.export(short, tmp_path / "short.mcap", "mcap"))
    assert sorted(messages) == ["/foot_forces", "/joint_states", "/motor_currents"]


def test_bad_exports_are_one_line(tmp_path):
    missing = invoke("export", str(tmp_path / "nothing"), "--format", "mcap")
    assert missing.exit_code == 1 and missing.stderr == f"Error: {tmp_path / 'nothing'}: no such results folder\n"
    with pytest.raises(ValueError, match="export format = 'xls'; allowed: csv, mcap"):
        export.export(None, tmp_path / "x.xls", "xls")  # type: ignore[arg-type]
