"""LuGre on some joints of a whole-arm identification ([CW95] eq. 2-4, its Stribeck curve the
BAS-RBFNN paper's eq. 2 with the RWSAVSBAS paper's exponent, eq. 7).

Two stages, the classic order of LuGre identification ([CW95] section IV): the arm is first
identified with each LuGre joint at its steady state (the ``stribeck`` family, which LuGre is
at constant velocity), which gives the base inertial parameters ``beta`` and the start; then
each LuGre joint's seven parameters by the equation error of its own torque on *every* row
(the slow rows and reversals the static fit may leave out are where the bristles show)::

    L(tau_j) - L(Y_b,j) beta = L(F_LuGre(theta; v_j)) + a_j L(d tau_j)

``L`` what the torque went through (:meth:`._signals.ArmSignals.parallel`); ``F_LuGre`` at the
sample instants, as the regressor is (:func:`friction_at_samples`: the bristle state stepped
exactly over each period at the period's mean velocity; friction taken as period means lagged
the regressor by half a sample, which left a misfit of 0.4 times the filtered noise on the
open-loop truth); the velocity the position through the cut-off's low-pass
(:func:`bristle_velocity`: through the wider band the static columns use, the encoder's steps
biased the bristles, whose travel is a few counts); ``a_j`` a change of the torque's delay, a
nuisance projected out (the stand-in's delay takes some of the bristles' lag). A joint's
friction enters its own torque only, so each LuGre joint is one problem of seven parameters.
sigma_0 and sigma_1 are searched as log10 in the single-joint route's box
(:data:`.._filtered.LOG_BOX`), from the best starts of a grid (sigma_0, w_s, delta) by
``scipy.optimize.least_squares`` within bounds.

Intervals: tau_c's and sigma_2's from the covariance of the joint's rows with the filter's own
correlation and the residuals' (:func:`._solve.arm_covariance`) and ``beta``'s uncertainty
carried in (Murphy and Topel 1985: ``+ G cov(beta) G'``, ``G`` the estimate's sensitivity to
``beta``). sigma_0, sigma_1, tau_s, w_s and delta trade against each other at a reversal,
where the low-pass (some hertz) smooths what happens in milliseconds; their intervals are the
profile likelihood's (:mod:`._lugre_profile`), each the projection of the five's joint 95 %
region (chi-square with :data:`PROFILE_DOF` degrees of freedom, scaled by what the correlated
rows and ``beta`` add). Each parameter's own profile (one degree of freedom) covered the truth
in 73-80 % of the seeds for sigma_0, tau_s and w_s with a Stribeck velocity of 0.03 rad/s
(``benchmarks/bench_arm_lugre.py --law e``, 15 determined of 20), while 95-100 % at 0.08.

The Stribeck velocity must be resolved. With a Stribeck velocity of 0.008 rad/s and sigma_0 =
1e5 N m/rad (``--law c``), which the joint crosses in milliseconds at a reversal, the
one-degree profiles of sigma_0, tau_s and w_s covered the truth in 55-60 % of 20 seeds: the rise
is seen only as an impulse there. Those fits all had a w_s interval reaching the box's lower
end or spanning more than a factor of 30 (:data:`W_S_SPAN`), while at 0.08 rad/s (laws ``a``
and ``b``, 50 seeds) the widest spanned 14.7: beyond it sigma_0, sigma_1, tau_s, w_s and
delta are reported not determined (:func:`_unresolved_rise`). Both choices were made on laws
``a``, ``b``, ``c`` and ``e``; law ``f`` and the closed-loop truth (``--truth sim``) check them.

A parameter at its search box's edge (:data:`EDGE_DECADES`), or whose profile stays flat to
both ends of the box, is not determined; one flat on one side is not bounded there, its
interval ending at the box.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.optimize
import scipy.stats

from ....models import get_model, lugre
from .._filtered import LOG_BOX
from ._friction import DELTA_BOX, W_S_BOX
from ._lugre_profile import Better, grid_interval, profile_interval
from ._records import interval
from ._signals import ArmSignals, _filt
from ._solve import Stack, arm_covariance

__all__ = ["LUGRE", "STAND_IN", "LuGreJoint", "fit_lugre_joint", "lugre_stage", "stand_ins"]

LUGRE = "lugre"
#: The family each LuGre joint takes in the first stage: LuGre's steady state.
STAND_IN = "stribeck"
#: The grid of log10 sigma_0 the search starts from.
GRID = np.arange(LOG_BOX["sigma_0"][0], LOG_BOX["sigma_0"][1] + 1e-9, 0.5)
#: ... with these Stribeck shapes (the stand-in's may be a wrong valley's: its slow rows
#: left out), each start's cost evaluated, the best :data:`LOCAL_SEARCHES` searched locally.
W_S_GRID = (0.01, 0.03, 0.1, 0.3)
DELTA_GRID = (1.0, 2.0)
LOCAL_SEARCHES = 4
#: A log-searched parameter within this many decades of its box's edge is not determined.
EDGE_DECADES = 0.05
#: The parameters whose intervals are their profiles' (:mod:`._lugre_profile`): sigma_0,
#: sigma_1, tau_s, w_s, delta; tau_c and sigma_2 enter about linearly (Wald's).
PROFILED = (1, 0, 4, 5, 6)
#: A Stribeck velocity whose 95 % interval spans more than this factor is not resolved:
#: then the bristles' and the rise's parameters are not determined (:func:`_unresolved_rise`).
W_S_SPAN = 30.0
#: Degrees of freedom of the profiles' threshold: the five weakly identified parameters
#: (sigma_0, sigma_1, tau_s, w_s, delta), each interval the projection of their joint 95 %
#: region (module notes).
PROFILE_DOF = 5
#: The grid [decades] of sigma_0's and sigma_1's profiles.
GRID_STEP = 1.0
#: Searches restarted from a profile point that fits better, at most (then the profiles are
#: taken about the best point found: :mod:`._lugre_profile`).
MAX_RESTARTS = 3
#: The most residual evaluations of the local search.
MAX_EVALS = 400

_NAMES = lugre.PARAM_NAMES  # sigma_0, sigma_1, sigma_2, tau_c, tau_s, w_s, delta
_LOG = (0, 1)
_LEVELS = ("sigma_2", "tau_c", "tau_s")


def stand_ins(joints: tuple[str, ...], friction: Any) -> tuple[Any, list[str]]:
    """``friction`` with every ``lugre`` replaced by :data:`STAND_IN`, and the LuGre joints."""
    if isinstance(friction, str):
        if friction.strip().lower() == LUGRE:
            return STAND_IN, list(joints)
        return friction, []
    if isinstance(friction, Mapping):
        lug = [j for j, f in friction.items() if str(f).strip().lower() == LUGRE]
        return {j: (STAND_IN if j in lug else f) for j, f in friction.items()}, lug
    return friction, []


def friction_at_samples(theta: np.ndarray, v: np.ndarray, dt: float) -> np.ndarray:
    """LuGre's friction at the sample instants of the velocity ``v`` (n,) sampled every ``dt``
    seconds (module notes): the bristle state stepped exactly over each period at the
    period's mean velocity (:func:`fricid.models.lugre.simulate`), from the steady state at
    the first sample; the friction from that state and the sample's own velocity."""
    s0, s1, s2 = theta[0], theta[1], theta[2]
    mid = np.empty_like(v)
    mid[0] = v[0]
    mid[1:] = 0.5 * (v[1:] + v[:-1])
    g = lugre.stribeck_curve(theta, v)
    _, z = lugre.simulate(theta, mid, dt, math.copysign(1.0, v[0]) * g[0] / s0)
    return s0 * z + s1 * (v - s0 * np.abs(v) * z / g) + s2 * v


