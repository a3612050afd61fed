"""The ``hexadyn`` command line.

User errors end with one line on stderr (``Error: ...``) and exit status 1, never a traceback.
Set ``HEXADYN_DEBUG=1`` to see the traceback of such an error.
"""

from __future__ import annotations

import os
from pathlib import Path

import click

import hexadyn

#: Scenario run by `hexadyn simulate` without an argument (and by `make run`): a shipped scenario
#: name or a path. The validation test case of Table 6.2 (tripod, T = 12 s, 5 steps, 5 % overlap)
#: at V_x = 1.5 cm/s with LuGre friction: 60 s of walking.
DEFAULT_SCENARIO = "validation_tripod_1_5cm"

#: Folder under which `hexadyn simulate` writes results when no --out is given.
RESULTS_ROOT = Path("results")

# Exceptions that report bad input (a missing file, a wrong value in a scenario) rather than a
# bug: they are shown as one clean line.
USER_ERRORS: tuple[type[BaseException], ...] = (OSError, ValueError)


class HexadynGroup(click.Group):
    """A click group that turns user errors raised by any command into one-line messages."""

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except USER_ERRORS as exc:
            if os.environ.get("HEXADYN_DEBUG"):
                raise
            raise click.ClickException(_one_line(exc)) from exc


@click.group(cls=HexadynGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(hexadyn.__version__, "-V", "--version", prog_name="hexadyn", message="%(prog)s %(version)s")
def cli() -> None:
    """Multiphysics dynamics and gait control of six-legged walking robots."""


@cli.command()
def info() -> None:
    """Print the engine version and the default robot description."""
    from hexadyn import _core

    robot = hexadyn.default_robot_path()
    click.echo(f"hexadyn {hexadyn.__version__}")
    click.echo(f"engine: {_core.__version__} ({_core.__file__})")
    if robot is None:
        click.echo(f"default robot: {hexadyn.DEFAULT_ROBOT} (description not shipped yet)")
    else:
        click.echo(f"default robot: {hexadyn.DEFAULT_ROBOT} ({robot})")


@cli.command()
@click.argument("scenario", required=False, default=None)
@click.option(
    "-o",
    "--out",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    help="Results folder (default: results/<scenario name>, numbered if it exists).",
)
@click.option("--overwrite", is_flag=True, help="Replace the --out folder if it exists.")
@click.option("--no-progress", is_flag=True, help="No progress bar.")
def simulate(scenario: str | None, out: Path | None, overwrite: bool, no_progress: bool) -> None:
    """Run SCENARIO (a scenario file or a shipped scenario name) and save its results.

    Without SCENARIO the default scenario is run (see `hexadyn scenarios`).
    """
    from hexadyn import _core

    path = hexadyn.resolve_scenario(scenario or DEFAULT_SCENARIO)
    # Validate before anything is created: a bad scenario leaves no results folder behind.
    info = _core.load_scenario(str(path))
    if out is None:
        out = _free_folder(RESULTS_ROOT / info["name"])
    elif out.exists() and not overwrite:
        raise click.ClickException(f"{out}: the results folder exists; use --overwrite or another --out")
    results = hexadyn.simulate(path, out=out, progress=not no_progress, overwrite=overwrite)
    s = results.summary
    click.echo(f"Results: {out}")
    click.echo(f"  scenario    {info['name']} ({path})")
    click.echo(f"  simulated   {s['duration_s']:.3f} s in {s['wall_time_s']:.2f} s wall time, {s['integration_steps']} steps ({s['rejected_steps']} rejected)")
    click.echo(f"  series      {results.timeseries.shape[0]} instants x {results.timeseries.shape[1]} columns")
    click.echo(f"  body height {s['body_height_change_m'] * 1e3:+.4f} mm over the run")
    click.echo(
        f"  energy      electrical {s['energy_electrical_j']:.4g} J, Joule {s['energy_joule_j']:.4g} J, "
        f"friction {s['energy_friction_j']:.4g} J, balance error {s['energy_balance_error_j']:.3g} J"
    )
    click.echo(f"  voltages    max |u| {s['max_abs_voltage_v']:.2f} V, saturated {100 * s['saturated_fraction']:.2f} % of commands, {s['limit_switch_cuts']} limit-switch cuts")
    if "tracking_error_xy_max_m" in s:
        click.echo(
            f"  walking     {s['distance_walked_m']:.3f} m walked (reference {s['reference_distance_m']:.3f} m), "
            f"XY tracking error max {s['tracking_error_xy_max_m'] * 1e3:.2f} mm, final {s['tracking_error_xy_final_m'] * 1e3:.2f} mm"
        )
        click.echo(
            f"  gait        {s['gait_pattern']}, {s['gait_switches']} gait switches, {s['clamped_ik_references']} clamped IK references, "
            f"at least {s['min_feet_on_ground']} feet on the ground"
        )


@cli.command()
def scenarios() -> None:
    """List the shipped scenarios (run one with `hexadyn simulate NAME`)."""
    from hexadyn import _core

    files = hexadyn.list_scenarios()
    click.echo(f"Shipped scenarios ({hexadyn.SCENARIOS_DIR}):")
    width = max((len(p.stem) for p in files), default=0)
    for p in files:
        info = _core.load_scenario(str(p))
        default = " (default)" if p.stem == DEFAULT_SCENARIO else ""
        click.echo(f"  {p.stem:<{width}}  {info['duration_s']:>6g} s  {info['description']}{default}")


@cli.command()
@click.argument("scenario", required=False, default=None)
@click.option("-o", "--out", type=click.Path(path_type=Path), required=True, help="Campaign folder (created, or resumed if it holds the same campaign).")
@click.option("--runs", type=int, default=None, help="Runs per velocity (default: the robot's [monte_carlo], 1000).")
@click.option("--velocities", default=None, help="Comma-separated forward velocities in m/s (default: 0.01,0.015,0.02,0.025).")
@click.option("--variants", default=None, help="Comma-separated friction variants (default: dry_viscous,dry_viscous_load).")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the friction draws.")
@click.option("--workers", type=int, default=None, help="Parallel simulations (default: every core).")
@click.option("--ray", "ray_address", default=None, metavar="ADDRESS", help='Run on a Ray cluster ("local": a Ray instance started here).')
@click.option("--no-progress", is_flag=True, help="No progress bar.")
def montecarlo(scenario, out, runs, velocities, variants, seed, workers, ray_address, no_progress) -> None:
    """Monte Carlo over the joint friction uncertainty (Section 6.5): Table 6.8 and Fig. 6.20.

    Simulates SCENARIO (default: the validation walk validation_tripod_1_5cm) for every friction
    variant, velocity and run, with friction drawn per run from the Gaussians of Table 6.7
    (truncated at 3 sigma, physical signs). Rerunning the same command resumes an interrupted
    campaign. Writes campaign.json, runs.sqlite, specific_resistance.csv/.png/.pdf to --out.
    """
    from hexadyn.montecarlo import DEFAULT_SCENARIO as CAMPAIGN_SCENARIO
    from hexadyn.montecarlo import Campaign

    def listed(option: str, text: str | None, convert):
        if text is None:
            return None
        try:
            return [convert(item) for item in text.split(",")]
        except ValueError as exc:
            raise click.BadParameter(f"{text!r}: {exc}", param_hint=option) from exc

    campaign = Campaign.create(
        scenario or CAMPAIGN_SCENARIO,
        velocities=listed("--velocities", velocities, float),
        runs_per_velocity=runs,
        variants=listed("--variants", variants, str.strip),
        seed=seed,
    )
    try:
        table = campaign.run(out, workers=workers, ray=ray_address, progress=not no_progress)
    except KeyboardInterrupt:
        click.echo(f"Interrupted: the finished runs are kept in {out}; run the same command again to resume.", err=True)
        raise SystemExit(130) from None
    shown = table.rename(columns={"velocity_m_s": "V_x (m/s)", "specific_resistance_mean": "xi mean", "specific_resistance_std": "xi sigma", "specific_resistance_minus_3_sigma": "mean-3sigma", "specific_resistance_plus_3_sigma": "mean+3sigma", "average_power_w_mean": "P mean (W)"})
    click.echo(f"Specific resistance xi = E/(m g l) (Table 6.8), {campaign.scenario_name}, seed {seed}:")
    click.echo(shown.to_string(index=False, float_format=lambda x: f"{x:.4g}"))
    if table["failed"].any():
        click.echo(f"{int(table['failed'].sum())} simulations failed (kept as failed in {out}/runs.sqlite, not retried).")
    click.echo(f"Results: {out} (specific_resistance.csv, specific_resistance.png, specific_resistance.pdf, runs.sqlite)")


def _free_folder(base: Path) -> Path:
    """`base`, or `base-2`, `base-3`... whichever does not exist yet."""
    if not base.exists():
        return base
    n = 2
    while (candidate := base.with_name(f"{base.name}-{n}")).exists():
        n += 1
    return candidate


def main(argv: list[str] | None = None) -> None:
    """Entry point of the ``hexadyn`` console script."""
    cli.main(args=argv, prog_name="hexadyn")


def _one_line(exc: BaseException) -> str:
    if isinstance(exc, OSError) and exc.strerror and exc.filename:
        return f"{exc.filename}: {exc.strerror}"
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


if __name__ == "__main__":  # pragma: no cover
    main()
