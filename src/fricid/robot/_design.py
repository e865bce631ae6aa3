"""The optimisation behind :func:`fricid.robot.excitation.design_excitation`: the coefficients
of every joint as one vector, the criterion and the effort limits by forward differences
(every perturbed design evaluated in one call of the regressor and of RNEA), the position,
velocity and acceleration limits as linear constraints with exact gradients."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .base import BaseParameters
from .model import RigidBodyModel
from .trajectories import FourierTrajectory, fourier_basis

__all__ = ["Problem"]

#: Forward-difference step of the coefficients.
STEP = 1e-6

#: Softness of the log-sum-exp peaks, as a fraction of each limit.
SOFT = 2e-3


class Problem:
    """The design problem of one robot (module notes). ``x`` holds, joint after joint,
    ``q0, a_1..a_H, b_1..b_H``."""

    def __init__(
        self,
        model: RigidBodyModel,
        base: BaseParameters,
        *,
        harmonics: int,
        w_f: float,
        samples: int,
        grid: int,
        limits: dict,
        friction: str,
        criterion: str,
        smooth: float,
        measure: Callable[..., float],
        columns: Callable[..., np.ndarray],
    ) -> None:
        self.model, self.base, self.H, self.w_f = model, base, harmonics, w_f
        self.n = model.n
        self.width = 2 * harmonics + 1
        self.size = self.n * self.width
        self.limits, self.friction, self.criterion, self.smooth = (
            limits,
            friction,
            criterion,
            smooth,
        )
        self.measure, self.columns = measure, columns
        period = 2 * np.pi / w_f
        self.t = np.arange(samples) * period / samples
        self.B = fourier_basis(self.t, w_f, harmonics)
        self.G = fourier_basis(np.arange(grid) * period / grid, w_f, harmonics)
        self.finite_effort = np.isfinite(limits["effort"])
        self.evaluations = 0
        self.converged, self.message = False, ""
        self._cache: tuple[bytes, np.ndarray, np.ndarray] | None = None
        self._steps: tuple[bytes, np.ndarray, np.ndarray] | None = None
        self.L, (self.centre, self.scale) = self._linear()

    # -- coefficients ------------------------------------------------------------------------

    def split(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``q0`` (..., n) and the coefficients ``c`` (..., n, 2H) of one or many ``x``."""
        X = x.reshape(*x.shape[:-1], self.n, self.width)
        return X[..., 0], X[..., 1:]

    def trajectory(self, x: np.ndarray, joints: tuple[str, ...]) -> FourierTrajectory:
        q0, c = self.split(x)
        return FourierTrajectory(joints, self.w_f, q0, c[:, : self.H], c[:, self.H :])

    def states(self, X: np.ndarray, B: tuple[np.ndarray, ...] | None = None) -> tuple:
        """``(q, dq, ddq)`` of the designs ``X`` (k, size), each (k, M, n)."""
        pos, vel, acc = self.B if B is None else B
        q0, c = self.split(X)
        q = q0[:, None, :] + np.einsum("mh,knh->kmn", pos, c)
        return q, np.einsum("mh,knh->kmn", vel, c), np.einsum("mh,knh->kmn", acc, c)

    # -- position, velocity and acceleration limits ------------------------------------------

    def _linear(self) -> tuple[np.ndarray, np.ndarray]:
        """Per quantity, the matrix ``L`` (grid, 2H + 1) giving that quantity of one joint on
        the grid from its ``[q0, c]``, and each joint's scale (half-range or limit)."""
        pos, vel, acc = self.G
        one, zero = np.ones((pos.shape[0], 1)), np.zeros((pos.shape[0], 1))
        L = np.stack([np.hstack([one, pos]), np.hstack([zero, vel]), np.hstack([zero, acc])])
        lim = self.limits
        half = 0.5 * (lim["upper"] - lim["lower"])
        centre = np.stack([0.5 * (lim["upper"] + lim["lower"]), 0 * half, 0 * half])
        scale = np.stack([half, lim["velocity"], lim["acceleration"]])
        return L, (centre, scale)

    def _soft_peaks(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each quantity's peak fraction ``max_t |u(t) - centre| / scale`` on the grid as a
        log-sum-exp (an upper bound, within ``SOFT log(2 grid)`` of it), shape (3, n), and
        the softmax weights' signed sums (3, n, grid) giving its gradient."""
        L, centre, scale = self.L, self.centre, self.scale
        X = x.reshape(self.n, self.width)
        u = (np.einsum("qgw,nw->qng", L, X) - centre[:, :, None]) / scale[:, :, None]
        both = np.concatenate([u, -u], axis=2) / SOFT
        top = both.max(axis=2, keepdims=True)
        e = np.exp(both - top)
        total = e.sum(axis=2, keepdims=True)
        peak = SOFT * (top[..., 0] + np.log(total[..., 0]))
        w = e / total
        G = u.shape[2]
        return peak, (w[..., :G] - w[..., G:]) / scale[:, :, None]

    def limits_fun(self, x: np.ndarray) -> np.ndarray:
        """``1 - peak`` per quantity and joint (>= 0 within the limits), shape (3 n,)."""
        return (1.0 - self._soft_peaks(x)[0]).ravel()

    def limits_jac(self, x: np.ndarray) -> np.ndarray:
        _, signed = self._soft_peaks(x)
        grad = -np.einsum("qng,qgw->qnw", signed, self.L)  # (3, n, width)
        J = np.zeros((3, self.n, self.size))
        for j in range(self.n):
            J[:, j, j * self.width : (j + 1) * self.width] = grad[:, j]
        return J.reshape(3 * self.n, self.size)

    def at_rest(self) -> np.ndarray:
        """``E x = 0``: every joint at rest at ``t = 0`` (``sum a_k = 0``, ``sum k b_k = 0``)."""
        E = np.zeros((2 * self.n, self.size))
        k = np.arange(1, self.H + 1)
        for j in range(self.n):
            E[2 * j, j * self.width + 1 : j * self.width + 1 + self.H] = 1.0
            E[2 * j + 1, j * self.width + 1 + self.H : (j + 1) * self.width] = k
        return E

    # -- criterion and effort -----------------------------------------------------------------

    def _batch(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Criterion (k,) and torque (k, M, n) of the designs ``X`` (k, size)."""
        q, dq, ddq = (s.reshape(-1, self.n) for s in self.states(X))
        M = self.t.size
        Y = self.base.columns(self.model.regressor(q, dq, ddq))
        W = np.concatenate([Y, self.columns(dq, self.friction, self.smooth)], axis=2)
        W = W.reshape(X.shape[0], M * self.n, W.shape[-1])
        tau = self.model.inverse_dynamics(q, dq, ddq).reshape(X.shape[0], M, self.n)
        self.evaluations += X.shape[0]
        return np.array([self.measure(w, self.criterion) for w in W]), tau

    def _point(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """Criterion and torque (1, M, n) at ``x`` (cached: SLSQP asks for both)."""
        key = x.tobytes()
        if self._cache is None or self._cache[0] != key:
            f, tau = self._batch(x[None, :])
            self._cache = (key, f, tau)
        return float(self._cache[1][0]), self._cache[2]

    def _perturbed(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Criterion (size,) and torque (size, M, n) at ``x`` plus each forward step."""
        key = x.tobytes()
        if self._steps is None or self._steps[0] != key:
            f, tau = self._batch(x + STEP * np.eye(self.size))
            self._steps = (key, f, tau)
        return self._steps[1], self._steps[2]

    def value(self, X: np.ndarray) -> np.ndarray:
        """The criterion of designs ``X`` (k, size), without gradients."""
        return self._batch(np.atleast_2d(X))[0]

    def fun(self, x: np.ndarray) -> float:
        return self._point(x)[0]

    def jac(self, x: np.ndarray) -> np.ndarray:
        return (self._perturbed(x)[0] - self._point(x)[0]) / STEP

    def _effort_peaks(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Soft peak ``|tau| / effort`` over the instants per joint with an effort limit, of
        torques (k, M, n): (k, m) and the signed softmax weights (k, M, m)."""
        u = tau[:, :, self.finite_effort] / self.limits["effort"][self.finite_effort]
        both = np.concatenate([u, -u], axis=1) / SOFT
        top = both.max(axis=1, keepdims=True)
        e = np.exp(both - top)
        total = e.sum(axis=1, keepdims=True)
        M = u.shape[1]
        return SOFT * (top[:, 0] + np.log(total[:, 0])), e[:, :M] / total - e[:, M:] / total

    def effort(self, x: np.ndarray) -> np.ndarray:
        """``1 - soft peak |tau| / effort`` per joint with a finite effort limit."""
        return 1.0 - self._effort_peaks(self._point(x)[1])[0][0]

    def effort_jac(self, x: np.ndarray) -> np.ndarray:
        peak0 = self._effort_peaks(self._point(x)[1])[0]
        peak = self._effort_peaks(self._perturbed(x)[1])[0]  # (size, m)
        return -((peak - peak0) / STEP).T

    def torque(self, X: np.ndarray) -> np.ndarray:
        """The torque (k, M, n) of designs ``X`` at the design instants (RNEA only)."""
        q, dq, ddq = (s.reshape(-1, self.n) for s in self.states(np.atleast_2d(X)))
        return self.model.inverse_dynamics(q, dq, ddq).reshape(-1, self.t.size, self.n)

    # -- random feasible starts ---------------------------------------------------------------

    def random_start(self, rng: np.random.Generator, rest: bool, fill: float = 0.8) -> np.ndarray:
        """A random design: ``q0`` in the middle of the range, random coefficients falling
        with the harmonic, each joint scaled to ``fill`` of its tightest linear limit, then all
        shrunk until the effort limits hold at the design instants."""
        lim = self.limits
        k = np.arange(1, self.H + 1)
        c = rng.normal(size=(self.n, 2 * self.H)) / np.concatenate([k, k])
        if rest:
            c[:, : self.H] -= c[:, : self.H].mean(axis=1, keepdims=True)
            b = c[:, self.H :]
            b -= np.outer(b @ k, k) / (k @ k)
        pos, vel, acc = self.G
        half = 0.5 * (lim["upper"] - lim["lower"])
        peak = np.max(
            np.stack(
                [
                    np.max(np.abs(pos @ c.T), axis=0) / half,
                    np.max(np.abs(vel @ c.T), axis=0) / lim["velocity"],
                    np.max(np.abs(acc @ c.T), axis=0) / lim["acceleration"],
                ]
            ),
            axis=0,
        )
        c *= (fill / peak)[:, None]
        x = np.hstack([0.5 * (lim["upper"] + lim["lower"])[:, None], c]).ravel()
        return self.shrink_to_effort(x)

    def shrink_to_effort(self, x: np.ndarray, tries: int = 30) -> np.ndarray:
        """``x`` with its oscillation shrunk by 10 % steps until the effort limits hold at
        the design instants (gravity at the middle of the range is the floor)."""
        eff = self.limits["effort"]
        for _ in range(tries):
            tau = self.torque(x)[0]
            if np.all(np.abs(tau) <= eff):
                return x
            q0, c = self.split(x.copy())
            x = np.hstack([q0[:, None], 0.9 * c]).ravel()
        return x
