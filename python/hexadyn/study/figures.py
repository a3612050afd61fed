"""The figures of a design study, one set per output:

- ``response_<output>``: the output against each parameter (one panel per parameter), every
  run a point; on a grid the mean over the other parameters at each level is joined by a line;
- ``sobol_<output>``: the first-order and total Sobol' indices per parameter, bars with their
  confidence intervals;
- ``morris_<output>``: Morris' mu* against sigma, each parameter a labelled point with the
  confidence interval of mu*.

Written with :func:`hexadyn.plots.save_figures` (the project's style, PNG at 300 dpi).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from hexadyn.study.spec import StudySpec

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["figures"]


def figures(spec: StudySpec, runs: pd.DataFrame, indices: pd.DataFrame | None) -> dict[str, Figure]:
    """Every figure of the study by file stem (``response_specific_resistance``...)."""
    figs = {}
    ok = runs[runs["status"] == "ok"]
    for output in spec.outputs:
        figs[f"response_{output}"] = _response(spec, ok, output)
        rows = None if indices is None else indices[indices["output"] == output]
        if rows is not None and spec.design.method == "sobol":
            figs[f"sobol_{output}"] = _sobol(spec, rows, output)
        elif rows is not None:
            figs[f"morris_{output}"] = _morris(spec, rows, output)
    return figs


def _response(spec: StudySpec, runs: pd.DataFrame, output: str) -> Figure:
    n = len(spec.parameters)
    cols = n if n <= 3 else math.ceil(math.sqrt(n))
    fig = Figure(figsize=(3.6 * cols, 3.0 * math.ceil(n / cols)), layout="constrained")
    axes = fig.subplots(math.ceil(n / cols), cols, squeeze=False, sharey=True).ravel()
    for ax, p in zip(axes, spec.parameters):
        ax.plot(runs[p.key], runs[output], ".", alpha=0.6 if len(runs) < 200 else 0.25, markersize=4)
        if spec.design.method == "grid" and len(runs):
            means = runs.groupby(p.key)[output].mean()
            ax.plot(means.index, means.to_numpy(), "o-", color="C1", label="mean over the others")
            ax.legend(loc="best", fontsize="small")
        ax.set_xlabel(p.key)
        ax.grid(True, alpha=0.3)
    for ax in axes[::cols]:
        ax.set_ylabel(output)
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.suptitle(f"{spec.name}: {output} ({spec.design.method}, {len(runs)} runs)")
    return fig


def _sobol(spec: StudySpec, rows: pd.DataFrame, output: str) -> Figure:
    fig = Figure(figsize=(max(4.0, 1.3 * len(rows) + 2.0), 3.6), layout="constrained")
    ax = fig.subplots()
    x = np.arange(len(rows))
    width = 0.38
    ax.bar(x - width / 2, rows["S1"], width, yerr=rows["S1_conf"], capsize=3, label="first order S1")
    ax.bar(x + width / 2, rows["ST"], width, yerr=rows["ST_conf"], capsize=3, label="total ST")
    ax.set_xticks(x, rows["parameter"], rotation=20, ha="right")
    ax.axhline(0.0, color="black", linewidth=0.6)
    ax.set_ylabel("Sobol' index")
    ax.set_title(f"{spec.name}: {output}, {spec.design.confidence:.0%} confidence intervals")
    ax.legend()
    ax.grid(True, axis="y", alpha=0.3)
    return fig


def _morris(spec: StudySpec, rows: pd.DataFrame, output: str) -> Figure:
    fig = Figure(figsize=(5.0, 4.0), layout="constrained")
    ax = fig.subplots()
    ax.errorbar(rows["mu_star"], rows["sigma"], xerr=rows["mu_star_conf"], fmt="o", capsize=3)
    for _, row in rows.iterrows():
        ax.annotate(row["parameter"], (row["mu_star"], row["sigma"]), textcoords="offset points", xytext=(4, 4), fontsize="small")
    ax.set_xlabel("μ* (mean |elementary effect|)")
    ax.set_ylabel("σ (std of the elementary effects)")
    ax.set_title(f"{spec.name}: {output}, Morris")
    ax.grid(True, alpha=0.3)
    return fig
