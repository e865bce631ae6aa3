"""The problem protocol every fit of fricid minimises, whatever the room, and
:class:`ResidualProblem`, which makes one of any batch residual function (the notes of
:mod:`fricid.identify.problem`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Protocol, runtime_checkable

import numpy as np

from ..errors import ConfigError

__all__ = ["Problem", "ResidualProblem"]


@runtime_checkable
class Problem(Protocol):
    """The problem protocol: what every fit of fricid minimises (after pymoo's ``Problem``).

    A problem takes a batch of candidates ``T (k, p)`` of its free parameters (``free_names``,
    in the coordinates its optimiser searches, inside ``bounds (p, 2)``) and knows nothing of
    the optimiser: ``residuals(T) -> (k, n)``, ``evaluate(T) -> (k,)`` (the loss),
    ``objective()`` (the callable to hand :func:`fricid.optim.minimize`: ``evaluate`` or a
    compiled twin), ``expand(T) -> (k, len(names))`` (every parameter, fixed ones included),
    ``n_obs`` (residuals per candidate), ``n_free`` (``p``), and ``y``, the observations in
    the residuals' units (the scale of an exact fit: the certification's floor of rounding).
    """

    names: Sequence[str]
    bounds: np.ndarray
    y: np.ndarray

    @property
    def free_names(self) -> list[str]: ...  # pragma: no cover

    @property
    def n_obs(self) -> int: ...  # pragma: no cover

    @property
    def n_free(self) -> int: ...  # pragma: no cover

    def expand(self, T: Any) -> np.ndarray: ...  # pragma: no cover

    def residuals(self, T: Any) -> np.ndarray: ...  # pragma: no cover

    def evaluate(self, T: Any) -> np.ndarray: ...  # pragma: no cover

    def objective(self) -> Callable[[np.ndarray], np.ndarray]: ...  # pragma: no cover


class ResidualProblem:
    """A least-squares :class:`Problem` given by its batch residual function.

    For the fits whose residuals are not a model's prediction minus samples (the trajectory
    routes' equation error, the joint's linear parameters projected out); the loss is the sum
    of the squared residuals.

    Parameters
    ----------
    residuals : callable
        ``(k, p) -> (k, n)``, in the coordinates of ``bounds``.
    bounds : array_like (p, 2)
        The search box (``inf`` where a parameter has none).
    names : sequence of str
        The ``p`` parameters' names.
    y : array_like (n,)
        The observations in the residuals' units (see :class:`Problem`).

    Examples
    --------
    >>> import numpy as np
    >>> from fricid.identify.problem import Problem, ResidualProblem
    >>> y = np.array([1.0, 2.0, 3.0])
    >>> line = ResidualProblem(lambda T: T[:, :1] * np.arange(1, 4) - y, [[0, 5]], ["a"], y)
    >>> isinstance(line, Problem), line.n_obs, line.n_free
    (True, 3, 1)
    >>> line.evaluate(np.array([[1.0], [0.0]]))
    array([ 0., 14.])
    """

    def __init__(
        self,
        residuals: Callable[[np.ndarray], np.ndarray],
        bounds: Any,
        names: Sequence[str],
        y: Any,
    ) -> None:
        self._residuals = residuals
        self.bounds = np.asarray(bounds, dtype=float)
        self._free_names = [str(n) for n in names]
        if self.bounds.shape != (len(self._free_names), 2):
            raise ConfigError(
                f"bounds must have shape ({len(self._free_names)}, 2), one row per name; got "
                f"{self.bounds.shape}"
            )
        self.names = tuple(self._free_names)
        self.y = np.asarray(y, dtype=float)

    @property
    def free_names(self) -> list[str]:
        return list(self._free_names)

    @property
    def n_obs(self) -> int:
        return int(self.y.size)

    @property
    def n_free(self) -> int:
        return len(self._free_names)

    def expand(self, T: Any) -> np.ndarray:
        return np.atleast_2d(np.asarray(T, dtype=float))  # every parameter is free

    def residuals(self, T: Any) -> np.ndarray:
        return self._residuals(T)

    def evaluate(self, T: Any) -> np.ndarray:
        """The sum of squared residuals of each candidate, ``(k, p) -> (k,)``."""
        r = self._residuals(T)
        return np.einsum("ij,ij->i", r, r)

    __call__ = evaluate

    def objective(self) -> Callable[[np.ndarray], np.ndarray]:
        return self.evaluate
