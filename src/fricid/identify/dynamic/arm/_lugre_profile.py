"""Profile-likelihood intervals of a LuGre joint's nonlinear parameters (:mod:`._lugre`).

Why not the Wald intervals (the covariance's): LuGre's equation error is far from linear in
sigma_0, sigma_1 and the Stribeck shape (tau_s, w_s, delta). Measured on the open-loop truth
(``benchmarks/bench_arm_lugre.py --truth own --law a``, seeds 0-9, 30 s, the Wald
intervals): the estimates' spread was 2.4 (sigma_0), 4.1 (sigma_1), 3.5 (tau_s), 2.8 (w_s) and
2.6 (delta) times their standard errors, 0.9 and 0.7 for tau_c and sigma_2. sigma_1's profile
is flat on one side and a cliff on the other (the bristles' damping acts only during their
transient at a reversal).

A parameter's interval is where its profile, the least cost with it fixed and every other
parameter free (:func:`profile_interval`), stays within ``q c`` of the least cost in units
of the noise's variance: ``q`` a chi-square quantile (the caller's: :data:`._lugre.PROFILE_DOF`),
``c >= 1`` the ratio of the parameter's variance with the filter's and the residuals'
correlation (and ``beta``'s uncertainty) to the variance without them (what the correlated
rows add, :func:`._solve.arm_covariance`). Each side is stepped out from the Wald
half-width, doubling, until the profile crosses; the crossing is then interpolated on the
signed root of the profile (twice). A side that reaches the search box's end below the
threshold is open. A profile point below the least cost means the search had stopped short or
in another valley: the fit restarts from it (:class:`Better`), a few times at most; then the
profiles are taken about the best point the search found (an interval about a point above the
least cost is wider than the least cost's).

sigma_0 and sigma_1 are profiled over a grid across their whole box instead
(:func:`grid_interval`): their valleys are long and flat (sigma_1's cost changed by a few
units over two decades on the open-loop truth, seed 21), where a local search stops wherever
its steps become small, and stepping out from such a stop found better fits again and again.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.optimize

__all__ = ["Better", "grid_interval", "profile_interval"]

#: Doublings of the step before a side is given up as reaching the box's end.
MAX_DOUBLINGS = 8
#: Evaluations of each profile point's search of the other parameters, and its relative
#: tolerance on the cost (a threshold is some units on a cost of as many units as rows).
POINT_EVALS = 60
POINT_FTOL = 1e-6
#: A profile point this share of the threshold below the least cost is a better fit to
#: restart from. Less is counted as at the least cost: a base above the least cost widens
#: the interval, never narrows it.
BETTER = 0.25


class Better(Exception):
    """A profile point fits better than the estimate: ``x`` is where."""

    def __init__(self, x: np.ndarray) -> None:
        super().__init__("a better fit than the estimate")
        self.x = x


@dataclass
class _Profile:
    residual: Callable[[np.ndarray], np.ndarray]
    lo: np.ndarray
    hi: np.ndarray
    restart: bool = True
    calls: int = 0

    def cost(self, x: np.ndarray, k: int, value: float) -> tuple[float, np.ndarray]:
        """The least ``sum r^2`` with ``x[k] = value``, and where."""
        free = [i for i in range(x.size) if i != k]

        def fixed(y: np.ndarray) -> np.ndarray:
            z = x.copy()
            z[free], z[k] = y, value
            return self.residual(z)

        sol = scipy.optimize.least_squares(
            fixed,
            np.clip(x[free], self.lo[free], self.hi[free]),
            bounds=(self.lo[free], self.hi[free]),
            max_nfev=POINT_EVALS,
            ftol=POINT_FTOL,
        )
        self.calls += int(sol.nfev) + int(sol.njev or 0) * len(free)  # FD Jacobians too
        z = x.copy()
        z[free], z[k] = sol.x, value
        return 2.0 * float(sol.cost), z


def _cross(inside: float, r_in: float, out: float, r_out: float, limit: float) -> float:
    """Where the profile's signed root reaches ``sqrt(limit)``, linearly between a point
    inside (root ``r_in``) and one outside (``r_out``); halfway when they do not differ."""
    if not r_out > r_in:
        return 0.5 * (inside + out)
    return inside + (math.sqrt(limit) - r_in) / (r_out - r_in) * (out - inside)


def _side(p: _Profile, x, k, d, half, limit, base) -> float | None:
    end = p.hi[k] if d > 0 else p.lo[k]
    inside, r_in, x_in = x[k], 0.0, x
    step = half
    for _ in range(MAX_DOUBLINGS):
        v = x[k] + d * step
        last = d * (v - end) >= 0
        v = end if last else v
        c, z = p.cost(x_in, k, v)
        if p.restart and c < base - BETTER * limit:
            raise Better(z)
        if c - base > limit:
            out, r_out = v, math.sqrt(c - base)
            for _ in range(2):  # the signed root is about linear in the parameter
                mid = _cross(inside, r_in, out, r_out, limit)
                cm, zm = p.cost(x_in, k, mid)
                if p.restart and cm < base - BETTER * limit:
                    raise Better(zm)
                if cm - base > limit:
                    out, r_out = mid, math.sqrt(cm - base)
                else:
                    inside, r_in, x_in = mid, math.sqrt(max(cm - base, 0.0)), zm
            return _cross(inside, r_in, out, r_out, limit)
        if last:
            return None
        inside, r_in, x_in = v, math.sqrt(max(c - base, 0.0)), z
        step *= 2.0
    return None


def profile_interval(
    residual, x, k, half, limit, lo, hi, restart: bool = True
) -> tuple[float | None, float | None, int]:
    """(lower end, upper end, evaluations) of parameter ``k``'s profile interval about the
    estimate ``x``: where the least ``sum r^2`` with ``x[k]`` fixed stays within ``limit`` of
    ``sum r^2`` at ``x`` (module notes); None for a side open to the box ``lo``, ``hi``.
    ``half``: the Wald half-width, the first step.

    Raises
    ------
    Better
        A profile point fits better than ``x`` (unless ``restart`` is false: the interval is
        then taken about ``x``, wider than about the better point).
    """
    p = _Profile(residual, lo, hi, restart)
    r = residual(x)
    base = float(r @ r)
    half = max(float(half), 1e-6 * (hi[k] - lo[k]) if np.isfinite(hi[k] - lo[k]) else 1e-6)
    lower = _side(p, x, k, -1.0, half, limit, base)
    upper = _side(p, x, k, 1.0, half, limit, base)
    return lower, upper, p.calls


def grid_interval(
    residual, x, k, grid, limit, lo, hi, restart: bool = True
) -> tuple[float | None, float | None, int]:
    """:func:`profile_interval` for parameter ``k`` from its profile on ``grid`` (ascending,
    across the box), walked out from the estimate both ways with warm starts; the ends
    interpolated on the signed root between grid points, then once more.

    Raises
    ------
    Better
        A grid point fits better than ``x`` (the best one is given), unless ``restart`` is
        false.
    """
    p = _Profile(residual, lo, hi, restart)
    r = residual(x)
    base = float(r @ r)
    grid = np.asarray(grid, dtype=float)
    costs = np.full(grid.size, np.nan)
    points: list[np.ndarray | None] = [None] * grid.size
    first = int(np.searchsorted(grid, x[k]))
    for order in (range(first, grid.size), range(first - 1, -1, -1)):
        start = x
        for i in order:
            costs[i], points[i] = p.cost(start, k, float(grid[i]))
            start = points[i]
    best = int(np.nanargmin(costs))
    if p.restart and costs[best] < base - BETTER * limit:
        raise Better(points[best])
    root = np.sqrt(np.clip(costs - base, 0.0, None))
    ends: list[float | None] = []
    for step in (-1, 1):
        i = first - 1 if step < 0 else first  # the grid's first point that side
        inside_v, r_in, x_in = x[k], 0.0, x
        while 0 <= i < grid.size and costs[i] - base <= limit:
            inside_v, r_in, x_in = grid[i], root[i], points[i]
            i += step
        if not 0 <= i < grid.size:
            ends.append(None)
            continue
        out_v, r_out = grid[i], root[i]
        mid = _cross(inside_v, r_in, out_v, r_out, limit)
        cm, _ = p.cost(x_in, k, mid)
        rm = math.sqrt(max(cm - base, 0.0))
        if cm - base > limit:
            out_v, r_out = mid, rm
        else:
            inside_v, r_in = mid, rm
        ends.append(_cross(inside_v, r_in, out_v, r_out, limit))
    return ends[0], ends[1], p.calls
