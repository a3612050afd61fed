"""The ``hexadyn`` command line.

User errors end with one line on stderr (``Error: ...``) and exit status 1, never a traceback.
Set ``HEXADYN_DEBUG=1`` to see the traceback of such an error.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import click

import hexadyn
from hexadyn.runner import free_results_folder

#: Scenario run by `hexadyn simulate` without an argument (and by `make run`): a shipped scenario
#: name or a path. The validation test case of Table 6.2 (tripod, T = 12 s, 5 steps, 5 % overlap)
#: at V_x = 1.5 cm/s with LuGre friction: 60 s of walking.
DEFAULT_SCENARIO = "validation_tripod_1_5cm"

#: Folder under which `hexadyn simulate` writes results when no --out is given.

# Exceptions that report bad input (a missing file, a wrong value in a scenario) rather than a
# bug: they are shown as one clean line.
USER_ERRORS: tuple[type[BaseException], ...] = (OSError, ValueError)
#: Exit status after Ctrl-C (128 + SIGINT, as shells report it).
INTERRUPTED = 130
#: Exit status of `simulate --strict` when a health check failed.
UNHEALTHY = 3


class HexadynGroup(click.Group):
    """A click group that turns user errors raised by any command into one-line messages."""

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except USER_ERRORS as exc:
            if os.environ.get("HEXADYN_DEBUG"):
                raise
            raise click.ClickException(_one_line(exc)) from exc
        except KeyboardInterrupt:
            if os.environ.get("HEXADYN_DEBUG"):
                raise
            click.echo("\nInterrupted: nothing was written.", err=True)
            raise SystemExit(INTERRUPTED) from None


@click.group(cls=HexadynGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(hexadyn.__version__, "-V", "--version", prog_name="hexadyn", message="%(prog)s %(version)s")
def cli() -> None:
    """Multiphysics dynamics and gait control of six-legged walking robots."""


@cli.command()
def info() -> None:
    """Print the engine version and the shipped robots (the names `scenario.robot` takes)."""
    from hexadyn import _core

    click.echo(f"hexadyn {hexadyn.__version__}")
    click.echo(f"engine: {_core.__version__} ({_core.__file__})")
    click.echo(f"default robot: {hexadyn.DEFAULT_ROBOT}")
    click.echo("shipped robots (scenario.robot):")
    for name in _core.SHIPPED_ROBOTS:
        p = _core.robot_properties(_core.shipped_robot_text(name), name)
        joints = ", ".join(f"{j} ({kind})" for j, kind in p["joints"])
        click.echo(f"  {name:<9} {p['leg_mechanism']} legs, {p['mass_kg']:.3f} kg, joints {joints}")


def _parse_legs(ctx: click.Context, param: click.Parameter, value: str) -> tuple[int, ...]:
    from hexadyn import plots

    try:
        return plots.parse_legs(value)
    except ValueError as exc:
        raise click.BadParameter(str(exc)) from None


def _parse_formats(ctx: click.Context, param: click.Parameter, value: str) -> tuple[str, ...]:
    from hexadyn import plots

    formats = tuple(dict.fromkeys(f.strip().lower() for f in value.split(",") if f.strip()))
    if not formats or any(f not in plots.FORMATS for f in formats):
        raise click.BadParameter(f"{value!r}; allowed: comma-separated formats among {', '.join(plots.FORMATS)}")
    return formats


#: Options shared by `simulate` and `plot`.
plot_options = [
    click.option("--legs", default="0,2", show_default=True, callback=_parse_legs, help="Legs of the per-actuator figures: comma-separated 0..5, or all."),
    click.option("--formats", default="png", show_default=True, callback=_parse_formats, help="Figure file formats: png (300 dpi), pdf, svg, comma-separated."),
]


def with_plot_options(f):
    for option in reversed(plot_options):
        f = option(f)
    return f


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
@click.option("--no-plots", is_flag=True, help="Do not write the figures into <out>/plots/.")
@click.option("--strict", is_flag=True, help=f"Exit with status {UNHEALTHY} if a health check of the run fails (see `warnings` in summary.json).")
@with_plot_options
def simulate(scenario: str | None, out: Path | None, overwrite: bool, no_progress: bool, no_plots: bool, strict: bool, legs: tuple[int, ...], formats: tuple[str, ...]) -> None:
    """Run SCENARIO (a scenario file or a shipped scenario name) and save its results.

    Without SCENARIO the default scenario is run (see `hexadyn scenarios`). The results folder
    gets the time series (streamed to disk as the run goes), the summary, the power and energy
    tables (power.csv, energy.csv) and, unless --no-plots, the figures in plots/ (see `hexadyn
    plot`). Every run checks its own health (energy balance, penetration, body fall, tracking);
    failed checks are printed and listed under `warnings` in summary.json. Ctrl-C stops the run
    and writes nothing (exit status 130).
    """
    from hexadyn import report

    path = hexadyn.resolve_scenario(scenario or DEFAULT_SCENARIO)
    if out is not None and out.exists() and not overwrite:
        raise click.ClickException(f"{out}: the results folder exists; use --overwrite or another --out")
    # Without --out: results/<scenario name>, numbered. The scenario is validated before
    # anything is created: a bad scenario leaves no results folder behind.
    results = hexadyn.simulate(path, out, progress=not no_progress, save=True, overwrite=overwrite, plots=not no_plots, legs=legs, formats=formats)
    out = results.path
    s = results.summary
    click.echo(f"Results: {out}")
    click.echo(f"  scenario    {s['scenario']} ({path})")
    click.echo(f"  simulated   {s['duration_s']:.3f} s in {s['wall_time_s']:.2f} s wall time, {s['integration_steps']} steps ({s['rejected_steps']} rejected)")
    click.echo(f"  series      {results.shape[0]} instants x {results.shape[1]} columns")
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
    if report.in_memory(results):
        _echo_power(results)
        _echo_ground_detection(results)
    else:
        click.echo(f"  analysis    skipped {s['analysis_skipped']}")
    if (out / "plots").is_dir():
        click.echo(f"  plots       {out / 'plots'} ({len(list((out / 'plots').iterdir()))} files)")
    for warning in s["warnings"]:
        click.secho(f"WARNING: {warning}", fg="red", bold=True, err=True)
    if s["warnings"] and strict:
        raise SystemExit(UNHEALTHY)


def _echo_power(results: hexadyn.Results) -> None:
    """The averaged power table (Tables 6.3-6.6 layout) and the key figures of the run."""
    from hexadyn import energy

    table = energy.averaged_power(results)
    s = results.summary
    click.echo(f"  power       averaged power {s['average_power_w']:.4g} W; friction work {100 * s['friction_share']:.1f} %, Joule {100 * s['joule_share']:.1f} % of the electrical energy")
    if "specific_resistance" in s:
        click.echo(f"              specific resistance {s['specific_resistance']:.4g} (Eq. 6.6, m = {s['robot_mass_kg']:g} kg)")
    phases = [p for p in table.index.unique("phase") if p != energy.ALL]
    if phases:
        total = table.xs(energy.TOTAL, level="leg")[energy.TOTAL]
        click.echo("              by foot phase: " + ", ".join(f"{p} {total[p]:.3g} W" for p in phases))
    click.echo("  averaged power per actuator (W):")
    block = table.loc[energy.ALL].rename(index=lambda leg: f"leg {leg}" if leg != energy.TOTAL else leg).rename_axis(index=None, columns=None)
    for line in block.to_string(float_format=lambda v: f"{v:7.3f}").splitlines():
        click.echo(f"    {line}")


def _echo_ground_detection(results: hexadyn.Results) -> None:
    """Table 5.7 of a ground detection run."""
    from hexadyn import ground_detection

    if not ground_detection.has_experiment(results):
        return
    stops = ground_detection.trials(results)
    click.echo(f"  ground detection: {len(stops)} stops; true force at the stop (N) and error eps_F = (threshold - F) / threshold (%), Table 5.7:")
    if not stops.empty:
        for line in ground_detection.format_table(ground_detection.table(stops)).splitlines():
            click.echo(f"    {line}")


@cli.command("ground-detection")
@click.argument("folder", type=click.Path(file_okay=False, path_type=Path))
def ground_detection_table(folder: Path) -> None:
    """Table 5.7 of the ground detection results FOLDER (a run of control mode
    ground_detection, e.g. `hexadyn simulate ground_detection`): the true contact force at each
    stop on a detection, per leg and threshold, with the mean and standard deviation of the
    error; written to FOLDER/ground_detection.csv and FOLDER/ground_detection_table.csv."""
    from hexadyn import atomic, ground_detection, report

    results = hexadyn.Results.load(folder)
    if not ground_detection.has_experiment(results):
        raise click.ClickException(f"{folder}: not the results of a ground detection run (control.mode = \"ground_detection\"; no gd_stop column)")
    stops = ground_detection.trials(results)
    atomic.write_file(folder / ground_detection.TRIALS_FILE, lambda p: report.write_csv(p, stops.set_index(["leg", "threshold_n", "trial"])))
    atomic.write_file(folder / ground_detection.TABLE_FILE, lambda p: report.write_csv(p, ground_detection.table(stops)))
    _echo_ground_detection(results)
    click.echo(f"Tables: {folder / ground_detection.TRIALS_FILE}, {folder / ground_detection.TABLE_FILE}")


@cli.command()
@click.argument("folder", type=click.Path(file_okay=False, path_type=Path))
@with_plot_options
def plot(folder: Path, legs: tuple[int, ...], formats: tuple[str, ...]) -> None:
    """(Re)generate the figures of the results FOLDER into FOLDER/plots/ (replaced atomically)."""
    from hexadyn import report

    results = hexadyn.Results.load(folder)
    if not report.in_memory(results):
        raise ValueError(f"{folder}: the time series ({results.shape[0]} instants) is too long to plot in memory; plot a part of it from Python (Results.read_columns)")
    figures = report.plot(results, folder / "plots", legs=legs, formats=formats)
    click.echo(f"Plots: {folder / 'plots'} ({len(figures)} figures x {len(formats)} formats)")


def _parse_velocities(ctx: click.Context, param: click.Parameter, value: str | None) -> tuple[float, ...] | None:
    """`--velocities` in cm/s (as the thesis quotes them, Table 6.2) -> m/s."""
    if value is None:
        return None
    try:
        cm_s = [float(v) for v in value.split(",")]
    except ValueError:
        raise click.BadParameter(f"{value!r}; allowed: comma-separated velocities in cm/s, e.g. 1,1.5,2,2.5") from None
    return tuple(v / 100 for v in cm_s)


@cli.command("compare-friction")
@click.argument("scenario", required=False, default=None)
@click.option("--velocities", default="1,1.5,2,2.5", show_default=True, callback=_parse_velocities, help="Forward velocities V_x in cm/s (Table 6.2, Fig. 6.19), comma-separated.")
@click.option("--models", default=None, help="Friction models, comma-separated (default: all four: none, dry_viscous, lugre, dry_viscous_load).")
@click.option("-o", "--out", type=click.Path(file_okay=False, path_type=Path), default=None, help="Output folder (default: results/compare_friction_<scenario name>, numbered if it exists).")
@click.option("--overwrite", is_flag=True, help="Replace the --out folder if it exists.")
@click.option("-j", "--jobs", type=click.IntRange(min=1), default=None, help="Worker processes (default: one per CPU).")
@click.option("--no-progress", is_flag=True, help="No progress bar.")
@click.option("--formats", default="png", show_default=True, callback=_parse_formats, help="Figure file formats: png (300 dpi), pdf, svg, comma-separated.")
def compare_friction(scenario: str | None, velocities: tuple[float, ...], models: str | None, out: Path | None, overwrite: bool, jobs: int | None, no_progress: bool, formats: tuple[str, ...]) -> None:
    """Run the validation walk with each friction model at several velocities (Section 6.4).

    SCENARIO (default: the validation case of Table 6.2) is run without friction, with the
    dry/viscous model, with LuGre, and with the dry/viscous model plus the load dependence of the
    horizontal joints, at each velocity, in parallel. Writes the averaged power per actuator and
    model (Tables 6.3-6.6), the robot power and specific resistance versus velocity with the fit
    P = alpha + beta V_x (Fig. 6.19) as CSV tables and plots.
    """
    from hexadyn import compare, energy

    path = hexadyn.resolve_scenario(scenario or DEFAULT_SCENARIO)
    if out is None:
        out = free_results_folder(f"compare_friction_{path.stem}")
    elif out.exists() and not overwrite:
        raise click.ClickException(f"{out}: the output folder exists; use --overwrite or another --out")
    names = list(compare.MODELS) if models is None else [m.strip() for m in models.split(",") if m.strip()]
    result = compare.compare_friction(path, velocities, models=names, jobs=jobs, progress=not no_progress)
    compare.save(result, out, overwrite=overwrite, formats=formats)
    click.echo(f"Friction comparison: {out}")
    fmt = lambda v: f"{v:7.3f}"  # noqa: E731
    for joint, table in compare.joint_tables(result).items():
        click.echo(f"  averaged power of the {joint} actuators (W), V_x = {result.table_velocity * 100:g} cm/s:")
        table = table.rename(index=lambda leg: f"leg {leg}" if leg != energy.TOTAL else leg).rename_axis(index=None)
        for line in table.to_string(float_format=fmt).splitlines():
            click.echo(f"    {line}")
    robot = result.robot.reset_index()
    robot["V_x_cm_s"] = robot.pop("velocity_m_s") * 100
    columns = ["V_x_cm_s", "model", "average_power_w", "specific_resistance", "friction_share"] + (["friction_power_share"] if "friction_power_share" in robot else [])
    click.echo("  robot power and specific resistance (Fig. 6.19); friction_share = friction work / electrical energy, friction_power_share = 1 - P(no friction) / P:")
    for line in robot[columns].to_string(index=False, float_format=fmt).splitlines():
        click.echo(f"    {line}")
    if result.fit.empty:
        click.echo("  fit P = alpha + beta V_x (Eq. 6.8) skipped: it needs at least two velocities")
        return
    click.echo("  fit P = alpha + beta V_x (Eq. 6.8), xi -> beta / (m g) (Eq. 6.11):")
    for line in result.fit.to_string(float_format=lambda v: f"{v:9.4g}").splitlines():
        click.echo(f"    {line}")


@cli.command()
def scenarios() -> None:
    """List the shipped scenarios (run one with `hexadyn simulate NAME`)."""
    from hexadyn import _core

    files = hexadyn.scenario_files()
    click.echo(f"Shipped scenarios ({hexadyn.SCENARIOS_DIR}):")
    width = max((len(p.stem) for p in files), default=0)
    for p in files:
        info = _core.load_scenario(str(p))
        default = " (default)" if p.stem == DEFAULT_SCENARIO else ""
        click.echo(f"  {p.stem:<{width}}  {info['duration_s']:>6g} s  {info['description']}{default}")


@cli.command()
@click.argument("scenario", required=False, default=None)
@click.option("-o", "--out", type=click.Path(path_type=Path), required=True, help="Campaign folder (created, or resumed if it holds the same campaign).")
@click.option("--robot", type=click.Choice(["amru5", "phantomx"]), default=None, help="Without SCENARIO: the shipped robot whose campaign walk to run (amru5: validation_tripod_1_5cm, phantomx: phantomx_montecarlo) [default: amru5].")
@click.option("--runs", type=int, default=None, help="Runs per velocity (default: the robot's [monte_carlo], 1000).")
@click.option("--velocities", default=None, callback=_parse_velocities, help="Forward velocities V_x in cm/s, comma-separated (default: the robot's [monte_carlo], 1,1.5,2,2.5).")
@click.option("--variants", default=None, help="Comma-separated friction variants (default: every variant of the robot: dry_viscous,dry_viscous_load on AMRU5, dry_viscous on serial legs).")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the friction draws.")
@click.option("--friction-stats", type=click.Path(exists=True, dir_okay=False, path_type=Path), default=None, help="Friction Gaussians identified by `hexadyn identify` (its friction_stats.toml) instead of Table 6.7.")
@click.option("--workers", type=int, default=None, help="Parallel simulations (default: every core).")
@click.option("--ray", "ray_address", default=None, metavar="ADDRESS", help='Run on a Ray cluster ("local": a Ray instance started here).')
@click.option("--no-progress", is_flag=True, help="No progress bar.")
def montecarlo(scenario, out, robot, runs, velocities, variants, seed, friction_stats, workers, ray_address, no_progress) -> None:
    """Monte Carlo over the joint friction uncertainty (Section 6.5): Table 6.8 and Fig. 6.20.

    Simulates SCENARIO (default: the validation walk validation_tripod_1_5cm, or with --robot
    phantomx the PhantomX's phantomx_montecarlo) for every friction variant, velocity and run,
    with friction drawn per run from the Gaussians of the robot's [monte_carlo] table (AMRU5:
    Table 6.7), truncated at 3 sigma, physical signs. Rerunning the same command resumes an
    interrupted campaign. Writes campaign.json, runs.sqlite, specific_resistance.csv/.png/.pdf
    to --out. A campaign with failed simulations (stored, not retried) ends with one line
    naming them and exit status 1.
    """
    from hexadyn.montecarlo import DEFAULT_SCENARIOS, Campaign
    from hexadyn.montecarlo.tables import failure_line

    if scenario is not None and robot is not None:
        raise click.BadParameter(f"--robot {robot} with the scenario {scenario}: the scenario names its robot; give one of them", param_hint="--robot")

    def listed(option: str, text: str | None, convert):
        if text is None:
            return None
        try:
            return [convert(item) for item in text.split(",")]
        except ValueError as exc:
            raise click.BadParameter(f"{text!r}: {exc}", param_hint=option) from exc

    campaign = Campaign.create(
        scenario or DEFAULT_SCENARIOS[robot or "amru5"],
        velocities=None if velocities is None else list(velocities),
        runs_per_velocity=runs,
        variants=listed("--variants", variants, str.strip),
        seed=seed,
        friction_stats=friction_stats,
    )
    try:
        table = campaign.run(out, workers=workers, ray=ray_address, progress=not no_progress)
    except KeyboardInterrupt:
        click.echo(f"Interrupted: the finished runs are kept in {out}; run the same command again to resume.", err=True)
        raise SystemExit(130) from None
    shown = table.rename(columns={"velocity_m_s": "V_x (m/s)", "specific_resistance_mean": "xi mean", "specific_resistance_std": "xi sigma", "specific_resistance_minus_3_sigma": "mean-3sigma", "specific_resistance_plus_3_sigma": "mean+3sigma", "average_power_w_mean": "P mean (W)"})
    click.echo(f"Specific resistance xi = E/(m g l) (Table 6.8), {campaign.scenario_name}, seed {seed}:")
    click.echo(shown.to_string(index=False, float_format=lambda x: f"{x:.4g}"))
    click.echo(f"Results: {out} (specific_resistance.csv, specific_resistance.png, specific_resistance.pdf, runs.sqlite)")
    if table["failed"].any():
        raise click.ClickException(failure_line(campaign.failures(out), len(campaign.keys()), out))


@cli.command("import-urdf")
@click.argument("urdf_file", type=click.Path(path_type=Path))
@click.option("--out", "out_file", type=click.Path(path_type=Path), required=True, help="The robot description to write (TOML, docs/robot-format.md).")
@click.option("--joint-names", default="coxa,femur,tibia", show_default=True, help="The names of a leg's three joints from the body to the foot, comma-separated: the results' columns.")
@click.option("--drives", "drives_file", type=click.Path(path_type=Path), default=None, help="A serial robot description whose drives, controller and ground to use [default: the shipped PhantomX's AX-12A servos].")
@click.option("--overwrite", is_flag=True, help="Replace an existing output file.")
def import_urdf_command(urdf_file: Path, out_file: Path, joint_names: str, drives_file: Path | None, overwrite: bool) -> None:
    """Write a hexadyn robot description of a URDF hexapod (six chains of three joints)."""
    from hexadyn.urdf import import_urdf

    names = tuple(n.strip() for n in joint_names.split(","))
    path = import_urdf(urdf_file, out_file, names, drives_file, overwrite)
    click.echo(f"Robot description: {path} (scenario.robot = \"{path}\"; check its drives)")


@cli.command("export-urdf")
@click.argument("robot")
@click.argument("out_file", type=click.Path(path_type=Path))
@click.option("--overwrite", is_flag=True, help="Replace an existing output file.")
def export_urdf_command(robot: str, out_file: Path, overwrite: bool) -> None:
    """Write a serial robot (shipped name or description file) as URDF, for ROS and MuJoCo users."""
    from hexadyn.urdf import export_urdf

    click.echo(f"URDF: {export_urdf(robot, out_file, overwrite)}")


@cli.command("export-mjcf")
@click.argument("robot")
@click.argument("out_file", type=click.Path(path_type=Path))
@click.option("--overwrite", is_flag=True, help="Replace an existing output file.")
def export_mjcf_command(robot: str, out_file: Path, overwrite: bool) -> None:
    """Write a robot (shipped name or description file, either leg mechanism) as MuJoCo MJCF."""
    from hexadyn.urdf import export_mjcf

    click.echo(f"MJCF: {export_mjcf(robot, out_file, overwrite)}")


@cli.command("urdf")
@click.argument("urdf_file", type=click.Path(path_type=Path))
@click.option("--height", type=float, default=None, help="Body height (m) for the workspaces [default: feet on the ground with the joints mid-range].")
@click.option("--lift", type=float, default=0.0, show_default=True, help="Foot lift (m): the workspaces span [ground, ground + lift].")
@click.option("--mjcf", "mjcf_file", type=click.Path(path_type=Path), default=None, help="Also write the robot as MuJoCo MJCF to this file.")
def urdf(urdf_file: Path, height: float | None, lift: float, mjcf_file: Path | None) -> None:
    """Show how hexadyn reads a hexapod's URDF file: legs, joints, masses and workspaces."""
    import pandas as pd

    from hexadyn.urdf import inspect, write_mjcf

    table = inspect(urdf_file, height, lift)
    if mjcf_file is not None:
        write_mjcf(urdf_file, mjcf_file)
    a = table.attrs
    click.echo(f"{a['name']}: {a['mass_kg']:.4g} kg, six legs of three joints; workspaces at body height {a['height_m']:.4g} m, lift {a['lift_m']:.4g} m (leg frames)")
    with pd.option_context("display.width", 200, "display.max_columns", None, "display.max_colwidth", 60):
        click.echo(table.drop(columns=["workspace"] if not table["workspace"].any() else []).to_string(float_format=lambda x: f"{x:.4g}"))
    if mjcf_file is not None:
        click.echo(f"MJCF: {mjcf_file}")


from hexadyn.view.command import view  # noqa: E402  (hexadyn view: the 3D animation of a results folder)

cli.add_command(view)


def main(argv: list[str] | None = None) -> None:
    """Entry point of the ``hexadyn`` console script. After Ctrl-C (everything already cleaned
    up and reported) the process ends at once, without the interpreter's teardown of pandas,
    pyarrow and matplotlib, which takes seconds on a loaded machine."""
    try:
        cli.main(args=argv, prog_name="hexadyn")
    except SystemExit as exc:
        if exc.code != INTERRUPTED:
            raise
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(INTERRUPTED)


def _one_line(exc: BaseException) -> str:
    if isinstance(exc, OSError) and exc.strerror and exc.filename:
        return f"{exc.filename}: {exc.strerror}"
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


from hexadyn.link.cli import robot  # noqa: E402  (the `hexadyn robot` commands)

cli.add_command(robot)

from hexadyn.identify.command import identify_command  # noqa: E402  (hexadyn identify: Chapter 5)

cli.add_command(identify_command)

from hexadyn.study.command import study_command  # noqa: E402  (hexadyn study: design studies)

cli.add_command(study_command)

if __name__ == "__main__":  # pragma: no cover
    main()
