"""Base inertial parameters: the combinations of a robot's standard inertial parameters that
its joint torques determine (Gautier 1991, by QR decomposition with column pivoting).

The regressor ``Y`` of :meth:`~fricid.robot.model.RigidBodyModel.regressor` has dependent
columns (a body's parameters that never act on any joint, or act only in sums with its
neighbours'). Stacking ``Y`` at random states and factoring ``Y P = Q R`` with pivoting gives
the rank ``r``, the independent columns ``b = P[:r]`` and the rest ``d``, with ``Y_d = Y_b K``,
``K = R_11^-1 R_12``: the torque is ``Y_b beta`` with ``beta = pi_b + K pi_d``. The same
decomposition of the gravity regressor alone (``dq = ddq = 0``) gives the base gravity
parameters a sweep can identify (module :mod:`fricid.robot.model`, BAS-RBFNN paper eq. 7 for
one joint).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from ..errors import ConfigError
from .model import PARAMETER_SYMBOLS, RigidBodyModel

__all__ = ["BaseParameters", "base_parameters", "random_states"]

#: A pivot of R below this fraction of the largest is a dependent column.
RANK_RTOL = 1e-8

#: Entries of K below this are rounding, set to zero.
K_ATOL = 1e-10


@dataclass(frozen=True)
class BaseParameters:
    """The base parameters of a robot (module notes).

    Attributes
    ----------
    independent : ndarray of int, shape (r,)
        Indices of the standard parameters kept (the columns ``b``).
    dependent : ndarray of int
        Indices regrouped into them (``d``).
    K : ndarray, shape (r, p - r)
        ``beta = pi[b] + K pi[d]``.
    names : tuple of str
        Each base parameter as its standard parameter and what is regrouped into it, e.g.
        ``panda_joint2:Izz + 1 panda_joint3:m ...``.
    kind : str
        ``"dynamics"`` (the full regressor) or ``"gravity"`` (gravity alone).
    """

    independent: np.ndarray
    dependent: np.ndarray
    K: np.ndarray
    names: tuple[str, ...]
    kind: str = "dynamics"

    @property
    def rank(self) -> int:
        """The number of base parameters."""
        return int(self.independent.size)

    def project(self, pi: np.ndarray) -> np.ndarray:
        """``beta = pi_b + K pi_d`` from the standard parameters ``pi``, shape (r,)."""
        pi = np.asarray(pi, dtype=float)
        return pi[self.independent] + self.K @ pi[self.dependent]

    def columns(self, Y: np.ndarray) -> np.ndarray:
        """The base regressor ``Y_b`` (the independent columns of ``Y``, last axis)."""
        return np.asarray(Y)[..., self.independent]


def random_states(
    model: RigidBodyModel, count: int, rng: np.random.Generator, *, gravity_only: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``count`` random ``(q, dq, ddq)`` within the URDF's position limits (``[-pi, pi]`` where
    none), speeds up to the velocity limits (1 where none), accelerations of the order 1;
    ``dq = ddq = 0`` with ``gravity_only``."""
    lo = np.where(np.isfinite(model.lower), model.lower, -np.pi)
    hi = np.where(np.isfinite(model.upper), model.upper, np.pi)
    q = rng.uniform(lo, hi, size=(count, model.n))
    if gravity_only:
        zero = np.zeros_like(q)
        return q, zero, zero
    vmax = np.where(np.isfinite(model.velocity_limit), model.velocity_limit, 1.0)
    dq = rng.uniform(-vmax, vmax, size=(count, model.n))
    ddq = rng.normal(0.0, 1.0, size=(count, model.n)) * np.maximum(vmax, 1.0)
    return q, dq, ddq


def _name(std: tuple[str, ...], i: int, dependent: np.ndarray, row: np.ndarray) -> str:
    parts = [std[i]]
    for j, k in zip(dependent, row, strict=True):
        if k:
            parts.append(f"{k:+.4g} {std[j]}")
    return " ".join(parts)


def base_parameters(
    model: RigidBodyModel,
    *,
    gravity_only: bool = False,
    states: int | None = None,
    seed: int = 0,
) -> BaseParameters:
    """The robot's base parameters, from its regressor at random states (module notes).

    Parameters
    ----------
    model : RigidBodyModel
    gravity_only : bool
        The base parameters of the gravity torque alone (what constant-velocity sweeps or
        static poses identify).
    states : int, optional
        Random states stacked (default ``20 n + 50``, many more rows than parameters).
    seed : int
        The random states' seed (the structure does not depend on it: a dependence holds at
        every state).
    """
    states = 20 * model.n + 50 if states is None else int(states)
    if states < 1:
        raise ConfigError(f"states must be >= 1; got {states}")
    rng = np.random.default_rng(seed)
    Y = model.regressor(*random_states(model, states, rng, gravity_only=gravity_only))
    W = Y.reshape(-1, Y.shape[-1])
    scale = np.linalg.norm(W, axis=0)
    _, R, perm = scipy.linalg.qr(W, mode="economic", pivoting=True)
    diag = np.abs(np.diag(R))
    rank = int(np.sum(diag > RANK_RTOL * diag[0])) if diag.size and diag[0] > 0 else 0
    if rank == 0:
        raise ConfigError("the regressor is zero: no parameter acts on any joint")
    b, d = perm[:rank], perm[rank:]
    K = scipy.linalg.solve_triangular(R[:rank, :rank], R[:rank, rank:])
    K[np.abs(K) < K_ATOL] = 0.0
    # columns that are zero everywhere depend on nothing: K's row entries for them are 0
    K[:, scale[d] == 0] = 0.0
    order = np.argsort(b, kind="stable")  # report in the standard order
    b, K = b[order], K[order]
    std = tuple(f"{j}:{s}" for j in model.joints for s in PARAMETER_SYMBOLS)
    names = tuple(_name(std, i, d, K[k]) for k, i in enumerate(b))
    return BaseParameters(b, d, K, names, "gravity" if gravity_only else "dynamics")
