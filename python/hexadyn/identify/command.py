"""``hexadyn identify``: the friction identification of Chapter 5 from logs (docs/identification.md)."""

from __future__ import annotations

from pathlib import Path

import click

from hexadyn.options import figure_format_option, no_progress_option, out_option, overwrite_option

__all__ = ["identify_command"]


@click.command("identify")
@click.argument("logs", nargs=-1, required=True, type=click.Path(exists=True, path_type=Path))
@click.option("--joint", default=None, help="Identify only this joint of the logs' robot (q_r, q_v or q_h on AMRU5; coxa, femur or tibia on the PhantomX; default: every joint the logs exercise).")
@out_option("Folder to write (tables, figures, joint_friction.toml, friction_stats.toml).", required=True)
@overwrite_option()
@click.option("--robot", type=click.Path(exists=True, dir_okay=False, path_type=Path), default=None, help="Robot description file of CSV logs, e.g. robots/phantomx/phantomx.toml (default: the embedded AMRU5); a results folder carries its own.")
@click.option("--transient", "transient_s", type=click.FloatRange(min=0.0), default=1.5, show_default=True, help="Seconds dropped after each reversal (velocity transient).")
@figure_format_option()
@no_progress_option()
def identify_command(logs: tuple[Path, ...], joint: str | None, out: Path, overwrite: bool, robot: Path | None, transient_s: float, format_: tuple[str, ...], no_progress: bool) -> None:
    """Identify joint friction from LOGS: results folders of the identification scenarios
    (identification_q_r, _q_v, _q_h, identification_breakaway_plus/_minus,
    identification_loaded_q_h, identification_loaded_q_v; phantomx_identification_coxa, _femur, _tibia) or CSV logs of a
    real robot. Each log is one campaign; several
    campaigns give the mean and standard deviation of Tables 5.3-5.5."""
    from tqdm.auto import tqdm

    from hexadyn import _core, atomic, inputs
    from hexadyn.identify import SectionOptions, identify, load_log
    from hexadyn.identify.output import save

    if out.exists() and not overwrite:
        atomic.refuse_existing(out, "identification folder")
    robot_text = None
    if robot is not None:
        robot_text = inputs.read_text(robot)
        _core.robot_properties(robot_text, str(robot))  # an invalid description is named now, by its file
    # The bar is drawn on a terminal only and erased when done: an error stays one line.
    with tqdm(total=2 * len(logs), desc="identify", unit="step", leave=False, disable=True if no_progress else None) as bar:

        def loaded():
            for path in logs:
                bar.set_postfix_str(path.name)
                log = load_log(path, robot_text)
                bar.update()
                yield log

        ident = identify(loaded(), joint, SectionOptions(transient_s=transient_s), progress=lambda _: bar.update())
    folder = save(ident, out, overwrite=overwrite, formats=format_)
    click.echo(f"{len(ident.fits)} dry/viscous fits, {len(ident.breakaways)} breakaways, {len(ident.load_fits)} load fits, {len(ident.efficiency_fits)} efficiency fits -> {folder}")
