"""The figure of the compensation study (matplotlib, Agg canvas; no global backend state)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .dynamic import RUNS, DynamicCompensationResult
from .tracking import CompensationResult

__all__ = ["plot_compensation", "plot_lugre_compensation"]


def plot_compensation(result: CompensationResult, path: str | os.PathLike[str]) -> Path:
    """Write a PNG of the study: reference and joint velocity, tracking error, and torques,
    without and with feed-forward, against time. Written atomically."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ..io.atomic import atomic_path

    runs = result.runs
    t = runs["time"]
    colours = {"without": "tab:red", "with": "tab:blue"}
    labels = {
        "without": "PD only",
        "with": "PD + friction feed-forward",
    }
    fig = Figure(figsize=(9.0, 8.0), layout="constrained")
    FigureCanvasAgg(fig)
    ax_v, ax_e, ax_f = fig.subplots(3, 1, sharex=True)
    ax_v.plot(t, runs["reference_velocity"], color="black", lw=1.0, ls="--", label="reference")
    for k, key in enumerate(("without", "with")):
        ax_v.plot(t, runs["velocity"][k], color=colours[key], lw=0.9, label=labels[key])
        ax_e.plot(
            t,
            1e3 * runs["error"][k],
            color=colours[key],
            lw=0.9,
            label=f"{labels[key]}: RMS {1e3 * result.rms[key]:.3g} mrad, "
            f"max {1e3 * result.max[key]:.3g} mrad",
        )
    ax_f.plot(
        t, runs["friction"][0], color=colours["without"], lw=0.9, label="friction, PD only run"
    )
    ax_f.plot(
        t, runs["friction"][1], color=colours["with"], lw=0.9, label="friction, feed-forward run"
    )
    ax_f.plot(
        t,
        result.feedforward,
        color="black",
        lw=1.0,
        ls="--",
        label=f"feed-forward ({result.model})",
    )
    _label_axes(ax_v, ax_e, ax_f)
    kp, kd = result.config.gains
    title = f"Friction compensation: model '{result.model}', true friction '{result.truth}'"
    if np.isfinite(result.improvement):
        title += f": {result.verdict().split(' (')[0]}"  # only what was measured
    fig.suptitle(f"{title}\n(K_p {kp:.3g} N m/rad, K_d {kd:.3g} N m s/rad)")
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    return path


def plot_lugre_compensation(
    result: DynamicCompensationResult, path: str | os.PathLike[str]
) -> Path:
    """Write a PNG of :func:`fricid.control.dynamic.lugre_compensation_study`: velocity,
    tracking error (zero-velocity crossing windows shaded) and friction against feed-forward,
    for PD only, static feed-forward and the LuGre observer. Written atomically."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ..io.atomic import atomic_path

    runs, t = result.runs, result.runs["time"]
    colours = dict(zip(RUNS, ("tab:red", "tab:orange", "tab:blue"), strict=True))
    fig = Figure(figsize=(9.0, 8.5), layout="constrained")
    FigureCanvasAgg(fig)
    ax_v, ax_e, ax_f = fig.subplots(3, 1, sharex=True)
    ax_v.plot(t, runs["reference_velocity"], color="black", lw=1.0, ls="--", label="reference")
    top = 1e3 * np.abs(runs["error"]).max()
    ax_e.fill_between(
        t, -top, top, where=result.crossing, color="0.9", label="zero-velocity crossings"
    )
    for k, name in enumerate(RUNS):
        c = colours[name]
        ax_v.plot(t, runs["velocity"][k], color=c, lw=0.9, label=name)
        ax_e.plot(
            t,
            1e3 * runs["error"][k],
            color=c,
            lw=0.9,
            label=f"{name}: RMS {1e3 * result.rms[name]:.3g} mrad, at crossings "
            f"{1e3 * result.rms_crossing[name]:.3g} mrad",
        )
        if k:
            ax_f.plot(t, runs["friction"][k], color=c, lw=0.9, label=f"true friction, {name} run")
            ax_f.plot(t, runs["feedforward"][k], color=c, lw=1.0, ls="--", label=f"{name}")
    _label_axes(ax_v, ax_e, ax_f)
    kp, kd = result.config.gains
    fig.suptitle(
        f"LuGre friction compensation: true friction '{result.truth}', model "
        f"'{result.model}'\n(K_p {kp:.3g} N m/rad, K_d {kd:.3g} N m s/rad; crossings: within "
        f"{result.crossing_window:g} periods of each reversal)"
    )
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    return path


def _label_axes(ax_v, ax_e, ax_f) -> None:
    """Units, grid and legend of the velocity, tracking-error and torque panels."""
    ax_v.set_ylabel("velocity [rad/s]")
    ax_e.set_ylabel("tracking error [mrad]")
    ax_f.set_ylabel("torque [N m]")
    ax_f.set_xlabel("time [s]")
    for ax in (ax_v, ax_e, ax_f):
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize="small")
