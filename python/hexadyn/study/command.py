"""``hexadyn study STUDY.toml``: a design study over a scenario's fields (docs/studies.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from hexadyn.options import figure_format_option, no_plots_option, no_progress_option, out_option, set_option, strict_option, warn_unhealthy, workers_option

__all__ = ["study_command"]

#: Failed runs a failure line names before "...".
_SHOWN = 4


@click.command("study")
@click.argument("study_file", metavar="STUDY", type=click.Path(path_type=Path))
@out_option("Study folder (created, or resumed if it holds the same study) [default: results/<study name>].")
@workers_option("Parallel runs (default: every core).")
@click.option("--ray", "ray_address", default=None, metavar="ADDRESS", help='Run on a Ray cluster ("local": a Ray instance started here).')
@set_option()
@figure_format_option()
@no_plots_option()
@no_progress_option()
@strict_option()
def study_command(study_file: Path, out: Path | None, workers: int | None, ray_address: str | None, overrides: dict[str, Any], format_: tuple[str, ...], no_plots: bool, no_progress: bool, strict: bool) -> None:
    """Run the design study STUDY (a study file, docs/studies.md): its base scenario under
    every run's parameter values, the outputs of each run and, for Sobol' and Morris designs,
    the sensitivity indices. Rerunning the same command resumes an interrupted study. Writes
    study.json, runs.sqlite, runs.csv/.parquet, indices.csv/.parquet and the figures to --out.
    A study with failed runs (stored, not retried) ends with one line naming them and exit
    status 1. Every run checks its health (as `hexadyn simulate`'s): the runs that failed a check
    are named on one WARNING line (their checks in the warnings column of runs.csv), and
    --strict then exits with status 3."""
    from hexadyn.runner import RESULTS_ROOT, safe_folder_name
    from hexadyn.study import Study

    study = Study.create(study_file, fixed=overrides)
    out = out if out is not None else RESULTS_ROOT / safe_folder_name(study.spec.name)
    try:
        results = study.run(out, workers=workers, ray=ray_address, progress=not no_progress, plots=not no_plots, formats=format_)
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
    unhealthy = results.unhealthy
    warnings = [] if unhealthy.empty else [f"{len(unhealthy)} of {len(results.runs)} runs failed a health check (run {_named(unhealthy)}); the first (run {unhealthy['run_index'].iloc[0]}): {'; '.join(unhealthy['warnings'].iloc[0])} (column warnings of {out / 'runs.csv'})"]
    failed = results.failures
    if len(failed):
        warn_unhealthy(warnings, strict=False)
        raise click.ClickException(
            f"{len(failed)} of {len(results.runs)} runs failed (run {_named(failed)}); the first (run {failed['run_index'].iloc[0]}): {failed['error'].iloc[0]}; "
            f"kept as failed in {out / 'runs.sqlite'} (not retried)"
        )
    warn_unhealthy(warnings, strict)


def _named(runs: Any) -> str:
    """The run indices of a table of runs, the first :data:`_SHOWN` then "..."."""
    indices = runs["run_index"].tolist()
    return ", ".join(map(str, indices[:_SHOWN])) + (", ..." if len(indices) > _SHOWN else "")
