"""The two routes of :mod:`fricid.identify.dynamic.trajectory`: inverse-dynamics regression and
simulation error (see that module's notes), each returning a :class:`_Stage` (estimate,
cluster-robust covariance, 95 % intervals, the optimiser's result, the problem it minimised,
timing).

Every stage's search is a problem of the problem protocol
(:class:`fricid.identify.problem.Problem`): a :class:`~fricid.identify.problem.ResidualProblem`
of the projected equation error, or :class:`_SimProblem` of the simulation error, so that its
convergence is certified as an analytic fit's is (:func:`._outcome.converged`). Which route
a model takes (:func:`route_for`) is decided here too; the module is longer than 500 lines
because the two routes share their stage, covariance and search-box code.
"""

from __future__ import annotations

import difflib
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import ConfigError, DataError
from ...models import lugre
from ...optim import METHODS, minimize
from ..problem import Problem, ResidualProblem
from ..static.uncertainty import jacobian
from ._data import Series, blocks, cluster_covariance, low_speed_windows

__all__ = [
    "DYNAMIC_MODELS",
    "JOINT_PARAMS",
    "JOINT_UNITS",
    "LSQ_STARTS",
    "LUGRE_LAWS",
    "ROUTES",
    "STATIC_MODELS",
    "route_for",
]

#: Routes of :func:`.trajectory.fit_trajectory` (the first is LuGre's default; LuGre's
#: ``presliding`` is taken by the default too when the log never slides).
ROUTES = ("filtered", "two_stage", "joint", "regression", "presliding")

#: Static models a trajectory identifies by regression.
STATIC_MODELS = ("stribeck", "coulomb_viscous", "stribeck_asym", "coulomb_viscous_asym")

#: Dynamic models a trajectory identifies.
DYNAMIC_MODELS = ("lugre", "lugre_asym", "dahl")
#: The LuGre laws: one set of levels, or one per direction (the filtered route only).
LUGRE_LAWS = ("lugre", "lugre_asym")


def route_for(key: str, route: str, with_static: bool) -> str:
    """The route :func:`.trajectory.fit_trajectory` takes for the model ``key`` asked for
    ``route`` (``with_static``: a static part from sweeps given), or a ConfigError: static
    models by the regression, Dahl and per-direction LuGre by the filtered route only,
    LuGre's filtered route with sweeps becomes ``two_stage``."""
    if key not in (*DYNAMIC_MODELS, *STATIC_MODELS):
        near = difflib.get_close_matches(key, (*DYNAMIC_MODELS, *STATIC_MODELS), n=1)
        raise ConfigError(
            f"a trajectory identifies {', '.join(DYNAMIC_MODELS)} or a static model "
            f"({', '.join(STATIC_MODELS)}); got '{key}'"
            + (f" (did you mean '{near[0]}'?)" if near else "")
        )
    if route not in ROUTES:
        raise ConfigError(f"unknown route '{route}'; one of: {', '.join(ROUTES)}")
    if key in ("dahl", "lugre_asym") and (route != "filtered" or with_static):
        why = ", not from a static part given (static=)" if with_static else ""
        raise ConfigError(f"{key} is identified by the filtered route only{why}")
    if key in STATIC_MODELS:
        return "regression"
    if key == "lugre" and route == "filtered" and with_static:
        return "two_stage"
    if key == "lugre" and route == "regression":
        raise ConfigError("LuGre's sigma_0 and sigma_1 need the simulation route (two_stage)")
    return route


#: Starts of the least-squares methods (the first at the given start: the static part's
#: defaults, or the first stage's estimate; the second at random in the box).
LSQ_STARTS = 2

#: The searches whose every evaluation simulates the joint over the whole log (the filtered and
#: output-error routes) stop once a step lowers the SSE by under this share of what the
#: convergence certificate resolves (``RESOLVE_SE^2 s^2``:
#: :func:`fricid.identify.static.convergence.noise_ftol`), not at ``lm``'s 1e-12.
SEARCH_SHARE = 0.1

#: Starts of the least-squares methods on the simulation route: one, from the box centre
#: (sigma_0 = 10^4.5 N m/rad, sigma_1 = 1 N m s/rad) or the two-stage estimate; on the virtual
#: joint the simulation error was unimodal in log sigma_0 (scanned 1e3-1e5), and on the 5
#: seeds of ``benchmarks/bench_trajectory.py`` a second, random start gave the same table
#: at about twice the route's time.
SIM_STARTS = 1

