"""A local viewer server (loopback only) on a free port: :func:`start` for scripts and tests,
:func:`serve` for ``hexadyn view`` (prints the URL, opens the browser, runs until Ctrl-C)."""

from __future__ import annotations

import contextlib
import io
import logging
import socket
import webbrowser
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Callable

from hexadyn.view.data import Run

if TYPE_CHECKING:  # viser is imported when a viewer starts
    import viser

    from hexadyn.view.app import Viewer

HOST = "127.0.0.1"


def free_port(host: str = HOST) -> int:
    """A TCP port nobody listens on right now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


def viser_server(port: int | None = None) -> "viser.ViserServer":
    """A viser server on 127.0.0.1 (a free port unless `port`), without viser's banner on stdout."""
    import viser

    logging.getLogger("websockets").setLevel(logging.WARNING)
    with contextlib.redirect_stdout(io.StringIO()):
        return viser.ViserServer(host=HOST, port=port or free_port(), verbose=False)


def stop_quietly(server: "viser.ViserServer") -> None:
    """Stops a viser server without its message on stdout."""
    with contextlib.redirect_stdout(io.StringIO()):
        server.stop()


@dataclass
class RunningViewer:
    """A started viewer: its URL, the :class:`~hexadyn.view.app.Viewer` and :meth:`stop`."""

    url: str
    viewer: "Viewer"
    server: "viser.ViserServer"

    def stop(self) -> None:
        self.viewer.close()
        stop_quietly(self.server)


def start(folder: str | Path, port: int | None = None) -> RunningViewer:
    """Starts a viewer of the results `folder` on 127.0.0.1 (a free port unless `port`)."""
    from hexadyn.view.app import Viewer

    run = Run(folder)
    server = viser_server(port)
    try:
        viewer = Viewer(server, run)
    except BaseException:
        stop_quietly(server)
        raise
    return RunningViewer(url=f"http://{HOST}:{server.get_port()}/", viewer=viewer, server=server)


def serve(folder: str | Path, port: int | None = None, open_browser: bool = True, echo: Callable[[str], None] = print) -> None:
    """Shows `folder` until interrupted: prints the URL and opens it unless `open_browser` is false."""
    running = start(folder, port)
    echo(f"Viewing {folder} at {running.url} (Ctrl-C to stop)")
    if open_browser:
        webbrowser.open(running.url)
    try:
        running.server.sleep_forever()
    except KeyboardInterrupt:
        pass
    finally:
        running.stop()
