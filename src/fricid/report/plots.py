"""Figures shared by the model report and the paper reproductions; each returns PNG bytes.

* :func:`friction_curves`: measured friction against velocity with the model's curves, one
  curve per temperature band and load band (BAS-RBFNN paper Fig. 8 a/c/e, RWSAVSBAS paper
  Fig. 8);
* :func:`residual_panels`: residuals against each input (BAS-RBFNN Fig. 8 b/d/f, RWSAVSBAS
  Fig. 7);
* :func:`parity`: predicted against measured;
* :func:`convergence`: best objective against evaluations (RWSAVSBAS Fig. 6, BAS-RBFNN Fig. 9);
* :func:`surface`: friction over two factors (BAS-RBFNN Fig. 6 a-c).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np
from matplotlib.axes import Axes

from ..samples import FrictionSamples
from .style import (
    COLORS,
    band_edges,
    in_band,
    new_figure,
    png,
    styled,
    torque_scale,
    velocity_scale,
)

__all__ = [
    "convergence",
    "friction_curves",
    "parity",
    "residual_panels",
    "set_velocity_axis",
    "stribeck_region",
    "surface",
    "velocity_grid",
]

Predict = Callable[[np.ndarray], np.ndarray]


def _fmt(lo: float, hi: float, unit: str, digits: int = 3) -> str:
    if np.isclose(lo, hi, rtol=0.01, atol=0.05 if unit == "°C" else 0.0):
        return f"{(lo + hi) / 2:.{digits}g} {unit}"
    return f"{lo:.{digits}g}–{hi:.{digits}g} {unit}"


def _mask(values: np.ndarray, band: tuple[float, float]) -> np.ndarray:
    return in_band(values, band)


def velocity_grid(velocity: np.ndarray, n: int = 200, *, log: bool) -> np.ndarray:
    """A dense velocity grid [rad/s] over the measured range of each sign, NaN between signs
    (so a line is broken at zero, where friction jumps)."""
    parts = []
    for sign in (-1.0, 1.0):
        a = np.abs(velocity[np.sign(velocity) == sign])
        if a.size == 0:
            continue
        lo, hi = float(a.min()), float(a.max())
        lo = lo * 0.8 if log else 0.0
        g = np.geomspace(max(lo, 1e-12), hi, n) if log else np.linspace(lo, hi, n)
        g = g[1:] if not log else g
        parts.append(sign * (g[::-1] if sign < 0 else g))
    if len(parts) == 2:
        return np.concatenate([parts[0], [np.nan], parts[1]])
    return parts[0] if parts else np.array([0.0])


def _wide(velocity: np.ndarray) -> bool:
    a = np.abs(velocity[velocity != 0])
    return a.size > 0 and a.max() / a.min() > 30


def _both_directions(samples: FrictionSamples) -> bool:
    return {-1, 1} <= set(samples.directions())


def set_velocity_axis(
    ax: Axes, velocity_display: np.ndarray, unit: str, *, speed: bool = False
) -> None:
    """Log x axis when the velocities span more than ~1.5 decades (so the Stribeck region stays
    visible): logarithmic for one sign, symmetric-log for both; linear otherwise. ``speed``
    labels the axis as ``|velocity|``."""
    v = velocity_display[np.isfinite(velocity_display) & (velocity_display != 0)]
    label = f"speed |velocity| [{unit}]" if speed else f"velocity [{unit}]"
    if v.size and _wide(v):
        if (v > 0).all():
            ax.set_xscale("log")
            label += ", log scale"
        else:
            ax.set_xscale("symlog", linthresh=float(np.abs(v).min()), linscale=0.4)
            label += ", symmetric log scale"
    ax.set_xlabel(label)


_DIRECTION = {
    1: ("positive direction", "o", "-"),
    -1: ("negative direction", "s", "--"),
    0: ("", "o", "-"),
}


def friction_curves(
    samples: FrictionSamples,
    predict: Predict | Mapping[str, Predict],
    *,
    velocity_unit: str = "rad/s",
    max_temperature_bands: int = 5,
    max_load_bands: int = 3,
    title: str = "Measured and predicted friction",
    width: float | None = None,
) -> bytes:
    """Measured friction (markers) and the model's prediction (lines) against velocity.

    One panel per load band, one colour per temperature band; each curve is evaluated at the
    band's median load and temperature. When both directions of motion are present the x axis
    is the speed |v| and the y axis the friction magnitude ``sign(v) F`` (markers and line
    style per direction), so an asymmetry shows as two curves. ``predict`` maps inputs
    ``(n, 3)`` to friction; a mapping of several models gives one line style per model.
    """
    models = dict(predict) if isinstance(predict, Mapping) else {"model": predict}
    vf, vunit = velocity_scale(velocity_unit)
    tf, tunit = torque_scale(samples.friction)
    t_bands = band_edges(samples.temperature, max_temperature_bands)
    l_bands = band_edges(samples.load, max_load_bands)
    # magnitudes against speed when both directions are present, or only the negative one
    both = _both_directions(samples) or bool((samples.velocity < 0).all())
    dirs = tuple(d for d in (1, -1) if (samples.direction == d).any()) if both else (0,)
    log = _wide(samples.velocity)
    styles = ["-", "--", ":", "-."]
    many_t = len(t_bands) > 1
    with styled():
        ncols = len(l_bands)
        fig, axes = new_figure(
            1, ncols, width=width or min(4.6 * ncols + 1.4, 15.0), height=4.4, sharey=True
        )
        for j, lb in enumerate(l_bands):
            ax = axes[0, j]
            in_load = _mask(samples.load, lb)
            for k, tb in enumerate(t_bands):
                color = COLORS[k % len(COLORS)]
                t_label = f", {_fmt(*tb, '°C')}" if many_t else ""
                for d in dirs:
                    sel = in_load & _mask(samples.temperature, tb)
                    if d:
                        sel &= samples.direction == d
                    if not sel.any():
                        continue
                    d_label, marker, dash = _DIRECTION[d]
                    v, f = samples.velocity[sel], samples.friction[sel]
                    x = np.abs(v) if both else v
                    y = np.sign(v) * f if both else f
                    what = ", ".join(p for p in (d_label,) if p)
                    ax.plot(
                        x * vf,
                        y * tf,
                        marker,
                        color=color,
                        ms=4.5,
                        alpha=0.6,
                        mfc=color if d >= 0 else "white",
                        label=f"measured{', ' + what if what else ''}{t_label}",
                    )
                    grid = velocity_grid(v, log=log)
                    ok = np.isfinite(grid)
                    X = np.column_stack(
                        [
                            grid,
                            np.full_like(grid, np.median(samples.load[sel])),
                            np.full_like(grid, np.median(samples.temperature[sel])),
                        ]
                    )
                    for m, (name, fn) in enumerate(models.items()):
                        yp = np.full_like(grid, np.nan)
                        yp[ok] = fn(X[ok])
                        xg = np.abs(grid) if both else grid
                        yg = np.sign(grid) * yp if both else yp
                        line = dash if len(models) == 1 else styles[m % len(styles)]
                        c = color if len(models) == 1 else COLORS[(m + 1) % len(COLORS)]
                        ax.plot(
                            xg * vf,
                            yg * tf,
                            line,
                            color=c,
                            label=f"{name}{', ' + what if what else ''}{t_label}",
                        )
            set_velocity_axis(
                ax, (np.abs(samples.velocity) if both else samples.velocity) * vf, vunit, speed=both
            )
            if not both and (samples.friction < 0).any() and (samples.friction > 0).any():
                ax.axhline(0, color="0.4", lw=0.6)
                if (samples.velocity < 0).any():
                    ax.axvline(0, color="0.4", lw=0.6)
            if len(l_bands) > 1 or not (np.isnan(lb[0]) or np.allclose(lb, 0)):  # no NaN title
                ax.set_title(f"load {_fmt(*lb, 'N m')}", fontweight="normal", fontsize=10)
            if j == 0:
                ax.set_ylabel(
                    f"|friction torque| [{tunit}]" if both else f"friction torque [{tunit}]"
                )
        n_entries = len(t_bands) * len(dirs) * (len(models) + 1)
        if len(l_bands) > 1 or n_entries > 6:
            handles, labels = axes[0, 0].get_legend_handles_labels()
            fig.legend(handles, labels, loc="outside right center")
        else:
            axes[0, -1].legend(loc="best")
        fig.suptitle(title, fontweight="bold")
        return png(fig)


def speed_sides(samples: FrictionSamples):
    """Per direction with samples: ``(k, d, sel, (label, marker, dash), grid, X)``, ``k`` its
    colour index, ``d`` its sign, ``sel`` its rows, ``grid`` a log speed grid [rad/s] over
    them and ``X`` the grid at the median load and temperature."""
    for k, d in enumerate((1, -1)):
        sel = np.sign(samples.velocity) == d
        if not sel.any():
            continue
        grid = velocity_grid(samples.velocity[sel], log=True)
        at = (np.median(samples.load), np.median(samples.temperature))
        X = np.column_stack([grid, np.full_like(grid, at[0]), np.full_like(grid, at[1])])
        yield k, d, sel, _DIRECTION[d], grid, X


def plot_measured(
    ax: Axes, samples: FrictionSamples, sel: np.ndarray, k: int, d: int, vf: float, tf: float
) -> None:
    """The measured |friction| of rows ``sel`` (direction ``d``, colour ``k``) against speed."""
    label, marker, _ = _DIRECTION[d]
    ax.plot(
        np.abs(samples.velocity[sel]) * vf,
        np.abs(samples.friction[sel]) * tf,
        marker,
        color=COLORS[k],
        ms=4.5,
        alpha=0.6,
        mfc=COLORS[k] if d > 0 else "white",
        label=f"measured, {label}",
    )


def stribeck_region(
    samples: FrictionSamples,
    predict: Predict,
    marks: Mapping[str, float],
    *,
    velocity_unit: str = "rad/s",
    title: str = "The Stribeck region: |friction| against speed",
    xlim: tuple[float, float] | None = None,
) -> bytes:
    """The friction magnitude against speed on a log axis, per direction, measured (markers)
    and the model at the median load and temperature (lines), with dotted lines at the
    velocities in ``marks`` [rad/s] (the model's Stribeck velocities); ``xlim`` [rad/s] limits
    the speed axis."""
    vf, vunit = velocity_scale(velocity_unit)
    tf, tunit = torque_scale(samples.friction)
    with styled():
        fig, axes = new_figure(1, 1, width=7.5, height=4.4)
        ax = axes[0, 0]
        for k, d, sel, (label, _, dash), grid, X in speed_sides(samples):
            plot_measured(ax, samples, sel, k, d, vf, tf)
            ax.plot(
                np.abs(grid) * vf,
                d * predict(X) * tf,
                dash,
                color=COLORS[k],
                label=f"model, {label}",
            )
        for k, (name, value) in enumerate(marks.items()):
            ax.axvline(value * vf, color="0.35", lw=0.9, ls=":")
            ax.annotate(
                name,
                (value * vf, 1.0),
                xycoords=("data", "axes fraction"),
                xytext=(0, 2 + 10 * k),
                textcoords="offset points",
                ha="center",
                va="bottom",
                fontsize=8,
            )
        ax.set_xscale("log")
        if xlim is not None:
            ax.set_xlim(xlim[0] * vf, xlim[1] * vf)
        ax.set_xlabel(f"speed |velocity| [{vunit}], log scale")
        ax.set_ylabel(f"|friction torque| [{tunit}]")
        ax.legend(loc="best")
        fig.suptitle(title, fontweight="bold")
        return png(fig)


def residual_panels(
    samples: FrictionSamples,
    residual: np.ndarray,
    *,
    velocity_unit: str = "rad/s",
    title: str = "Residuals (measured − predicted)",
) -> bytes:
    """Residuals against each input that varies (velocity always), coloured by temperature
    (or by direction of motion), with the ±2 RMSE band. With both directions present the
    velocity panel uses the speed |v|, open squares marking the negative direction."""
    residual = np.asarray(residual, dtype=float)
    vf, vunit = velocity_scale(velocity_unit)
    rf, runit = torque_scale(residual)
    both = _both_directions(samples)
    speed = np.abs(samples.velocity) if both else samples.velocity
    inputs = [("velocity", speed * vf, "")]
    if np.ptp(samples.load) > 0:
        inputs.append(("load", samples.load, "load [N m]"))
    if np.ptp(samples.temperature) > 0:
        inputs.append(("temperature", samples.temperature, "temperature [°C]"))
    rmse = float(np.sqrt(np.mean(residual**2)))
    color_by_t = np.ptp(samples.temperature) > 0
    groups = [(d, samples.direction == d) for d in (1, -1)] if both else [(0, slice(None))]
    with styled():
        n = len(inputs)
        fig, axes = new_figure(1, n, width=min(4.2 * n + 1.0, 14.0), height=3.8, sharey=True)
        sc = None
        for j, (name, x, label) in enumerate(inputs):
            ax = axes[0, j]
            for g, (d, sel) in enumerate(groups):
                d_label, marker, _ = _DIRECTION[d]
                if color_by_t:
                    kw = dict(c=samples.temperature[sel], cmap="coolwarm")
                else:
                    kw = dict(color=COLORS[g])
                sc = ax.scatter(
                    x[sel],
                    residual[sel] * rf,
                    s=16,
                    alpha=0.75,
                    marker=marker,
                    edgecolors="none",
                    label=d_label or None,
                    **kw,
                )
            ax.axhline(0, color="0.3", lw=0.8)
            for s in (-2, 2):
                ax.axhline(
                    s * rmse * rf, color="0.45", lw=0.9, ls="--", label="±2 RMSE" if s > 0 else None
                )
            if name == "velocity":
                set_velocity_axis(ax, x, vunit, speed=both)
            else:
                ax.set_xlabel(label)
            if j == 0:
                ax.set_ylabel(f"residual [{runit}]")
                ax.legend(loc="best")
        if color_by_t and sc is not None:
            fig.colorbar(sc, ax=axes[0, -1], label="temperature [°C]", shrink=0.9)
        fig.suptitle(title, fontweight="bold")
        return png(fig)


def parity(
    measured: np.ndarray,
    predicted: Mapping[str, np.ndarray] | np.ndarray,
    *,
    title: str = "Predicted against measured friction",
) -> bytes:
    """Predicted against measured friction, with the identity line."""
    series = dict(predicted) if isinstance(predicted, Mapping) else {"model": predicted}
    f, unit = torque_scale(measured)
    with styled():
        fig, axes = new_figure(width=4.8, height=4.5)
        ax = axes[0, 0]
        lo = min(float(np.min(measured)), *(float(np.min(p)) for p in series.values()))
        hi = max(float(np.max(measured)), *(float(np.max(p)) for p in series.values()))
        pad = 0.04 * (hi - lo or 1.0)
        ax.plot(
            [(lo - pad) * f, (hi + pad) * f],
            [(lo - pad) * f, (hi + pad) * f],
            color="0.4",
            lw=0.9,
            label="identity",
        )
        for k, (name, p) in enumerate(series.items()):
            ax.plot(
                np.asarray(measured) * f,
                np.asarray(p) * f,
                "o",
                ms=4,
                alpha=0.6,
                mec="none",
                color=COLORS[k % len(COLORS)],
                label=name,
            )
        ax.set_xlabel(f"measured friction [{unit}]")
        ax.set_ylabel(f"predicted friction [{unit}]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.legend(loc="upper left")
        ax.set_title(title)
        return png(fig)


def convergence(
    histories: Mapping[str, Sequence[np.ndarray] | np.ndarray],
    *,
    title: str = "Convergence",
    ylabel: str = "best SSE [N² m²]",
    xlabel: str = "objective evaluations",
    log_y: bool = True,
    log_x: bool = False,
    band: bool = True,
    reference: Mapping[str, float] | None = None,
) -> bytes:
    """Best-so-far objective against evaluations, one line per method.

    Each value of ``histories`` is one ``(m, 2)`` array (nfev, best) or a list of them (runs):
    the mean over runs is drawn on a common evaluation grid, with the min-max range shaded
    when ``band``. ``reference`` draws horizontal lines (e.g. the paper's final values).
    Methods beyond the palette's colours are told apart by their line style.
    """
    with styled():
        fig, axes = new_figure(width=7.0, height=4.2)
        ax = axes[0, 0]
        for k, (name, runs) in enumerate(histories.items()):
            if isinstance(runs, list | tuple):
                runs_list = [np.asarray(r, dtype=float) for r in runs]
            else:
                runs_list = [np.asarray(runs, dtype=float)]
            runs_list = [r for r in runs_list if r.ndim == 2 and len(r) > 0]
            if not runs_list:
                continue
            color = COLORS[k % len(COLORS)]
            style = ("-", "--", "-.", ":")[(k // len(COLORS)) % 4]  # past the palette
            grid, curves = _common_grid(runs_list, log=log_x)
            mean = curves.mean(axis=0)
            label = name if len(runs_list) == 1 else f"{name} (mean of {len(runs_list)} runs)"
            ax.plot(grid, mean, color=color, ls=style, label=label, drawstyle="steps-post")
            if band and len(runs_list) > 1:
                ax.fill_between(
                    grid,
                    curves.min(axis=0),
                    curves.max(axis=0),
                    color=color,
                    alpha=0.15,
                    step="post",
                    lw=0,
                )
        for k, (name, value) in enumerate((reference or {}).items()):
            ax.axhline(value, color=COLORS[(k + 4) % len(COLORS)], ls=":", lw=1.2, label=name)
        if log_y:
            ax.set_yscale("log")
        if log_x:
            ax.set_xscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.legend(loc="upper right")
        return png(fig)


def _common_grid(
    runs: list[np.ndarray], n: int = 400, *, log: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """Best-so-far curves of several runs on one evaluation grid (step interpolation); the
    grid is log-spaced when ``log`` (for a logarithmic evaluation axis)."""
    top = max(float(r[-1, 0]) for r in runs)
    start = min(float(r[0, 0]) for r in runs)
    if log:
        grid = np.unique(np.geomspace(max(start, 1.0), max(top, 1.0), 4 * n).round())
    else:
        grid = np.unique(np.concatenate([np.linspace(start, top, n), *[r[:, 0] for r in runs]]))
        if grid.size > 4 * n:
            grid = np.linspace(start, top, 4 * n)
    curves = []
    for r in runs:
        idx = np.searchsorted(r[:, 0], grid, side="right") - 1
        vals = r[np.clip(idx, 0, None), 1].astype(float)
        vals[idx < 0] = np.nan
        curves.append(vals)
    out = np.array(curves)
    # before a run's first record use its first value (keeps the mean defined)
    first = np.array([r[0, 1] for r in runs])[:, None]
    return grid, np.where(np.isnan(out), first, out)


def surface(
    x: np.ndarray,
    y: np.ndarray,
    z: np.ndarray,
    *,
    xlabel: str,
    ylabel: str,
    zlabel: str,
    title: str,
    ax: Axes | None = None,
) -> None:
    """A 3-D surface of ``z`` over the grid ``x`` (columns) by ``y`` (rows) on a 3-D ``ax``."""
    X, Y = np.meshgrid(x, y)
    ax.plot_surface(X, Y, z, cmap="viridis", edgecolor="0.25", linewidth=0.25, alpha=0.95)
    ax.set_xlabel(xlabel, labelpad=4)
    ax.set_ylabel(ylabel, labelpad=4)
    ax.set_zlabel(zlabel, labelpad=6)
    ax.set_title(title, fontsize=10)
    ax.view_init(elev=24, azim=-128)