def _theta(x: np.ndarray) -> np.ndarray:
    theta = np.array(x, dtype=float)
    theta[list(_LOG)] = 10.0 ** theta[list(_LOG)]
    return theta


def bristle_velocity(sig: ArmSignals, j: int) -> np.ndarray:
    """Joint ``j``'s velocity at the log's rate through the cut-off's low-pass (module notes):
    the position through the low-pass, differentiated. A wider band lets the encoder's steps
    in, and the bristles, whose whole travel is a few counts, turn that noise into a bias."""
    if sig.wide_position is None:
        return sig.full_dq[:, j]
    position = _filt(sig.low_pass, sig.wide_position[:, j : j + 1])[:, 0]
    return np.gradient(position) * sig.rate


def filtered_friction(
    theta: np.ndarray, sig: ArmSignals, j: int, v: np.ndarray | None = None
) -> np.ndarray:
    """Joint ``j``'s LuGre friction along ``sig``'s motion (velocity ``v``, default
    :func:`bristle_velocity`) through the torque's filters, at the kept rows."""
    v = bristle_velocity(sig, j) if v is None else v
    return sig.parallel(friction_at_samples(theta, v, 1.0 / sig.rate))


def _start(entry: dict[str, Any]) -> np.ndarray:
    """The steady state from the stand-in's record (defaults where it has no number)."""
    rec = entry["parameters"]

    def value(name: str, default: float) -> float:
        x = rec.get(name, {}).get("value")
        return float(x) if x is not None and np.isfinite(x) else default

    tau_c = max(value("tau_c", 0.1), 1e-3)
    tau_s = max(value("tau_s", tau_c), tau_c)
    w_s = float(np.clip(value("w_s", 0.05), *W_S_BOX))
    delta = float(np.clip(value("delta", 1.0), *DELTA_BOX))
    return np.array([np.nan, np.nan, max(value("tau_v", 0.0), 0.0), tau_c, tau_s, w_s, delta])


