"""The ``hexadyn view`` command (registered in :mod:`hexadyn.cli`); viser is imported only when
the command runs."""

from __future__ import annotations

from pathlib import Path

import click


@click.command()
@click.argument("folder", type=click.Path(path_type=Path))
@click.option("--html", "html_file", type=click.Path(dir_okay=False, path_type=Path), default=None, help="Write a self-contained HTML export (plays from a file:// URL or any static web server) instead of serving.")
@click.option("--port", type=click.IntRange(0, 65535), default=0, show_default=True, help="Port on 127.0.0.1: taken is an error; 0 for any free one (the URL printed says which).")
@click.option("--no-open", is_flag=True, help="Do not open a browser (headless use): only print the URL.")
def view(folder: Path, html_file: Path | None, port: int, no_open: bool) -> None:
    """Watch the run in results FOLDER: a 3D animation in the browser with the time plots.

    Serves the viewer on http://127.0.0.1:PORT/ until Ctrl-C and opens it in the browser:
    play, pause, speed, time slider, follow-the-body camera, the joint positions, tracking
    errors, currents and power of a chosen leg and the gait diagram with a cursor at the
    current time. With --html, writes the animation to one HTML file instead.
    """
    try:
        import viser  # noqa: F401
    except ImportError as exc:
        raise click.ClickException("hexadyn view needs viser: pip install 'hexadyn[view]'") from exc
    from hexadyn.view.data import ViewError

    try:
        if html_file is not None:
            from hexadyn.view.export import export_html

            path = export_html(folder, html_file)
            click.echo(f"Wrote {path} ({path.stat().st_size / 1e6:.1f} MB): open it in a browser, or serve it from any static web server")
            return
        from hexadyn.view.server import serve

        serve(folder, port=port, open_browser=not no_open, echo=click.echo)
    except ViewError as exc:
        raise click.ClickException(str(exc)) from exc