#: Names of the joint's rigid-body parameters.
JOINT_PARAMS = ("inertia", "p_x", "p_y")
JOINT_UNITS = {"inertia": "kg m^2", "p_x": "N m", "p_y": "N m"}


@dataclass
class _Stage:
    """One route's estimate: names, values, standard errors, 95 % intervals, bookkeeping;
    ``problem`` is what the optimiser minimised (None when nothing was searched)."""

    names: list[str]
    values: np.ndarray
    stderr: np.ndarray
    low: np.ndarray
    high: np.ndarray
    cov: np.ndarray
    result: Any
    seconds: float
    clusters: int
    rms: dict[str, float]
    bounds: np.ndarray
    problem: Problem | None = None
    #: the regression's columns (its predictions' derivatives, ``(n, p)``), for
    #: :func:`._window.predicted_bias`
    columns: np.ndarray | None = None

    def table(self) -> dict[str, dict[str, float]]:
        return {
            n: {
                "value": float(v),
                "stderr": float(s),
                "ci95_low": float(lo),
                "ci95_high": float(hi),
            }
            for n, v, s, lo, hi in zip(
                self.names, self.values, self.stderr, self.low, self.high, strict=True
            )
        }


def _t975(dof: int) -> float:
    from scipy.stats import t

    return float(t.ppf(0.975, max(dof, 1)))


def _run(problem: Problem, method, x0, seed, max_evals, starts=None, ftol=None):
    """``minimize`` of ``problem`` over its box: with its residuals for the least-squares
    methods (``starts`` of them, default :data:`LSQ_STARTS`; ``ftol`` their relative
    tolerance on the SSE, default theirs), its loss for the others."""
    key = method.strip().lower()
    if key not in METHODS:
        raise ConfigError(f"unknown method '{method}'; choose one of: {', '.join(METHODS)}")
    bounds = problem.bounds
    if METHODS[key].uses_residuals:
        n = LSQ_STARTS if starts is None else starts
        options = {"n_starts": n} if "n_starts" in METHODS[key].options else None
        if options is not None and ftol is not None:
            options["ftol"] = float(ftol)
        return minimize(
            None,
            bounds,
            key,
            seed=seed,
            max_evals=max_evals,
            x0=x0,
            residuals=problem.residuals,
            options=options,
        )
    return minimize(problem.objective(), bounds, key, seed=seed, max_evals=max_evals, x0=x0)


def _regression(series, vf, acc, mask, model, gravity, method, seed, max_evals, cluster_n, fixed):
    """The inverse-dynamics route (module notes); ``fixed`` holds the friction parameters."""
    t0 = time.perf_counter()
    y = series.torque[mask]
    q = series.position[mask]
    cols = [acc[mask]] + ([-np.cos(q), np.sin(q)] if gravity == "fit" else [])
    Phi = np.column_stack(cols)
    nd, d = Phi.shape[1], model.n_params
    Qphi, _ = np.linalg.qr(Phi)
    X = np.column_stack([vf[mask], np.zeros(mask.sum()), series.temperature[mask]])
    rough = np.linalg.lstsq(np.column_stack([Phi, np.sign(X[:, 0]), X[:, 0]]), y, rcond=None)[0]
    F_scale = y - Phi @ rough[:nd]
    bounds = model.bounds(X, F_scale)
    x0 = np.clip(model.defaults(X, F_scale), bounds[:, 0], bounds[:, 1])

    def projected(P):
        R = y[None, :] - model.predict(np.atleast_2d(P), X)
        return R - (R @ Qphi) @ Qphi.T

    result, search = None, None
    if fixed is None:
        search = ResidualProblem(projected, bounds, model.param_names, y)
        result = _run(search, method, x0, seed, max_evals)
        theta = np.asarray(result.x, dtype=float)
    else:
        theta = np.asarray(fixed, dtype=float)
    c = np.linalg.lstsq(Phi, y - model.predict(theta, X), rcond=None)[0]

    def full(P):
        P = np.atleast_2d(P)
        return y[None, :] - model.predict(P[:, :d], X) - P[:, d:] @ Phi.T

    names = list(JOINT_PARAMS[:nd])
    box = np.column_stack([np.full(nd, -np.inf), np.full(nd, np.inf)])
    if fixed is None:
        p_hat, resid = np.concatenate([theta, c]), full
        names = list(model.param_names) + names
        box = np.vstack([bounds, box])
    else:
        p_hat = c

        def resid(P):
            P = np.atleast_2d(P)
            return full(np.column_stack([np.broadcast_to(theta, (len(P), d)), P]))

    Jm, r0 = jacobian(resid, p_hat)
    labels = blocks(series.time.size, cluster_n)[mask]
    cov, se, g = cluster_covariance(Jm, r0, labels)
    tq = _t975(g - 1)
    low = np.maximum(p_hat - tq * se, box[:, 0])
    high = np.minimum(p_hat + tq * se, box[:, 1])
    rms = {"torque": float(np.sqrt(np.mean(r0**2)))}
    seconds = time.perf_counter() - t0
    stage = _Stage(names, p_hat, se, low, high, cov, result, seconds, g, rms, box, search, -Jm)
    return stage, theta, c, r0


