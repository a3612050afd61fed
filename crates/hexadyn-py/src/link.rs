//! The robot link (`hexadyn.link`): the packet codecs (for the Python mirror and tools), a
//! scenario run on the robot through the master (`robot_run`) and the slave emulator
//! (`robot_emulate`). Both block without the GIL and check for Ctrl-C every 100 ms.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use hexadyn::link::clock::{Clock, VirtualClock};
use hexadyn::link::emulator::{Emulator, EmulatorOptions, EmulatorReport};
use hexadyn::link::faults::Faults;
use hexadyn::link::protocol::{Commands, Duty, Goal, MotorCommands, Protocol, ServoCommands, Setpoint, SlaveReply, COMMAND_SIZE};
use hexadyn::link::run::spawn_robot_run;
use hexadyn::link::LinkConfig;
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use crate::scenario::load;

const POLL: Duration = Duration::from_millis(100);

fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

fn config(path: &PathBuf) -> PyResult<LinkConfig> {
    LinkConfig::from_file(path).map_err(value_error)
}

/// The protocol of version 3 (motor duties) or 4 (servo goals).
fn protocol(version: u8) -> PyResult<Protocol> {
    Protocol::of_version(version).ok_or_else(|| value_error(format!("protocol version {version}: allowed 3 (motor duties) or 4 (servo goals)")))
}

fn command_bytes<S: Setpoint>(seq: u16, run: u32, setpoints: Vec<S>) -> PyResult<[u8; COMMAND_SIZE]> {
    let setpoints: [S; 18] = setpoints.try_into().map_err(|d: Vec<S>| value_error(format!("{} setpoints: allowed 18", d.len())))?;
    Ok(Commands { seq, run, setpoints }.encode())
}

/// The 36-byte command packet of sequence number `seq` and run number `run` with 18 setpoints:
/// signed duties (-1023..1023) for `version` 3, servo command words (bits 0-10 the goal
/// register, bit 11 the torque enable: 0..4095) for version 4.
#[pyfunction]
#[pyo3(signature = (seq, setpoints, version = 3, run = 0))]
pub fn encode_command<'py>(py: Python<'py>, seq: u16, setpoints: Vec<i32>, version: u8, run: u32) -> PyResult<Bound<'py, PyBytes>> {
    let bytes = match protocol(version)? {
        Protocol::Motors => command_bytes(seq, run, setpoints.iter().map(|&d| i16::try_from(d).ok().and_then(Duty::new).ok_or_else(|| value_error(format!("duty {d}: allowed -1023..1023")))).collect::<PyResult<_>>()?)?,
        Protocol::Servos => command_bytes(seq, run, setpoints.iter().map(|&w| u16::try_from(w).ok().filter(|&w| w < 1 << 12).and_then(|w| Goal::from_word(w).ok()).ok_or_else(|| value_error(format!("servo word {w}: allowed 0..4095")))).collect::<PyResult<_>>()?)?,
    };
    Ok(PyBytes::new(py, &bytes))
}

/// Decodes a command packet of `version`: (seq, run, setpoints as in `encode_command`);
/// ValueError naming why it is rejected.
#[pyfunction]
#[pyo3(signature = (data, version = 3))]
pub fn decode_command(data: &[u8], version: u8) -> PyResult<(u16, u32, Vec<i32>)> {
    match protocol(version)? {
        Protocol::Motors => MotorCommands::decode(data).map(|c| (c.seq, c.run, c.setpoints.iter().map(|d| i32::from(d.get())).collect())),
        Protocol::Servos => ServoCommands::decode(data).map(|c| (c.seq, c.run, c.setpoints.iter().map(|g| i32::from(g.bits())).collect())),
    }
    .map_err(value_error)
}

/// The 20-byte slave packet of `version` (fields saturated to their ranges as a board's
/// counters and A/D converters are; `leg` modulo 6).
#[pyfunction]
#[pyo3(signature = (leg, seq, counts, currents_ma, supply, version = 3))]
pub fn encode_reply<'py>(py: Python<'py>, leg: u8, seq: u16, counts: [i32; 3], currents_ma: [i16; 3], supply: u8, version: u8) -> PyResult<Bound<'py, PyBytes>> {
    Ok(PyBytes::new(py, &SlaveReply { leg, seq, counts, currents_ma, supply }.encode(protocol(version)?)))
}

/// Decodes a slave packet of `version`: (leg, seq, counts, currents_ma, supply); ValueError
/// naming why it is rejected.
#[pyfunction]
#[pyo3(signature = (data, version = 3))]
pub fn decode_reply(data: &[u8], version: u8) -> PyResult<(u8, u16, [i32; 3], [i16; 3], u8)> {
    let r = SlaveReply::decode(data, protocol(version)?).map_err(value_error)?;
    Ok((r.leg, r.seq, r.counts, r.currents_ma, r.supply))
}