def _sigma_1(x: np.ndarray) -> float:
    """log10 sigma_1 as :func:`fricid.sim.robot_lugre.lugre_like` sets it, in the box."""
    s0, s2, tau_c, tau_s = 10.0 ** x[0], x[2], x[3], x[4]
    bound = 4.0 * s2 * tau_c / (tau_s - tau_c) if tau_s > tau_c else np.inf
    s1 = min(0.5 * bound, 0.02 * math.sqrt(s0))
    return float(np.clip(math.log10(max(s1, 1e-300)), *LOG_BOX["sigma_1"]))


def _bounds() -> tuple[np.ndarray, np.ndarray]:
    lo = [LOG_BOX["sigma_0"][0], LOG_BOX["sigma_1"][0], 0.0, 1e-6, 1e-6, W_S_BOX[0], DELTA_BOX[0]]
    hi = [LOG_BOX["sigma_0"][1], LOG_BOX["sigma_1"][1], np.inf, np.inf, np.inf, *W_S_BOX[1:]]
    hi.append(DELTA_BOX[1])
    return np.array(lo), np.array(hi)


@dataclass
class LuGreJoint:
    """One LuGre joint's second stage: its parameters (:data:`fricid.models.lugre.PARAM_NAMES`
    order), their records as the arm fit file keeps them, its noise and what was done."""

    joint: str
    index: int
    theta: np.ndarray
    records: dict[str, dict[str, Any]]
    noise: float
    provenance: dict[str, Any] = field(default_factory=dict)

    def predict(self, sig: ArmSignals) -> np.ndarray:
        """The joint's filtered LuGre friction along ``sig``'s motion (the kept rows), with
        the change of its torque's delay (``provenance["delay_change"]``, samples)."""
        change = self.provenance.get("delay_change", 0.0)
        return filtered_friction(self.theta, sig, self.index) + change * sig.dtau[:, self.index]

    def reasons(self) -> list[str]:
        """What the joint's verdict should say beyond its parameters' records."""
        margin = self.provenance.get("passivity_margin", 0.0)
        if margin >= 0:
            return []
        return [
            "the LuGre estimate is not passive (sigma_1 above 4 sigma_2 tau_c / (tau_s - "
            f"tau_c) by {-margin:.3g} N m s/rad): simulated with it, the joint can gain energy "
            "at low speed"
        ]

    def entry(self, stand_in: dict[str, Any]) -> dict[str, Any]:
        """The joint's friction entry of the fit file, replacing the stand-in's."""
        out = {k: v for k, v in stand_in.items() if k not in ("family", "parameters")}
        return {"family": LUGRE, "parameters": self.records, **out}


