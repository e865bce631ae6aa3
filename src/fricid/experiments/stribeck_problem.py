"""The Stribeck identification problem of the RWSAVSBAS paper: data, objective, exact optimum.

[R] B. Kou et al., "A New Parameter Identification Method for Industrial Robots with
Friction", Machines 10(5) 349, 2022: the Stribeck model (eq. 7, delta = 1) fitted to 17
friction samples by minimising the SSE (eq. 11). :func:`paper2_samples` simulates them on the
``paper2`` preset, :class:`StribeckProblem` holds the objective (an
:class:`~fricid.identify.problem.IdentificationProblem`; :func:`sse_objective` hands the
optimisers its callable, with the compiled twin every analytic fit uses) and
:func:`global_optimum` finds the exact optimum by variable projection.

The search box (:data:`BOUNDS`) is ours ([R] does not give one): tau_c and tau_s in
[0, 2] N m, w_s in [0.001, 1] rad/s, tau_v in [0, 0.1] N m s/rad. The beetle methods step in
the unit box mapped onto it, so a step of 0.1 moves tau_s by 0.2 N m but w_s by 0.1 rad/s:
the box sets what [R]'s step sizes mean.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares, lsq_linear

from ..identify.problem import IdentificationProblem
from ..models import Stribeck
from ..optim import JitObjective
from ..samples import FrictionSamples

__all__ = [
    "BOUNDS",
    "FREE",
    "StribeckProblem",
    "global_optimum",
    "paper2_samples",
    "sse_objective",
]

#: The free parameters (delta fixed to 1, [R] 2.3).
FREE = ("tau_c", "tau_s", "w_s", "tau_v")

#: Search bounds of the benchmark, one row per free parameter (see the module docstring).
BOUNDS = np.array([[0.0, 2.0], [0.0, 2.0], [1e-3, 1.0], [0.0, 0.1]])


def paper2_samples(seed: int = 0, size: str = "full") -> tuple[np.ndarray, np.ndarray]:
    """The 17 friction samples of the ``paper2`` preset: velocity [rad/s], friction [N m].

    Simulates the virtual joint (:func:`fricid.sim.simulate`) and extracts it with
    ``gravity="none"`` (a horizontal joint, [R] 2.1); the direction-combined samples (eq. 11
    of the BAS-RBFNN paper) are the 17 points of [R]. The one place the study gets its data.
    """
    from ..extract import extract
    from ..sim import preset, simulate

    result = extract(simulate(preset("paper2", size), seed=seed), gravity="none")
    s = result.samples
    return np.asarray(s.X[:, 0], dtype=float), np.asarray(s.y, dtype=float)


@dataclass
class StribeckProblem:
    """The SSE of [R] eq. 11 for the Stribeck model of fricid (delta fixed to 1).

    A thin view of an :class:`~fricid.identify.problem.IdentificationProblem` (the one place
    fricid's objective is written) with the study's box :data:`BOUNDS`.
    """

    velocity: np.ndarray
    friction: np.ndarray
    bounds: np.ndarray = field(default_factory=lambda: BOUNDS.copy())

    def __post_init__(self) -> None:
        self.velocity = np.ascontiguousarray(self.velocity, dtype=float)
        self.friction = np.ascontiguousarray(self.friction, dtype=float)
        model = Stribeck()
        samples = FrictionSamples(
            velocity=self.velocity, load=0.0, temperature=25.0, friction=self.friction
        )
        names = [n for n in model.param_names if n != "delta"]
        self.identification = IdentificationProblem(
            model,
            samples,
            loss="sse",
            bounds={n: tuple(b) for n, b in zip(names, self.bounds, strict=True)},
            fixed={"delta": 1.0},
        )

    def predict(self, theta: np.ndarray) -> np.ndarray:
        """Friction ``(k, n)`` for free parameters ``theta (k, 4)``."""
        return self.identification.predict(theta)

    def residuals(self, theta: np.ndarray) -> np.ndarray:
        return self.identification.residuals(theta)

    def sse(self, theta: np.ndarray) -> np.ndarray:
        return self.identification.evaluate(theta)

    def objective(self, jit: bool = True):
        """The objective for :func:`fricid.optim.minimize`; see :func:`sse_objective`."""
        return sse_objective(self, jit=jit)


def global_optimum(problem: StribeckProblem, n_grid: int = 4001) -> tuple[np.ndarray, float]:
    """The exact global optimum by variable projection.

    For fixed w_s the model is linear in (tau_c, tau_s, tau_v): ``f = (1 - e) tau_c + e tau_s +
    v tau_v`` with ``e = exp(-v / w_s)`` (v > 0). A dense log-spaced grid of ``n_grid`` values
    of w_s over its bounds, each with the bounded linear least-squares solution
    (``scipy.optimize.lsq_linear``), gives the best w_s to grid resolution; a bounded
    least-squares polish of all four parameters from the best few grid points finishes it.
    """
    v, y, b = problem.velocity, problem.friction, problem.bounds
    av, sg = np.abs(v), np.sign(v)
    grid = np.geomspace(b[2, 0], b[2, 1], n_grid)
    lin_bounds = (b[[0, 1, 3], 0], b[[0, 1, 3], 1])
    sse = np.empty(n_grid)
    coef = np.empty((n_grid, 3))
    for i, ws in enumerate(grid):
        e = np.exp(-av / ws)
        A = np.column_stack([sg * (1.0 - e), sg * e, v])
        c, *_ = np.linalg.lstsq(A, y, rcond=None)
        if np.any(c < lin_bounds[0]) or np.any(c > lin_bounds[1]):
            c = lsq_linear(A, y, bounds=lin_bounds, method="bvls").x
        coef[i] = c
        r = A @ c - y
        sse[i] = r @ r
    best_theta, best_sse = None, np.inf
    for i in np.argsort(sse)[:5]:
        start = np.array([coef[i, 0], coef[i, 1], grid[i], coef[i, 2]])
        start = np.clip(start, b[:, 0] + 1e-12 * (b[:, 1] - b[:, 0]), b[:, 1])
        sol = least_squares(
            lambda t: problem.residuals(t[None])[0],
            start,
            bounds=(b[:, 0], b[:, 1]),
            method="trf",
            xtol=1e-15,
            ftol=1e-15,
            gtol=1e-15,
            max_nfev=2000,
        )
        for cand in (sol.x, start):
            s = float(problem.sse(cand[None])[0])
            if s < best_sse:
                best_theta, best_sse = cand.copy(), s
    return best_theta, best_sse


def sse_objective(problem: StribeckProblem, *, jit: bool = True):
    """The SSE objective ([R] eq. 11) of ``problem`` as the optimisers take it.

    Parameters
    ----------
    problem : StribeckProblem
        The data and box.
    jit : bool
        With numba available, the :class:`~fricid.optim.JitObjective` of the problem's
        :meth:`~fricid.identify.problem.IdentificationProblem.objective`: every call runs the
        compiled loss kernel of fricid's analytic models
        (:func:`fricid.models._kernels.loss_kernel`), so every method evaluates candidates
        with the same compiled code, and RWSAVSBAS can also run its whole inner loop compiled
        on it; otherwise, or with ``jit=False``, the batched numpy :meth:`StribeckProblem.sse`.

    Returns
    -------
    callable
        ``f(X)`` with ``X`` of shape ``(k, 4)`` returning ``(k,)``.

    Notes
    -----
    The study writes no objective of its own: both paths are the
    :class:`~fricid.identify.problem.IdentificationProblem`'s (the compiled kernel computes
    the numpy path's SSE; a test holds them together).
    """
    if jit:
        fun = problem.identification.objective()
        if isinstance(fun, JitObjective):
            return fun
    return problem.sse
