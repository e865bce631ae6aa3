"""``method="varpro"``: the exact least-squares optimum by variable projection.

Most friction models are linear in most of their parameters: for fixed values of the others
(the Stribeck velocity and exponent, ...) the prediction is a linear combination of a few
basis functions, ``f(theta) = f_0(nu) + A(nu) c``, where ``c`` are the parameters a model
declares in ``linear_params`` and ``nu`` the rest. Separable (variable-projection) least
squares (Golub and Pereyra 1973; Golub and Pereyra 2003, "Separable nonlinear least squares:
the variable projection method and its applications", Inverse Problems 19 R1) minimises the
projected functional ``min_c ||W^(1/2) (f_0(nu) + A(nu) c - y)||^2`` over ``nu`` alone, the
inner problem solved in closed form for each ``nu``.

What :func:`varpro` does
    1. The basis ``A(nu)`` and offset ``f_0(nu)`` come from the model itself: its prediction
       with the free linear parameters set to 0 and to each unit vector (so fixed parameters,
       linear or not, stay at their values, and nothing but the declaration is asked of a
       model).
    2. The nonlinear parameters (1 or 2 for the Stribeck model, 2 for ``msk``, 3 for ``vlt``,
       none for Coulomb-viscous) are searched on a grid over their whole search box:
       log-spaced where the box is positive, linear otherwise (:data:`GRID_POINTS` points per
       axis). At each grid point the linear parameters are the bounded linear least-squares
       solution inside their box (unconstrained by a batched pseudo-inverse; where that leaves
       the box, ``scipy.optimize.lsq_linear`` with BVLS, Stark and Parker 1995), so
       non-negativity and the other bounds hold exactly. The unconstrained SSE bounds the
       constrained one from below, so only grid points that could rank among the best are
       solved with BVLS.
    3. The best grid points of distinct basins (:data:`N_POLISH` of them, at least 3 grid
       steps apart) are polished by least squares over the nonlinear parameters alone, the
       linear ones projected out at every step (scipy's bounded trust-region reflective
       solver in the unit box of the nonlinear parameters, a forward-difference Jacobian in
       one batched model call, as ``lm``'s), and the lowest wins. Each bounded linear solve
       first tries the previous solve's active set and keeps it when the Karush-Kuhn-Tucker
       conditions hold (the inner problem is convex, so that is its optimum), else BVLS.

    The search box is covered whatever the start, so there is none: ``fit(..., x0=...)`` warns
    that it is not used (``IgnoredArgumentWarning``) and the model file records no ``init``.
    For a model with parameters per direction (``*_asym``) each direction's parameters are
    searched and polished on its own samples (the problem separates).

Losses and weights
    Weights (``weights="std"`` or given) enter as row scaling, exactly. ``mse`` is ``sse`` over
    ``n`` (the same minimiser). A robust loss (``soft_l1``, ``huber``) is not separable: the
    grid then ranks the nonlinear parameters by the (weighted) l2 projection and the polish
    minimises the robust loss over all free parameters from there, so with a robust loss
    ``varpro`` is a well-started local method, not an exact one (the result's message says so).

Cost: one batched model evaluation per grid point and linear parameter (plus one), counted as
evaluations (``nfev``); the polish's evaluations are added.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import least_squares, lsq_linear

from ...errors import ConfigError
from ...optim import OptimizeResult, minimize, single_blas_thread
from ..problem import IdentificationProblem

__all__ = ["GRID_POINTS", "N_POLISH", "SUMMARY", "VARPRO_OPTIONS", "linear_split", "varpro"]

#: One line on the method, as ``fricid methods`` lists it.
SUMMARY = (
    "exact least-squares optimum by variable projection (Golub-Pereyra): the linear "
    "parameters in closed form within their bounds, the others on a grid then polished; "
    "models that declare linear_params (all analytic ones)"
)

#: Grid points per nonlinear axis, by the number of nonlinear parameters searched together.
GRID_POINTS: dict[int, int] = {1: 128, 2: 32, 3: 12}

#: Best grid points of distinct basins polished by ``lm``.
N_POLISH = 3

#: Options of ``method="varpro"`` (``fit(..., options=...)``): ``grid`` points per axis
#: (default :data:`GRID_POINTS`), ``n_polish`` (:data:`N_POLISH`), ``polish_evals`` (the
#: most residual vectors one polish over the nonlinear parameters asks for; default
#: ``200 (q + 1)`` for ``q`` nonlinear parameters).
VARPRO_OPTIONS = ("grid", "n_polish", "polish_evals")

#: Forward-difference step of the polish's Jacobian, in the unit box of the nonlinear
#: parameters (as ``lm``'s).
_FD_STEP = 1e-7

#: Model evaluations (rows of length n) per chunk of the grid: bounds the memory used.
_CHUNK_VALUES = 4_000_000


@dataclass
class _Block:
    """Free parameters searched together: nonlinear ``nl`` and linear ``lin`` (positions in the
    free vector), on the samples ``rows``."""

    nl: list[int]
    lin: list[int]
    rows: np.ndarray


def linear_split(problem: IdentificationProblem) -> tuple[list[int], list[int]]:
    """Positions in the free vector of the linear and the nonlinear free parameters.

    Raises
    ------
    ConfigError
        The model declares no ``linear_params`` (variable projection does not apply).
    """
    model = problem.model
    declared = tuple(getattr(model, "linear_params", ()) or ())
    if not declared or not hasattr(model, "param_names"):
        name = getattr(model, "name", type(model).__name__)
        raise ConfigError(
            f"method 'varpro' needs a model that declares which parameters enter linearly; "
            f"model '{name}' declares none (use --method lm)"
        )
    free = problem.free_names
    lin = [i for i, n in enumerate(free) if n in declared]
    nl = [i for i, n in enumerate(free) if n not in declared]
    return lin, nl


def _blocks(problem: IdentificationProblem, lin: list[int], nl: list[int]) -> list[_Block]:
    """One block, or one per direction for a model with parameters per direction."""
    n = problem.n_obs
    if not getattr(problem.model, "is_asymmetric", False):
        return [_Block(nl, lin, np.ones(n, dtype=bool))]
    free = problem.free_names
    v = problem.X[:, 0]
    blocks = []
    for suffix, rows in (("_pos", v >= 0), ("_neg", v < 0)):
        pick = [i for i in nl if free[i].endswith(suffix)]
        blocks.append(_Block(pick, [i for i in lin if free[i].endswith(suffix)], rows))
    return blocks


def _axes(bounds: np.ndarray, points: int) -> list[np.ndarray]:
    """Grid axes: log-spaced over a positive box, linear otherwise."""
    axes = []
    for lo, hi in bounds:
        if lo > 0 and hi / lo > 10:
            axes.append(np.geomspace(lo, hi, points))
        else:
            axes.append(np.linspace(lo, hi, points))
    return axes


class _Projection:
    """The projected least-squares problem of one block: basis, bounded linear solves.

    A problem of the problem protocol (:class:`fricid.identify.problem.Problem`) over the
    block's nonlinear parameters ``nu`` (``free_names``, in ``bounds``): :meth:`residuals` are
    the weighted residuals with the linear parameters solved for each candidate, and
    :meth:`expand` gives the whole free vector of ``problem`` (``names``) with them.
    """

    def __init__(self, problem: IdentificationProblem, block: _Block, start: np.ndarray):
        self.problem, self.block, self.start = problem, block, start
        rows = block.rows
        w = problem._sqrt_w
        self.sqrt_w = np.ones(int(rows.sum())) if w is None else w[rows]
        self.y = problem.y[rows]
        lo_hi = problem.bounds[block.lin]
        self.lo, self.hi = lo_hi[:, 0], lo_hi[:, 1]
        self.names = tuple(problem.free_names)
        self.bounds = problem.bounds[block.nl]
        self.nfev = 0
        self._active: tuple[np.ndarray, np.ndarray] | None = None

    # -- the problem protocol ------------------------------------------------------------
    @property
    def free_names(self) -> list[str]:
        return [self.names[i] for i in self.block.nl]

    @property
    def n_obs(self) -> int:
        return int(self.y.size)

    @property
    def n_free(self) -> int:
        return len(self.block.nl)

    def residuals(self, NU: np.ndarray) -> np.ndarray:
        """Weighted residuals ``(G, n)`` at nonlinear values ``NU (G, q)``, the linear
        parameters solved within their bounds for each."""
        A, b = self.basis(NU)
        return self.solve_ab(A, b, NU.shape[0])[2]

    def evaluate(self, NU: np.ndarray) -> np.ndarray:
        """The projected SSE ``(G,)``: the problem's least SSE at each ``nu``."""
        R = self.residuals(np.atleast_2d(NU))
        return np.einsum("gn,gn->g", R, R)

    def objective(self):
        return self.evaluate

    def expand(self, NU: np.ndarray) -> np.ndarray:
        """Free vectors ``(G, p)`` of ``problem``: ``NU`` with the linear parameters solved."""
        NU = np.atleast_2d(np.asarray(NU, dtype=float))
        A, b = self.basis(NU)
        C = self.solve_ab(A, b, NU.shape[0])[0]
        return self.candidates(NU, C)

    def candidates(self, NU: np.ndarray, C: np.ndarray | None = None) -> np.ndarray:
        """Free vectors ``(G, p)`` with the block's nonlinear values ``NU`` (and linear ``C``)."""
        Z = np.repeat(self.start[None], NU.shape[0], axis=0)
        Z[:, self.block.nl] = NU
        if C is not None:
            Z[:, self.block.lin] = C
        return Z

    def basis(self, NU: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Weighted basis ``(G, n, m)`` and weighted target ``(G, n)`` (y minus the offset)."""
        m = len(self.block.lin)
        G = NU.shape[0]
        Z = np.repeat(self.candidates(NU, np.zeros((G, m))), m + 1, axis=0)
        for j, pos in enumerate(self.block.lin):
            Z[j + 1 :: m + 1, pos] = 1.0
        P = self.problem.predict(Z)[:, self.block.rows].reshape(G, m + 1, -1)
        self.nfev += Z.shape[0]
        offset = P[:, 0]
        A = (P[:, 1:] - offset[:, None]).transpose(0, 2, 1) * self.sqrt_w[None, :, None]
        b = (self.y[None] - offset) * self.sqrt_w[None]
        return A, b

    def solve(self, NU: np.ndarray, keep: int) -> tuple[np.ndarray, np.ndarray]:
        """Bounded linear solutions ``C (G, m)`` at nonlinear values ``NU (G, q)`` and their
        SSE ``(G,)``: exact for the grid points that could rank among the ``keep`` best,
        ``inf`` for the others."""
        A, b = self.basis(NU)
        C, sse, _ = self.solve_ab(A, b, keep)
        return C, sse

    def solve_ab(
        self, A: np.ndarray, b: np.ndarray, keep: int
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`solve` on a basis, also returning the weighted residuals ``(G, n)``."""
        G, m = A.shape[0], A.shape[2]
        if m == 0:
            return np.zeros((G, 0)), np.einsum("gn,gn->g", b, b), -b
        scale = np.sqrt(np.einsum("gnm,gnm->gm", A, A))
        scale = np.where(scale > 0, scale, 1.0)
        C = np.einsum("gmn,gn->gm", np.linalg.pinv(A / scale[:, None], rcond=1e-13), b) / scale
        span = self.hi - self.lo
        inside = np.all((self.lo - 1e-9 * span <= C) & (self.hi + 1e-9 * span >= C), axis=1)
        C = np.where(inside[:, None], np.clip(C, self.lo, self.hi), C)
        R = np.einsum("gnm,gm->gn", A, C) - b
        sse = np.einsum("gn,gn->g", R, R)  # a lower bound where not inside
        exact = inside.copy()
        for g in np.argsort(sse):
            if exact[g]:
                continue
            known = np.sort(sse[exact])
            if known.size >= keep and sse[g] >= known[keep - 1]:
                break
            C[g] = self.bounded(A[g], b[g])
            R[g] = A[g] @ C[g] - b[g]
            sse[g], exact[g] = float(R[g] @ R[g]), True
        return C, np.where(exact, sse, np.inf), R

    def bounded(self, A: np.ndarray, b: np.ndarray) -> np.ndarray:
        """``argmin ||A c - b||`` over the box of the linear parameters.

        First the active set of the last solve (neighbouring grid points and polish steps
        mostly share it), accepted if it satisfies the Karush-Kuhn-Tucker conditions (then it
        is the optimum: the problem is convex); else BVLS (``scipy.optimize.lsq_linear``).
        """
        if self._active is not None:
            c = self._on_active_set(A, b, *self._active)
            if c is not None:
                return c
        c = np.clip(lsq_linear(A, b, bounds=(self.lo, self.hi), method="bvls").x, self.lo, self.hi)
        tol = 1e-12 * (self.hi - self.lo)
        self._active = (c <= self.lo + tol, c >= self.hi - tol)
        return c

    def _on_active_set(
        self, A: np.ndarray, b: np.ndarray, lower: np.ndarray, upper: np.ndarray
    ) -> np.ndarray | None:
        free = ~(lower | upper)
        c = np.where(lower, self.lo, np.where(upper, self.hi, 0.0))
        if free.any():
            rhs = b - A[:, ~free] @ c[~free]
            c[free] = np.linalg.lstsq(A[:, free], rhs, rcond=None)[0]
        span = self.hi - self.lo
        if np.any(c < self.lo - 1e-9 * span) or np.any(c > self.hi + 1e-9 * span):
            return None
        c = np.clip(c, self.lo, self.hi)
        r = A @ c - b
        g = A.T @ r
        gtol = 1e-9 * np.sqrt(np.einsum("nm,nm->m", A, A)) * max(float(np.linalg.norm(b)), 1e-300)
        if np.any(g[lower] < -gtol[lower]) or np.any(g[upper] > gtol[upper]):
            return None
        return c

    def polish(self, nu0: np.ndarray, bounds: np.ndarray, max_nfev: int) -> tuple[Any, ...]:
        """Least squares over the nonlinear parameters alone, the linear ones projected out
        (scipy's bounded trust-region reflective solver in the unit box of ``bounds``).

        Returns ``(nu, c, sse, converged)``.
        """
        lo, width = bounds[:, 0], bounds[:, 1] - bounds[:, 0]

        def residuals(U: np.ndarray) -> np.ndarray:
            return self.residuals(lo + np.clip(U, 0.0, 1.0) * width)

        def jacobian(u: np.ndarray) -> np.ndarray:
            """Forward differences, every column in one batched call (inward at the upper
            face), as ``lm``'s (:mod:`fricid.optim._least_squares`)."""
            step = np.where(u + _FD_STEP <= 1.0, _FD_STEP, -_FD_STEP)
            U = np.repeat(u[None], u.size + 1, axis=0)
            U[1:] += np.diag(step)
            R = residuals(U)
            return ((R[1:] - R[0]) / step[:, None]).T

        u0 = np.clip((nu0 - lo) / width, 1e-9, 1.0 - 1e-9)
        sol = least_squares(
            lambda u: residuals(u[None])[0],
            u0,
            jac=jacobian,
            bounds=(0.0, 1.0),
            method="trf",
            ftol=1e-12,
            xtol=1e-12,
            gtol=1e-12,
            max_nfev=max_nfev,
        )
        nu = lo + np.clip(sol.x, 0.0, 1.0) * width
        A, b = self.basis(nu[None])
        C, sse, _ = self.solve_ab(A, b, 1)
        return nu, C[0], float(sse[0]), bool(sol.status > 0)


def _search(
    proj: _Projection, bounds: np.ndarray, points: int, n_keep: int
) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """The best grid points of distinct basins, ``(nu, c, sse)``, best first."""
    axes = _axes(bounds, points)
    if axes:
        index = np.stack(np.meshgrid(*[np.arange(a.size) for a in axes], indexing="ij"), -1)
        index = index.reshape(-1, len(axes))
    else:  # every free parameter is linear: one linear solve
        index = np.zeros((1, 0), dtype=int)
    NU = np.empty(index.shape)
    for j, a in enumerate(axes):
        NU[:, j] = a[index[:, j]]
    per = max(1, _CHUNK_VALUES // max(1, (len(proj.block.lin) + 1) * proj.y.size))
    C = np.empty((NU.shape[0], len(proj.block.lin)))
    sse = np.empty(NU.shape[0])
    for s in range(0, NU.shape[0], per):
        C[s : s + per], sse[s : s + per] = proj.solve(NU[s : s + per], 5 * n_keep)
    picked: list[int] = []
    for g in np.argsort(sse):
        if not np.isfinite(sse[g]) or len(picked) == n_keep:
            break
        if all(np.max(np.abs(index[g] - index[h])) > 2 for h in picked):
            picked.append(int(g))
    return [(NU[g], C[g], float(sse[g])) for g in picked]


def _option(options: dict[str, Any], name: str, default: int) -> int:
    value = options.get(name, default)
    if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value < 1:
        raise ConfigError(
            f"method 'varpro': option '{name}' must be an integer >= 1; got {value!r}"
        )
    return int(value)


@single_blas_thread
def varpro(
    problem: IdentificationProblem,
    *,
    seed: int | np.random.Generator | None = 0,
    max_evals: int | None = None,
    options: dict[str, Any] | None = None,
    callback: Callable[[OptimizeResult], Any] | None = None,
) -> OptimizeResult:
    """Minimise ``problem`` by variable projection (see the module docstring).

    Parameters
    ----------
    problem : IdentificationProblem
        A named model's problem; the model declares ``linear_params``.
    seed : int or numpy.random.Generator, optional
        Recorded; the search is deterministic (a robust loss's ``lm`` polish gets it).
    max_evals : int, optional
        The budget of a robust loss's ``lm`` polish (the projected polishes have the option
        ``polish_evals``).
    options : dict, optional
        :data:`VARPRO_OPTIONS`.
    callback : callable, optional
        Called once with the result (and at each step of a robust loss's ``lm`` polish).

    Returns
    -------
    OptimizeResult
        ``x`` (free parameters), ``fun`` (the problem's loss), ``nfev`` (grid and polish),
        ``status`` (0 when every projected polish converged by scipy's criterion, 1 when one
        spent its budget; with a robust loss, its ``lm`` polish's), ``method`` "varpro", and
        ``grid_points``.

    Raises
    ------
    ConfigError
        The model declares no linear parameters; an unknown or bad option.
    """
    opts = dict(options or {})
    unknown = sorted(set(opts) - set(VARPRO_OPTIONS))
    if unknown:
        raise ConfigError(
            f"method 'varpro' has no option(s) {', '.join(unknown)}; its options: "
            f"{', '.join(VARPRO_OPTIONS)}"
        )
    lin, nl = linear_split(problem)
    n_polish = _option(opts, "n_polish", N_POLISH)
    start = problem.start()
    x = start.copy()
    nfev, grid_points, converged = 0, 0, True
    for block in _blocks(problem, lin, nl):
        proj = _Projection(problem, block, start)
        q, box = len(block.nl), problem.bounds[block.nl]
        points = _option(opts, "grid", GRID_POINTS.get(q, 8)) if q else 1
        found = _search(proj, box, points, n_polish)
        grid_points += points**q
        best = found[0] + (True,)
        if q:
            budget = _option(opts, "polish_evals", 200 * (q + 1))
            for nu0, _, _ in found:
                polished = proj.polish(nu0, box, budget)
                if polished[2] <= best[2]:
                    best = polished
            converged = converged and best[3]
        x[block.nl], x[block.lin] = best[0], best[1]
        nfev += proj.nfev
    fun = float(problem.evaluate(x[None])[0])
    history = [[nfev, fun]]
    status = 0 if converged else 1
    exact_l2 = problem.f_scale is None
    what = "exact (l2)" if exact_l2 else "robust loss: l2-projected grid, then an lm polish"
    message = (
        f"{'converged' if converged else 'polish budget spent'}; variable projection, {what}: "
        f"{grid_points} grid points over {', '.join(problem.free_names[i] for i in nl) or '-'}"
        + (f", the best {n_polish} polished over them" if nl else "")
    )
    if not exact_l2:
        res = minimize(
            problem.evaluate,
            problem.bounds,
            method="lm",
            x0=x,
            options={"n_starts": 1},
            max_evals=max_evals,
            residuals=problem.residuals,
            seed=seed,
            callback=callback,
        )
        nfev += int(res.nfev)
        if float(res.fun) <= fun:
            x, fun = np.asarray(res.x, dtype=float), float(res.fun)
        status = int(res.status)
        message += f" ({res.message})"
        history.append([nfev, fun])
    result = OptimizeResult(
        x=x,
        fun=fun,
        nfev=nfev,
        nit=grid_points,
        history=np.array(history, dtype=float),
        status=status,
        message=message,
        success=status == 0,
        method="varpro",
        seed=seed if isinstance(seed, int) else None,
        max_evals=nfev if max_evals is None else max(int(max_evals), nfev),
        grid_points=grid_points,
    )
    if callback is not None and exact_l2:
        callback(result)
    return result
