"""``hexadyn view FOLDER --html FILE``: the animation as one self-contained HTML file.

The scene of :class:`~hexadyn.view.scene.RobotScene` is recorded frame by frame with viser's
scene serializer and embedded in viser's prebuilt client page: the file plays with viser's own
playback bar (play, pause, speed, time slider) from any static web server or a ``file://`` URL,
without hexadyn or Python. Long runs are decimated to at most `max_frames` frames, evenly
spread in time, so the file stays small (a few MB for a 60 s walk at 25 frames per second).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hexadyn import atomic
from hexadyn.view.data import Run

#: Frames per simulated second recorded, and the most frames an export holds.
EXPORT_FPS = 25.0
MAX_FRAMES = 3000


def frame_indices(run: Run, fps: float = EXPORT_FPS, max_frames: int = MAX_FRAMES) -> np.ndarray:
    """The recorded instants an export shows: every 1/fps s of simulated time, fewer if that
    would exceed `max_frames`; the first and last instants are included."""
    count = int(min(max_frames, max(2, np.floor(run.duration * fps) + 1)))
    times = np.linspace(run.t[0], run.t[-1], count)
    return np.unique([run.index_at(t) for t in times])


def export_html(folder: str | Path, file: str | Path, fps: float = EXPORT_FPS, max_frames: int = MAX_FRAMES) -> Path:
    """Writes the animation of the results `folder` to the HTML `file`; returns its path."""
    from hexadyn.view.scene import RobotScene
    from hexadyn.view.server import stop_quietly, viser_server

    run = Run(folder)
    file = Path(file)
    if file.is_dir():
        raise ValueError(f"{file}: is a folder; give the HTML file to write")
    indices = frame_indices(run, fps, max_frames)
    server = viser_server()
    try:
        scene = RobotScene(server, run)
        recorder = server.get_scene_serializer()
        for previous, index in zip(indices[:-1], indices[1:]):
            recorder.insert_sleep(float(run.t[index] - run.t[previous]))
            scene.show(run.frame(int(index)))
        page = recorder.as_html()
    finally:
        stop_quietly(server)
    file.parent.mkdir(parents=True, exist_ok=True)
    atomic.write_file(file, lambda tmp: tmp.write_text(page, encoding="utf-8"))
    return file
