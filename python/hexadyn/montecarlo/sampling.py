"""Friction draws of the Monte Carlo runs (Section 6.5, Eq. 6.12, Table 6.7).

Every drawn parameter follows a Gaussian N(mu*, sigma*^2); a value outside mu* +- 3 sigma* or
with a non-physical sign is rejected and drawn again, so each parameter follows the normal
distribution truncated to the intersection of both intervals. The distributions come from the
robot description through ``hexadyn._core.monte_carlo_distributions`` (not computed here), or
from friction statistics (``hexadyn identify``'s ``friction_stats.toml``). A distribution whose
accepted interval a draw falls in with a probability below :data:`MIN_ACCEPTANCE` is refused
before any draw (:meth:`FrictionDistributions.check`): rejection would take more than
1 / MIN_ACCEPTANCE draws per value, and forever for an interval of width zero.

A run is identified by (velocity index, run index); its random stream is
``np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(velocity_index, run_index)))``,
so a draw does not depend on scheduling, worker count or interruptions. Every friction variant
of a run uses the same draw (common random numbers).

The efficiencies of the transmission-efficiency friction (the thesis' prospects, Chapter 8) are
drawn only when friction statistics give them (``hexadyn identify`` of sawtooth logs at several
foot loads), after the robot's Gaussians: the draws of the other parameters stay those of the
robot's set-up.
"""

from __future__ import annotations

import dataclasses
import math
import os
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["FrictionDistributions", "MIN_ACCEPTANCE", "EFFICIENCY_KEYS", "draw_friction", "read_friction_stats"]

#: The smallest probability of a draw to be kept (within +- truncation_sigmas and physical)
#: a distribution may have: at most 100 draws per kept value on average. The shipped robots'
#: lowest is 0.91 (AMRU5's q_r f_v^+, Table 6.7: N(3.46, 2.55^2) kept at or above 0).
MIN_ACCEPTANCE = 0.01

#: The keys of a joint's efficiencies (``model.joint_friction.<joint>.eta_forward``) and their
#: physical values, 0 < eta <= 1 (the law of ``physics/friction.rs``).
EFFICIENCY_KEYS = ("eta_forward", "eta_backward")
EFFICIENCY_BOUNDS = (math.nextafter(0.0, 1.0), 1.0)


