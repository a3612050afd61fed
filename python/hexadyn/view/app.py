"""The interactive viewer of one run on a viser server: the 3D scene, the playback controls
(play, pause, speed, time slider, follow-the-body camera), the time plots with a cursor tied to
the slider, the gait diagram and a state read-out.

The browser holds only the current frame: each seek or playback tick computes that frame's
kinematics (:meth:`hexadyn.view.data.Run.frame`) and sends the moved parts.

The read-out is an HTML element ``#hexadyn-state`` whose ``data-t``, ``data-index`` and
``data-feet`` attributes (JSON, metres, full precision) carry the time and the foot positions of
the frame on show, for tests and scripts driving the page.
"""

from __future__ import annotations

import html
import json
import threading
import time

import numpy as np
import viser

from hexadyn.view.charts import SignalCharts, gait_chart, signal_groups
from hexadyn.view.data import LEGS, Frame, Run
from hexadyn.view.scene import RobotScene
from hexadyn.vocabulary import PHASE_CODES

#: Playback speeds offered (simulated seconds per wall-clock second).
SPEEDS = ("0.25", "0.5", "1", "2", "5", "10", "50")
#: While playing: scene updates per second, and updates per second of the panel (time slider and
#: read-out) and of the chart cursors, fewer as they cost the browser more than the scene.
TICK_HZ = 30.0
PANEL_HZ = 5.0
CURSOR_HZ = 2.0


class Viewer:
    """A run shown on `server`; :meth:`seek` and :meth:`play` drive it from Python too."""

    def __init__(self, server: viser.ViserServer, run: Run):
        self.server = server
        self.run = run
        self._lock = threading.RLock()
        self._playing = False
        self._stop = threading.Event()
        self._last_cursor = 0.0
        self._last_panel = 0.0
        self.scene = RobotScene(server, run)
        self._build_panel()
        self.frame: Frame = run.frame(0)
        self._show(self.frame)
        self._thread = threading.Thread(target=self._playback, name="hexadyn-view-playback", daemon=True)
        self._thread.start()

    def _build_panel(self) -> None:
        gui, run = self.server.gui, self.run
        gui.configure_theme(control_width="large", dark_mode=False, show_logo=False, show_share_button=False)  # loopback only
        frames = f"{run.t.size} frames" + (f" of {run.instants} instants" if run.t.size < run.instants else "")
        gui.add_markdown(f"**{html.escape(run.name)}**  \n{run.duration:g} s, {frames}" + BODY_NOTES[run.body_source] + ("" if run.has_forces else "  \nno ground forces recorded"))
        with gui.add_folder("Playback"):
            step = float(np.median(np.diff(run.t))) if run.t.size > 1 else 1.0
            self.time_slider = gui.add_slider("Time (s)", min=float(run.t[0]), max=float(max(run.t[-1], run.t[0] + step)), step=step, initial_value=float(run.t[0]))
            self.play_button = gui.add_button("Play", icon=viser.Icon.PLAYER_PLAY)
            self.speed = gui.add_dropdown("Speed (x)", SPEEDS, initial_value="1")
            self.follow = gui.add_checkbox("Follow body", initial_value=False)

        @self.time_slider.on_update
        def _(event: viser.GuiEvent) -> None:
            if event.client is not None:  # a user's move, not ours
                self.seek(self.time_slider.value)

        @self.play_button.on_click
        def _(_: viser.GuiEvent) -> None:
            self.pause() if self._playing else self.play()

        groups = list(signal_groups(run))
        with gui.add_folder("Time plots"):
            self.group = gui.add_dropdown("Signals", groups, initial_value=groups[0])
            self.leg = gui.add_dropdown("Leg", [str(leg) for leg in range(LEGS)], initial_value="0")
            self._charts_folder = gui.add_folder("Charts")
        self.charts = self._make_charts()

        @self.group.on_update
        @self.leg.on_update
        def _(_: viser.GuiEvent) -> None:
            with self._lock:
                self.charts.remove()
                self.charts = self._make_charts()
                self.charts.move_cursor(self.frame.t)

        self.gait = None
        if run.has_phases:
            with gui.add_folder("Gait diagram"):
                self.gait = gait_chart(gui, run)
        with gui.add_folder("State", expand_by_default=False):
            self.readout = gui.add_html("")

    def _make_charts(self) -> SignalCharts:
        with self._charts_folder:
            return SignalCharts(self.server.gui, self.run, self.group.value, int(self.leg.value))

    # -- driving the viewer ------------------------------------------------------------------

    def seek(self, t: float) -> Frame:
        """Shows the recorded instant nearest to time `t`."""
        with self._lock:
            self._show(self.run.frame(self.run.index_at(t)))
            self._move_cursors()
            return self.frame

    def play(self) -> None:
        with self._lock:
            if self.frame.index >= self.run.t.size - 1:
                self._show(self.run.frame(0))
            self._playing = True
            self.play_button.label, self.play_button.icon = "Pause", viser.Icon.PLAYER_PAUSE

    def pause(self) -> None:
        with self._lock:
            self._playing = False
            self.play_button.label, self.play_button.icon = "Play", viser.Icon.PLAYER_PLAY
            self._show_panel()
            self._move_cursors()

    @property
    def playing(self) -> bool:
        return self._playing

    def close(self) -> None:
        """Stops the playback thread (the server is stopped by its owner)."""
        self._stop.set()
        self._thread.join(timeout=2.0)

    # -- internals -----------------------------------------------------------------------------

    def _show(self, frame: Frame, panel: bool = True) -> None:
        self.frame = frame
        with self.server.atomic():
            self.scene.show(frame)
        if self.follow.value:
            self._follow(frame.body_position)
        if panel:
            self._show_panel()

    def _show_panel(self) -> None:
        self.time_slider.value = self.frame.t
        self.readout.content = _readout(self.frame, self.run.has_forces)
        self._last_panel = time.monotonic()

    def _follow(self, body: np.ndarray) -> None:
        """Translates each client's camera so that it looks at the body from where it was
        (viser moves the look-at point with the position)."""
        for client in self.server.get_clients().values():
            offset = np.asarray(client.camera.position) - np.asarray(client.camera.look_at)
            client.camera.position = body + offset

    def _move_cursors(self) -> None:
        self.charts.move_cursor(self.frame.t)
        if self.gait is not None:
            self.gait.move_cursor(self.frame.t)
        self._last_cursor = time.monotonic()

    def _playback(self) -> None:
        """Advances the time while playing, TICK_HZ times a second, at the chosen speed."""
        last = time.monotonic()
        sim_time = None
        while not self._stop.wait(1.0 / TICK_HZ):
            now = time.monotonic()
            with self._lock:
                if not self._playing:
                    sim_time = None
                    last = now
                    continue
                if sim_time is None:
                    sim_time = self.frame.t
                sim_time += float(self.speed.value) * (now - last)
                last = now
                index = self.run.index_at(sim_time)
                if index != self.frame.index:
                    self._show(self.run.frame(index), panel=now - self._last_panel >= 1.0 / PANEL_HZ)
                if now - self._last_cursor >= 1.0 / CURSOR_HZ:
                    self._move_cursors()
                if index >= self.run.t.size - 1:
                    self.pause()


