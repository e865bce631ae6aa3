"""Figures of the two seed papers, drawn from arrays (the reproductions compute the arrays).

[B] is the BAS-RBFNN paper, [R] the RWSAVSBAS paper (see
:mod:`fricid.experiments.paper_numbers`). Every function returns PNG bytes.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .style import COLORS, new_figure, png, styled, torque_scale, velocity_scale

__all__ = [
    "error_per_point",
    "gravity_fit",
    "indicator_bars",
    "mse_curves",
    "prediction_panels",
    "stribeck_construction",
    "surfaces",
    "unseen_region",
]


def gravity_fit(
    theta: np.ndarray,
    tau_g: np.ndarray,
    fits: Mapping[str, tuple[float, float]],
    *,
    title: str = "Gravity torque and its eq. 7 fit",
) -> bytes:
    """[B] Fig. 1: gravity torque estimates ``-(tau+ + tau-)/2`` (eq. 11) against joint
    position, with ``tau_g = p_x cos(theta) - p_y sin(theta)`` (eq. 7) for each named
    ``(p_x, p_y)`` (ours, the paper's, the virtual joint's truth)."""
    theta = np.asarray(theta, dtype=float)
    deg = np.degrees(theta)
    f, unit = torque_scale(tau_g)
    grid = np.linspace(theta.min() - np.radians(2), theta.max() + np.radians(2), 200)
    styles = ["-", "--", ":"]
    with styled():
        fig, axes = new_figure(width=6.8, height=4.3)
        ax = axes[0, 0]
        ax.plot(
            deg,
            np.asarray(tau_g) * f,
            "o",
            ms=4,
            alpha=0.55,
            mec="none",
            color=COLORS[0],
            label="estimates, eq. 11 (one per operating point)",
        )
        for k, (name, (px, py)) in enumerate(fits.items()):
            ax.plot(
                np.degrees(grid),
                (px * np.cos(grid) - py * np.sin(grid)) * f,
                styles[k % 3],
                color=COLORS[(k + 1) % len(COLORS)],
                label=f"{name}: p_x = {px:.4g}, p_y = {py:.4g} N m",
            )
        ax.set_xlabel("joint position θ [deg]")
        ax.set_ylabel(f"gravity torque τ_g [{unit}]")
        ax.legend(loc="best")
        ax.set_title(title)
        return png(fig)


def surfaces(panels: list[dict], *, title: str) -> bytes:
    """[B] Fig. 6 a-c: friction over two factors, one 3-D surface per panel.

    Each panel: ``x, y`` (1-D axes), ``z`` (len(y), len(x)), ``xlabel, ylabel, title`` and
    optionally ``xlog`` (x is drawn as log10 with the real values as tick labels).
    """
    zall = np.concatenate([np.ravel(p["z"]) for p in panels])
    f, unit = torque_scale(zall)
    with styled():
        fig = None
        fig, axes = new_figure(
            1, len(panels), width=5.0 * len(panels), height=4.6, subplot_kw={"projection": "3d"}
        )
        for ax, p in zip(axes[0], panels, strict=True):
            x = np.asarray(p["x"], dtype=float)
            xs = np.log10(x) if p.get("xlog") else x
            X, Y = np.meshgrid(xs, np.asarray(p["y"], dtype=float))
            ax.plot_surface(
                X,
                Y,
                np.asarray(p["z"]) * f,
                cmap="viridis",
                edgecolor="0.3",
                linewidth=0.3,
                alpha=0.95,
                antialiased=True,
            )
            if p.get("xlog"):
                ticks = [t for t in (0.1, 0.3, 1, 3, 10, 30, 100) if x.min() <= t <= x.max()]
                ax.set_xticks(np.log10(ticks), [f"{t:g}" for t in ticks])
            ax.set_xlabel(p["xlabel"], labelpad=6)
            ax.set_ylabel(p["ylabel"], labelpad=6)
            ax.set_zlabel(f"friction [{unit}]", labelpad=8)
            ax.set_title(p["title"], fontsize=10)
            ax.view_init(elev=24, azim=p.get("azim", -128))
            ax.tick_params(labelsize=8, pad=1)
            ax.set_box_aspect(None, zoom=0.86)
        fig.suptitle(title, fontweight="bold")
        return png(fig)


def indicator_bars(
    ours: Mapping[str, Mapping[str, float]],
    paper: Mapping[str, Mapping[str, float]],
    labels: Mapping[str, str],
    *,
    title: str,
) -> bytes:
    """[B] Fig. 7: fitness, RMSE and RMSPE of each model, each normalised by its largest value
    over the models (as the paper's normalised indicators), ours beside the paper's."""
    models = list(ours)
    keys = [("fitness", "fitness R²"), ("rmse", "RMSE"), ("rmspe", "RMSPE")]
    with styled():
        fig, axes = new_figure(1, 3, width=11.0, height=3.9)
        for ax, (key, name) in zip(axes[0], keys, strict=True):
            ov = np.array([ours[m][key] for m in models], dtype=float)
            pv = np.array([paper.get(m, {}).get(key, np.nan) for m in models], dtype=float)
            x = np.arange(len(models))
            ax.bar(x - 0.19, ov / np.nanmax(np.abs(ov)), 0.36, color=COLORS[0], label="ours")
            ax.bar(
                x + 0.19,
                pv / np.nanmax(np.abs(pv)),
                0.36,
                color=COLORS[1],
                alpha=0.8,
                hatch="//",
                edgecolor="white",
                label="paper",
            )
            ax.set_xticks(x, [labels[m] for m in models], rotation=12)
            ax.set_title(name)
            ax.set_ylim(0, 1.12)
            ax.grid(axis="x", visible=False)
        axes[0, 0].set_ylabel("normalised value (÷ largest)")
        axes[0, 1].legend(loc="upper right")
        fig.suptitle(title, fontweight="bold")
        return png(fig)


def prediction_panels(
    measured: np.ndarray,
    predictions: Mapping[str, np.ndarray],
    *,
    title: str,
    letters: str = "abcdef",
) -> bytes:
    """[B] Fig. 8 a-f: for each model, predicted and measured friction over the sample index
    (left) and the prediction error (right)."""
    measured = np.asarray(measured, dtype=float)
    f, unit = torque_scale(measured)
    errs = {k: measured - np.asarray(v) for k, v in predictions.items()}
    ef, eunit = torque_scale(np.concatenate(list(errs.values())))
    n = len(predictions)
    idx = np.arange(1, measured.size + 1)
    with styled():
        fig, axes = new_figure(n, 2, width=12.0, height=2.7 * n + 0.6, sharex=True)
        elim = max(float(np.max(np.abs(e))) for e in errs.values()) * ef * 1.08
        for r, (name, pred) in enumerate(predictions.items()):
            a, b = axes[r]
            a.plot(
                idx,
                measured * f,
                "o",
                ms=2.5,
                color="0.35",
                alpha=0.6,
                mec="none",
                label="measured",
            )
            a.plot(
                idx,
                np.asarray(pred) * f,
                "-",
                lw=0.9,
                color=COLORS[r % len(COLORS)],
                label="predicted",
            )
            a.set_ylabel(f"friction [{unit}]")
            a.set_title(
                f"({letters[2 * r]}) {name}: predicted and measured", loc="left", fontsize=10
            )
            a.legend(loc="upper right", ncols=2)
            e = errs[name] * ef
            b.plot(idx, e, "-", lw=0.8, color=COLORS[r % len(COLORS)])
            b.axhline(0, color="0.3", lw=0.7)
            b.set_ylim(-elim, elim)
            b.set_ylabel(f"error [{eunit}]")
            mean = float(np.mean(np.abs(e)))
            b.set_title(
                f"({letters[2 * r + 1]}) {name}: error, mean |e| {mean:.3g} {eunit}",
                loc="left",
                fontsize=10,
            )
        axes[-1, 0].set_xlabel("sample number")
        axes[-1, 1].set_xlabel("sample number")
        fig.suptitle(title, fontweight="bold")
        return png(fig)


def mse_curves(
    curves: Mapping[str, list[np.ndarray]],
    target: float,
    *,
    title: str,
    paper_epochs: Mapping[str, float] | None = None,
    letters: str = "abcdefghij",
    ncols: int | None = None,
    sharey: bool = True,
    log_epochs: bool = False,
) -> bytes:
    """[B] Fig. 9: the best training MSE against the epoch, one panel per method: each run
    (seed) a thin line, their median a thick one (a run that stopped at the target carried on
    at its last value), the target MSE dashed and, where given, the epoch at which the paper
    reached it dotted. MSE on a log scale, shared by the panels if ``sharey``; ``log_epochs``:
    epochs on a log scale too (linear below 1), for runs far shorter than the paper's."""
    paper_epochs = paper_epochs or {}
    n = len(curves)
    ncols = ncols or min(n, 4)
    nrows = -(-n // ncols)
    finite = np.concatenate([np.ravel(c) for runs in curves.values() for c in runs])
    finite = finite[np.isfinite(finite) & (finite > 0)]
    lo = min(float(finite.min()), target) / 1.5
    hi = max(float(finite.max()), target) * 1.5
    with styled():
        fig, axes = new_figure(
            nrows, ncols, width=4.4 * ncols + 0.4, height=3.5 * nrows + 0.6, sharey=sharey
        )
        for ax in axes.ravel()[n:]:
            ax.set_visible(False)
        for k, (ax, (name, runs)) in enumerate(zip(axes.ravel(), curves.items(), strict=False)):
            color = COLORS[k % len(COLORS)]
            length = max(len(c) for c in runs)
            padded = np.stack([np.concatenate([c, np.full(length - len(c), c[-1])]) for c in runs])
            for c in runs:
                ax.plot(np.arange(len(c)), c, "-", lw=0.7, alpha=0.45, color=color)
            ax.plot(
                np.arange(length),
                np.median(padded, axis=0),
                "-",
                lw=2.2,
                color=color,
                label=f"median of {len(runs)} runs",
            )
            ax.axhline(target, color="0.15", ls="--", lw=1.1, label=f"target MSE {target:g}")
            reached = [int(np.argmax(c <= target)) for c in runs if np.any(c <= target)]
            if reached:
                ax.plot(
                    reached,
                    [target] * len(reached),
                    "v",
                    ms=6,
                    color=color,
                    mec="white",
                    label=f"ours reached it ({len(reached)}/{len(runs)} runs)",
                )
            if name in paper_epochs:
                ep = float(paper_epochs[name])
                ax.axvline(ep, color="0.35", ls=":", lw=1.6)
                ax.annotate(
                    f"paper reached it: epoch {ep:g}",
                    (ep, 0.5),
                    xycoords=("data", "axes fraction"),
                    xytext=(-3, 0),
                    textcoords="offset points",
                    rotation=90,
                    ha="right",
                    va="center",
                    fontsize=8.5,
                    color="0.2",
                )
                ax.set_xlim(0, max(length - 1, ep * 1.08))
            else:
                ax.set_xlim(0, max(length - 1, 1))
            ax.set_yscale("log")
            if sharey:
                ax.set_ylim(lo, hi)
            if log_epochs:
                ax.set_xscale("symlog", linthresh=1.0)
            ax.set_title(f"({letters[k]}) {name}", loc="left", fontsize=10)
            ax.set_xlabel("epoch, log scale" if log_epochs else "epoch")
            ax.legend(loc="upper right", fontsize=8)
        for row in axes:
            row[0].set_ylabel("training MSE (friction scaled to [-1, 1])")
        fig.suptitle(title, fontweight="bold")
        return png(fig)


def unseen_region(
    temperature: np.ndarray,
    errors: Mapping[str, np.ndarray],
    *,
    title: str,
    highlight: str,
    train_max_temperature: float,
    paper: Mapping[str, float] | None = None,
) -> bytes:
    """[B] Fig. 10: absolute prediction errors in the unseen region.

    (a) the ``highlight`` model's error at each point (as the paper's figure), the points
    inside the training temperatures shaded, the paper's mean and maximum as lines; (b) every
    model's mean absolute error per temperature (log scale), the highest training temperature
    marked: where the error grows with the distance from the training data."""
    temperature = np.asarray(temperature, dtype=float)
    allv = np.concatenate([np.ravel(e) for e in errors.values()])
    f, unit = torque_scale(np.concatenate([np.ravel(errors[highlight]), [0.0]]))
    paper = paper or {}
    temps = np.unique(np.round(temperature, 6))
    with styled():
        fig, axes = new_figure(
            1, 2, width=14.5, height=5.2, gridspec_kw={"width_ratios": [1.45, 1.0]}
        )
        a, b = axes[0]
        e = np.abs(np.asarray(errors[highlight], dtype=float)) * f
        idx = np.arange(1, e.size + 1)
        inside = temperature <= train_max_temperature + 1e-9
        if inside.any():
            a.axvspan(
                idx[inside].min() - 0.5,
                idx[inside].max() + 0.5,
                color="0.88",
                zorder=0,
                label=f"≤ {train_max_temperature:g} °C (inside the training temperatures)",
            )
        a.plot(idx, e, "-o", ms=2.8, lw=0.8, color=COLORS[0], label=f"{highlight} (ours)")
        for key, ls in (("mean", "--"), ("max", ":")):
            if key in paper:
                a.axhline(
                    paper[key] * f,
                    color=COLORS[1],
                    ls=ls,
                    lw=1.4,
                    label=f"paper's {key}: {paper[key] * f:.3g} {unit}",
                )
        a.axhline(
            e.mean(), color=COLORS[0], ls="--", lw=1.2, label=f"our mean: {e.mean():.3g} {unit}"
        )
        for t in temps:
            at = np.flatnonzero(np.isclose(temperature, t))
            a.annotate(
                f"{t:g} °C",
                (idx[at].mean(), 1.0),
                xycoords=("data", "axes fraction"),
                ha="center",
                va="top",
                fontsize=8,
                color="0.3",
            )
        a.set_ylim(0, max(float(e.max()), paper.get("max", 0.0) * f) * 1.12)
        a.set_xlim(0.5, e.size + 0.5)
        a.set_xlabel("sample number in the unseen region (ordered by temperature)")
        a.set_ylabel(f"absolute error [{unit}]")
        a.set_title(f"(a) {highlight}: error at each point", loc="left", fontsize=10)
        a.legend(loc="upper center", bbox_to_anchor=(0.5, -0.15), ncols=3, fontsize=8)
        bf, bunit = torque_scale(allv)
        markers = ["o", "s", "^", "D", "v", "P", "X", "*"]
        for k, (name, err) in enumerate(errors.items()):
            err = np.abs(np.asarray(err, dtype=float))
            means = [err[np.isclose(temperature, t)].mean() * bf for t in temps]
            b.plot(
                temps,
                means,
                "-" + markers[k % len(markers)],
                ms=5,
                lw=1.8 if name == highlight else 1.1,
                color=COLORS[k % len(COLORS)],
                label=name,
            )
        b.axvline(train_max_temperature, color="0.3", ls="--", lw=1.0)
        b.annotate(
            "highest training\ntemperature",
            (train_max_temperature, 0.97),
            xycoords=("data", "axes fraction"),
            xytext=(4, 0),
            textcoords="offset points",
            va="top",
            fontsize=8,
            color="0.3",
        )
        b.set_yscale("log")
        b.set_xlabel("temperature [°C]")
        b.set_ylabel(f"mean absolute error [{bunit}], log scale")
        b.set_title("(b) every model: mean error per temperature", loc="left", fontsize=10)
        b.legend(loc="center left", bbox_to_anchor=(1.02, 0.5), fontsize=8)
        fig.suptitle(title, fontweight="bold")
        return png(fig)


def stribeck_construction(
    velocity: np.ndarray,
    friction: np.ndarray,
    params: Mapping[str, float],
    *,
    title: str,
    velocity_unit: str = "rad/s",
    label: str = "Stribeck fit",
) -> bytes:
    """[R] Fig. 3 and 4: measured friction against velocity, the fitted Stribeck curve (eq. 7)
    and its construction: tau_s at zero speed, the high-speed tangent ``tau_c + tau_v w``
    meeting the axis at tau_c, and w_s."""
    v = np.abs(np.asarray(velocity, dtype=float))
    y = np.abs(np.asarray(friction, dtype=float))
    tc, ts, ws, tv = (float(params[k]) for k in ("tau_c", "tau_s", "w_s", "tau_v"))
    delta = float(params.get("delta", 1.0))
    vf, vunit = velocity_scale(velocity_unit)
    f, unit = torque_scale(y)
    grid = np.linspace(0.0, v.max() * 1.03, 600)
    curve = tc + (ts - tc) * np.exp(-((grid / ws) ** delta)) + tv * grid
    with styled():
        fig, axes = new_figure(1, 2, width=12.0, height=4.4)
        for j, ax in enumerate(axes[0]):
            zoom = j == 1
            ax.plot(v * vf, y * f, "o", color=COLORS[0], ms=5, label="measured friction")
            ax.plot(grid * vf, curve * f, "-", color=COLORS[1], label=label)
            ax.plot(
                grid * vf,
                (tc + tv * grid) * f,
                "--",
                color="0.35",
                lw=1.1,
                label="high-speed tangent τ_c + τ_v w",
            )
            ax.axhline(tc * f, color=COLORS[2], ls=":", lw=1.2, label=f"τ_c = {tc:.3g} N m")
            ax.plot([0], [ts * f], "D", color=COLORS[3], ms=7, label=f"τ_s = {ts:.3g} N m")
            # w_s: where the zero-speed tangent meets the tau_c level (for delta = 1)
            ax.plot(
                [ws * vf],
                [tc * f],
                "^",
                color=COLORS[4],
                ms=8,
                label=f"w_s = {ws * vf:.3g} {vunit}",
            )
            ax.plot([0, ws * vf], [ts * f, tc * f], "-", color=COLORS[4], lw=0.9)
            ax.set_xlabel(f"velocity w [{vunit}]")
            ax.set_ylabel(f"friction torque [{unit}]")
            if zoom:
                ax.set_xlim(0, min(v.max(), 8 * ws) * vf)
                ax.set_title("low-speed detail (Stribeck region)", fontsize=10, fontweight="normal")
            else:
                ax.set_xlim(-0.015 * v.max() * 1.03 * vf, None)
                ax.legend(loc="upper right", fontsize=8)
            ax.set_ylim(0, None)
        fig.suptitle(title, fontweight="bold")
        return png(fig)


def error_per_point(
    velocity: np.ndarray,
    errors: Mapping[str, np.ndarray],
    *,
    title: str,
    velocity_unit: str = "rad/s",
) -> bytes:
    """[R] Fig. 7: prediction error at each sampling point for each algorithm's best run."""
    v = np.abs(np.asarray(velocity, dtype=float))
    order = np.argsort(v)
    ef, eunit = torque_scale(np.concatenate([np.ravel(e) for e in errors.values()]))
    vf, vunit = velocity_scale(velocity_unit)
    markers = ["o", "s", "^", "D", "v"]
    with styled():
        fig, axes = new_figure(1, 2, width=12.0, height=4.2)
        a, b = axes[0]
        idx = np.arange(1, v.size + 1)
        for k, (name, e) in enumerate(errors.items()):
            e = np.asarray(e)[order] * ef
            c = COLORS[k % len(COLORS)]
            a.plot(idx, e, "-" + markers[k % 5], ms=4, lw=1, color=c, label=name)
            b.plot(v[order] * vf, e, markers[k % 5], ms=5, color=c, label=name)
        for ax in (a, b):
            ax.axhline(0, color="0.3", lw=0.7)
            ax.set_ylabel(f"error (measured − predicted) [{eunit}]")
        a.set_xlabel("sampling point (by increasing velocity)")
        b.set_xlabel(f"velocity [{vunit}], log scale")
        b.set_xscale("log")
        a.legend(loc="best")
        fig.suptitle(title, fontweight="bold")
        return png(fig)
