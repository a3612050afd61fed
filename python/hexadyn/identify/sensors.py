"""The real robot's sensors, for logs that lack them (simulated logs, test fixtures): incremental
encoders on the motor shafts (500 counts per revolution, Section 2.3.2; a position servo's own
sensor on a serial robot, the resolution of its description) and the current sensor
chain of Section 5.6.2 (Hall-effect sensor, 2 A range, a 30 Hz analog low-pass filter, then a
3 Hz digital low-pass filter in the controller), with Gaussian noise.

INTERPRETATION: the thesis gives the cut-off frequencies, not the filter orders: both are taken
first order (one RC stage; one pole in the controller), the analog one discretized at the log's
sampling rate by the bilinear transform (scipy.signal.butter with fs). The noise is white,
added before the analog filter, with a standard deviation in percent of the sensor's full
scale (1-2 % in the issue's test case). The filters are causal, as on the robot.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import signal

from hexadyn.identify.logs import LEGS, Log, column
from hexadyn.identify.torques import joint_constants

__all__ = ["SensorModel", "low_pass", "measure"]

ANALOG_HZ = 30.0
DIGITAL_HZ = 3.0
#: Range of the Hall-effect current sensor (A), Section 5.2.2.
FULL_SCALE_A = 2.0


def low_pass(x: np.ndarray, cutoff_hz: float, dt: float) -> np.ndarray:
    """First-order causal low-pass filter of a signal sampled every `dt`, started at rest on
    the first sample."""
    b, a = signal.butter(1, cutoff_hz, fs=1.0 / dt)
    zi = signal.lfilter_zi(b, a) * x[0]
    return signal.lfilter(b, a, x, zi=zi)[0]


class SensorModel:
    """What the robot's sensors would have recorded.

    Args:
        noise_percent: current noise, standard deviation in % of the 2 A full scale.
        digital_filter: also apply the controller's 3 Hz filter.
        quantize: round the joint positions to the encoder counts.
        seed: of the noise.
    """

    def __init__(self, noise_percent: float = 0.0, digital_filter: bool = True, quantize: bool = True, seed: int = 0) -> None:
        self.noise = noise_percent / 100.0 * FULL_SCALE_A
        self.digital_filter = digital_filter
        self.quantize = quantize
        self.rng = np.random.default_rng(seed)


def _period_mean_current(log: Log, joint: str, leg: int) -> np.ndarray:
    """The mean motor current over each control period, what the analog filter sees (it
    integrates the continuous current), from the engine's cumulative electrical energy
    E_el = integral of u i dt under the held voltage u: (E_el(t_k) - E_el(t_k-1)) / (u_k dt).
    The sampled current where the voltage is zero or the log has no energy column."""
    f = log.frame
    i = f[column("i", joint, leg)].to_numpy(dtype=float)
    energy, voltage = f"E_el_{joint}[{leg}]", column("u", joint, leg)
    if energy not in f or voltage not in f:
        return i
    u = f[voltage].to_numpy(dtype=float)
    de = np.diff(f[energy].to_numpy(dtype=float), prepend=np.nan)
    dt = np.diff(log.t, prepend=np.nan)
    held = np.abs(u) > 1e-9
    mean = np.where(held, de / np.where(held, u, 1.0) / dt, i)
    mean[0] = i[0]
    return mean


def measure(log: Log, sensors: SensorModel) -> Log:
    """The log as the sensors read it: measured current columns ``i_meas_<joint>[leg]`` (noise,
    30 Hz analog and, optionally, 3 Hz digital filtering of the period-mean current) next to
    the true ones, and the positions rounded to encoder counts. The identification then uses the measured currents."""
    frame = log.frame.copy()
    dt = float(np.median(np.diff(log.t)))
    added = {}
    for joint in log.joints.names:
        for leg in LEGS:
            if not log.has(joint, leg):
                continue
            i = _period_mean_current(log, joint, leg)
            i = i + sensors.rng.normal(0.0, sensors.noise, len(i)) if sensors.noise > 0 else i
            i = low_pass(i, ANALOG_HZ, dt)
            if sensors.digital_filter:
                i = low_pass(i, DIGITAL_HZ, dt)
            added[column("i_meas", joint, leg)] = i
            if sensors.quantize:
                step = joint_constants(log, joint, leg)["encoder_resolution"]
                name = column("q", joint, leg)
                frame[name] = np.round(frame[name].to_numpy() / step) * step
    # The sensors' readings replace those of a log that has some (the engine's own sensor model).
    frame = pd.concat([frame.drop(columns=[c for c in added if c in frame.columns]), pd.DataFrame(added, index=frame.index)], axis=1)
    return Log(log.source, frame, log.robot_text, log.foot_load_kg, log.motions)
