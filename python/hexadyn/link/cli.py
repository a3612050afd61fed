"""``hexadyn robot``: a scenario's controller on the robot through the master/slave link of
Section 2.3.2 (``robot run``), and six emulated slave boards on the simulated robot to test the
whole chain without it (``robot emulate``). Registered in :mod:`hexadyn.cli`."""

from __future__ import annotations

from pathlib import Path

import click

import hexadyn
from hexadyn.link import resolve_link
from hexadyn.options import no_plots_option, no_progress_option, out_option, overwrite_option, set_option, strict_option, warn_unhealthy

LINK_HELP = "Link configuration file (addresses, period, timing, safety), or 'loopback' for the shipped one on 127.0.0.0/8."


@click.group("robot")
def robot() -> None:
    """Run a scenario on the robot, or emulate the robot's slave boards (Section 2.3.2)."""


def _silent_slave(ctx: click.Context, param: click.Parameter, value: str | None) -> tuple[int, int] | None:
    if value is None:
        return None
    try:
        leg, after = (int(x) for x in value.split(":"))
        if not 0 <= leg < 6 or after < 0:
            raise ValueError
    except ValueError:
        raise click.BadParameter(f"{value!r}; allowed: LEG:COMMANDS, a leg 0..5 and a number of commands >= 0 (e.g. 3:500)") from None
    return leg, after


#: The faults the emulated slaves inject into their packets (`robot emulate`, `robot run --emulated`).
_FAULT_OPTIONS = (
    click.option("--loss", type=click.FloatRange(0, 1), default=0.0, show_default=True, help="Probability that a slave packet is lost."),
    click.option("--delay-ms", type=click.FloatRange(0), default=0.0, show_default=True, help="Extra delay of every slave packet (ms)."),
    click.option("--jitter-ms", type=click.FloatRange(0), default=0.0, show_default=True, help="Extra delay drawn uniformly in [0, jitter] per packet (ms)."),
    click.option("--duplicate", type=click.FloatRange(0, 1), default=0.0, show_default=True, help="Probability that a packet is sent twice."),
    click.option("--reorder", type=click.FloatRange(0, 1), default=0.0, show_default=True, help="Probability that a packet is sent after the slave's next one."),
    click.option("--corrupt", type=click.FloatRange(0, 1), default=0.0, show_default=True, help="Probability that one byte of a packet is changed."),
    click.option("--wrong-size", type=click.FloatRange(0, 1), default=0.0, show_default=True, help="Probability that a packet is cut short or lengthened."),
    click.option("--max-consecutive", type=click.IntRange(0), default=None, help="At most this many packets of one slave destroyed in a row (lost, corrupted, resized)."),
    click.option("--silent-slave", callback=_silent_slave, default=None, help="LEG:COMMANDS: that slave stops answering after so many commands."),
    click.option("--seed", type=click.IntRange(0, 2**64 - 1), default=0, show_default=True, help="Seed of the fault draws."),
)


def _fault_options(command):
    """Adds the fault options to `command` (its function takes them as keyword arguments)."""
    for option in reversed(_FAULT_OPTIONS):
        command = option(command)
    return command


def _faults(loss: float, delay_ms: float, jitter_ms: float, duplicate: float, reorder: float, corrupt: float, wrong_size: float, max_consecutive: int | None, silent_slave: tuple[int, int] | None, seed: int) -> dict:
    """The fault options as the engine takes them (``_core.robot_emulate``, ``_core.robot_run``)."""
    faults = {"loss": loss, "delay_s": delay_ms * 1e-3, "jitter_s": jitter_ms * 1e-3, "duplicate": duplicate, "reorder": reorder, "corrupt": corrupt, "wrong_size": wrong_size, "seed": seed}
    if max_consecutive is not None:
        faults["max_consecutive"] = max_consecutive
    if silent_slave is not None:
        faults["silent_slave"] = silent_slave
    return faults


def _stall(ctx: click.Context, param: click.Parameter, value: str | None) -> tuple[float, float] | None:
    if value is None:
        return None
    try:
        at, ms = (float(x) for x in value.split(":"))
        if not (at >= 0 and ms >= 0):
            raise ValueError
    except ValueError:
        raise click.BadParameter(f"{value!r}; allowed: T:MS, a time T >= 0 s and a duration MS >= 0 ms (e.g. 0.5:60)") from None
    return at, ms * 1e-3