def fit_lugre_joint(
    sig: ArmSignals,
    Yb: np.ndarray,
    beta: np.ndarray,
    cov_beta: np.ndarray,
    j: int,
    joint: str,
    stand_in: dict[str, Any],
    rho: np.ndarray,
    noise: float,
) -> LuGreJoint:
    """Joint ``j``'s LuGre parameters given the arm's ``beta`` (module notes).

    ``Yb`` the filtered base regressor (N, n, r), ``cov_beta`` beta's covariance,
    ``stand_in`` the joint's record from the first stage, ``rho`` the filters' correlation
    (:func:`._filter_cov.filter_correlation`), ``noise`` the joint's noise from the first stage
    (the residuals' scale)."""
    timing = sig.dtau[:, j] / np.linalg.norm(sig.dtau[:, j])  # the torque's delay, a nuisance
    target = sig.tau[:, j] - Yb[:, j, :] @ beta
    scale = noise if np.isfinite(noise) and noise > 0 else float(np.std(target)) or 1.0

    v = bristle_velocity(sig, j)

    def residual(x: np.ndarray) -> np.ndarray:
        r = (target - filtered_friction(_theta(x), sig, j, v)) / scale
        return r - timing * (timing @ r)

    lo, hi = _bounds()
    x0 = _start(stand_in)
    starts = []
    for ls0, w_s, delta in itertools.product(GRID, W_S_GRID, DELTA_GRID):
        x = x0.copy()
        x[0], x[5], x[6] = ls0, w_s, delta
        x[1] = _sigma_1(x)
        r = residual(x)
        starts.append((float(r @ r), x))
    starts.sort(key=lambda s: s[0])
    sols = [_search(residual, x, lo, hi) for _, x in starts[:LOCAL_SEARCHES]]
    evaluations = sum(_evaluations(s_) for s_ in sols) + len(starts)
    sol = min(sols, key=lambda s_: float(s_.cost))
    restarts = 0
    for attempt in range(MAX_RESTARTS + 1):
        restart = attempt < MAX_RESTARTS
        x, res, J = sol.x, sol.fun, sol.jac
        m, p = J.shape
        sigma = scale * math.sqrt(float(res @ res) / max(m - p - 1, 1))
        res_w, J_w = res * scale / sigma, J * scale / sigma
        st = Stack(J_w, res_w, np.zeros(m, dtype=int), np.arange(m), [0], 0)
        cov, _, t, *_ = arm_covariance(J_w, res_w, st, 1, rho)
        # beta's uncertainty (Murphy and Topel 1985): d x / d beta = (J'J)^-1 J' Y_b,j / sigma
        Y = Yb[:, j, :] / sigma
        G = np.linalg.lstsq(J_w, Y - np.outer(timing, timing @ Y), rcond=None)[0]
        cov = cov + G @ cov_beta @ G.T
        se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
        naive = np.diag(np.linalg.pinv(J_w.T @ J_w))
        q = float(scipy.stats.chi2.ppf(0.95, PROFILE_DOF))
        try:
            ends = {}
            for k in PROFILED:
                inflation = cov[k, k] / naive[k] if naive[k] > 0 else 1.0
                inflation = float(inflation) if np.isfinite(inflation) else 1.0
                limit = q * max(inflation, 1.0) * (sigma / scale) ** 2
                if k in _LOG:  # long flat valleys: the whole box (._lugre_profile)
                    grid = np.arange(lo[k], hi[k] + 1e-9, GRID_STEP)
                    low, high, calls = grid_interval(residual, x, k, grid, limit, lo, hi, restart)
                else:
                    half = t * se[k] if np.isfinite(se[k]) and se[k] > 0 else 0.1
                    low, high, calls = profile_interval(
                        residual, x, k, half, limit, lo, hi, restart
                    )
                ends[k] = (low, high)
                evaluations += calls
            break
        except Better as better:  # another valley, lower: search from there
            restarts += 1
            sol = _search(residual, better.x, lo, hi)
            evaluations += _evaluations(sol)
    theta = _theta(x)
    units = {p_.name: p_.unit for p_ in get_model(LUGRE).parameters}
    records = {
        name: _record(name, k, x, se, t, lo, hi, ends, units.get(name, ""), sig.cutoff)
        for k, name in enumerate(_NAMES)
    }
    _unresolved_rise(records, lo[5])
    _untold_viscous(records)
    provenance = {
        "stage": "equation error given the arm's base parameters, every row",
        "start_sigma_0": float(10.0 ** starts[0][1][0]),
        "evaluations": evaluations,
        "restarts": restarts,
        "status": int(sol.status),
        "passivity_margin": float(lugre.passivity_margin(theta)),
        "rows": int(m),
        "delay_change": float(
            timing @ (target - filtered_friction(theta, sig, j, v)) / np.linalg.norm(sig.dtau[:, j])
        ),
    }
    return LuGreJoint(joint, j, theta, records, float(sigma), provenance)


def _evaluations(sol) -> int:
    """The residual evaluations of a scipy least-squares search, its finite-difference
    Jacobians' included (its ``nfev`` leaves them out)."""
    return int(sol.nfev) + int(sol.njev or 0) * int(sol.x.size)


def _search(residual, x, lo, hi):
    return scipy.optimize.least_squares(
        residual,
        np.clip(x, lo, hi),
        bounds=(lo, hi),
        x_scale="jac",
        max_nfev=MAX_EVALS,
        ftol=1e-12,
        xtol=1e-10,
        gtol=1e-12,
    )


