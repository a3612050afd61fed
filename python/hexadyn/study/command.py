"""``hexadyn study STUDY.toml``: a design study over a scenario's fields (docs/studies.md)."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import click

__all__ = ["study_command"]

#: Failed runs a failure line names before "...".
_SHOWN = 4


def _parse_settings(ctx: click.Context, param: click.Parameter, values: tuple[str, ...]) -> dict[str, Any]:
    """``--set KEY=VALUE`` -> {KEY: VALUE}, VALUE read as a TOML value (``12.0``, ``true``,
    ``"lugre"``), else as a string."""
    settings = {}
    for item in values:
        key, sep, text = item.partition("=")
        if not sep or not key.strip():
            raise click.BadParameter(f"{item!r}; allowed: KEY=VALUE, a dotted scenario field and its value, e.g. scenario.duration_s=12", param_hint="--set")
        try:
            value = tomllib.loads(f"v = {text}")["v"]
        except tomllib.TOMLDecodeError:
            value = text
        settings[key.strip()] = value
    return settings


def _parse_formats(ctx: click.Context, param: click.Parameter, value: str) -> tuple[str, ...]:
    from hexadyn.plots import FORMATS

    formats = tuple(dict.fromkeys(f.strip().lower() for f in value.split(",") if f.strip()))
    if not formats or any(f not in FORMATS for f in formats):
        raise click.BadParameter(f"{value!r}; allowed: comma-separated formats among {', '.join(FORMATS)}")
    return formats


@click.command("study")
@click.argument("study_file", metavar="STUDY", type=click.Path(path_type=Path))
@click.option("-o", "--out", type=click.Path(path_type=Path), default=None, help="Study folder (created, or resumed if it holds the same study) [default: results/<study name>].")
@click.option("--workers", type=int, default=None, help="Parallel runs (default: every core).")
@click.option("--ray", "ray_address", default=None, metavar="ADDRESS", help='Run on a Ray cluster ("local": a Ray instance started here).')
@click.option("--set", "settings", multiple=True, metavar="KEY=VALUE", callback=_parse_settings, help="Set a scenario field for every run, as the study's [fixed] table does (repeatable).")
@click.option("--format", "formats", default="png", show_default=True, callback=_parse_formats, help="Figure formats, comma-separated (png, pdf, svg).")
@click.option("--no-plots", is_flag=True, help="Write the tables only, no figures.")
@click.option("--no-progress", is_flag=True, help="No progress bar.")
def study_command(study_file: Path, out: Path | None, workers: int | None, ray_address: str | None, settings: dict[str, Any], formats: tuple[str, ...], no_plots: bool, no_progress: bool) -> None:
    """Run the design study STUDY (a study file, docs/studies.md): its base scenario under
    every run's parameter values, the outputs of each run and, for Sobol' and Morris designs,
    the sensitivity indices. Rerunning the same command resumes an interrupted study. Writes
    study.json, runs.sqlite, runs.csv/.parquet, indices.csv/.parquet and the figures to --out.
    A study with failed runs (stored, not retried) ends with one line naming them and exit
    status 1."""
    from hexadyn.runner import RESULTS_ROOT, safe_folder_name
    from hexadyn.study import Study

    study = Study.create(study_file, fixed=settings)
    out = out if out is not None else RESULTS_ROOT / safe_folder_name(study.spec.name)
    try:
        results = study.run(out, workers=workers, ray=ray_address, progress=not no_progress, plots=not no_plots, formats=formats)
    except KeyboardInterrupt:
        click.echo(f"Interrupted: the finished runs are kept in {out}; run the same command again to resume.", err=True)
        raise SystemExit(130) from None
    spec = study.spec
    ok = results.runs[results.runs["status"] == "ok"]
    click.echo(f"Study {spec.name}: {spec.design.method} design, {len(results.runs)} runs of {len(spec.parameters)} parameters")
    for output in spec.outputs:
        values = ok[output]
        click.echo(f"  {output}: {values.min():.4g} .. {values.max():.4g} (mean {values.mean():.4g}) over {values.count()} runs")
    if results.indices is not None:
        shown = results.indices.set_index(["output", "parameter"])
        click.echo("Sobol' indices (S1 first order, ST total, +- conf):" if spec.design.method == "sobol" else "Morris (mu*, sigma):")
        for line in shown.to_string(float_format=lambda x: f"{x:.3f}").splitlines():
            click.echo(f"  {line}")
    click.echo(f"Results: {out} (runs.csv, runs.parquet{', indices.csv' if results.indices is not None else ''}{'' if no_plots else ', figures'}, runs.sqlite)")
    failed = results.failures
    if len(failed):
        indices = ", ".join(map(str, failed["run_index"].tolist()[:_SHOWN])) + (", ..." if len(failed) > _SHOWN else "")
        raise click.ClickException(
            f"{len(failed)} of {len(results.runs)} runs failed (run {indices}); the first (run {failed['run_index'].iloc[0]}): {failed['error'].iloc[0]}; "
            f"kept as failed in {out / 'runs.sqlite'} (not retried)"
        )
