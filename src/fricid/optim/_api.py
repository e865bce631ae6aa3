"""The optimiser API, shaped after ``scipy.optimize.minimize`` (DESIGN.md, "Optimiser API").

``minimize(fun, bounds, method=..., seed=..., max_evals=..., options=..., callback=...)``
(:mod:`fricid.optim._minimize`) dispatches to one solver class per method through
:data:`METHODS`, and returns one :class:`OptimizeResult`; ``minimize_runs`` makes independent
runs (batched where the method allows) and returns a list of them. This module holds what the
solvers share: the result, the status codes, the counted objective, the solver base class,
the registry and the option checks.

Conventions every method honours:

* ``fun`` takes a batch ``(k, d)`` and returns ``(k,)``; one candidate evaluated is one
  evaluation (``nfev``), for every method, so budgets compare fairly. Least-squares methods
  also take ``residuals``, a batch ``(k, d) -> (k, n)`` residual function; one residual
  vector is one evaluation.
* Search happens in the unit box ``[0, 1]^d`` mapped linearly onto ``bounds``; candidates
  that step outside are **clipped** back onto the box (not reflected), so ``bounds`` are never
  left. Step lengths and antenna lengths of the beetle methods are in these unit-box units:
  the width of the bounds therefore sets how far a step of 0.1 goes in each parameter.
* NaN (or inf) objective values count as the worst possible value (``+inf``), never as the
  best. An objective that returns no finite value at all raises :class:`ConfigError`.
* ``history`` is the best-so-far value against the evaluation count, an array ``(m, 2)``
  with columns ``nfev, best fun``, one row per improvement plus the final count; it is
  monotone (``nfev`` increasing, ``fun`` non-increasing).
* Randomness comes only from ``seed`` (int or ``numpy.random.Generator``) through
  ``numpy.random.default_rng``; the integer seed used is recorded in the result.
* ``status`` says why a run ended (:data:`STATUS_MESSAGES`): ``0`` converged (the method's
  own convergence criterion, stated in its docstring, was met), ``1`` evaluation budget spent,
  ``2`` stopped by the callback, ``4`` the method's iteration limit or schedule ended without
  meeting its criterion; ``3`` (no finite value) is the status of a run whose objective
  returned no finite value, which :func:`minimize` raises as :class:`ConfigError`.
  ``success`` is ``status == 0``: converged, not merely finished. Per method: ``lm``/``trf``
  converge when scipy's ``least_squares`` met ``ftol``, ``xtol`` or ``gtol`` in the start that
  found the best point; ``de`` and ``dual_annealing`` when scipy reports success (DE only
  with a ``tol`` or ``atol`` option above its default 0); the beetle family when its step
  schedule ran to the end with a last step of at most ``xtol`` (unit-box units); ``ga`` when
  its stall criterion (option ``stall``) fired; ``cmaes`` (without restarts) when cma stopped
  on ``tolfun``, ``tolx`` or ``tolfunhist``; ``bas+lm`` when its ``lm`` polish converged.
* ``minimize_runs`` makes N independent runs with seeds ``seed .. seed + N - 1``. Methods marked
  ``batched`` advance all runs in lockstep and evaluate their candidates in one call of
  ``fun`` per iteration; each run's result is still bit-identical to running it alone with
  its seed, provided ``fun`` evaluates each row independently of the others (true of
  element-wise numpy code). Other methods run the N runs one after another.
* An objective may carry a ``jit_kernel`` attribute (see :class:`JitObjective`): a numba
  function ``kernel(X, out, data)`` writing ``fun(X)`` into ``out``. Methods with a compiled fast
  path (``rwsavsbas``) then run whole iterations in compiled code; all others, and those with
  option ``jit=False``, call ``fun``.

Optimisers know nothing of friction: this package imports nothing of fricid but ``errors``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, ClassVar

import numpy as np

from ..errors import ConfigError

__all__ = [
    "BUDGET",
    "CALLBACK",
    "CONVERGED",
    "ITERATIONS",
    "METHODS",
    "NO_FINITE",
    "STATUS_MESSAGES",
    "Budget",
    "JitObjective",
    "Objective",
    "OptimizeResult",
    "Solver",
    "check_bounds",
    "choice_option",
    "positive_option",
    "register",
]


#: ``OptimizeResult.status``: the method's convergence criterion was met.
CONVERGED = 0
#: ``OptimizeResult.status``: the evaluation budget (``max_evals``) was spent.
BUDGET = 1
#: ``OptimizeResult.status``: the callback stopped the run.
CALLBACK = 2
#: Status of a run whose objective returned no finite value (raised as :class:`ConfigError`).
NO_FINITE = 3
#: ``OptimizeResult.status``: the method's iteration limit or schedule ended unconverged.
ITERATIONS = 4

#: The standard message of each status (``OptimizeResult.message`` starts with it, or, for
#: the budget, names the budget).
STATUS_MESSAGES: dict[int, str] = {
    CONVERGED: "converged",
    BUDGET: "evaluation budget spent",
    CALLBACK: "stopped by the callback",
    NO_FINITE: "no finite objective value",
    ITERATIONS: "iteration limit reached without convergence",
}


def clip01(U: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """``np.clip(U, 0, 1)`` without its Python-level overhead (hot loops call it often)."""
    out = np.maximum(U, 0.0, out=out)
    return np.minimum(out, 1.0, out=out)


class OptimizeResult(dict):
    """The result of :func:`minimize`: a dict with attribute access (like scipy's).

    Keys: ``x`` (best point, in bounds), ``fun`` (its value), ``nfev``, ``nit``,
    ``history`` ((m, 2): nfev, best-so-far fun), ``status`` (int, see
    :data:`STATUS_MESSAGES`), ``message`` (starting with the status's standard message, or
    naming the budget), ``success`` (``status == 0``: converged), ``method``, ``seed`` (the
    integer seed used, or None when a Generator was passed), ``max_evals`` (the budget the run
    had); methods may add more.
    """

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError as exc:
            raise AttributeError(name) from exc

    __setattr__ = dict.__setitem__  # type: ignore[assignment]
    __delattr__ = dict.__delitem__  # type: ignore[assignment]

    def __repr__(self) -> str:
        keys = ("method", "fun", "x", "nfev", "nit", "status", "success", "message")
        body = ", ".join(f"{k}={self[k]!r}" for k in keys if k in self)
        return f"OptimizeResult({body})"


class Budget(Exception):
    """Raised inside a solver when the evaluation budget is spent (caught by :func:`minimize`)."""


class JitObjective:
    """A batch objective with a compiled twin, for the compiled fast paths.

    ``JitObjective(fun, kernel, data)`` is called like ``fun``; ``kernel`` must be a numba
    ``@njit`` function ``kernel(X, out, data)`` that writes ``fun(X)`` for a C-contiguous
    float64 batch ``X (k, d)`` (parameter space, not the unit box) into the float64 array
    ``out (k,)``; ``data`` is a tuple (arrays, numbers) handed to every call, so one compiled
    kernel (cacheable, defined at module level) serves any data set. Both must compute the
    same function (up to rounding); methods without a fast path use ``fun``.
    """

    def __init__(
        self, fun: Callable[[np.ndarray], np.ndarray], kernel: Any, data: tuple = ()
    ) -> None:
        self.fun = fun
        self.jit_kernel = kernel
        self.jit_data = tuple(data)

    def __call__(self, X: np.ndarray) -> np.ndarray:
        return self.fun(X)


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
            f"bounds[{i}] has lower >= upper ({float(b[i, 0])!r} >= {float(b[i, 1])!r}); "
            "fix the parameter's range (fixed parameters are passed separately)"
        )
    return b


class Objective:
    """Wraps a batch objective for ``runs`` lockstep runs: maps the unit box to bounds, counts
    evaluations, keeps each run's best point and its history.

    ``__call__(U)`` takes unit-box points ``(runs, k, d)`` (clipped to [0, 1]), evaluates all
    ``runs * k`` of them in one call of ``fun`` and returns ``(runs, k)`` values with NaN/inf
    replaced by ``+inf``. ``nfev`` counts the evaluations of *each* run (they advance in
    lockstep). A batch the budget cannot pay for in full is cut to what is left, evaluated,
    and then :class:`Budget` is raised, so ``nfev`` never exceeds ``max_evals``.
    """

    def __init__(
        self,
        fun: Callable[[np.ndarray], np.ndarray],
        bounds: np.ndarray,
        max_evals: int,
        callback: Callable[[OptimizeResult], Any] | None = None,
        runs: int = 1,
    ) -> None:
        self.fun = fun
        self.kernel = getattr(fun, "jit_kernel", None)
        self.kernel_data = tuple(getattr(fun, "jit_data", ()))
        self.lower = bounds[:, 0].copy()
        self.span = bounds[:, 1] - bounds[:, 0]
        self.dim = bounds.shape[0]
        self.runs = int(runs)
        self.max_evals = int(max_evals)
        self.callback = callback
        self.nfev = 0
        self.best_u = np.full((self.runs, self.dim), np.nan)
        self.best_f = np.full(self.runs, np.inf)
        self._rows = np.arange(self.runs)
        self._hist_n: list[int] = []
        self._hist_f: list[np.ndarray] = []
        self.stopped_by_callback = False

    # unit box <-> parameters
    def to_x(self, U: np.ndarray) -> np.ndarray:
        return self.lower + clip01(U) * self.span

    def to_u(self, X: np.ndarray) -> np.ndarray:
        return np.clip((np.asarray(X, dtype=float) - self.lower) / self.span, 0.0, 1.0)

    @property
    def remaining(self) -> int:
        return self.max_evals - self.nfev

    def evaluate_x(self, X: np.ndarray) -> np.ndarray:
        """Evaluate parameter-space points ``(k, d)`` (no clipping, no counting)."""
        if X.ndim != 2 or X.dtype != np.float64 or not X.flags.c_contiguous:
            X = np.ascontiguousarray(np.atleast_2d(np.asarray(X, dtype=float)))
        raw = self.fun(X)
        try:
            f = np.asarray(raw, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ConfigError(
                f"the objective must return an array of {X.shape[0]} numbers; {exc}"
            ) from None
        if f.shape != (X.shape[0],):
            raise ConfigError(
                f"the objective must return shape ({X.shape[0]},) for a batch of "
                f"{X.shape[0]} points of shape {X.shape}; got {f.shape}"
            )
        return np.where(np.isfinite(f), f, np.inf)

    def __call__(self, U: np.ndarray) -> np.ndarray:
        U = clip01(U)
        R, k, d = U.shape
        if k > self.remaining:
            if self.remaining > 0:
                self(U[:, : self.remaining])
            raise Budget
        f = self.evaluate_x(self.lower + U.reshape(R * k, d) * self.span).reshape(R, k)
        self.nfev += k
        self.offer(U, f)
        return f

    def call1(self, U: np.ndarray) -> np.ndarray:
        """Single-run convenience: ``(k, d) -> (k,)`` (``runs`` must be 1)."""
        return self(np.asarray(U, dtype=float)[None])[0]

    def offer(self, U: np.ndarray, f: np.ndarray) -> None:
        """Offer evaluated (already counted) points ``U (runs, k, d)`` with values
        ``f (runs, k)`` as best candidates; a snapshot is kept when any run improves."""
        i = np.argmin(f, axis=1)
        rows = self._rows
        fi = f[rows, i]
        better = fi < self.best_f
        if better.any():
            self.best_f[better] = fi[better]
            self.best_u[better] = U[rows[better], i[better]]
            self.snapshot()

    def record(self, u: np.ndarray, f: float) -> None:
        """Single run: offer one point evaluated outside ``__call__`` (already counted)."""
        self.offer(np.asarray(u, dtype=float)[None, None, :], np.array([[f]], dtype=float))

    def snapshot(self) -> None:
        self._hist_n.append(self.nfev)
        self._hist_f.append(self.best_f.copy())

    def notify(self, nit: int) -> None:
        """Call the user's callback with each run's intermediate result; returning True or
        raising ``StopIteration`` stops the run (all runs of a lockstep batch)."""
        if self.callback is None:
            return
        stop = False
        for r in range(self.runs):
            res = OptimizeResult(
                x=self.to_x(self.best_u[r]), fun=float(self.best_f[r]), nfev=self.nfev, nit=nit
            )
            if self.runs > 1:
                res["run"] = r
            try:
                stop = bool(self.callback(res)) or stop
            except StopIteration:
                stop = True
        if stop:
            self.stopped_by_callback = True
            raise Budget

    def history(self, r: int = 0) -> np.ndarray:
        """Run ``r``'s best-so-far against nfev: one row per improvement, plus the end."""
        n = np.asarray(self._hist_n, dtype=float)
        f = np.asarray([h[r] for h in self._hist_f], dtype=float)
        if f.size:
            prev = np.concatenate([[np.inf], np.minimum.accumulate(f)[:-1]])
            keep = f < prev
            n, f = n[keep], f[keep]
        if f.size and n[-1] < self.nfev:
            n, f = np.append(n, self.nfev), np.append(f, f[-1])
        if not f.size:
            return np.empty((0, 2))
        return np.column_stack([n, f])


class Solver:
    """Base class of a method: ``__init__`` validates options, ``run`` searches.

    Subclasses set ``name``, ``summary`` (one line for docs, ``--help`` and errors),
    ``options`` (name -> default), ``default_evals`` (or override :meth:`default_budget`) and
    ``batched`` (True when :meth:`run` advances ``objective.runs`` runs in lockstep, drawing
    run ``r``'s random numbers from ``rngs[r]`` only), and implement :meth:`run`, which calls
    ``self.objective`` on unit-box batches until the budget raises :class:`Budget` or the
    method ends by itself; it returns ``(nit, message)`` and sets ``self.converged`` to True
    when its stated convergence criterion was met (the result's ``status`` 0; otherwise 4).
    ``self.nit`` is kept current so an interrupted run still reports its iterations.
    """

    name: str = ""
    summary: str = ""
    options: ClassVar[dict[str, Any]] = {}
    default_evals: int = 10_000
    uses_residuals: bool = False
    batched: bool = False

    def __init__(
        self,
        options: dict[str, Any],
        *,
        dim: int,
        x0: np.ndarray | None = None,
        residuals: Callable[[np.ndarray], np.ndarray] | None = None,
    ) -> None:
        unknown = sorted(set(options) - set(self.options))
        if unknown:
            raise ConfigError(
                f"unknown option(s) {', '.join(unknown)} for method '{self.name}'; "
                f"it takes: {', '.join(self.options) or 'none'}"
            )
        self.opts = {**self.options, **options}
        self.dim = int(dim)
        self.x0 = x0
        self.residuals = residuals
        self.nit = 0
        self.converged = False
        self.objective: Objective
        self.rngs: list[np.random.Generator] = []
        self.validate()

    def bind(self, objective: Objective, rngs: Sequence[np.random.Generator]) -> Solver:
        """Attach the objective and one random generator per run."""
        self.objective = objective
        self.rngs = list(rngs)
        return self

    @property
    def rng(self) -> np.random.Generator:
        """The generator of a single run."""
        return self.rngs[0]

    def default_budget(self) -> int:
        """The evaluation budget when ``max_evals`` is None (may depend on the options)."""
        return self.default_evals

    def validate(self) -> None:
        """Check ``self.opts``; raise :class:`ConfigError` naming the bad option."""

    def start_points(self) -> np.ndarray:
        """Each run's start in the unit box ``(runs, d)``: ``x0`` when given, else uniform from
        that run's generator (its first draw)."""
        obj = self.objective
        if self.x0 is not None:
            return np.broadcast_to(obj.to_u(self.x0), (obj.runs, obj.dim)).copy()
        return np.stack([g.random(obj.dim) for g in self.rngs])

    def run(self) -> tuple[int, str]:  # pragma: no cover - abstract
        raise NotImplementedError


#: Method name -> solver class. Filled by :func:`register`.
METHODS: dict[str, type[Solver]] = {}


def register(cls: type[Solver]) -> type[Solver]:
    """Class decorator adding a solver to :data:`METHODS` under ``cls.name``."""
    METHODS[cls.name] = cls
    return cls


def positive_option(
    opts: dict[str, Any],
    name: str,
    method: str,
    *,
    integer: bool = False,
    open_unit: bool = False,
    allow_zero: bool = False,
) -> None:
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
        need = (
            "an integer > 0"
            if integer
            else "a number in (0, 1)"
            if open_unit
            else ("a number >= 0" if allow_zero else "a number > 0")
        )
        raise ConfigError(f"option '{name}' of method '{method}' must be {need}; got {v!r}")


def choice_option(opts: dict[str, Any], name: str, method: str, choices: Sequence[Any]) -> None:
    """Raise :class:`ConfigError` unless ``opts[name]`` is one of ``choices``."""
    v = opts[name]
    if isinstance(v, str):
        v = v.strip().lower()
        opts[name] = v
    if not any(v is c or (type(v) is type(c) and v == c) for c in choices):
        shown = ", ".join(repr(c) for c in choices)
        raise ConfigError(f"option '{name}' of method '{method}' must be one of {shown}; got {v!r}")