@dataclass
class _Windows:
    """The simulation route's data: the samples of every window, concatenated."""

    index: np.ndarray
    reset: np.ndarray
    carry: np.ndarray
    labels: np.ndarray
    tau: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    dt: float
    count: int


def _windows(series: Series, vf, acc, v_window, before, after, longest) -> _Windows:
    spans = low_speed_windows(np.abs(vf), v_window, before, after, longest)
    if not spans:
        raise DataError(
            f"the trajectory never comes below {v_window:g} rad/s: nothing determines the "
            "dynamic friction (sigma_0, sigma_1); record reversals, sticking or pre-sliding",
            file=None,
        )
    index = np.concatenate([np.arange(a, b) for a, b, _ in spans])
    reset = np.zeros(index.size, dtype=bool)
    carry = np.zeros(index.size, dtype=bool)
    labels = np.zeros(index.size, dtype=np.int64)
    at, previous = 0, None
    for a, b, w in spans:
        reset[at] = True
        carry[at] = previous == (a, w)  # a segment continuing the last: z carries on
        previous = (b, w)
        labels[at : at + b - a] = w
        at += b - a
    return _Windows(
        index,
        reset,
        carry,
        labels,
        series.torque[index],
        series.position[index],
        series.velocity[index],
        acc[index],
        series.dt,
        int(spans[-1][2]) + 1,
    )


#: Parameters of the simulation route searched on a log scale.
_LOG = ("sigma_0", "sigma_1")


