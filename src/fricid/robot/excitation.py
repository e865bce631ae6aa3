"""Excitation design: a periodic Fourier trajectory of every joint (Swevers et al. 1997, module
:mod:`.trajectories`) whose stacked regressor is as well conditioned as the robot's limits
allow (the sweeps of one joint at constant speeds are in :mod:`.sweeps`).

The information matrix. At ``M`` instants of one period, the rows of every joint's torque
``tau = Y_b(q, dq, ddq) beta + F(dq) phi`` are stacked into ``W = [Y_b F]`` (``M n`` rows):
``Y_b`` the base regressor (:func:`fricid.robot.base.base_parameters`), ``F`` the friction
columns of each joint (``coulomb_viscous_asym``: ``1[dq > 0]``, ``-1[dq < 0]`` and ``dq``;
``coulomb_viscous``: ``sign(dq)`` and ``dq``; ``none``). The criterion is the condition
number of ``W`` (Swevers 1997 eq. 27; Gautier and Khalil 1992) or, ``d-optimal``, ``-log det
W^T W`` per row (the volume of the parameters' confidence ellipsoid). While optimising, the
steps of the Coulomb columns are smoothed, ``tanh(dq / eps)``, so the criterion is smooth in
the coefficients; the figures reported use the exact steps.

The limits. Position ``[lo, hi]`` (the URDF's, narrowed by a workspace, less ``margin`` of its
width at each end), velocity and acceleration ``|dq|, |ddq| <= (1 - margin)`` their limits at a
fine grid of the period, and effort ``|M ddq + C dq + g| <= (1 - margin) effort_limit`` at
the ``M`` instants. Each is one constraint per joint and quantity: its peak as a log-sum-exp
(an upper bound of the maximum, within 0.2 % of the limit times ``log`` of the points), with
exact gradients for the first three (linear in the coefficients) and forward differences for
the effort. SLSQP (:func:`scipy.optimize.minimize`) runs from the best of several random
feasible designs for a budget of criterion evaluations; the result is the better of its best
iterate within the limits and its last iterate, either shrunk about ``q0`` until every limit
holds on a grid four times finer (what the optimiser's tolerances leave over).

The default acceleration limit is each joint's velocity limit times ``w_f H``: the
acceleration of the highest harmonic at the full speed (the velocity limit times ``w_f`` alone
would leave the higher harmonics almost no amplitude).

The standard errors. With independent torque noise of std ``sigma_j`` on joint ``j``, the
least-squares estimate of ``(beta, phi)`` from the periodic part sampled at ``rate`` for
``duration`` has covariance ``(W^T S^-1 W)^-1`` with ``S = diag(sigma_j^2)`` (one period's sum
times the number of periods).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np
import scipy.optimize

from ..errors import ConfigError
from .base import BaseParameters, base_parameters
from .limits import peak_fractions, resolve_limits
from .model import RigidBodyModel
from .trajectories import FourierTrajectory

__all__ = [
    "CRITERIA",
    "FRICTION_COLUMNS",
    "ExcitationDesign",
    "design_excitation",
    "friction_columns",
    "information_matrix",
    "peak_fractions",
    "resolve_limits",
]

#: The design criteria.
CRITERIA = ("cond", "d-optimal")

#: Friction regressor columns per joint, by law.
FRICTION_COLUMNS = {
    "coulomb_viscous_asym": ("Fc+", "Fc-", "Fv"),
    "coulomb_viscous": ("Fc", "Fv"),
    "none": (),
}

#: Instants per period on the fine grid that checks the linear limits.
GRID = 400

#: A soft peak this far over a limit (a fraction) still counts as within it while optimising
#: (SLSQP meets its constraints to a tolerance; :func:`_feasible` then shrinks the result).
SLACK = 2e-3

#: Smoothing speed of the Coulomb steps while optimising [rad/s].
SMOOTH = 1e-2


def friction_columns(dq: np.ndarray, friction: str, smooth: float = 0.0) -> np.ndarray:
    """The friction regressor ``F``, shape ``(N, n, c n)``: joint ``j``'s row holds its own
    columns only (module notes); ``smooth > 0`` replaces the steps by ``tanh(dq / smooth)``."""
    if friction not in FRICTION_COLUMNS:
        raise ConfigError(f"friction must be one of {sorted(FRICTION_COLUMNS)}; got {friction!r}")
    dq = np.atleast_2d(dq)
    sign = np.tanh(dq / smooth) if smooth > 0 else np.sign(dq)
    per = {
        "coulomb_viscous_asym": (0.5 * (sign + np.abs(sign)), 0.5 * (sign - np.abs(sign)), dq),
        "coulomb_viscous": (sign, dq),
        "none": (),
    }[friction]
    c, (N, n) = len(per), dq.shape
    F = np.zeros((N, n, c * n))
    for j in range(n):
        for i, col in enumerate(per):
            F[:, j, c * j + i] = col[:, j]
    return F


def information_matrix(
    model: RigidBodyModel, base: BaseParameters, q, dq, ddq, friction: str, smooth: float = 0.0
) -> np.ndarray:
    """``W = [Y_b F]`` stacked over samples and joints, shape ``(N n, r + c n)``."""
    Y = base.columns(model.regressor(q, dq, ddq))
    W = np.concatenate([Y, friction_columns(dq, friction, smooth)], axis=2)
    return W.reshape(-1, W.shape[-1])


def _criterion(W: np.ndarray, criterion: str) -> float:
    s = np.linalg.svd(W, compute_uv=False)
    if criterion == "cond":
        return float(np.log(s[0] / s[-1])) if s[-1] > 0 else np.inf
    return float(-2.0 * np.sum(np.log(s)) / W.shape[1]) if s[-1] > 0 else np.inf


@dataclass(frozen=True)
class ExcitationDesign:
    """A designed excitation and what it promises (module notes).

    Attributes
    ----------
    trajectory : FourierTrajectory
    criterion, friction : str
    names : tuple of str
        The columns of ``W``: the base parameters, then ``<joint>:<friction column>``.
    cond : float
        The condition number of ``W`` at the design instants (exact Coulomb steps).
    cond_start : float
        The same for the best random feasible start.
    logdet, logdet_start : float
        ``log det W^T W / (rows)`` of the design and of the start.
    limits : dict
        ``lower``, ``upper``, ``velocity``, ``acceleration``, ``effort`` (n,) used, ``margin``.
    margins : dict
        Per quantity, each joint's peak over the fine grid as a fraction of its limit
        (``position``: of the half-width about the middle).
    samples, evaluations : int
    seconds : float
    converged : bool
    message : str
    """

    trajectory: FourierTrajectory
    criterion: str
    friction: str
    names: tuple[str, ...]
    cond: float
    cond_start: float
    logdet: float
    logdet_start: float
    limits: dict = field(repr=False)
    margins: dict = field(repr=False)
    samples: int = 0
    evaluations: int = 0
    seconds: float = 0.0
    converged: bool = False
    message: str = ""
    seed: int = 0

    @property
    def joints(self) -> tuple[str, ...]:
        return self.trajectory.joints

    def covariance(
        self, model: RigidBodyModel, torque_noise, *, rate: float = 1000.0, duration=None
    ) -> np.ndarray:
        """The predicted covariance of ``(beta, phi)`` (module notes) with torque noise std
        ``torque_noise`` [N m] (one number or one per joint), from the periodic part sampled
        at ``rate`` [Hz] for ``duration`` s (default one period)."""
        return predicted_covariance(
            model, self.trajectory, self.friction, torque_noise, rate=rate, duration=duration
        )

    def standard_errors(self, model: RigidBodyModel, torque_noise, **kw) -> np.ndarray:
        """The square roots of :meth:`covariance`'s diagonal, in :attr:`names`' order."""
        return np.sqrt(np.diag(self.covariance(model, torque_noise, **kw)))


def predicted_covariance(
    model: RigidBodyModel,
    trajectory: FourierTrajectory,
    friction: str,
    torque_noise,
    *,
    rate: float = 1000.0,
    duration: float | None = None,
) -> np.ndarray:
    """``(W^T S^-1 W)^-1`` over ``duration`` s at ``rate`` Hz (module notes)."""
    sigma = np.broadcast_to(np.asarray(torque_noise, dtype=float), (model.n,))
    if not (np.isfinite(sigma).all() and (sigma > 0).all()):
        raise ConfigError(f"the torque noise must be > 0 N m; got {torque_noise}")
    if not (np.isfinite(rate) and rate > 0):
        raise ConfigError(f"the rate must be > 0 Hz; got {rate}")
    period = trajectory.period
    duration = period if duration is None else float(duration)
    t = np.arange(round(period * rate)) / rate
    W = information_matrix(model, _base(model), *trajectory.evaluate(t), friction)
    W = W / np.tile(sigma, t.size)[:, None]
    info = (W.T @ W) * (duration / period)
    return np.linalg.pinv(info)


_BASE_CACHE: dict[int, tuple[RigidBodyModel, BaseParameters]] = {}


def _base(model: RigidBodyModel) -> BaseParameters:
    hit = _BASE_CACHE.get(id(model))
    if hit is None or hit[0] is not model:
        hit = (model, base_parameters(model))
        _BASE_CACHE.clear()
        _BASE_CACHE[id(model)] = hit
    return hit[1]


# -- the design ------------------------------------------------------------------------------


def design_excitation(
    model: RigidBodyModel,
    *,
    harmonics: int = 5,
    period: float = 10.0,
    samples: int = 40,
    criterion: str = "cond",
    friction: str = "coulomb_viscous_asym",
    workspace: Mapping[str, tuple[float, float]] | None = None,
    acceleration_limit: float | np.ndarray | None = None,
    margin: float = 0.05,
    at_rest: bool = False,
    starts: int = 8,
    seed: int = 0,
    max_evaluations: int = 10000,
    progress: Callable[[int, int], None] | None = None,
) -> ExcitationDesign:
    """A Fourier excitation of every joint of ``model`` optimised for ``criterion`` within
    the limits (module notes).

    Parameters
    ----------
    model : RigidBodyModel
    harmonics : int
        ``H``, harmonics of the base frequency ``w_f = 2 pi / period``.
    period : float
        The period [s].
    samples : int
        Instants per period at which ``W`` and the efforts are evaluated while optimising.
    criterion : {"cond", "d-optimal"}
    friction : str
        A key of :data:`FRICTION_COLUMNS`.
    workspace : mapping, optional
        ``joint -> (lo, hi)`` [rad or m], within the URDF's limits.
    acceleration_limit : float or array, optional
        [rad/s^2]; default each joint's velocity limit times ``w_f H``.
    margin : float
        The fraction of each limit (of the position range's width at each end) kept free.
    at_rest : bool
        Every joint at rest at ``t = 0`` (and so at the end of every period).
    starts : int
        Random feasible designs drawn; the optimisation starts from the best.
    seed : int
    max_evaluations : int
        Evaluations of the criterion (a gradient costs one per coefficient plus one).
    progress : callable, optional
        ``progress(evaluations, max_evaluations)`` after each iteration.
    """
    from threadpoolctl import threadpool_limits

    # many small SVDs: BLAS threads only cost (and oversubscribe a shared machine)
    with threadpool_limits(limits=1, user_api="blas"):
        return _design(
            model, harmonics, period, samples, criterion, friction, workspace,
            acceleration_limit, margin, at_rest, starts, seed, max_evaluations, progress,
        )  # fmt: skip


def _design(
    model, harmonics, period, samples, criterion, friction, workspace, acceleration_limit,
    margin, at_rest, starts, seed, max_evaluations, progress,
) -> ExcitationDesign:  # fmt: skip
    """:func:`design_excitation` with its arguments checked here."""
    from ._design import Problem

    if criterion not in CRITERIA:
        raise ConfigError(f"criterion must be one of {CRITERIA}; got {criterion!r}")
    if friction not in FRICTION_COLUMNS:
        raise ConfigError(f"friction must be one of {sorted(FRICTION_COLUMNS)}; got {friction!r}")
    if int(harmonics) < 1 or int(samples) < 2 or int(starts) < 1:
        raise ConfigError(
            f"need harmonics >= 1, samples >= 2, starts >= 1; got {harmonics}, {samples}, {starts}"
        )
    if not (np.isfinite(period) and period > 0):
        raise ConfigError(f"the period must be > 0 s; got {period}")
    t0 = time.perf_counter()
    w_f = 2.0 * np.pi / float(period)
    limits = resolve_limits(model, workspace, acceleration_limit, w_f, int(harmonics), margin)
    base = _base(model)
    names = base.names + tuple(f"{j}:{c}" for j in model.joints for c in FRICTION_COLUMNS[friction])
    if len(names) > int(samples) * model.n:
        raise ConfigError(
            f"{samples} instants x {model.n} joints are fewer rows than the {len(names)} "
            "parameters: raise samples"
        )
    grid = max(GRID, 20 * int(harmonics))
    problem = Problem(
        model,
        base,
        harmonics=int(harmonics),
        w_f=w_f,
        samples=int(samples),
        grid=grid,
        limits=limits,
        friction=friction,
        criterion=criterion,
        smooth=SMOOTH,
        measure=_criterion,
        columns=friction_columns,
    )
    rng = np.random.default_rng(seed)
    X = np.array([problem.random_start(rng, at_rest) for _ in range(int(starts))])
    x_start = X[int(np.argmin(problem.value(X)))]
    rate = grid / float(period) * 4
    found = _optimise(problem, x_start, at_rest, max_evaluations, progress)
    options = [problem.trajectory(_feasible(problem, x, x_start, model, limits, rate), model.joints)
               for x in found]  # fmt: skip
    score = [_exact(model, base, problem.t, tr, friction) for tr in options]
    pick = [c if criterion == "cond" else -d for c, d in score]
    traj = options[int(np.argmin(pick))]
    start = problem.trajectory(x_start, model.joints)
    exact = {
        key: _exact(model, base, problem.t, tr, friction) for key, tr in (("x", traj), ("s", start))
    }
    return ExcitationDesign(
        traj,
        criterion,
        friction,
        names,
        cond=exact["x"][0],
        cond_start=exact["s"][0],
        logdet=exact["x"][1],
        logdet_start=exact["s"][1],
        limits=limits,
        margins=peak_fractions(model, traj, limits, rate=grid / float(period) * 4),
        samples=int(samples),
        evaluations=problem.evaluations,
        seconds=time.perf_counter() - t0,
        converged=bool(problem.converged),
        message=problem.message,
        seed=int(seed),
    )


def _exact(model, base, t, traj, friction) -> tuple[float, float]:
    """Condition number and ``log det W^T W / rows`` with the exact Coulomb steps."""
    W = information_matrix(model, base, *traj.evaluate(t), friction)
    s = np.linalg.svd(W, compute_uv=False)
    cond = float(s[0] / s[-1]) if s[-1] > 0 else np.inf
    logdet = (
        float(2.0 * np.sum(np.log(s)) - W.shape[1] * np.log(W.shape[0])) if s[-1] > 0 else -np.inf
    )
    return cond, logdet


def _optimise(problem, x0, at_rest, max_evaluations, progress) -> tuple[np.ndarray, np.ndarray]:
    """SLSQP from ``x0`` within the budget (module notes): its best iterate within the limits
    (``x0`` if none is) and its last (which :func:`_feasible` may have to shrink)."""
    cons = [{"type": "ineq", "fun": problem.limits_fun, "jac": problem.limits_jac}]
    if problem.finite_effort.any():
        cons.append({"type": "ineq", "fun": problem.effort, "jac": problem.effort_jac})
    if at_rest:
        E = problem.at_rest()
        cons.append({"type": "eq", "fun": lambda x: E @ x, "jac": lambda x: E})
    maxiter = max(1, int(max_evaluations) // (problem.size + 1))
    best = [problem.fun(x0), x0]

    def keep(x: np.ndarray) -> None:
        """Remember ``x`` if it is within the limits and the best so far (SLSQP's iterates
        may cross a limit on their way; its last one is not always its best)."""
        inside = np.all(problem.limits_fun(x) >= -SLACK) and np.all(
            problem.effort(x) >= -SLACK if problem.finite_effort.any() else True
        )
        if at_rest:
            inside = inside and np.allclose(problem.at_rest() @ x, 0.0, atol=1e-9)
        f = problem.fun(x)
        if inside and np.isfinite(f) and f < best[0]:
            best[:] = [f, np.array(x, dtype=float)]

    def step(xk: np.ndarray) -> None:
        keep(xk)
        if progress is not None:
            progress(min(problem.evaluations, int(max_evaluations)), int(max_evaluations))
        if problem.evaluations >= max_evaluations:
            raise StopIteration  # the budget is spent: SLSQP returns its last iterate

    res = scipy.optimize.minimize(
        problem.fun,
        x0,
        jac=problem.jac,
        method="SLSQP",
        constraints=cons,
        callback=step,
        options={"maxiter": maxiter, "ftol": 1e-6},
    )
    spent = problem.evaluations >= max_evaluations
    problem.converged = bool(res.success) and not spent
    problem.message = (
        f"the budget of {max_evaluations} evaluations is spent" if spent else str(res.message)
    )
    last = np.asarray(res.x, dtype=float)
    if at_rest:  # onto E x = 0 exactly (SLSQP meets it to a tolerance)
        last = last - E.T @ np.linalg.solve(E @ E.T, E @ last)
    keep(last)
    return best[1], last


def _feasible(problem, x, x_start, model, limits, rate) -> np.ndarray:
    """``x`` with its oscillation about ``q0`` shrunk until every limit holds on a grid four
    times finer than the constraints' (the optimiser may end a rounding outside); the start
    when nothing smaller helps."""
    traj = problem.trajectory(x, model.joints)
    for _ in range(40):
        peaks = peak_fractions(model, traj, limits, rate)
        worst = max(float(np.nanmax(np.r_[v, 0.0])) for v in peaks.values())
        if worst <= 1.0:
            return x
        q0, c = problem.split(x.copy())
        x = np.hstack([q0[:, None], c / max(worst, 1.0 + 1e-3)]).ravel()
        x = _clip_q0(problem, x)
        traj = problem.trajectory(x, model.joints)
    return x_start


def _clip_q0(problem, x: np.ndarray) -> np.ndarray:
    lim = problem.limits
    q0, c = problem.split(x.copy())
    q0 = np.clip(q0, lim["lower"], lim["upper"])
    return np.hstack([q0[:, None], c]).ravel()