@robot.command("run")
@click.argument("scenario")
@click.option("--link", "link", required=True, help=LINK_HELP)
@set_option()
@out_option("Results folder (default: results/<scenario name>-robot, numbered if it exists).")
@overwrite_option()
@no_progress_option()
@no_plots_option()
@strict_option()
@click.option("--emulated", is_flag=True, help="Drive the six emulated slaves in this process instead of the robot, in lock-step on a virtual clock (free ports of the configured addresses, no real time: the same results on any machine).")
@click.option("--stall-at", callback=_stall, default=None, help="T:MS, with --emulated: the master freezes T seconds after its start for MS milliseconds (virtual time), as a stopped process would: a rehearsal of a master overrun.")
@_fault_options
def run(scenario: str, link: str, overrides: dict, out: Path | None, overwrite: bool, no_progress: bool, no_plots: bool, strict: bool, emulated: bool, stall_at: tuple[float, float] | None, **faults) -> None:
    """Drive the robot with SCENARIO's controller through the link and save what the master saw.

    The master broadcasts the 18 motor commands every period, collects the six slave packets and
    runs the scenario's controller (the one `hexadyn simulate` runs). The results folder is the
    one of `hexadyn simulate`: encoder positions, references, voltages, currents, energies of
    the samples, and the link's timing (lateness, last_reply, missed_periods). A safety stop (a
    slave silent for 3 periods, the master's overrun, a socket error) or Ctrl-C puts every motor
    at 0 V; the results up to it are saved with the reason (summary `safety_stop`,
    `safety_stop_reason`), and the exit status is 1 with that reason on one line. With
    --emulated the master drives `robot emulate`'s six slaves in lock-step instead (a rehearsal
    without timing), with the fault options of `robot emulate` and --stall-at to rehearse the
    safety stops. --set changes the scenario's fields (its description then says so).
    """
    from hexadyn import _core, energy, health, report
    from hexadyn.runner import free_results_folder
    from hexadyn.results import Results

    chosen = hexadyn.Scenario.load(scenario).update(overrides)
    path = chosen.path
    link_path = resolve_link(link)
    rehearsal = {"faults": _faults(**faults), "stall": stall_at} if emulated else {}
    if not emulated:
        defaults = {p.name: p.default for p in click.get_current_context().command.params}
        faulted = [name for name, value in [*faults.items(), ("stall_at", stall_at)] if value != defaults[name]]
        if faulted:
            raise click.ClickException(f"--{faulted[0].replace('_', '-')}: faults are rehearsed on the emulated slaves only; allowed with --emulated")
    if out is None:
        out = free_results_folder(f"{chosen.name}-robot")
    elif out.exists() and not overwrite:
        raise click.ClickException(f"{out}: the results folder exists; use --overwrite or another --out")
    fields = chosen.overrides() or None
    if no_progress:
        raw = _core.robot_run(str(path), str(link_path), overrides=fields, emulated=emulated, **rehearsal)
    else:
        from tqdm.auto import tqdm

        with tqdm(total=chosen.duration_s, desc=f"{chosen.name} (robot)", unit="s", bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.2f}/{total:.2f} s [{elapsed}<{remaining}]") as bar:
            raw = _core.robot_run(str(path), str(link_path), lambda t, _d: bar.update(max(0.0, t - bar.n)), fields, emulated=emulated, **rehearsal)
    results = Results.from_engine(raw, scenario_path=path)
    energy.add_energy_figures(results)
    results.summary["warnings"] = health.check(results.summary)
    report.save(results, out, overwrite=overwrite)
    if not no_plots and report.skipped_analysis(results) is None:
        _save_plots(results, out / report.PLOTS_DIR, progress=not no_progress)
    s = results.summary
    click.echo(f"Results: {out}")
    click.echo(f"  scenario    {chosen.name} ({path}) on the link {link_path}")
    click.echo(f"  ran         {s['duration_s']:.2f} s, {s['control_periods']} control periods, {s['missed_periods']} missed, real-time threads: {s['realtime']}")
    click.echo(f"  lateness    p50 {s['lateness_p50_s'] * 1e6:.1f} us, p99 {s['lateness_p99_s'] * 1e6:.1f} us, max {s['lateness_max_s'] * 1e6:.1f} us (broadcast against its deadline)")
    click.echo(f"  slaves      last packet p50 {s['last_reply_p50_s'] * 1e3:.2f} ms after the broadcast; controller p99 {s['controller_p99_s'] * 1e3:.3f} ms")
    dropped = {k[len("packets_") :]: v for k, v in s.items() if k.startswith("packets_") and v}
    click.echo(f"  dropped     {', '.join(f'{v} {k}' for k, v in dropped.items()) or 'none'}")
    for period, message in raw["events"][:10]:
        click.echo(f"    period {period}: {message}")
    if len(raw["events"]) > 10:
        click.echo(f"    ... {len(raw['events']) - 10} more events")
    click.echo(f"  energy      electrical {s['energy_electrical_j']:.4g} J (sampled u i), max |u| {s['max_abs_voltage_v']:.2f} V")
    if raw["stop"] is not None:
        warn_unhealthy(s["warnings"], strict=False)  # the safety stop's status 1 comes first
        raise click.ClickException(raw["stop"])
    warn_unhealthy(s["warnings"], strict)


