"""A local viewer server (loopback only), on the port asked or any free one (port 0):
:func:`start` for scripts and tests, :func:`serve` for ``hexadyn view`` (prints the URL, opens
the browser, runs until Ctrl-C). A port asked for that is taken is an error: viser would
silently serve on the next free one."""

from __future__ import annotations

import contextlib
import io
import logging
import webbrowser
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Callable

from hexadyn.view.data import Run, ViewError

if TYPE_CHECKING:  # viser is imported when a viewer starts
    import viser

    from hexadyn.view.app import Viewer

HOST = "127.0.0.1"


def viser_server(port: int = 0) -> "viser.ViserServer":
    """A viser server on 127.0.0.1, on `port` or, for 0, any free port (the OS's choice, read back
    with ``get_port()``), without viser's banner on stdout. ViewError if `port` is taken."""
    import viser

    logging.getLogger("websockets").setLevel(logging.WARNING)
    with contextlib.redirect_stdout(io.StringIO()):
        server = viser.ViserServer(host=HOST, port=port, verbose=False)
    if port and server.get_port() != port:
        stop_quietly(server)
        raise ViewError(f"--port {port}: taken on {HOST}; allowed: a free port, or 0 for any free one")
    return server


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


def start(folder: str | Path, port: int = 0) -> RunningViewer:
    """Starts a viewer of the results `folder` on 127.0.0.1, on `port` (0: any free port)."""
    from hexadyn.view.app import Viewer

    run = Run(folder)
    server = viser_server(port)
    try:
        viewer = Viewer(server, run)
    except BaseException:
        stop_quietly(server)
        raise
    return RunningViewer(url=f"http://{HOST}:{server.get_port()}/", viewer=viewer, server=server)


def serve(folder: str | Path, port: int = 0, open_browser: bool = True, echo: Callable[[str], None] = print) -> None:
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
