"""[R] Fig. 6 with its two reference levels both visible, and whether they coincide computed.

[R] Kou et al., "A New Parameter Identification Method for Industrial Robots with Friction",
Machines 10(5) 349, 2022, Fig. 6: average fitness (SSE) curves over 8 runs. Ours adds two
horizontal references: the exact optimum (variable projection) and the paper's final
RWSAVSBAS average. On the ``paper2`` preset they lie within a few per cent of each other (its
noise is calibrated so), so drawn alike one hides the other: here the optimum is a wide pale
band, the paper's level a dark dashed line with markers on top of it, and the legend says
when they coincide, with the ratio computed from the two numbers.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..plots import _common_grid
from ..style import COLORS, new_figure, png, styled

__all__ = ["COINCIDE_RTOL", "coincide", "fig6_convergence"]

#: Two reference levels "coincide" on the figure when they differ by at most this fraction
#: (at 5 % they are closer than a line's width on a log axis spanning several decades).
COINCIDE_RTOL = 0.05


def coincide(a: float, b: float, rtol: float = COINCIDE_RTOL) -> bool:
    """Whether two positive levels differ by at most ``rtol`` relative to the smaller."""
    lo, hi = sorted((float(a), float(b)))
    return lo > 0 and hi / lo - 1.0 <= rtol


def fig6_convergence(
    histories: Mapping[str, Sequence[np.ndarray]],
    *,
    title: str,
    optimum: float,
    paper: tuple[str, float] | None = None,
) -> bytes:
    """Mean best-so-far SSE against evaluations per method (log axes), the exact optimum and,
    optionally, the paper's level ``(label, value)``, each drawn so that both stay visible.

    Parameters
    ----------
    histories : mapping
        Per method, the runs' ``(m, 2)`` arrays of (evaluations, best SSE).
    title : str
        The figure's title.
    optimum : float
        The exact optimum's SSE [N^2 m^2].
    paper : tuple, optional
        The paper's label and value, e.g. its RWSAVSBAS average.

    Returns
    -------
    bytes
        The PNG.
    """
    with styled():
        fig, axes = new_figure(width=7.5, height=5.2)
        ax = axes[0, 0]
        for k, (name, runs) in enumerate(histories.items()):
            arrays = [np.asarray(r, dtype=float) for r in runs]
            arrays = [r for r in arrays if r.ndim == 2 and len(r)]
            if not arrays:
                continue
            grid, curves = _common_grid(arrays, log=True)
            ax.plot(
                grid,
                curves.mean(axis=0),
                color=COLORS[k % len(COLORS)],
                drawstyle="steps-post",
                label=f"{name} (mean of {len(arrays)} runs)",
            )
        same = paper is not None and coincide(optimum, paper[1])
        opt_label = f"exact optimum, SSE {optimum:.3g}"
        if paper is not None and same:
            opt_label += f" (coincides with the paper's level: ratio {paper[1] / optimum:.3g})"
        ax.axhline(optimum, color="0.55", lw=6.0, alpha=0.45, zorder=1, label=opt_label)
        ax.set_yscale("log")
        ax.set_xscale("log")
        if paper is not None:
            label, value = paper
            xl = ax.get_xlim()
            ax.plot(
                np.geomspace(max(xl[0], 1e-12), xl[1], 12),
                np.full(12, value),
                ls="--",
                lw=1.3,
                color="black",
                marker="D",
                ms=4,
                zorder=5,
                label=f"{label}, {value:.3g}" + (" (on the optimum's band)" if same else ""),
            )
            ax.set_xlim(xl)
        ax.set_xlabel("objective evaluations")
        ax.set_ylabel("best SSE [N² m²]")
        ax.set_title(title)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncols=2, fontsize=7.5)
        return png(fig)