def _save_plots(results, folder: Path, progress: bool) -> None:
    """The figures of `hexadyn simulate` that what the master saw supports: per joint of legs 0
    and 2, the gait diagram, the averaged power and the energy breakdown (not the trajectory:
    the robot has no navigation system to measure its body position)."""
    from hexadyn import atomic, energy, plots

    figures = {f"leg{leg}_{j}": plots.joint_figure(results, leg, j) for leg in plots.DEFAULT_LEGS for j in results.joints.names}
    if energy.foot_phases(results) is not None:
        figures["gait_diagram"] = plots.gait_diagram(results)
    figures["averaged_power"] = plots.averaged_power_figure(results)
    figures["energy_breakdown"] = plots.energy_breakdown_figure(results)
    atomic.write_folder(folder, lambda tmp: plots.save_figures(figures, tmp, ("png",), progress=progress))


@robot.command("emulate")
@click.argument("scenario")
@click.option("--link", "link", required=True, help=LINK_HELP)
@set_option()
@_fault_options
@click.option("--idle-timeout", type=click.FloatRange(0, min_open=True), default=None, help="Stop after this many seconds without a command, once the first came (default: run until Ctrl-C).")
def emulate(scenario: str, link: str, overrides: dict, idle_timeout: float | None, **faults) -> None:
    """Emulate the six slave boards on SCENARIO's simulated robot.

    Each command packet applies the 18 duties to the multiphysics model, which advances one
    control period; slave l answers 2.5 ms + l x 0.5 ms after the broadcast (Figs. 2.21-2.22)
    with the encoder counts, currents and supply of the model. The boards follow the master of
    their handshake (its address, port and run number) and refuse every other command; 50 ms
    without a command, their watchdog sets every output to 0 V. Faults are injected into the
    slave packets as asked; --set changes the fields of the simulated robot's scenario. Stop
    with Ctrl-C (or --idle-timeout).
    """
    from hexadyn import _core

    chosen = hexadyn.Scenario.load(scenario).update(overrides)
    path = chosen.path
    link_path = resolve_link(link)
    def ready() -> None:
        click.echo(f"Emulating the six slaves of {path.stem} with the link {link_path}; Ctrl-C to stop", err=True)

    report = _core.robot_emulate(str(path), str(link_path), _faults(**faults), idle_timeout, ready, chosen.overrides() or None)
    f = {k: v for k, v in report["faults"].items() if v}
    click.echo(f"Emulator: {report['commands']} commands applied ({report['t']:.2f} s simulated), {report['sent']} packets sent, {report['ignored']} commands ignored (old), {report['rejected']} rejected")
    click.echo(f"  refused     {report['refused']} commands not from the boards' master; watchdog: outputs at 0 V {report['watchdog_trips']} time(s), 50 ms after a master's last command")
    click.echo(f"  faults      {', '.join(f'{v} {k}' for k, v in f.items()) or 'none'}")
    click.echo(f"  model       period p99 {report['step_time_p99_s'] * 1e3:.2f} ms, max {report['step_time_max_s'] * 1e3:.2f} ms; real-time threads: {report['realtime']}")
    x, y = report["body"][:2]
    click.echo(f"  body        X = {x:.4f} m, Y = {y:.4f} m at the end")
    if report["error"]:
        raise click.ClickException(report["error"])
    if report["interrupted"]:
        raise SystemExit(130)
