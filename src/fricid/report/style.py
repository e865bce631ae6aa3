"""One look for every figure: matplotlib without pyplot (Agg canvas, no display), readable
fonts, light grids, and display units chosen from the data (N m or mN m; rad/s, deg/s, rpm).

Figures are :class:`matplotlib.figure.Figure` objects created directly, never through pyplot,
so no global figure registry or interactive backend is involved; :func:`png` renders one.
"""

from __future__ import annotations

import contextlib
import io
from collections.abc import Iterator

import matplotlib
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..units import UNITS

__all__ = [
    "COLORS",
    "RC",
    "band_edges",
    "in_band",
    "new_figure",
    "png",
    "styled",
    "torque_scale",
    "velocity_scale",
]

#: Colour cycle (Okabe-Ito, readable for colour-blind readers and in greyscale).
COLORS = (
    "#0072B2",
    "#D55E00",
    "#009E73",
    "#CC79A7",
    "#E69F00",
    "#56B4E9",
    "#000000",
    "#F0E442",
)

#: rcParams used for every figure.
RC = {
    "font.size": 10,
    "axes.titlesize": 11,
    "axes.titleweight": "bold",
    "axes.labelsize": 10,
    "legend.fontsize": 8.5,
    "legend.framealpha": 0.85,
    "xtick.labelsize": 9,
    "ytick.labelsize": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.6,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "axes.prop_cycle": matplotlib.cycler(color=COLORS),
    "lines.linewidth": 1.6,
    "lines.markersize": 5,
    "savefig.dpi": 110,
    "figure.dpi": 110,
    "savefig.facecolor": "white",
    "figure.facecolor": "white",
}


@contextlib.contextmanager
def styled() -> Iterator[None]:
    """Apply :data:`RC` for the duration (artists read rcParams when created and drawn)."""
    with matplotlib.rc_context(RC):
        yield


def new_figure(
    nrows: int = 1,
    ncols: int = 1,
    *,
    width: float = 7.0,
    height: float = 4.2,
    squeeze: bool = False,
    **kwargs,
) -> tuple[Figure, np.ndarray]:
    """A figure with a grid of axes (``squeeze=False``: always a 2-D array), constrained
    layout, Agg canvas. Call inside :func:`styled`."""
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, squeeze=squeeze, **kwargs)
    return fig, axes


def png(fig: Figure) -> bytes:
    """Render ``fig`` to PNG bytes (inside :func:`styled`)."""
    buf = io.BytesIO()
    with styled():
        fig.savefig(buf, format="png")
    return buf.getvalue()


def torque_scale(values) -> tuple[float, str]:
    """Display factor and unit for torques: mN m below 0.5 N m, else N m."""
    arr = np.asarray(values, dtype=float)
    arr = arr[np.isfinite(arr)]
    big = float(np.max(np.abs(arr))) if arr.size else 1.0
    return (1e3, "mN m") if big < 0.5 else (1.0, "N m")


def velocity_scale(unit: str = "rad/s") -> tuple[float, str]:
    """Factor from rad/s to ``unit`` (``rad/s``, ``deg/s``, ``rpm``, ``rev/s``) and its label."""
    scale, _ = UNITS["velocity"][unit]
    return 1.0 / scale, unit


def in_band(values: np.ndarray, band: tuple[float, float]) -> np.ndarray:
    """Which ``values`` lie in the inclusive ``band``; a band of NaN (a quantity not
    measured, :func:`band_edges` of NaN) holds the NaN values."""
    values = np.asarray(values, dtype=float)
    if np.isnan(band[0]):
        return np.isnan(values)
    return (values >= band[0]) & (values <= band[1])


def band_edges(values, max_bands: int) -> list[tuple[float, float]]:
    """Split the distinct ``values`` into at most ``max_bands`` contiguous bands of about equal
    count; returns inclusive (low, high) per band.

    Values closer than 1/200 of their range count as one (a measured temperature scatters
    around its set-point). NaN values (not measured) get a band of their own, ``(nan, nan)``,
    last (:func:`in_band`): a band whose end was NaN held no sample at all."""
    every = np.asarray(values, dtype=float).ravel()
    arr = every[np.isfinite(every)]
    unmeasured = [(float("nan"), float("nan"))] if arr.size < every.size else []
    span = float(np.ptp(arr)) if arr.size else 0.0
    if span == 0.0:
        return [(float(arr.min()), float(arr.max())), *unmeasured] if arr.size else unmeasured
    return _finite_bands(arr, span, max_bands) + unmeasured


def _finite_bands(arr: np.ndarray, span: float, max_bands: int) -> list[tuple[float, float]]:
    """:func:`band_edges` of finite values spanning ``span > 0``."""
    distinct = np.unique(arr)
    # cluster: a gap larger than span/200 starts a new group
    starts = np.flatnonzero(np.diff(distinct) > span / 200.0) + 1
    clusters = np.split(distinct, starts)
    if len(clusters) <= max_bands:
        return [(float(c[0]), float(c[-1])) for c in clusters]
    groups = np.array_split(np.arange(len(clusters)), max_bands)
    return [(float(clusters[g[0]][0]), float(clusters[g[-1]][-1])) for g in groups]