/// Runs the scenario's controller on the robot through the link configured in `link` (with
/// `emulated`, on the six emulated slaves instead, in this process, in lock-step on a virtual
/// clock: free ports of the configured addresses, no real time, the same outcome on any
/// machine) and returns the dict of `run_scenario` ("columns", "units", "descriptions", "summary",
/// "scenario", "robot", "robot_source") plus "events" (the dropped packets and missed periods
/// the master logged, as (period, message)), "stop" (the safety stop, or None) and, with
/// `emulated`, "emulator" (the emulator's report, as `robot_emulate` returns it). Ctrl-C
/// stops the robot at the next period (0 V) and returns what was recorded. `progress(t_s,
/// duration_s)` is called every 100 ms. With `emulated`, a rehearsal of faults: `faults` as
/// `robot_emulate` takes them, and `stall` = (t_s, duration_s): the master freezes `t_s` seconds
/// after its start (virtual time) for `duration_s`. Raises ValueError for invalid files, a
/// scenario that does not fit the link, or slaves that do not answer (in time).
#[pyfunction]
#[pyo3(signature = (scenario, link, progress = None, overrides = None, emulated = false, faults = None, stall = None))]
#[allow(clippy::too_many_arguments)]
pub fn robot_run<'py>(
    py: Python<'py>,
    scenario: PathBuf,
    link: PathBuf,
    progress: Option<Py<PyAny>>,
    overrides: Option<Bound<'py, PyDict>>,
    emulated: bool,
    faults: Option<Bound<'py, PyDict>>,
    stall: Option<(f64, f64)>,
) -> PyResult<Bound<'py, PyDict>> {
    let s = load(&scenario, overrides.as_ref())?;
    let mut config = config(&link)?;
    let (text, robot, robot_source, duration) = (s.text.clone(), s.robot_text.clone(), s.robot_source.clone(), s.duration);
    if !emulated && (faults.is_some() || stall.is_some()) {
        return Err(value_error("faults and a master stall are rehearsed on the emulated slaves only: allowed with emulated = True"));
    }
    let faults = faults_from(faults.as_ref())?;
    let (clock, emulator) = if emulated {
        let v = VirtualClock::new();
        if let Some((at, length)) = stall {
            let seconds = |x: f64, what: &str| if x.is_finite() && x >= 0.0 { Ok(Duration::from_secs_f64(x)) } else { Err(value_error(format!("stall {what} = {x} s: allowed a time >= 0"))) };
            v.stall(v.now() + seconds(at, "instant")?, seconds(length, "duration")?);
        }
        let clock = Clock::Virtual(v);
        config.master.set_port(0);
        config.broadcast.set_port(0);
        let emulator = py.detach(|| Emulator::start(&s, &config, EmulatorOptions { clock: clock.clone(), faults, ..Default::default() })).map_err(value_error)?;
        config.broadcast.set_port(emulator.command_address().port());
        (clock, Some(emulator))
    } else {
        (Clock::Monotonic, None)
    };
    let handle = spawn_robot_run(s, config, clock).map_err(value_error)?;
    let mut python_error = None;
    while !handle.is_finished() {
        py.detach(|| std::thread::sleep(POLL));
        let called = py.check_signals().and_then(|()| match &progress {
            Some(f) => f.call1(py, (handle.t(), duration)).map(|_| ()),
            None => Ok(()),
        });
        if let Err(e) = called {
            handle.interrupt();
            if !e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) {
                python_error = Some(e);
            }
        }
    }
    let run = py.detach(|| handle.join()).map_err(value_error)?;
    let emulator = emulator.map(|e| py.detach(|| e.stop()));
    if let Some(e) = python_error {
        return Err(e);
    }
    let (columns, units, descriptions) = (PyDict::new(py), PyDict::new(py), PyDict::new(py));
    for c in run.series.columns {
        units.set_item(&c.name, c.unit)?;
        descriptions.set_item(&c.name, &c.description)?;
        columns.set_item(&c.name, PyArray1::from_vec(py, c.values))?;
    }
    let d = PyDict::new(py);
    d.set_item("columns", columns)?;
    d.set_item("units", units)?;
    d.set_item("descriptions", descriptions)?;
    d.set_item("summary", crate::scenario::entries_dict(py, run.summary)?)?;
    d.set_item("scenario", text)?;
    d.set_item("robot", robot)?;
    d.set_item("robot_source", robot_source)?;
    d.set_item("events", run.events.into_iter().map(|e| (e.period, e.message)).collect::<Vec<_>>())?;
    d.set_item("stop", run.stop.map(|s| s.to_string()))?;
    if let Some(report) = emulator {
        d.set_item("emulator", report_dict(py, &report, false)?)?;
    }
    Ok(d)
}

