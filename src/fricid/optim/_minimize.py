"""The entry points :func:`minimize` (one run) and :func:`minimize_runs` (independent runs,
batched where the method allows); the conventions they honour are in :mod:`fricid.optim._api`.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

from ..errors import ConfigError, IgnoredArgumentWarning, user_stacklevel
from ._api import (
    BUDGET,
    CALLBACK,
    CONVERGED,
    ITERATIONS,
    METHODS,
    NO_FINITE,
    STATUS_MESSAGES,
    Budget,
    Objective,
    OptimizeResult,
    Solver,
    check_bounds,
)

__all__ = ["DEFAULT_LSQ_METHOD", "DEFAULT_METHOD", "minimize", "minimize_runs"]

#: The method of :func:`minimize` when none is named and no residuals are given: a cheap
#: bounded local method (as scipy's ``minimize`` defaults to a local quasi-Newton one); the
#: global methods (the beetle family, ``ga``, ``de``, ...) are one argument away.
DEFAULT_METHOD = "lbfgsb"

#: The method when none is named and ``residuals`` are given: bounded least squares.
DEFAULT_LSQ_METHOD = "lm"


def _check_seed_int(seed) -> int:
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ConfigError(f"seed must be a non-negative int or a numpy Generator; got {seed!r}")
    return int(seed)


def _seeds(seed, runs: int | None) -> tuple[list[np.random.Generator], list[int | None]]:
    """One generator per run, and the integer seed each was made from."""
    if runs is None:
        if isinstance(seed, np.random.Generator):
            return [seed], [None]
        if seed is None:
            seed = int(np.random.SeedSequence().entropy % (2**32))
        s = _check_seed_int(seed)
        return [np.random.default_rng(s)], [s]
    if isinstance(seed, np.random.Generator):
        base = int(seed.integers(2**31))
    elif seed is None:
        base = int(np.random.SeedSequence().entropy % (2**31))
    else:
        base = _check_seed_int(seed)
    seeds = [base + r for r in range(runs)]
    return [np.random.default_rng(s) for s in seeds], list(seeds)


def _result(
    objective: Objective, r: int, nit: int, status: int, message: str, key: str, seed
) -> OptimizeResult:
    best_f = float(objective.best_f[r])
    finite = np.isfinite(best_f)
    x = objective.to_x(objective.best_u[r]) if finite else np.full(objective.dim, np.nan)
    if not finite:
        status, message = NO_FINITE, STATUS_MESSAGES[NO_FINITE]
    return OptimizeResult(
        x=x,
        fun=best_f,
        nfev=objective.nfev,
        nit=nit,
        history=objective.history(r),
        status=status,
        message=message,
        success=status == CONVERGED,
        method=key,
        seed=seed,
        max_evals=objective.max_evals,
    )


def _solve(solver: Solver, objective: Objective) -> tuple[int, int, str]:
    """Run ``solver``; return ``(nit, status, message)``."""
    try:
        nit, detail = solver.run()
    except Budget:
        nit = solver.nit
        if objective.stopped_by_callback:
            status, message = CALLBACK, STATUS_MESSAGES[CALLBACK]
        else:
            status, message = BUDGET, f"evaluation budget of {objective.max_evals} spent"
    else:
        status = CONVERGED if solver.converged else ITERATIONS
        message = f"{STATUS_MESSAGES[status]}: {detail}"
    if not np.isfinite(objective.best_f).any():
        raise ConfigError(
            f"{STATUS_MESSAGES[NO_FINITE]}: the objective returned NaN or inf for every one "
            f"of the {objective.nfev} candidates evaluated; check it and the bounds"
        )
    return nit, status, message


def minimize(
    fun: Callable[[np.ndarray], np.ndarray] | None,
    bounds,
    method: str | None = None,
    *,
    seed: int | np.random.Generator | None = None,
    max_evals: int | None = None,
    options: dict[str, Any] | None = None,
    callback: Callable[[OptimizeResult], Any] | None = None,
    x0=None,
    residuals: Callable[[np.ndarray], np.ndarray] | None = None,
) -> OptimizeResult:
    """Minimise ``fun`` over the box ``bounds`` with ``method``: one run.

    Parameters
    ----------
    fun : callable or None
        Batch objective ``(k, d) -> (k,)``, or None when ``residuals`` is given (then ``fun``
        is the sum of squared residuals).
    bounds : sequence of (float, float)
        ``(lower, upper)``, one pair per parameter.
    method : str, optional
        A key of :data:`METHODS` (case-insensitive). Default: :data:`DEFAULT_LSQ_METHOD`
        (``lm``, bounded least squares) when ``residuals`` are given, else
        :data:`DEFAULT_METHOD` (``lbfgsb``, bounded quasi-Newton): cheap and local, from
        ``x0`` or the box centre. Name a global method (``rwsavsbas``, ``bas``, ``ga``,
        ``de``, ...) to search the whole box.
    seed : int or numpy.random.Generator, optional
        The same seed gives the same result bit for bit; None draws one (recorded in the
        result).
    max_evals : int, optional
        Budget in candidate evaluations (the method's default when None).
    options : dict, optional
        Method options; unknown names raise :class:`ConfigError` listing the known ones.
    callback : callable, optional
        Called with an intermediate :class:`OptimizeResult` (``x``, ``fun``, ``nfev``,
        ``nit``) after each iteration; returning True or raising ``StopIteration`` stops the
        run (status 2).
    x0 : array_like, optional
        Starting point, for the methods that use one.
    residuals : callable, optional
        Batch residuals ``(k, d) -> (k, n)`` for the least-squares methods (``lm``, ``trf``,
        ``bas+lm``). Given to another method together with ``fun``, it is ignored with an
        :class:`~fricid.errors.IgnoredArgumentWarning`.

    Returns
    -------
    OptimizeResult
        The run's result; ``success`` is True only when the method converged (``status``
        0; see the module notes for each method's criterion).

    Raises
    ------
    ConfigError
        Bad method, bounds, options, seed or budget, or an objective that returned no
        finite value at all.

    See Also
    --------
    minimize_runs : independent runs, batched where the method allows.
    """
    return _minimize(
        fun, bounds, method, seed, max_evals, options, callback, x0, residuals, None, 3
    )[0]


def minimize_runs(
    fun: Callable[[np.ndarray], np.ndarray] | None,
    bounds,
    method: str | None = None,
    *,
    runs: int,
    seed: int | np.random.Generator | None = None,
    max_evals: int | None = None,
    options: dict[str, Any] | None = None,
    callback: Callable[[OptimizeResult], Any] | None = None,
    x0=None,
    residuals: Callable[[np.ndarray], np.ndarray] | None = None,
) -> list[OptimizeResult]:
    """``runs`` independent runs of :func:`minimize`, batched where the method allows.

    Parameters
    ----------
    fun, bounds, method, max_evals, options, x0, residuals
        As for :func:`minimize` (``max_evals`` is the budget of each run; the default
        methods are local and deterministic, so their runs from one start agree: name a
        global method for independent runs).
    runs : int
        Number of runs, at least 1.
    seed : int or numpy.random.Generator, optional
        Run ``r`` uses seed ``seed + r``; a Generator gives the base seed by one draw, None
        draws one.
    callback : callable, optional
        As for :func:`minimize`; the intermediate result also has ``run`` (its index) when
        ``runs > 1``. Stopping one run of a lockstep batch stops them all.

    Returns
    -------
    list of OptimizeResult
        One per run. Methods marked ``batched`` (bas, vsbas, ibas, rwsavsbas; ga with
        ``dedupe=False``) advance the runs in lockstep with one objective call per iteration
        for all of them; each run's result is still bit-identical to ``minimize(...,
        seed=seed + r)``, provided ``fun`` evaluates each row independently of the others
        (true of element-wise numpy code).
        Other methods make the runs one after another.
    """
    if isinstance(runs, bool) or not isinstance(runs, int | np.integer) or runs < 1:
        raise ConfigError(f"runs must be a positive integer; got {runs!r}")
    return _minimize(
        fun, bounds, method, seed, max_evals, options, callback, x0, residuals, int(runs), 3
    )


def _minimize(
    fun, bounds, method, seed, max_evals, options, callback, x0, residuals, runs, stacklevel
) -> list[OptimizeResult]:
    """The one implementation behind :func:`minimize` (``runs`` None) and
    :func:`minimize_runs`; warnings point at the first caller outside fricid
    (:func:`fricid.errors.user_stacklevel`; ``stacklevel`` is kept for the callers)."""
    if method is None:
        method = DEFAULT_LSQ_METHOD if residuals is not None else DEFAULT_METHOD
    key = str(method).strip().lower()
    if key not in METHODS:
        raise ConfigError(
            f"unknown method '{method}'; choose one of: "
            + "; ".join(f"{k} ({c.summary})" for k, c in METHODS.items())
        )
    cls = METHODS[key]
    b = check_bounds(bounds)
    if fun is None and residuals is None:
        raise ConfigError("give an objective `fun`, or `residuals` for least squares")
    if cls.uses_residuals and residuals is None:
        raise ConfigError(f"method '{key}' ({cls.summary}) needs `residuals`")
    if residuals is not None and fun is not None and not cls.uses_residuals:
        warnings.warn(
            f"method '{key}' does not use `residuals`; it minimises `fun` (least-squares "
            "methods: " + ", ".join(k for k, c in METHODS.items() if c.uses_residuals) + ")",
            IgnoredArgumentWarning,
            stacklevel=user_stacklevel(),
        )
    if fun is None:
        res_fun = residuals

        def fun(X: np.ndarray) -> np.ndarray:
            r = np.asarray(res_fun(X), dtype=float)
            if r.ndim != 2 or r.shape[0] != X.shape[0]:
                raise ConfigError(
                    f"the residual function must return shape ({X.shape[0]}, n) for a batch of "
                    f"{X.shape[0]} points; got {r.shape}"
                )
            return np.einsum("kn,kn->k", r, r)

    if max_evals is not None and (
        isinstance(max_evals, bool) or not isinstance(max_evals, int | np.integer) or max_evals < 1
    ):
        raise ConfigError(f"max_evals must be a positive integer; got {max_evals!r}")
    if x0 is not None:
        x0 = np.asarray(x0, dtype=float)
        if x0.shape != (b.shape[0],):
            raise ConfigError(f"x0 has shape {x0.shape}; the bounds give {b.shape[0]} parameters")
        if not np.isfinite(x0).all() or np.any(x0 < b[:, 0]) or np.any(x0 > b[:, 1]):
            raise ConfigError("x0 lies outside the bounds")
    opts = dict(options or {})
    solver = cls(opts, dim=b.shape[0], x0=x0, residuals=residuals)
    budget = int(max_evals) if max_evals is not None else solver.default_budget()
    rngs, seeds = _seeds(seed, runs)
    n = len(rngs)

    results: list[OptimizeResult] = []
    if solver.batched:
        objective = Objective(fun, b, budget, callback, runs=n)
        nit, status, message = _solve(solver.bind(objective, rngs), objective)
        results = [_result(objective, r, nit, status, message, key, seeds[r]) for r in range(n)]
    else:
        for r in range(n):
            one = solver if r == 0 else cls(opts, dim=b.shape[0], x0=x0, residuals=residuals)
            objective = Objective(fun, b, budget, callback, runs=1)
            nit, status, message = _solve(one.bind(objective, [rngs[r]]), objective)
            results.append(_result(objective, 0, nit, status, message, key, seeds[r]))
    return results