class _SimProblem:
    """Simulation-error residuals over the windows, for a chosen set of free parameters: a
    problem of the problem protocol (:class:`fricid.identify.problem.Problem`).

    The full vector (``names``) is LuGre's seven parameters then J, p_x, p_y; the optimiser
    moves ``free_names`` of them (at positions ``free``; sigma_0, sigma_1 as log10) inside
    ``bounds`` (in those coordinates, :func:`_sim_bounds`).
    """

    def __init__(
        self, w: _Windows, base: np.ndarray, free_names: list[str], n_sub: int, bounds
    ) -> None:
        self.w, self.base, self.n_sub = w, base, n_sub
        self.names = (*lugre.PARAM_NAMES, *JOINT_PARAMS)
        self.free_names = list(free_names)
        self.free = [self.names.index(n) for n in free_names]
        self.bounds = np.asarray(bounds, dtype=float)
        self.log = np.array([n in _LOG for n in free_names])
        self.keep = ~w.reset
        self.scale = np.ones(2)

    @property
    def n_free(self) -> int:
        return len(self.free)

    @property
    def n_obs(self) -> int:
        return 2 * int(self.keep.sum())

    @property
    def y(self) -> np.ndarray:
        """The measured positions and velocities, scaled as the residuals are."""
        k = self.keep
        return np.concatenate([self.w.q[k] / self.scale[0], self.w.v[k] / self.scale[1]])

    def to_u(self, values: np.ndarray) -> np.ndarray:
        return np.where(self.log, np.log10(np.maximum(values, 1e-300)), values)

    def to_values(self, U: np.ndarray) -> np.ndarray:
        return np.where(self.log, 10.0**U, U)

    def full(self, U, at=None) -> np.ndarray:
        U = np.atleast_2d(U)
        P = np.tile(self.base if at is None else at, (len(U), 1))
        P[:, self.free] = self.to_values(U)
        return P

    def expand(self, U) -> np.ndarray:
        """Every parameter ``(k, 10)``, natural units, of candidates ``U (k, p)``."""
        return self.full(U)

    def simulate(self, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        w = self.w
        sim = lugre.simulate_joint(
            P[:, :7],
            P[:, 7],
            P[:, 8],
            P[:, 9],
            w.dt,
            w.tau,
            q0=w.q[0],
            v0=w.v[0],
            reset=w.reset,
            carry=w.carry,
            measured=(w.q, w.v, w.a),
            n_sub=self.n_sub,
        )
        return sim["position"], sim["velocity"]

    def residuals_full(self, P: np.ndarray) -> np.ndarray:
        Q, V = self.simulate(np.atleast_2d(P))
        k = self.keep
        r = np.hstack(
            [(Q[:, k] - self.w.q[k]) / self.scale[0], (V[:, k] - self.w.v[k]) / self.scale[1]]
        )
        return np.where(np.isfinite(r), r, 1e6)

    def residuals(self, U) -> np.ndarray:
        return self.residuals_full(self.full(U))

    def evaluate(self, U) -> np.ndarray:
        """The sum of squared (scaled) residuals of each candidate."""
        r = self.residuals(U)
        return np.einsum("ij,ij->i", r, r)

    def objective(self):
        return self.evaluate

    def set_scale(self, P: np.ndarray) -> None:
        Q, V = self.simulate(np.atleast_2d(P))
        k = self.keep
        rq = float(np.sqrt(np.mean((Q[0, k] - self.w.q[k]) ** 2)))
        rv = float(np.sqrt(np.mean((V[0, k] - self.w.v[k]) ** 2)))
        self.scale = np.array([rq if rq > 0 else 1.0, rv if rv > 0 else 1.0])

    def labels(self) -> np.ndarray:
        lab = self.w.labels[self.keep]
        return np.concatenate([lab, lab])


def _simulation(problem: _SimProblem, x0_u, method, seed, max_evals, first=None):
    """The simulation-error route over ``problem.free_names`` in ``problem.bounds``; ``first``
    = (stage, names in the full vector) carries the first stage's covariance into this one
    (Murphy-Topel)."""
    t0 = time.perf_counter()
    bounds_u = problem.bounds
    result = _run(problem, method, x0_u, seed, max_evals, SIM_STARTS)
    u_hat = np.asarray(result.x, dtype=float)
    Jm, r0 = jacobian(problem.residuals, u_hat)
    cov, se, g = cluster_covariance(Jm, r0, problem.labels())
    if first is not None:
        stage, held = first
        P_hat = problem.full(u_hat)[0]
        sel = [i for i, n in enumerate(held) if n is not None and n not in problem.free_names]
        if sel:
            cols = [problem.names.index(held[i]) for i in sel]

            def shifted(S):
                S = np.atleast_2d(S)
                P = np.tile(P_hat, (len(S), 1))
                P[:, cols] = S
                return problem.residuals_full(P)

            J21, _ = jacobian(shifted, P_hat[cols])
            cov, se = _two_step(Jm, J21, stage.cov[np.ix_(sel, sel)], cov, se)
    tq = _t975(g - 1)
    lo_u = np.maximum(u_hat - tq * se, bounds_u[:, 0])
    hi_u = np.minimum(u_hat + tq * se, bounds_u[:, 1])
    values = problem.to_values(u_hat)
    stderr = np.where(problem.log, values * np.log(10.0) * se, se)
    rms = dict(
        zip(
            ("position", "velocity"),
            problem.scale
            * np.sqrt([np.mean(r0[: r0.size // 2] ** 2), np.mean(r0[r0.size // 2 :] ** 2)]),
            strict=True,
        )
    )
    return _Stage(
        list(problem.free_names),
        values,
        stderr,
        problem.to_values(lo_u),
        problem.to_values(hi_u),
        cov,
        result,
        time.perf_counter() - t0,
        g,
        {k: float(v) for k, v in rms.items()},
        np.column_stack([problem.to_values(bounds_u[:, 0]), problem.to_values(bounds_u[:, 1])]),
        problem,
    )


def _two_step(Jm, J21, V1, cov, se):
    """Murphy and Topel's (1985) two-step covariance: ``V2 + G V1 G^T``,
    ``G = -(J2' J2)^-1 J2' J21`` (``J21``: sensitivity of this stage's residuals to the
    held parameters of covariance ``V1``)."""
    G = -np.linalg.pinv(Jm) @ J21
    extra = G @ np.nan_to_num(V1) @ G.T
    with np.errstate(invalid="ignore"):
        return cov + extra, np.sqrt(se**2 + np.clip(np.diag(extra), 0, None))


def _refine_static(
    series, vf, acc, mask, dyn: _Stage, stage1: _Stage, gravity, method, seed, max_evals, cluster_n
):
    """The regression again, with LuGre's friction along the measured motion (module notes).

    ``u - F_LuGre(vf; sigma_0, sigma_1, static) = J qdd - p_x cos q + p_y sin q`` on the
    regression's samples, where ``F_LuGre`` is :func:`fricid.models.lugre.simulate` along the
    filtered velocity from the steady state at the first sample, with sigma_0 and sigma_1
    held at the simulation route's estimate ``dyn``; the static part (sigma_2 and the
    Stribeck parameters) starts from ``stage1`` (in ``stribeck`` order and names, then J, p_x,
    p_y). The uncertainty of sigma_0 and sigma_1 is carried in by :func:`_two_step`.
    """
    t0 = time.perf_counter()
    y = series.torque[mask]
    q = series.position[mask]
    cols = [acc[mask]] + ([-np.cos(q), np.sin(q)] if gravity == "fit" else [])
    Phi = np.column_stack(cols)
    nd = Phi.shape[1]
    Qphi, _ = np.linalg.qr(Phi)
    v = np.ascontiguousarray(vf)
    d = 5  # stribeck's tau_c, tau_s, w_s, tau_v, delta

    def lugre_theta(P, du):
        P = np.atleast_2d(P)
        th = np.empty((len(P), 7))
        th[:, 0:2] = 10.0 ** np.asarray(du, dtype=float)
        th[:, 2:7] = P[:, [3, 0, 1, 2, 4]]  # sigma_2 = tau_v, then the Stribeck curve
        return th

    dyn_u = np.log10(dyn.values)

    def friction(P, du=None):
        th = lugre_theta(P, dyn_u if du is None else du)
        z0 = np.sign(v[0]) * lugre.stribeck_curve(th, v[:1])[:, 0] / th[:, 0]
        F, _ = lugre.simulate(th, v, series.dt, z0)
        return np.atleast_2d(F)[:, mask]

    def projected(P):
        R = y[None, :] - friction(P)
        return R - (R @ Qphi) @ Qphi.T

    bounds = stage1.bounds[:d]
    x0 = np.clip(stage1.values[:d], bounds[:, 0], bounds[:, 1])
    search = ResidualProblem(projected, bounds, stage1.names[:d], y)
    result = _run(search, method, x0, seed, max_evals, 1)
    theta = np.asarray(result.x, dtype=float)
    c = np.linalg.lstsq(Phi, y - friction(theta)[0], rcond=None)[0]

    def full(P):
        P = np.atleast_2d(P)
        return y[None, :] - friction(P[:, :d]) - P[:, d:] @ Phi.T

    p_hat = np.concatenate([theta, c])
    Jm, r0 = jacobian(full, p_hat)
    labels = blocks(series.time.size, cluster_n)[mask]
    cov, se, g = cluster_covariance(Jm, r0, labels)

    def shifted(U):
        base = y - Phi @ p_hat[d:]
        return np.vstack([base - friction(theta, u)[0] for u in np.atleast_2d(U)])

    J21, _ = jacobian(shifted, dyn_u)
    cov, se = _two_step(Jm, J21, dyn.cov, cov, se)
    box = np.vstack([bounds, np.column_stack([np.full(nd, -np.inf), np.full(nd, np.inf)])])
    tq = _t975(g - 1)
    low = np.maximum(p_hat - tq * se, box[:, 0])
    high = np.minimum(p_hat + tq * se, box[:, 1])
    names = list(stage1.names[:d]) + list(JOINT_PARAMS[:nd])
    rms = {"torque": float(np.sqrt(np.mean(r0**2)))}
    seconds = time.perf_counter() - t0
    return _Stage(names, p_hat, se, low, high, cov, result, seconds, g, rms, box, search)


def _sim_bounds(
    free_names: list[str], w: _Windows, stage1: _Stage, names_full: dict[str, str]
) -> np.ndarray:
    """Search box of the simulation route over ``free_names`` on the windows ``w``, in its
    coordinates (log10 for sigma_0, sigma_1)."""
    out = []
    by_name = {
        names_full.get(n, n): (v, b)
        for n, v, b in zip(stage1.names, stage1.values, stage1.bounds, strict=True)
    }
    for n in free_names:
        if n == "sigma_0":
            out.append((2.0, 7.0))
        elif n == "sigma_1":
            out.append((-3.0, 3.0))
        elif n == "inertia":
            v = max(by_name[n][0], 1e-6)
            out.append((0.2 * v, 5.0 * v))
        elif n in ("p_x", "p_y"):
            v = by_name[n][0]
            half = max(0.5 * abs(v), 0.05 * float(np.max(np.abs(w.tau))))
            out.append((v - half, v + half))
        else:
            out.append(tuple(by_name[n][1]))
    return np.array(out, dtype=float)