/// Emulates the six slave boards on the scenario's simulated robot with the link configured in
/// `link`, until Ctrl-C or `idle_timeout_s` without a command after the first one (None: until
/// Ctrl-C). `faults` maps fault names to values: loss, duplicate, reorder, corrupt,
/// wrong_size (probabilities), delay_s, jitter_s, max_consecutive (int), silent_slave
/// (leg, after_commands) and seed. `ready()` is called once the slaves listen. Returns the
/// report as a dict.
#[pyfunction]
#[pyo3(signature = (scenario, link, faults = None, idle_timeout_s = None, ready = None, overrides = None))]
pub fn robot_emulate<'py>(
    py: Python<'py>,
    scenario: PathBuf,
    link: PathBuf,
    faults: Option<Bound<'py, PyDict>>,
    idle_timeout_s: Option<f64>,
    ready: Option<Py<PyAny>>,
    overrides: Option<Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let s = load(&scenario, overrides.as_ref())?;
    let config = config(&link)?;
    let faults = faults_from(faults.as_ref())?;
    let idle_timeout = idle_timeout_s.map(|t| if t.is_finite() && t > 0.0 { Ok(Duration::from_secs_f64(t)) } else { Err(value_error(format!("idle timeout {t} s: allowed a time > 0"))) }).transpose()?;
    let emulator = py.detach(|| Emulator::start(&s, &config, EmulatorOptions { faults, idle_timeout, ..Default::default() })).map_err(value_error)?;
    if let Some(f) = ready {
        f.call0(py)?;
    }
    let mut interrupted = None;
    while !emulator.is_finished() {
        py.detach(|| std::thread::sleep(POLL));
        if let Err(e) = py.check_signals() {
            interrupted = Some(e);
            break;
        }
    }
    let report = py.detach(|| emulator.wait(&AtomicBool::new(true)));
    report_dict(py, &report, interrupted.is_some())
}

/// An emulator's report as a dict.
fn report_dict<'py>(py: Python<'py>, report: &EmulatorReport, interrupted: bool) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("commands", report.commands)?;
    d.set_item("sent", report.sent)?;
    d.set_item("ignored", report.refused.old)?;
    d.set_item("rejected", report.refused.rejected.total())?;
    d.set_item("refused", report.refused.foreign())?;
    d.set_item("watchdog_trips", report.watchdog.len())?;
    let f = report.faults;
    let fd = PyDict::new(py);
    for (k, v) in [("lost", f.lost), ("silenced", f.silenced), ("duplicated", f.duplicated), ("reordered", f.reordered), ("corrupted", f.corrupted), ("wrong_size", f.wrong_size)] {
        fd.set_item(k, v)?;
    }
    d.set_item("faults", fd)?;
    d.set_item("t", report.t)?;
    d.set_item("body", report.body.to_vec())?;
    d.set_item("step_time_p99_s", report.step_time.p99)?;
    d.set_item("step_time_max_s", report.step_time.max)?;
    d.set_item("realtime", report.realtime)?;
    d.set_item("error", report.error.clone())?;
    d.set_item("interrupted", interrupted)?;
    Ok(d)
}

fn faults_from(d: Option<&Bound<'_, PyDict>>) -> PyResult<Faults> {
    let mut f = Faults::default();
    let Some(d) = d else { return Ok(f) };
    for (k, v) in d.iter() {
        let key: String = k.extract()?;
        let bad = |allowed: &str| value_error(format!("fault {key} = {v}: allowed {allowed}"));
        let seconds = |v: &Bound<'_, PyAny>| -> PyResult<Duration> {
            let x: f64 = v.extract()?;
            if x.is_finite() && x >= 0.0 { Ok(Duration::from_secs_f64(x)) } else { Err(bad("a time >= 0 s")) }
        };
        match key.as_str() {
            "loss" => f.loss = v.extract()?,
            "duplicate" => f.duplicate = v.extract()?,
            "reorder" => f.reorder = v.extract()?,
            "corrupt" => f.corrupt = v.extract()?,
            "wrong_size" => f.wrong_size = v.extract()?,
            "delay_s" => f.delay = seconds(&v)?,
            "jitter_s" => f.jitter = seconds(&v)?,
            "max_consecutive" => f.max_consecutive = v.extract()?,
            "silent_slave" => f.silent_slave = v.extract()?,
            "seed" => f.seed = v.extract()?,
            _ => return Err(bad("one of loss, duplicate, reorder, corrupt, wrong_size, delay_s, jitter_s, max_consecutive, silent_slave, seed")),
        }
    }
    f.validate().map_err(value_error)?;
    Ok(f)
}
