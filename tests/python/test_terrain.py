"""The terrain of a scenario from Python: `_core.terrain_triangles` against the shipped PLY
files read independently here (their header and binary payload), the analytic grounds as
squares, the shipped terrains as package data."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

import hexadyn
from hexadyn import _core, report
from hexadyn.view.data import Run

from conftest import shortened

TERRAINS = hexadyn.SCENARIOS_DIR / "terrains"


def read_binary_ply(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """A binary little-endian PLY of float x, y, z and uchar/int triangle lists, read by hand."""
    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    assert "format binary_little_endian 1.0" in header
    count = {line.split()[1]: int(line.split()[2]) for line in header if line.startswith("element")}
    n, m = count["vertex"], count["face"]
    vertices = np.frombuffer(data, dtype="<f4", count=3 * n, offset=end).reshape(n, 3).astype(float)
    faces = []
    offset = end + 12 * n
    for _ in range(m):
        assert data[offset] == 3
        faces.append(struct.unpack_from("<3i", data, offset + 1))
        offset += 13
    assert offset == len(data)
    return vertices, np.array(faces)


def test_shipped_terrains_are_package_data():
    names = sorted(p.name for p in TERRAINS.glob("*.ply"))
    assert names == ["rough_ground.ply", "rough_ground_phantomx.ply", "slope_20deg.ply", "step_8cm.ply"]


def test_mesh_terrain_triangles_are_those_of_the_file():
    vertices, faces = _core.terrain_triangles(str(hexadyn.SCENARIOS_DIR / "tripod_rough_ground.toml"))
    file_vertices, file_faces = read_binary_ply(TERRAINS / "rough_ground.ply")
    assert vertices.dtype == np.float64 and faces.dtype == np.uint32
    assert vertices.shape == file_vertices.shape and faces.shape == file_faces.shape == (38400, 3)
    # The same triangles (the engine renumbers the vertices when it merges duplicates), with the
    # file's upward orientation.
    np.testing.assert_allclose(vertices[faces], file_vertices[file_faces], rtol=0, atol=1e-7)
    # Section 7.7.5's rough ground: flat near the start, 1.5 cm RMS away from it.
    r = np.hypot(vertices[:, 0], vertices[:, 1])
    assert np.all(vertices[r < 0.6, 2] == 0)
    assert abs(np.sqrt(np.mean(vertices[r > 1.2, 2] ** 2)) - 0.015) < 0.003
    # The PhantomX's (phantomx_free_gait_rough): the same ground at a third of its size, flat
    # within 0.3 m of the start, 0.5 cm RMS beyond 0.6 m.
    vertices, faces = _core.terrain_triangles(str(hexadyn.SCENARIOS_DIR / "phantomx_free_gait_rough.toml"))
    assert faces.shape == (38400, 3)
    r = np.hypot(vertices[:, 0], vertices[:, 1])
    assert np.all(vertices[r < 0.3, 2] == 0)
    assert abs(np.sqrt(np.mean(vertices[r > 0.6, 2] ** 2)) - 0.005) < 0.001


def test_analytic_grounds_are_squares(tmp_path: Path):
    vertices, faces = _core.terrain_triangles(str(hexadyn.SCENARIOS_DIR / "validation_tripod_1_5cm.toml"), half_width_m=2.0, centre_x_m=1.0)
    assert faces.shape == (2, 3)
    np.testing.assert_array_equal(vertices[:, 2], 0.0)
    assert vertices[:, 0].min() == -1.0 and vertices[:, 0].max() == 3.0
    # The 3 cm step: its vertical face at x = 0.6 m joins the two levels.
    vertices, faces = _core.terrain_triangles(str(hexadyn.SCENARIOS_DIR / "tripod_low_step.toml"))
    assert faces.shape == (6, 3)
    assert set(np.round(vertices[:, 2], 12)) == {0.0, 0.03}
    assert np.all(np.isclose(vertices[vertices[:, 0] < 0.6 - 1e-9, 2], 0.0))
    with pytest.raises(ValueError, match="half_width_m"):
        _core.terrain_triangles(str(hexadyn.SCENARIOS_DIR / "tripod_low_step.toml"), half_width_m=-1.0)
    with pytest.raises(ValueError, match=r"terrain\.file"):
        _core.terrain_triangles(str(hexadyn.SCENARIOS_DIR / "tripod_low_step.toml"), overrides={"terrain": {"kind": "mesh", "file": "terrains/none.ply"}})


def test_the_viewer_draws_a_ground_that_is_not_flat(tmp_path: Path):
    step = shortened("tripod_low_step", tmp_path, duration=0.1)
    report.save(hexadyn.simulate(step, progress=False), tmp_path / "step")
    vertices, faces = Run(tmp_path / "step").terrain(np.array([0.5, 0.0]), 2.0)
    assert vertices.dtype == np.float32 and faces.shape == (6, 3)
    assert np.isclose(vertices[:, 2].max(), 0.03)
    flat = shortened("validation_tripod_1_5cm", tmp_path, duration=0.1)
    report.save(hexadyn.simulate(flat, progress=False), tmp_path / "flat")
    assert Run(tmp_path / "flat").terrain(np.array([0.0, 0.0]), 2.0) is None
