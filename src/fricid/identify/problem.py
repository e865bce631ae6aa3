"""``IdentificationProblem``: what is identified, from which data, by which loss (after pymoo's
``Problem``; STYLE.md, "Problems, algorithms, termination").

A problem knows the model, the data and the objective; it knows nothing of the optimiser. It
evaluates a whole batch of candidate parameter vectors ``T (k, p)`` at once (DESIGN.md,
"Vectorised"): :meth:`IdentificationProblem.residuals` gives ``(k, n)`` weighted residuals and
:meth:`IdentificationProblem.evaluate` the loss ``(k,)``, the one place where fricid's
identification objective is written (``identify.fit``, the RBF trainer and the papers' studies
all use it).

:class:`Problem` is the protocol every fit's problem follows, whatever the room: names, the
search box, residuals and loss of a batch, sizes. :class:`IdentificationProblem` is one;
:class:`ResidualProblem` makes one of any batch residual function (the trajectory routes'
projected equation error, the variable projection's inner problem), so that convergence
certification (:func:`fricid.identify.static.convergence.certify`) and the Jacobian's
uncertainty (:func:`fricid.identify.static.uncertainty.jacobian`) apply to every fit the
same way.

Robust losses (``soft_l1``, ``huber``) for logs with spikes are written as a least-squares
problem on transformed residuals, ``r' = sign(r) c sqrt(rho((r / c)^2))``, so that
``sum r'^2 = c^2 sum rho((r / c)^2)`` is scipy's ``least_squares`` robust cost and every
optimiser, Levenberg-Marquardt included, minimises it unchanged.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Protocol

import numpy as np

from ..errors import ConfigError
from ..samples import FrictionSamples
from ._protocol import Problem, ResidualProblem

__all__ = [
    "LOSSES",
    "ROBUST_LOSSES",
    "IdentificationProblem",
    "Predictor",
    "Problem",
    "ResidualProblem",
    "robust_residuals",
]

#: The losses: ``sse``, the sum of (weighted) squared errors (the RWSAVSBAS paper's fitness,
#: eq. 11 there), also called ``l2``; ``mse``, that sum over the number of samples (the
#: BAS-RBFNN paper's training error, eq. 16-17 up to the factor 2); the robust ``soft_l1``
#: and ``huber`` (:data:`ROBUST_LOSSES`, summed as ``sse``).
LOSSES = ("sse", "mse", "l2", "soft_l1", "huber")

#: Robust losses, ``rho(z)`` of the squared scaled residual ``z = (r / c)^2`` (scipy's
#: ``least_squares``): ``soft_l1`` ``2 (sqrt(1 + z) - 1)``; ``huber`` ``z`` for ``z <= 1``,
#: else ``2 sqrt(z) - 1``. Both are quadratic for residuals well below the scale ``c`` and
#: grow linearly beyond it, so a spike pulls the fit with bounded force.
ROBUST_LOSSES = ("soft_l1", "huber")


def robust_residuals(R: np.ndarray, loss: str, scale: float) -> np.ndarray:
    """Residuals whose squares sum to a robust loss: ``sign(r) c sqrt(rho((r / c)^2))``.

    Parameters
    ----------
    R : numpy.ndarray
        Residuals, any shape.
    loss : {"soft_l1", "huber"}
        See :data:`ROBUST_LOSSES`.
    scale : float
        ``c`` > 0, in the units of ``R``: residuals well below it count as in least squares.

    Returns
    -------
    numpy.ndarray
        Same shape as ``R``; equal to ``R`` where ``|R| << c`` (and for ``huber``, wherever
        ``|R| <= c``).
    """
    z = (R / scale) ** 2
    if loss == "soft_l1":
        rho = 2.0 * (np.sqrt(1.0 + z) - 1.0)
    elif loss == "huber":
        rho = np.where(z <= 1.0, z, 2.0 * np.sqrt(np.maximum(z, 1.0)) - 1.0)
    else:
        raise ConfigError(f"unknown robust loss '{loss}'; choose one of: soft_l1, huber")
    return np.sign(R) * scale * np.sqrt(rho)


def _check_directions(samples: FrictionSamples, model: Any) -> None:
    """A model with parameters per direction needs samples of each direction, not combined."""
    dirs = set(samples.directions())
    if 0 in dirs:
        raise ConfigError(
            f"model '{model.name}' has parameters per direction, but the samples combine "
            "both directions (eq. 11); extract per-direction samples or fit the symmetric "
            "model"
        )
    if not {-1, 1} <= dirs:
        only = "positive" if 1 in dirs else "negative"
        raise ConfigError(
            f"model '{model.name}' has parameters per direction, but the samples hold the "
            f"{only} direction only"
        )


class Predictor(Protocol):
    """What a problem needs of a model: a batch prediction ``(k, p), X -> (k, n)``."""

    def predict(self, theta: Any, X: Any) -> np.ndarray: ...  # pragma: no cover


def _check_regions(model: Any, base: np.ndarray, full: np.ndarray) -> None:
    """A :class:`ConfigError` when a fixed value or a search bound lies outside the valid
    region of its parameter (``fricid.models.Parameter.region``): the fit could return a
    model that no model file may hold."""
    if not hasattr(model, "region_violation"):
        return
    for vector, what in (
        (base, "fixed at"),
        (full[:, 0], "bounded below by"),
        (full[:, 1], "bounded above by"),
    ):
        bad = model.region_violation(vector)
        if bad is not None:
            raise ConfigError(
                f"parameter '{bad[0].name}' {what} {bad[1]!r}, outside its valid region "
                f"({bad[0].rule}) of model '{model.name}'"
            )


class IdentificationProblem:
    """A model to identify from data, with its loss, bounds and fixed parameters.

    Parameters
    ----------
    model : FrictionModel or Predictor
        An analytic model of :mod:`fricid.models` (parameters named, with data-scaled default
        values and bounds), or any object with a batch ``predict(T (k, p), X) -> (k, n)``
        (then ``bounds`` must be the ``(p, 2)`` array and nothing can be fixed).
    samples : FrictionSamples or tuple of (ndarray, ndarray)
        The data: velocity, load, temperature, friction and direction from
        :class:`~fricid.samples.FrictionSamples` (a model with parameters per direction
        needs samples of both directions, each apart: RWSAVSBAS paper eq. 11), or ``(X, y)``
        arrays for a generic model.
    loss : {"sse", "l2", "mse", "soft_l1", "huber"}, default "sse"
        See :data:`LOSSES`; ``l2`` is ``sse``.
    bounds : mapping of str to (float, float), or array_like (p, 2), optional
        Named models: search bounds of some parameters (the others keep the model's
        data-scaled bounds). Generic models: the bounds of every parameter (required).
    fixed : mapping of str to float, optional
        Parameters held at a value (named models only), e.g. ``{"delta": 1.0}``.
    weights : array_like (n,), optional
        Non-negative weights of the squared errors (weighted least squares); residuals are
        scaled by their square roots (:func:`fricid.identify.validate.sample_weights` gives
        ``1 / se^2`` from the samples' own standard errors).
    f_scale : float, optional
        The scale ``c`` [N m] of a robust loss (required with ``soft_l1`` and ``huber``, where
        it applies to the weighted residuals; ignored otherwise).

    Attributes
    ----------
    X : ndarray (n, 3)
        Inputs: velocity [rad/s], load [N m], temperature [degC] (generic models: any ``X``).
    y : ndarray (n,)
        Measured friction [N m].
    names : tuple of str
        Every parameter's name (generic models: ``p0, p1, ...``).
    free : list of int
        Indices of the free parameters in ``names``.
    free_names : list of str
    base : ndarray (p_all,)
        The full parameter vector: the model's data-scaled defaults, fixed values set.
    bounds : ndarray (p, 2)
        Search bounds of the free parameters.
    fixed : dict of str to float

    Examples
    --------
    >>> import numpy as np
    >>> from fricid.identify.problem import IdentificationProblem
    >>> from fricid.models import get_model
    >>> from fricid.samples import FrictionSamples
    >>> model = get_model("coulomb_viscous")
    >>> v = np.linspace(0.1, 1.0, 5)
    >>> samples = FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=0.3 + 0.1 * v)
    >>> problem = IdentificationProblem(model, samples, loss="sse")
    >>> problem.free_names
    ['f_c', 'beta']
    >>> problem.evaluate(np.array([[0.3, 0.1], [0.3, 0.0]])).round(4)
    array([0.    , 0.0202])
    """

    def __init__(
        self,
        model: Any,
        samples: FrictionSamples | tuple[Any, Any],
        *,
        loss: str = "sse",
        bounds: Mapping[str, tuple[float, float]] | Any | None = None,
        fixed: Mapping[str, float] | None = None,
        weights: Any | None = None,
        f_scale: float | None = None,
    ) -> None:
        self.model = model
        if isinstance(samples, FrictionSamples):
            self.samples: FrictionSamples | None = samples
            X, y = samples.X, samples.y
            if getattr(model, "is_asymmetric", False):
                _check_directions(samples, model)
        else:
            self.samples = None
            X, y = samples
        self.X = np.asarray(X, dtype=float)
        self.y = np.asarray(y, dtype=float)
        if self.y.ndim != 1 or self.X.shape[0] != self.y.shape[0]:
            raise ConfigError(
                f"the data need X (n, ...) and y (n,) of one length; got {self.X.shape} and "
                f"{self.y.shape}"
            )
        key = str(loss).strip().lower()
        if key not in LOSSES:
            raise ConfigError(f"unknown loss '{loss}'; choose one of: {', '.join(LOSSES)}")
        self.loss = "sse" if key == "l2" else key
        self.f_scale = None
        if self.loss in ROBUST_LOSSES:
            if f_scale is None or not np.isfinite(f_scale) or f_scale <= 0:
                raise ConfigError(
                    f"loss '{key}' needs a scale f_scale > 0 [N m] (the measurement scatter); "
                    f"got {f_scale!r}"
                )
            self.f_scale = float(f_scale)
        self.weights = None if weights is None else self._check_weights(weights)
        self._sqrt_w = None if self.weights is None else np.sqrt(self.weights)
        self.fixed = {str(k): float(v) for k, v in (fixed or {}).items()}
        self._jit: Any = None
        if hasattr(model, "param_names"):
            self._init_named(bounds)
        else:
            self._init_generic(bounds)

    # -- set-up ---------------------------------------------------------------------------
    def _check_weights(self, weights: Any) -> np.ndarray:
        w = np.asarray(weights, dtype=float)
        if w.shape != self.y.shape or not np.isfinite(w).all() or (w < 0).any():
            raise ConfigError(
                f"weights must be {self.y.size} finite numbers >= 0, one per sample; got an "
                f"array of shape {w.shape}"
            )
        return w

    def _init_named(self, bounds: Mapping[str, tuple[float, float]] | None) -> None:
        model = self.model
        self.names = tuple(model.param_names)
        unknown = [k for k in self.fixed if k not in self.names]
        if unknown:
            raise ConfigError(
                f"cannot fix unknown parameter(s) {', '.join(unknown)} of model '{model.name}'; "
                f"its parameters: {', '.join(self.names)}"
            )
        self.free = [i for i, n in enumerate(self.names) if n not in self.fixed]
        if not self.free:
            raise ConfigError("every parameter is fixed; nothing to identify")
        full = model.bounds(self.X, self.y)
        for name, pair in dict(bounds or {}).items():
            if name not in self.names:
                raise ConfigError(
                    f"bounds given for unknown parameter '{name}' of model '{model.name}'; "
                    f"its parameters: {', '.join(self.names)}"
                )
            lo, hi = (float(v) for v in pair)
            if not lo < hi:
                raise ConfigError(f"bounds for '{name}' need lower < upper; got ({lo}, {hi})")
            full[self.names.index(name)] = (lo, hi)
        self.base = model.defaults(self.X, self.y)
        for name, value in self.fixed.items():
            self.base[self.names.index(name)] = value
        self.bounds = full[self.free]
        _check_regions(model, self.base, full)

    def _init_generic(self, bounds: Any) -> None:
        if bounds is None or isinstance(bounds, Mapping):
            raise ConfigError(
                "a model without named parameters needs bounds as a (p, 2) array of "
                "(lower, upper) pairs"
            )
        if self.fixed:
            raise ConfigError("only a model with named parameters can have fixed parameters")
        b = np.asarray(bounds, dtype=float)
        if b.ndim != 2 or b.shape[1] != 2 or b.shape[0] == 0:
            raise ConfigError(f"bounds must have shape (p, 2); got {b.shape}")
        self.names = tuple(f"p{i}" for i in range(b.shape[0]))
        self.free = list(range(b.shape[0]))
        self.base = np.zeros(b.shape[0])
        self.bounds = b

    # -- sizes ----------------------------------------------------------------------------
    @property
    def free_names(self) -> list[str]:
        return [self.names[i] for i in self.free]

    @property
    def n_obs(self) -> int:
        """Number of samples (residuals per candidate)."""
        return int(self.y.size)

    @property
    def n_free(self) -> int:
        """Number of free parameters (the search dimension)."""
        return len(self.free)

    # -- evaluation -----------------------------------------------------------------------
    def expand(self, T: Any) -> np.ndarray:
        """Full parameter vectors ``(k, p_all)`` of free-parameter candidates ``T (k, p)``."""
        T = np.atleast_2d(np.asarray(T, dtype=float))
        if len(self.free) == self.base.size:
            return T
        full = np.empty((T.shape[0], self.base.size))
        full[...] = self.base  # (np.broadcast_to costs more on the small batches of hot loops)
        full[:, self.free] = T
        return full

    def predict(self, T: Any) -> np.ndarray:
        """The model's friction ``(k, n)`` for candidates ``T (k, p)``."""
        return np.atleast_2d(self.model.predict(self.expand(T), self.X))

    def residuals(self, T: Any) -> np.ndarray:
        """Weighted residuals ``sqrt(w) (model - y)``, shape ``(k, n)``, for ``T (k, p)``;
        with a robust loss, transformed by :func:`robust_residuals`."""
        r = self.predict(T) - self.y
        r = r if self._sqrt_w is None else r * self._sqrt_w
        return r if self.f_scale is None else robust_residuals(r, self.loss, self.f_scale)

    def loss_of(self, R: np.ndarray) -> np.ndarray:
        """The loss ``(k,)`` of weighted residuals ``R (k, n)``: the objective, written once."""
        sse = np.einsum("kn,kn->k", R, R)
        return sse / self.n_obs if self.loss == "mse" else sse

    def evaluate(self, T: Any) -> np.ndarray:
        """The loss of each candidate, ``(k, p) -> (k,)``: what optimisers minimise.

        A model may offer ``fused_mse(T, X, y) -> (k,)``, the unweighted mean squared error
        computed without forming the residuals (the RBF trainer's ridge scorer); it is used
        when there are no weights and the loss is not robust, and is the same quantity.
        """
        T = np.atleast_2d(np.asarray(T, dtype=float))
        fused = getattr(self.model, "fused_mse", None)
        if fused is not None and self._sqrt_w is None and self.f_scale is None:
            mse = fused(self.expand(T), self.X, self.y)
            return mse if self.loss == "mse" else mse * self.n_obs
        return self.loss_of(self.residuals(T))

    __call__ = evaluate

    def objective(self) -> Any:
        """What optimisers should minimise: :meth:`evaluate`, or for a built-in analytic model
        (:func:`fricid.models._kernels.kernel_for`) a :class:`~fricid.optim.JitObjective`
        whose calls and compiled fast path (RWSAVSBAS) run the model's numba kernel, the same
        loss up to rounding (1e-12 relative; issue 14: ``fit --method rwsavsbas`` took the
        numpy path, 11x the cost of evaluating its candidates in batches)."""
        if self._jit is None:
            self._jit = self.evaluate
            if (
                hasattr(self.model, "param_names")
                and getattr(self.model, "fused_mse", None) is None
            ):
                from ..models._kernels import kernel_data, kernel_for, loss_kernel
                from ..optim import JitObjective

                code = kernel_for(self.model)
                if code is not None:
                    data = kernel_data(
                        code,
                        self.X,
                        self.y,
                        self._sqrt_w,
                        self.base,
                        self.free,
                        self.loss,
                        self.f_scale,
                    )

                    def compiled(T: np.ndarray) -> np.ndarray:
                        T = np.ascontiguousarray(np.atleast_2d(T), dtype=float)
                        out = np.empty(T.shape[0])
                        loss_kernel(T, out, data)
                        return out

                    self._jit = JitObjective(compiled, loss_kernel, data)
        return self._jit

    def start(self, x0: Mapping[str, float] | None = None) -> np.ndarray:
        """A starting point ``(p,)``: the defaults clipped into the bounds, with ``x0``'s
        values (by name) for the free parameters it names."""
        start = np.clip(self.base[self.free], self.bounds[:, 0], self.bounds[:, 1])
        for name, value in (x0 or {}).items():
            if name not in self.names or name in self.fixed:
                raise ConfigError(f"x0 names '{name}', which is not a free parameter")
            start[self.free.index(self.names.index(name))] = float(value)
        return start

    def at_bound(self, x: np.ndarray, rtol: float = 1e-6) -> list[str]:
        """Free parameters of ``x (p,)`` within ``rtol`` of the box width of a bound."""
        lo, hi = self.bounds[:, 0], self.bounds[:, 1]
        gap = np.minimum(x - lo, hi - x)
        return [n for n, g, s in zip(self.free_names, gap, hi - lo, strict=True) if g <= rtol * s]
