"""The ``hexadyn`` command line.

User errors end with one line on stderr (``Error: ...``) and exit status 1, never a traceback;
a wrong command line (an unknown option, a bad option value) with one line too and exit status
2. Set ``HEXADYN_DEBUG=1`` to see the traceback of such an error. The options shared by several
commands are spelled the same in all of them (:mod:`hexadyn.options`, docs/cli.md).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import click

import hexadyn
from hexadyn import _core, atomic
from hexadyn.options import (
    figure_format_option,
    format_option,
    no_plots_option,
    no_progress_option,
    out_option,
    overwrite_option,
    set_option,
    strict_option,
    warn_unhealthy,
    workers_option,
)
from hexadyn.runner import RESULTS_ROOT, free_results_folder

#: Scenario run by `hexadyn simulate` without an argument (and by `make run`): a shipped scenario
#: name or a path. The validation test case of Table 6.2 (tripod, T = 12 s, 5 steps, 5 % overlap)
#: at V_x = 1.5 cm/s with LuGre friction: 60 s of walking.
DEFAULT_SCENARIO = "validation_tripod_1_5cm"

# Exceptions that report bad input (a missing file, a wrong value in a scenario) rather than a
# bug: they are shown as one clean line.
USER_ERRORS: tuple[type[BaseException], ...] = (OSError, ValueError)
#: Exit status after Ctrl-C (128 + SIGINT, as shells report it).
INTERRUPTED = 130


class OneLineUsageError(click.UsageError):
    """A wrong command line, shown as one line (without click's usage block) that names the
    option, the value, what is allowed and where the help is."""

    def __init__(self, error: click.UsageError) -> None:
        where = f" (see '{error.ctx.command_path} --help')" if error.ctx is not None else ""
        super().__init__(" ".join(error.format_message().split()) + where)

    def show(self, file=None) -> None:
        click.echo(f"Error: {self.format_message()}", file=file, err=True)


def _usage_in_one_line(error: click.UsageError) -> click.UsageError:
    """`error` as one line; the help that a group without a command prints stays as it is."""
    if isinstance(error, (OneLineUsageError, click.exceptions.NoArgsIsHelpError)):
        return error
    return OneLineUsageError(error)


class HexadynGroup(click.Group):
    """A click group that turns user errors raised by any command into one-line messages."""

    def make_context(self, info_name, args, parent=None, **extra) -> click.Context:
        try:
            return super().make_context(info_name, args, parent, **extra)
        except click.UsageError as exc:
            raise _usage_in_one_line(exc) from None

    def invoke(self, ctx: click.Context):
        # A run killed while saving (kill -9, a power cut) could not remove its temporary
        # folder: every command first removes those whose writer is gone from the results root.
        atomic.remove_stale(RESULTS_ROOT)
        try:
            return super().invoke(ctx)
        except click.UsageError as exc:
            raise _usage_in_one_line(exc) from None
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
    """Print what is shipped: the version, the robots (the names `scenario.robot` takes, their
    descriptions printed by `hexadyn robot-file NAME`) and the scenarios."""
    click.echo(f"hexadyn {hexadyn.__version__}")
    click.echo(f"engine: {_core.__version__} ({_core.__file__})")
    click.echo(f"default robot: {hexadyn.DEFAULT_ROBOT}")
    click.echo("shipped robots (scenario.robot; the description file: hexadyn robot-file NAME):")
    for name in _core.SHIPPED_ROBOTS:
        p = _core.robot_properties(_core.shipped_robot_text(name), name)
        joints = ", ".join(f"{j} ({kind})" for j, kind in p["joints"])
        click.echo(f"  {name:<9} {p['leg_mechanism']} legs, {p['mass_kg']:.3f} kg, joints {joints}")
    click.echo(f"shipped scenarios: {len(hexadyn.list_scenarios())} in {hexadyn.SCENARIOS_DIR} (hexadyn scenarios lists them)")


@cli.command("robot-file")
@click.argument("robot", type=click.Choice(list(_core.SHIPPED_ROBOTS)))
def robot_file(robot: str) -> None:
    """Print the description file of the shipped ROBOT (TOML, docs/robot-format.md): the fields
    a robot description needs, the start of one of your own (`> my_robot.toml`)."""
    click.echo(_core.shipped_robot_text(robot), nl=False)


def _parse_legs(ctx: click.Context, param: click.Parameter, value: str) -> tuple[int, ...]:
    from hexadyn import plots

    try:
        return plots.parse_legs(value)
    except ValueError as exc:
        raise click.BadParameter(str(exc)) from None


#: Options shared by `simulate` and `plot`.
plot_options = [
    click.option("--legs", default="0,2", show_default=True, callback=_parse_legs, help="Legs of the per-actuator figures: comma-separated 0..5, or all."),
    figure_format_option(),
]


def with_plot_options(f):
    for option in reversed(plot_options):
        f = option(f)
    return f


@cli.command()
@click.argument("scenario", required=False, default=None)
@set_option()
@out_option("Results folder (default: results/<scenario name>, numbered if it exists).")
@overwrite_option()
@no_progress_option()
@no_plots_option()
@strict_option()
@with_plot_options
def simulate(scenario: str | None, overrides: dict, out: Path | None, overwrite: bool, no_progress: bool, no_plots: bool, strict: bool, legs: tuple[int, ...], format_: tuple[str, ...]) -> None:
    """Run SCENARIO (a scenario file or a shipped scenario name) and save its results.

    Without SCENARIO the default scenario is run (see `hexadyn scenarios`); --set changes its
    fields (its description then says so: `[derived: ...]`). The results folder
    gets the time series (streamed to disk as the run goes), the summary, the power and energy
    tables (power.csv, energy.csv) and, unless --no-plots, the figures in plots/ (see `hexadyn
    plot`). Every run checks its own health (energy balance, penetration, body fall, tracking);
    failed checks are printed and listed under `warnings` in summary.json. Ctrl-C stops the run
    and writes nothing (exit status 130).
    """
    from hexadyn import report

    run = _scenario(scenario, overrides)
    path = run.path
    if out is not None and out.exists() and not overwrite:
        raise click.ClickException(f"{out}: the results folder exists; use --overwrite or another --out")
    # Without --out: results/<scenario name>, numbered. The scenario is validated before
    # anything is created: a bad scenario leaves no results folder behind.
    results = run.simulate(out, progress=not no_progress, save=True, overwrite=overwrite, plots=not no_plots, legs=legs, formats=format_)
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
    if report.skipped_analysis(results) is None:
        _echo_power(results)
        _echo_ground_detection(results)
    else:
        click.echo(f"  analysis    skipped {s['analysis_skipped']}")
    if (out / "plots").is_dir():
        click.echo(f"  plots       {out / 'plots'} ({len(list((out / 'plots').iterdir()))} files)")
    warn_unhealthy(s["warnings"], strict)


def _scenario(scenario: str | None, overrides: dict) -> hexadyn.Scenario:
    """SCENARIO (default: :data:`DEFAULT_SCENARIO`) with the fields of --set, checked by the
    engine."""
    return hexadyn.Scenario.load(scenario or DEFAULT_SCENARIO).update(overrides)


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
@no_progress_option()
def plot(folder: Path, legs: tuple[int, ...], format_: tuple[str, ...], no_progress: bool) -> None:
    """(Re)generate the figures of the results FOLDER into FOLDER/plots/ (replaced atomically)."""
    from hexadyn import report

    results = hexadyn.Results.load(folder)
    if not report.in_memory(results):
        raise ValueError(f"{folder}: the time series ({results.shape[0]} instants) is too long to plot in memory; plot a part of it from Python (Results.read_columns)")
    try:
        figures = report.plot(results, folder / "plots", legs=legs, formats=format_, progress=not no_progress)
    except ValueError as exc:  # what the figures cannot be drawn from, said of the folder
        raise ValueError(f"{folder}: {exc}") from exc
    except KeyError as exc:  # a column the figures need, missing from a damaged time series
        raise ValueError(f"{folder}: the time series has no column {exc}; allowed: the columns the run that wrote the folder recorded") from exc
    click.echo(f"Plots: {folder / 'plots'} ({len(figures)} figures x {len(format_)} formats)")


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
@click.option("--models", default=None, help="Friction models, comma-separated (default: all five: none, dry_viscous, lugre, dry_viscous_load, efficiency).")
@set_option()
@out_option("Output folder (default: results/compare_friction_<scenario name>, numbered if it exists).")
@overwrite_option()
@workers_option()
@no_progress_option()
@no_plots_option()
@strict_option()
@figure_format_option()
def compare_friction(scenario: str | None, velocities: tuple[float, ...], models: str | None, overrides: dict, out: Path | None, overwrite: bool, workers: int | None, no_progress: bool, no_plots: bool, strict: bool, format_: tuple[str, ...]) -> None:
    """Run the validation walk with each friction model at several velocities (Section 6.4).

    SCENARIO (default: the validation case of Table 6.2) is run without friction, with the
    dry/viscous model, with LuGre, with the dry/viscous model plus the load dependence of the
    horizontal joints, and with the transmission-efficiency law, at each velocity, in parallel. Writes the averaged power per actuator and
    model (Tables 6.3-6.6), the robot power and specific resistance versus velocity with the fit
    P = alpha + beta V_x (Fig. 6.19) as CSV tables and plots. --set changes the scenario's fields
    for every run (the friction model and the velocity are set over them). Every run checks its
    own health (as `hexadyn simulate`'s): a failed check is printed and kept in the `warnings`
    column of robot_power.csv, and makes --strict exit with status 3.
    """
    from hexadyn import compare, energy

    path = _scenario(scenario, overrides).path  # the fields of --set checked on the scenario first
    if out is None:
        out = free_results_folder(f"compare_friction_{path.stem}")
    elif out.exists() and not overwrite:
        raise click.ClickException(f"{out}: the output folder exists; use --overwrite or another --out")
    names = list(compare.MODELS) if models is None else [m.strip() for m in models.split(",") if m.strip()]
    result = compare.compare_friction(path, velocities, models=names, workers=workers, progress=not no_progress, overrides=overrides)
    compare.save(result, out, overwrite=overwrite, formats=format_, with_plots=not no_plots, progress=not no_progress)
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
    else:
        click.echo("  fit P = alpha + beta V_x (Eq. 6.8), xi -> beta / (m g) (Eq. 6.11):")
        for line in result.fit.to_string(float_format=lambda v: f"{v:9.4g}").splitlines():
            click.echo(f"    {line}")
    warn_unhealthy(compare.warning_lines(result), strict)


@cli.command()
def scenarios() -> None:
    """List the shipped scenarios (run one with `hexadyn simulate NAME`)."""
    files = hexadyn.scenario_files()
    click.echo(f"Shipped scenarios ({hexadyn.SCENARIOS_DIR}):")
    width = max((len(p.stem) for p in files), default=0)
    for p in files:
        info = _core.load_scenario(str(p))
        default = " (default)" if p.stem == DEFAULT_SCENARIO else ""
        click.echo(f"  {p.stem:<{width}}  {info['duration_s']:>6g} s  {info['description']}{default}")


@cli.command()
@click.argument("scenario", required=False, default=None)
@out_option("Campaign folder (created, or resumed if it holds the same campaign).", required=True)
@click.option("--robot", type=click.Choice(["amru5", "phantomx"]), default=None, help="Without SCENARIO: the shipped robot whose campaign walk to run (amru5: validation_tripod_1_5cm, phantomx: phantomx_montecarlo) [default: amru5].")
@click.option("--runs", type=int, default=None, help="Runs per velocity (default: the robot's [monte_carlo], 1000).")
@click.option("--velocities", default=None, callback=_parse_velocities, help="Forward velocities V_x in cm/s, comma-separated (default: the robot's [monte_carlo], 1,1.5,2,2.5).")
@click.option("--variants", default=None, help="Comma-separated friction variants: dry_viscous, dry_viscous_load (AMRU5), efficiency (default: those of Section 6.5 the robot has: dry_viscous,dry_viscous_load on AMRU5, dry_viscous on serial legs).")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the friction draws.")
@click.option("--friction-stats", type=click.Path(exists=True, dir_okay=False, path_type=Path), default=None, help="Friction Gaussians identified by `hexadyn identify` (its friction_stats.toml) instead of Table 6.7.")
@set_option()
@workers_option()
@click.option("--ray", "ray_address", default=None, metavar="ADDRESS", help='Run on a Ray cluster ("local": a Ray instance started here).')
@no_progress_option()
@strict_option()
def montecarlo(scenario, out, robot, runs, velocities, variants, seed, friction_stats, overrides, workers, ray_address, no_progress, strict) -> None:
    """Monte Carlo over the joint friction uncertainty (Section 6.5): Table 6.8 and Fig. 6.20.

    Simulates SCENARIO (default: the validation walk validation_tripod_1_5cm, or with --robot
    phantomx the PhantomX's phantomx_montecarlo) for every friction variant, velocity and run,
    with friction drawn per run from the Gaussians of the robot's [monte_carlo] table (AMRU5:
    Table 6.7), truncated at 3 sigma, physical signs; --set changes the scenario's fields for
    every run (the drawn friction and the velocity are set over them). Rerunning the same command resumes an
    interrupted campaign. Writes campaign.json, runs.sqlite, specific_resistance.csv/.png/.pdf
    to --out. A campaign with failed simulations (stored, not retried) ends with one line
    naming them and exit status 1. Every run checks its own health (as `hexadyn simulate`'s,
    kept in runs.sqlite): the runs that failed a check are named in one WARNING line, and
    --strict then exits with status 3.
    """
    from hexadyn.montecarlo import DEFAULT_SCENARIOS, Campaign
    from hexadyn.montecarlo.tables import failure_line, warning_line

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
        overrides=overrides,
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
    unhealthy = campaign.unhealthy(out)
    warnings = [] if unhealthy.empty else [warning_line(unhealthy, len(campaign.keys()), out)]
    if table["failed"].any():
        warn_unhealthy(warnings, strict=False)
        raise click.ClickException(failure_line(campaign.failures(out), len(campaign.keys()), out))
    warn_unhealthy(warnings, strict)


@cli.command("export")
@click.argument("folder", type=click.Path(file_okay=False, path_type=Path))
@format_option(("csv", "mcap"), None, "csv: the time series as one table; mcap: channels for Foxglove Studio (body pose, joint states, foot forces, motor currents).", several=False, required=True)
@out_option("The file to write (default: FOLDER/timeseries.csv or FOLDER/timeseries.mcap).", folder=False)
@overwrite_option("file")
def export_command(folder: Path, format_: str, out: Path | None, overwrite: bool) -> None:
    """Export the results FOLDER for other tools: the time series as CSV, or as an MCAP file of
    JSON channels logged at the run's times (docs/cli.md lists them)."""
    from hexadyn import export

    results = hexadyn.Results.load(folder)
    path = export.export(results, out or folder / f"timeseries{export.FORMATS[format_]}", format_, overwrite=overwrite)
    written = "every column" if format_ == "csv" else ", ".join(c.topic for c in export.channels(results))
    click.echo(f"Export: {path} ({results.shape[0]} instants, {written})")


@cli.command("import-urdf")
@click.argument("urdf_file", type=click.Path(path_type=Path))
@out_option("The robot description to write (TOML, docs/robot-format.md).", required=True, folder=False)
@click.option("--joint-names", default="coxa,femur,tibia", show_default=True, help="The names of a leg's three joints from the body to the foot, comma-separated: the results' columns.")
@click.option("--drives", "drives_file", type=click.Path(path_type=Path), default=None, help="A serial robot description whose drives, controller and ground to use [default: the shipped PhantomX's AX-12A servos].")
@overwrite_option("file")
def import_urdf_command(urdf_file: Path, out: Path, joint_names: str, drives_file: Path | None, overwrite: bool) -> None:
    """Write a hexadyn robot description of a URDF hexapod (six chains of three joints)."""
    from hexadyn.urdf import import_urdf

    names = tuple(n.strip() for n in joint_names.split(","))
    path = import_urdf(urdf_file, out, names, drives_file, overwrite)
    click.echo(f"Robot description: {path} (scenario.robot = \"{path}\"; check its drives)")


@cli.command("export-urdf")
@click.argument("robot")
@out_option("The URDF file to write.", required=True, folder=False)
@overwrite_option("file")
def export_urdf_command(robot: str, out: Path, overwrite: bool) -> None:
    """Write a serial ROBOT (shipped name or description file) as URDF, for ROS and MuJoCo users."""
    from hexadyn.urdf import export_urdf

    click.echo(f"URDF: {export_urdf(robot, out, overwrite)}")


@cli.command("export-mjcf")
@click.argument("robot")
@out_option("The MJCF file to write.", required=True, folder=False)
@overwrite_option("file")
def export_mjcf_command(robot: str, out: Path, overwrite: bool) -> None:
    """Write a ROBOT (shipped name or description file, either leg mechanism) as MuJoCo MJCF."""
    from hexadyn.urdf import export_mjcf

    click.echo(f"MJCF: {export_mjcf(robot, out, overwrite)}")


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
