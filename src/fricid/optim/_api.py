"""The optimiser API, shaped after ``scipy.optimize.minimize`` (DESIGN.md, "Optimiser API").

``minimize(fun, bounds, method=..., seed=..., max_evals=..., options=..., callback=...)``
dispatches to one solver class per method through :data:`METHODS`, and returns an
:class:`OptimizeResult`.

Conventions every method honours:

* ``fun`` takes a batch ``(k, d)`` and returns ``(k,)``; one candidate evaluated is one
  evaluation (``nfev``), for every method, so budgets compare fairly. Least-squares methods
  also take ``residuals``, a batch ``(k, d) -> (k, n)`` residual function; one residual
  vector is one evaluation.
* Search happens in the unit box ``[0, 1]^d`` mapped linearly onto ``bounds``; candidates
  that step outside are clipped back onto the box, so ``bounds`` are never left.
* NaN (or inf) objective values count as the worst possible value, never as the best.
* ``history`` is the best-so-far value against the evaluation count, an array ``(m, 2)``
  with columns ``nfev, best fun``; it is monotone non-increasing.
* Randomness comes only from ``seed`` (int or ``numpy.random.Generator``) through
  ``numpy.random.default_rng``; the integer seed used is recorded in the result.

Optimisers know nothing of friction: this package imports nothing of fricid but ``errors``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..errors import ConfigError

__all__ = [
    "METHODS",
    "Budget",
    "Objective",
    "OptimizeResult",
    "Solver",
    "check_bounds",
    "minimize",
    "register",
]


class OptimizeResult(dict):
    """The result of :func:`minimize`: a dict with attribute access (like scipy's).

    Keys: ``x`` (best point, in bounds), ``fun`` (its value), ``nfev``, ``nit``,
    ``history`` ((m, 2): nfev, best-so-far fun), ``message``, ``success``, ``method``,
    ``seed`` (the integer seed used, or None when a Generator was passed); methods may add more.
    """

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError as exc:
            raise AttributeError(name) from exc

    __setattr__ = dict.__setitem__  # type: ignore[assignment]
    __delattr__ = dict.__delitem__  # type: ignore[assignment]

    def __repr__(self) -> str:
        keys = ("method", "fun", "x", "nfev", "nit", "success", "message")
        body = ", ".join(f"{k}={self[k]!r}" for k in keys if k in self)
        return f"OptimizeResult({body})"


class Budget(Exception):
    """Raised inside a solver when the evaluation budget is spent (caught by :func:`minimize`)."""


def check_bounds(bounds) -> np.ndarray:
    """Validate ``bounds`` (a sequence of (lower, upper) pairs) and return a ``(d, 2)`` array."""
    try:
        b = np.asarray(bounds, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"bounds must be a sequence of (lower, upper) pairs: {exc}") from None
    if b.ndim != 2 or b.shape[1] != 2 or b.shape[0] == 0:
        raise ConfigError(
            f"bounds must be a non-empty sequence of (lower, upper) pairs; got shape {b.shape}"
        )
    if not np.isfinite(b).all():
        raise ConfigError("bounds must be finite")
    bad = np.flatnonzero(b[:, 0] >= b[:, 1])
    if bad.size:
        i = int(bad[0])
        raise ConfigError(
            f"bounds[{i}] has lower >= upper ({b[i, 0]!r} >= {b[i, 1]!r}); "
            "fix the parameter's range (fixed parameters are passed separately)"
        )
    return b


class Objective:
    """Wraps a batch objective: maps the unit box to bounds, counts evaluations, keeps the best.

    ``__call__(U)`` takes unit-box points ``(k, d)`` (clipped to [0, 1]) and returns ``(k,)``
    values with NaN/inf replaced by ``+inf``. It raises :class:`Budget` before evaluating a
    batch that the budget cannot pay for in full, after spending what is left on a prefix, so
    ``nfev`` never exceeds ``max_evals``.
    """

    def __init__(
        self,
        fun: Callable[[np.ndarray], np.ndarray],
        bounds: np.ndarray,
        max_evals: int,
        callback: Callable[[OptimizeResult], Any] | None = None,
    ) -> None:
        self.fun = fun
        self.lower = bounds[:, 0].copy()
        self.span = bounds[:, 1] - bounds[:, 0]
        self.dim = bounds.shape[0]
        self.max_evals = int(max_evals)
        self.callback = callback
        self.nfev = 0
        self.best_u = np.full(self.dim, np.nan)
        self.best_f = np.inf
        self._hist_n: list[int] = []
        self._hist_f: list[float] = []
        self.stopped_by_callback = False

    # unit box <-> parameters
    def to_x(self, U: np.ndarray) -> np.ndarray:
        return self.lower + np.clip(U, 0.0, 1.0) * self.span

    def to_u(self, X: np.ndarray) -> np.ndarray:
        return np.clip((np.asarray(X, dtype=float) - self.lower) / self.span, 0.0, 1.0)

    @property
    def remaining(self) -> int:
        return self.max_evals - self.nfev

    def evaluate_x(self, X: np.ndarray) -> np.ndarray:
        """Evaluate parameter-space points ``(k, d)`` (no clipping, no budget check)."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        f = np.asarray(self.fun(X), dtype=float)
        if f.shape != (X.shape[0],):
            raise ConfigError(
                f"the objective must return shape ({X.shape[0]},) for a batch of "
                f"{X.shape[0]} points; got {f.shape}"
            )
        return np.where(np.isfinite(f), f, np.inf)

    def __call__(self, U: np.ndarray) -> np.ndarray:
        U = np.clip(np.atleast_2d(U), 0.0, 1.0)
        k = U.shape[0]
        if k > self.remaining:
            if self.remaining > 0:
                self(U[: self.remaining])
            raise Budget
        f = self.evaluate_x(self.to_x(U))
        self.nfev += k
        i = int(np.argmin(f))
        if f[i] < self.best_f:
            self.best_f = float(f[i])
            self.best_u = U[i].copy()
        self._hist_n.append(self.nfev)
        self._hist_f.append(self.best_f)
        return f

    def record(self, u: np.ndarray, f: float) -> None:
        """Offer a point evaluated outside ``__call__`` (already counted) as a best candidate."""
        if f < self.best_f:
            self.best_f = float(f)
            self.best_u = np.asarray(u, dtype=float).copy()
            self._hist_n.append(self.nfev)
            self._hist_f.append(self.best_f)

    def notify(self, nit: int) -> None:
        """Call the user's callback with the intermediate result; it may stop the run."""
        if self.callback is None:
            return
        res = OptimizeResult(x=self.to_x(self.best_u), fun=self.best_f, nfev=self.nfev, nit=nit)
        try:
            stop = self.callback(res)
        except StopIteration:
            stop = True
        if stop:
            self.stopped_by_callback = True
            raise Budget

    @property
    def history(self) -> np.ndarray:
        if not self._hist_n:
            return np.empty((0, 2))
        return np.column_stack([np.asarray(self._hist_n, float), np.asarray(self._hist_f)])


class Solver:
    """Base class of a method: ``__init__`` validates options, ``run`` searches.

    Subclasses set ``name``, ``summary`` (one line for docs and errors), ``options``
    (name -> default) and ``default_evals``, and implement :meth:`run`, which calls
    ``self.objective`` on unit-box batches until the budget raises :class:`Budget` or the
    method ends by itself; it returns ``(nit, message)``. ``self.nit`` is kept current so an
    interrupted run still reports its iterations.
    """

    name: str = ""
    summary: str = ""
    options: dict[str, Any] = {}
    default_evals: int = 10_000
    uses_residuals: bool = False

    def __init__(self, objective: Objective, rng: np.random.Generator, options: dict[str, Any],
                 x0: np.ndarray | None = None,
                 residuals: Callable[[np.ndarray], np.ndarray] | None = None) -> None:
        unknown = sorted(set(options) - set(self.options))
        if unknown:
            raise ConfigError(
                f"unknown option(s) {', '.join(unknown)} for method '{self.name}'; "
                f"it takes: {', '.join(self.options) or 'none'}"
            )
        self.objective = objective
        self.rng = rng
        self.opts = {**self.options, **options}
        self.x0 = x0
        self.residuals = residuals
        self.nit = 0
        self.validate()

    def validate(self) -> None:
        """Check ``self.opts``; raise :class:`ConfigError` naming the bad option."""

    def run(self) -> tuple[int, str]:  # pragma: no cover - abstract
        raise NotImplementedError


#: Method name -> solver class. Filled by :func:`register`.
METHODS: dict[str, type[Solver]] = {}


def register(cls: type[Solver]) -> type[Solver]:
    """Class decorator adding a solver to :data:`METHODS` under ``cls.name``."""
    METHODS[cls.name] = cls
    return cls


def _seed(seed) -> tuple[np.random.Generator, int | None]:
    if isinstance(seed, np.random.Generator):
        return seed, None
    if seed is None:
        seed = int(np.random.SeedSequence().entropy % (2**32))
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ConfigError(f"seed must be a non-negative int or a numpy Generator; got {seed!r}")
    return np.random.default_rng(int(seed)), int(seed)


def positive_option(opts: dict[str, Any], name: str, method: str, *, integer: bool = False,
                    open_unit: bool = False, allow_zero: bool = False) -> None:
    """Raise :class:`ConfigError` unless ``opts[name]`` is a positive number (an int, or in
    the open interval (0, 1), when asked)."""
    v = opts[name]
    ok = isinstance(v, int | float | np.integer | np.floating) and not isinstance(v, bool)
    ok = ok and np.isfinite(v) and (v >= 0 if allow_zero else v > 0)
    if integer:
        ok = ok and float(v).is_integer()
    if open_unit:
        ok = ok and 0 < v < 1
    if not ok:
        need = "an integer > 0" if integer else "a number in (0, 1)" if open_unit else (
            "a number >= 0" if allow_zero else "a number > 0")
        raise ConfigError(f"option '{name}' of method '{method}' must be {need}; got {v!r}")


def minimize(
    fun: Callable[[np.ndarray], np.ndarray] | None,
    bounds,
    method: str = "rwsavsbas",
    *,
    seed: int | np.random.Generator | None = None,
    max_evals: int | None = None,
    options: dict[str, Any] | None = None,
    callback: Callable[[OptimizeResult], Any] | None = None,
    x0=None,
    residuals: Callable[[np.ndarray], np.ndarray] | None = None,
) -> OptimizeResult:
    """Minimise ``fun`` over the box ``bounds`` with ``method``.

    Parameters
    ----------
    fun : callable ``(k, d) -> (k,)``, or None when ``residuals`` is given (then ``fun`` is
        the sum of squared residuals).
    bounds : sequence of ``(lower, upper)``, one pair per parameter.
    method : a key of :data:`METHODS` (case-insensitive).
    seed : int or ``numpy.random.Generator``; the same seed gives the same result bit for bit.
    max_evals : budget in candidate evaluations (method's default when None).
    options : method options; unknown names raise :class:`ConfigError` listing the known ones.
    callback : called with an intermediate :class:`OptimizeResult` after each iteration;
        returning True or raising ``StopIteration`` stops the run.
    x0 : optional starting point (methods that use one).
    residuals : callable ``(k, d) -> (k, n)`` for least-squares methods.
    """
    key = str(method).strip().lower()
    if key not in METHODS:
        raise ConfigError(f"unknown method '{method}'; choose one of: {', '.join(METHODS)}")
    cls = METHODS[key]
    b = check_bounds(bounds)
    if fun is None and residuals is None:
        raise ConfigError("give an objective `fun`, or `residuals` for least squares")
    if cls.uses_residuals and residuals is None:
        raise ConfigError(f"method '{key}' is a least-squares method and needs `residuals`")
    if fun is None:
        res_fun = residuals

        def fun(X: np.ndarray) -> np.ndarray:
            r = np.asarray(res_fun(X), dtype=float)
            return np.einsum("kn,kn->k", r, r)

    if max_evals is None:
        max_evals = cls.default_evals
    if isinstance(max_evals, bool) or not isinstance(max_evals, int | np.integer) or max_evals < 1:
        raise ConfigError(f"max_evals must be a positive integer; got {max_evals!r}")
    rng, used_seed = _seed(seed)
    objective = Objective(fun, b, int(max_evals), callback)
    if x0 is not None:
        x0 = np.asarray(x0, dtype=float)
        if x0.shape != (b.shape[0],):
            raise ConfigError(
                f"x0 has shape {x0.shape}; the bounds give {b.shape[0]} parameters"
            )
        if np.any(x0 < b[:, 0]) or np.any(x0 > b[:, 1]):
            raise ConfigError("x0 lies outside the bounds")
    solver = cls(objective, rng, dict(options or {}), x0=x0, residuals=residuals)
    try:
        nit, message = solver.run()
        success = True
    except Budget:
        nit = solver.nit
        if objective.stopped_by_callback:
            message, success = "stopped by the callback", True
        else:
            message, success = f"evaluation budget of {objective.max_evals} spent", True
    if not np.isfinite(objective.best_f):
        success = False
        message = "no finite objective value was found"
    x = objective.to_x(objective.best_u) if np.isfinite(objective.best_f) else np.full(
        b.shape[0], np.nan)
    return OptimizeResult(
        x=x,
        fun=objective.best_f,
        nfev=objective.nfev,
        nit=nit,
        history=objective.history,
        message=message,
        success=success,
        method=key,
        seed=used_seed,
    )
