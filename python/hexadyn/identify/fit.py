"""Least-squares fits with their uncertainty: a linear model y = X p fitted by
``scipy.optimize.least_squares``, with a confidence interval per parameter from the Jacobian
(the covariance s^2 (J^T J)^-1 with Student's t) and one by bootstrap (the points resampled
with replacement, percentile interval).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize, stats

__all__ = ["Estimate", "fit_linear", "LEVEL", "BOOTSTRAP_SAMPLES"]

#: Confidence level of the intervals.
LEVEL = 0.95
#: Bootstrap resamples (seeded: the intervals are reproducible).
BOOTSTRAP_SAMPLES = 2000


@dataclass(frozen=True)
class Estimate:
    """A fitted parameter: value, standard error and the two confidence intervals (NaN where
    the points do not determine them: as many points as parameters)."""

    value: float
    stderr: float
    ci_low: float
    ci_high: float
    boot_low: float
    boot_high: float

    def covers(self, truth: float) -> bool:
        """Whether the Jacobian interval holds `truth`."""
        return self.ci_low <= truth <= self.ci_high


def fit_linear(X: np.ndarray, y: np.ndarray, seed: int = 0) -> list[Estimate]:
    """Fits y ~ X p (X: n x m, n >= m) by least squares and returns one :class:`Estimate` per
    column of X."""
    X = np.asarray(X, dtype=float)
    y = np.asarray(y, dtype=float)
    n, m = X.shape
    p, jac, residual = _solve(X, y)
    dof = n - m
    if dof > 0:
        s2 = float(residual @ residual) / dof
        cov = s2 * np.linalg.pinv(jac.T @ jac)
        stderr = np.sqrt(np.maximum(np.diag(cov), 0.0))
        half = stats.t.ppf(0.5 + LEVEL / 2, dof) * stderr
    else:
        stderr = np.full(m, np.nan)
        half = np.full(m, np.nan)
    boot = _bootstrap(X, y, seed) if n > m else np.full((2, m), np.nan)
    return [Estimate(float(p[k]), float(stderr[k]), float(p[k] - half[k]), float(p[k] + half[k]), float(boot[0, k]), float(boot[1, k])) for k in range(m)]


def _solve(X: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    # Scaled columns: dry friction (~1e2 N) and viscous slopes (~1e4 N s/m) side by side.
    scale = np.where(np.abs(X).max(axis=0) > 0, np.abs(X).max(axis=0), 1.0)
    Xs = X / scale
    start = np.linalg.lstsq(Xs, y, rcond=None)[0]
    result = optimize.least_squares(lambda p: Xs @ p - y, start, jac=lambda p: Xs, method="lm" if len(y) >= X.shape[1] else "trf")
    p = result.x / scale
    return p, X, y - X @ p


def _bootstrap(X: np.ndarray, y: np.ndarray, seed: int) -> np.ndarray:
    """Percentile interval of the pairs bootstrap (resamples that cannot determine p, a
    singular normal matrix, are skipped)."""
    rng = np.random.default_rng(seed)
    n, m = X.shape
    scale = np.where(np.abs(X).max(axis=0) > 0, np.abs(X).max(axis=0), 1.0)
    k = rng.integers(0, n, (BOOTSTRAP_SAMPLES, n))
    Xb, yb = X[k] / scale, y[k]
    normal = np.einsum("bni,bnj->bij", Xb, Xb)
    rhs = np.einsum("bni,bn->bi", Xb, yb)
    ok = np.linalg.cond(normal) < 1e12
    draws = np.linalg.solve(normal[ok], rhs[ok][..., None])[..., 0] / scale
    alpha = (1 - LEVEL) / 2
    return np.quantile(draws, [alpha, 1 - alpha], axis=0)