def _record(name, k, x, se, t, lo, hi, ends, unit, cutoff) -> dict[str, Any]:
    """Parameter ``k``'s record: the profile interval where there is one (``ends``), else
    the Wald interval; not determined at the box's edge, open both ways, or unbounded."""
    value, s = float(x[k]), float(se[k])
    log = k in _LOG
    scale = (lambda u: 10.0**u) if log else (lambda u: u)
    nd = ""
    if not np.isfinite(s):
        nd = "not determined: the data do not inform it"
    elif k in ends:
        if log or name == "w_s":  # in decades
            at = value if log else math.log10(value)
            low, high = (lo[k], hi[k]) if log else (math.log10(lo[k]), math.log10(hi[k]))
            edge = min(at - low, high - at) < EDGE_DECADES
        else:
            edge = value - lo[k] < 1e-3 * (hi[k] - lo[k] if np.isfinite(hi[k]) else 1.0)
            edge |= np.isfinite(hi[k]) and hi[k] - value < 1e-3 * (hi[k] - lo[k])
        a, b = ends[k]
        if edge:
            nd = f"not determined: at the search box's edge ({_span(name, lo[k], hi[k], k)})"
        elif a is None and b is None:
            nd = "not determined: its profile stays flat to both ends of the search box"
    elif name in _LEVELS and value - t * s < 0:
        nd = "not determined: its 95 % interval reaches below zero"
    if nd:
        if k in _LOG:
            nd += f"; the low-pass at {cutoff:.3g} Hz smooths the bristles' transient at reversals"
        return _undetermined(unit, nd)
    v = scale(value)
    stderr = v * math.log(10.0) * s if log else s
    if k not in ends:
        return {"value": v, "unit": unit, "stderr": stderr, "ci95": interval(v, stderr, t),
                "not_determined": False, "note": ""}  # fmt: skip
    a, b = ends[k]
    note = "interval from the profile likelihood"
    if a is None or b is None:
        side = "below" if a is None else "above"
        note = f"not bounded by the data {side}: the interval ends at the search box's end"
    ci = [scale(lo[k] if a is None else a), scale(hi[k] if b is None else b)]
    if not np.isfinite(ci[1]):
        ci[1] = None
    return {"value": v, "unit": unit, "stderr": stderr, "ci95": ci, "not_determined": False,
            "note": note}  # fmt: skip


def _unresolved_rise(records: dict[str, dict[str, Any]], w_s_low: float) -> None:
    """The bristles and the Stribeck rise not determined where the Stribeck velocity is not
    resolved (module notes): its interval reaching the search box's lower end or spanning
    more than :data:`W_S_SPAN` times."""
    rec = records["w_s"]
    low, high = rec["ci95"]
    if rec["value"] is not None and low > w_s_low * (1 + 1e-9) and (high or 1.0) < W_S_SPAN * low:
        return
    span = "" if rec["value"] is None else f" (95 % interval {low:.3g}-{high or 1.0:.3g} rad/s)"
    why = (
        f"not determined: the Stribeck velocity is not resolved by the data{span}; below it "
        "the bristles and the Stribeck rise trade against each other, and their intervals "
        "there were measured to miss (module notes)"
    )
    for name in ("sigma_0", "sigma_1", "tau_s", "w_s", "delta"):
        records[name] = _undetermined(records[name]["unit"], why)


def _untold_viscous(records: dict[str, dict[str, Any]]) -> None:
    """tau_c not determined where sigma_2 is not: the search holds sigma_2 at zero, and the
    Coulomb level then takes what the viscous term would (a tight interval about a biased
    level, measured on a PD-tracked light arm that stuck at more than half its samples:
    tau_c 27 % high, six standard errors from the truth)."""
    if not records["sigma_2"]["not_determined"] or records["tau_c"]["not_determined"]:
        return
    records["tau_c"] = _undetermined(
        records["tau_c"]["unit"],
        "not determined: the viscous level sigma_2 is not, and the Coulomb level takes what the "
        "viscous term would",
    )


def _undetermined(unit: str, note: str) -> dict[str, Any]:
    """A parameter's record when the data do not determine it: no value, the reason."""
    return {"value": None, "unit": unit, "stderr": None, "ci95": [None, None],
            "not_determined": True, "note": note}  # fmt: skip


def _span(name: str, lo: float, hi: float, k: int) -> str:
    if k in _LOG:
        return f"{name} from 1e{lo:g} to 1e{hi:g}"
    return f"{name} from {lo:g} to {hi:g}"


def lugre_stage(sig, Yb, beta, cov_beta, names, joints, fric, sigma, rho) -> dict[int, LuGreJoint]:
    """The second stage of every LuGre joint in ``names`` (module notes): each joint's record
    in ``fric`` and noise in ``sigma`` replaced by its LuGre fit's; joint index -> its fit."""
    out: dict[int, LuGreJoint] = {}
    for name in names:
        j = joints.index(name)
        lj = fit_lugre_joint(sig, Yb, beta, cov_beta, j, name, fric[name], rho, float(sigma[j]))
        fric[name] = lj.entry(fric[name])
        sigma[j] = lj.noise
        out[j] = lj
    return out