@dataclass(frozen=True)
class FrictionDistributions:
    """The Monte Carlo set-up of a robot description (its ``[monte_carlo]`` table).

    Attributes:
        robot: ``"amru5"`` or the robot description file.
        runs_per_velocity, truncation_sigmas, velocities_m_per_s: the defaults of a campaign and
            the truncation (+- 3 sigma in the thesis).
        gaussians: scenario field (``model.joint_friction.q_r.tau_f_d_plus``...) -> (mu, sigma),
            in the order they are drawn.
        physical_bounds: scenario field -> (low, high), the physical values.
        load_parameters: the fields of ``gaussians`` acting only with the load influence
            (Eq. 5.12 coefficients of q_h).
        fixed: scenario field -> value of the parameters set but not drawn (the horizontal
            viscous slopes, neglected in Section 6.5).
        joints: the names of a leg's joints (AMRU5's ``q_r``, ``q_v``, ``q_h``; a serial
            robot's own, which key its fields: ``model.joint_friction.femur.tau_f_d``).
    """

    robot: str
    runs_per_velocity: int
    truncation_sigmas: float
    velocities_m_per_s: tuple[float, ...]
    gaussians: dict[str, tuple[float, float]]
    physical_bounds: dict[str, tuple[float, float]]
    load_parameters: tuple[str, ...]
    fixed: dict[str, float]
    joints: tuple[str, ...] = ("q_r", "q_v", "q_h")

    @classmethod
    def of_robot(cls, robot: str = "amru5") -> FrictionDistributions:
        """Reads the distributions of a robot description (a shipped robot, ``"amru5"`` or
        ``"phantomx"``, or a file path; a serial one needs its ``[monte_carlo]`` table)."""
        from hexadyn import _core

        d = _core.monte_carlo_distributions(robot)
        return cls(
            robot=d["robot"],
            runs_per_velocity=int(d["runs_per_velocity"]),
            truncation_sigmas=float(d["truncation_sigmas"]),
            velocities_m_per_s=tuple(float(v) for v in d["velocities_m_per_s"]),
            gaussians={k: (float(mu), float(sigma)) for k, (mu, sigma) in d["gaussians"].items()},
            physical_bounds={k: (float(lo), float(hi)) for k, (lo, hi) in d["physical_bounds"].items()},
            load_parameters=tuple(d["load_parameters"]),
            fixed={k: float(v) for k, v in d["fixed"].items()},
            joints=tuple(d["joints"]),
        )

    @property
    def efficiency_parameters(self) -> tuple[str, ...]:
        """The fields of ``gaussians`` acting only with the efficiency law."""
        return tuple(f for f in self.gaussians if self._is_efficiency(f))

    def _is_efficiency(self, field: str) -> bool:
        prefix, _, key = field.rpartition(".")
        return key in EFFICIENCY_KEYS and prefix in {f"model.joint_friction.{j}" for j in self.joints}

    def with_stats(self, stats: dict[str, tuple[float, float]], source: str) -> FrictionDistributions:
        """The same set-up with the Gaussians of `stats` (scenario field -> (mu, sigma), e.g.
        identified by ``hexadyn identify``) in place of the robot's, and the joints'
        efficiencies it gives drawn after them. Fields the robot's set-up holds fixed (the
        horizontal viscous slopes, neglected in Section 6.5) are left fixed; any other field
        not drawn is an error naming `source`."""
        unknown = [f for f in stats if f not in self.gaussians and f not in self.fixed and not self._is_efficiency(f)]
        if unknown:
            efficiencies = f"model.joint_friction.<{'|'.join(self.joints)}>.<{'|'.join(EFFICIENCY_KEYS)}>"
            raise ValueError(f"{source}: {', '.join(unknown)}: not a friction parameter of the Monte Carlo runs; allowed: {', '.join(self.gaussians)}, {efficiencies}")
        gaussians = {f: stats.get(f, g) for f, g in self.gaussians.items()}
        added = {f: g for f, g in stats.items() if f not in gaussians and self._is_efficiency(f)}
        bounds = {**self.physical_bounds, **{f: EFFICIENCY_BOUNDS for f in added}}
        return dataclasses.replace(self, gaussians={**gaussians, **added}, physical_bounds=bounds)

    def accepted_interval(self, field: str) -> tuple[float, float]:
        """The values a draw of ``field`` keeps: mu +- truncation_sigmas sigma, physical ones.

        Raises ValueError when the two intervals do not meet (no draw would ever be kept).
        """
        mu, sigma = self.gaussians[field]
        low, high = self.physical_bounds[field]
        k = self.truncation_sigmas
        lo, hi = max(mu - k * sigma, low), min(mu + k * sigma, high)
        if not lo <= hi:
            raise ValueError(f"{self.robot}: {field} ~ N({mu}, {sigma}^2) has no physical value within +-{k} sigma")
        return lo, hi

    def acceptance(self, field: str) -> float:
        """The probability that a draw of ``field`` lies in its :meth:`accepted_interval`
        (1 for sigma = 0: every draw is mu)."""
        mu, sigma = self.gaussians[field]
        lo, hi = self.accepted_interval(field)
        if sigma == 0:
            return 1.0
        a, b = (lo - mu) / sigma, (hi - mu) / sigma
        if a > 0:  # the upper tail, computed as the lower one: no cancellation
            a, b = -b, -a
        return 0.5 * (math.erfc(-b / math.sqrt(2)) - math.erfc(-a / math.sqrt(2)))

    def check(self, source: str) -> None:
        """Refuses a distribution a draw could not honestly come from: an empty accepted
        interval, or one kept with a probability below :data:`MIN_ACCEPTANCE`. `source` names
        where the distributions come from (the robot, a friction statistics file).

        Raises:
            ValueError: naming `source`, the field, the Gaussian and the accepted interval.
        """
        for field, (mu, sigma) in self.gaussians.items():
            try:
                p = self.acceptance(field)
            except ValueError as exc:
                raise ValueError(f"{source}: {exc}") from None
            if p < MIN_ACCEPTANCE:
                lo, hi = self.accepted_interval(field)
                low, high = self.physical_bounds[field]
                raise ValueError(
                    f"{source}: {field} ~ N({mu!r}, {sigma!r}^2) keeps a draw with probability {p:.3g}: its accepted interval "
                    f"[{lo!r}, {hi!r}] is mu +- {self.truncation_sigmas:g} sigma within the physical values [{low!r}, {high!r}]; "
                    f"allowed: a probability of at least {MIN_ACCEPTANCE:g}"
                )


def draw_friction(distributions: FrictionDistributions, seed: int, velocity_index: int, run_index: int) -> dict[str, float]:
    """The friction parameters of run (velocity_index, run_index), all of ``gaussians``.

    Parameters are drawn one after the other in the order of ``distributions.gaussians``, each
    redrawn until it lies in its :meth:`~FrictionDistributions.accepted_interval` (a
    distribution passed by :meth:`~FrictionDistributions.check` takes 1 / MIN_ACCEPTANCE draws
    or fewer on average).
    """
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(velocity_index, run_index)))
    drawn = {}
    for field, (mu, sigma) in distributions.gaussians.items():
        lo, hi = distributions.accepted_interval(field)
        x = math.nan
        while not lo <= x <= hi:
            x = mu + sigma * float(rng.standard_normal())
        drawn[field] = x
    return drawn


def read_friction_stats(path: str | os.PathLike) -> dict[str, tuple[float, float]]:
    """The ``[friction_stats]`` table of a file written by ``hexadyn identify``
    (``friction_stats.toml``): scenario field -> (mu, sigma), sigma >= 0, both finite.

    Raises:
        ValueError: naming the file, the field and the value.
    """
    from hexadyn import inputs

    path = Path(path)
    try:
        table = tomllib.loads(inputs.read_text(path)).get("friction_stats")
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path}: cannot read the friction statistics: {exc}") from exc
    if not isinstance(table, dict) or not table:
        raise ValueError(f"{path}: no [friction_stats] table (the file `hexadyn identify` writes as friction_stats.toml)")
    stats = {}
    for field, entry in table.items():
        mu, sigma = (entry.get("mu"), entry.get("sigma")) if isinstance(entry, dict) else (None, None)
        ok = all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in (mu, sigma))
        if not ok or sigma < 0:
            raise ValueError(f"{path}: field `friction_stats.\"{field}\"` = {entry!r}: need {{ mu = finite, sigma = finite >= 0 }}")
        stats[field] = (float(mu), float(sigma))
    return stats
