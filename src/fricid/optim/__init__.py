"""Generic optimisers behind one API (DESIGN.md, "Optimiser API").

``minimize(fun, bounds, method=...)`` with methods registered in :data:`METHODS`. Nothing here
knows about friction: objectives are plain batch functions ``(k, d) -> (k,)``.

Methods (``METHODS[name].summary`` has the one-line description):

* beetle antennae search family: ``bas``, ``vsbas``, ``ibas``, ``rwsavsbas``;
* ``ga``, a real-coded genetic algorithm;
* local: ``lbfgsb`` (scipy's bounded quasi-Newton L-BFGS-B with a batched finite-difference
  gradient: the default of :func:`minimize` without residuals), ``lm`` (the default
  least-squares method, and of :func:`minimize` given residuals: scipy's bounded trust-region
  reflective solver with a batched Jacobian);
* baselines: ``trf`` (``lm`` with scipy's own Jacobian),
  ``lm_minpack`` (MINPACK in sin coordinates, legacy), ``de``, ``dual_annealing`` (scipy),
  ``cmaes`` (the ``cma`` package);
* ``bas+lm``: a beetle global phase polished by ``lm``.

``minimize`` makes one run and returns one :class:`OptimizeResult`, whose ``status`` (see
:data:`STATUS_MESSAGES`) says why it ended and whose ``success`` means converged.
``minimize_runs(..., runs=N)`` makes N independent runs (seeds ``seed .. seed + N - 1``),
batched into one objective call per iteration for bas, vsbas, ibas, rwsavsbas and ga (with
option ``dedupe=False``; by default GA skips its clones, each run counting its own).
:func:`one_blas_thread` (a context) and :func:`single_blas_thread` (a decorator) keep BLAS to
one thread on the least-squares paths (:mod:`fricid.optim._threads`).
:class:`JitObjective` pairs an objective with a numba kernel for RWSAVSBAS's compiled path.
Conventions (unit box, clipping, NaN, history, budgets): :mod:`fricid.optim._api`.
"""

from __future__ import annotations

from . import (  # noqa: F401  (each registers its methods)
    _bas,
    _cmaes,
    _ga,
    _hybrid,
    _ibas,
    _least_squares,
    _local,
    _rwsavsbas,
    _scipy_global,
    _vsbas,
)
from ._api import METHODS, STATUS_MESSAGES, JitObjective, OptimizeResult, check_bounds
from ._minimize import minimize, minimize_runs
from ._threads import blas_threads, one_blas_thread, single_blas_thread

__all__ = [
    "METHODS",
    "STATUS_MESSAGES",
    "JitObjective",
    "OptimizeResult",
    "blas_threads",
    "check_bounds",
    "minimize",
    "minimize_runs",
    "one_blas_thread",
    "single_blas_thread",
]

#: The order methods are listed in (errors, ``--help``): the beetle family first.
_ORDER = (
    "bas",
    "vsbas",
    "ibas",
    "rwsavsbas",
    "ga",
    "bas+lm",
    "lbfgsb",
    "lm",
    "trf",
    "lm_minpack",
    "de",
    "dual_annealing",
    "cmaes",
)
for _name in sorted(METHODS, key=lambda k: _ORDER.index(k) if k in _ORDER else len(_ORDER)):
    METHODS[_name] = METHODS.pop(_name)