#: What the panel says of a body pose that was not recorded (:attr:`Run.body_source`).
BODY_NOTES = {
    "recorded": "",
    "reference": "  \nbody: the controller's reference pose (no measured pose)",
    "still": "  \nbody: not recorded, shown still at the origin",
}

#: Phase code -> name for the read-out (the free gait's failed leg included).
PHASE_NAMES = {code: name for name, code in PHASE_CODES.items()}


def _readout(frame: Frame, forces: bool) -> str:
    """The state read-out: a table for people, data attributes for scripts; F_z blank when the
    run recorded no `forces`."""
    feet = frame.feet
    rows = "".join(
        f"<tr><td>{leg}</td><td>{feet[leg, 0]:.4f}</td><td>{feet[leg, 1]:.4f}</td><td>{feet[leg, 2]:.4f}</td><td>{f'{frame.forces[leg, 2]:.1f}' if forces else ''}</td><td>{PHASE_NAMES.get(int(frame.phases[leg]), '')}</td></tr>"
        for leg in range(LEGS)
    )
    attributes = f'data-t="{frame.t!r}" data-index="{frame.index}" data-feet="{html.escape(json.dumps(feet.tolist()))}"'
    return (
        f'<div id="hexadyn-state" {attributes} style="font-size:0.8em">'
        f"<div>t = {frame.t:.2f} s, body ({frame.body_position[0]:.3f}, {frame.body_position[1]:.3f}, {frame.body_position[2]:.3f}) m</div>"
        "<table><tr><th>foot</th><th>x (m)</th><th>y (m)</th><th>z (m)</th><th>F<sub>z</sub> (N)</th><th>phase</th></tr>"
        f"{rows}</table></div>"
    )
