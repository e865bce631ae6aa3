"""Parameter uncertainty from the Jacobian at the optimum, as scipy's ``curve_fit`` computes it.

The covariance is ``s^2 (J^T J)^+`` with ``s^2 = SSE / (n - p)`` and the pseudo-inverse taken
through the singular value decomposition of ``J`` itself (never ``J^T J``, which would square
its condition number), dropping singular values below ``eps * max(J.shape) * s[0]`` (scipy's
``curve_fit``). ``J``'s columns are scaled to unit length first (as MINPACK scales its
variables), so that the cut-off measures collinearity, not the parameters' units; the
covariance is scaled back (for a full-rank ``J`` this is exactly ``s^2 (J^T J)^-1``).

A parameter is *not determined* (standard error NaN) when its direction is not within the
span of the singular vectors whose singular values exceed :data:`DETERMINED_RCOND` times the
largest: a finite-difference Jacobian is accurate to about 1e-9 relative, so a direction the
data cannot see shows a singular value of that size rather than one below scipy's cut-off.
:func:`null_directions` says which combination of parameters is free.

:func:`assess` is what ``fit`` reports (issue 11, defects 5 and 7): no interval at all for a
fit that did not converge or for a degenerate optimum (a rank-deficient Jacobian: the
linearised intervals there, such as ``Coulomb 2e-10 +- 210 N m``, mean nothing); otherwise
profile-likelihood intervals inside the search box (:mod:`fricid.identify.static.profile`) for up
to :data:`PROFILE_AUTO_MAX` free parameters (or when asked: then every side is profiled by
re-fits; by default only the sides where the quadratic approximation fails at the Jacobian
interval's ends, near a bound or for a poorly determined parameter,
:mod:`fricid.identify.static.curvature`, the others taking its checked ends), else the
Jacobian's Wald intervals cut at the box with the cut sides flagged; each side that reaches a
bound other than zero is named in an :class:`~fricid.errors.IdentifiabilityWarning`, with the
parameter's strongest correlation.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from .shared_error import propagate

__all__ = [
    "INTERVALS",
    "PROFILE_AUTO_MAX",
    "Uncertainty",
    "assess",
    "covariance_svd",
    "floored_covariance",
    "jacobian",
    "jacobian_uncertainty",
    "null_directions",
]

#: The interval methods of :func:`assess`: ``auto`` (profile for at most
#: :data:`PROFILE_AUTO_MAX` free parameters, re-fitted only on the sides the quadratic
#: approximation misses, else Jacobian), ``profile`` (every side re-fitted), ``jacobian``,
#: ``none``.
INTERVALS = ("auto", "profile", "jacobian", "none")

#: ``intervals="auto"`` profiles fits with at most this many free parameters (re-fitting
#: every side took about 0.2 s for the Stribeck model's five on 30 samples, eight parameters of
#: ``vlt`` seconds; the sides the quadratic approximation passes cost no re-fit).
PROFILE_AUTO_MAX = 5

#: A correlation at least this strong is named as the reason a parameter is not bounded.
STRONG_CORREL = 0.9

#: A parameter counts as determined when at least ``1 - DETERMINED_TOL`` of its unit vector's
#: squared length lies in the span of the right singular vectors (of the column-scaled
#: Jacobian) with singular values above ``DETERMINED_RCOND * s[0]``.
DETERMINED_TOL = 1e-6
DETERMINED_RCOND = 1e-6


def jacobian(
    residual: Callable[[np.ndarray], np.ndarray], theta: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Central-difference Jacobian ``(n, p)`` of a batch residual ``(k, p) -> (k, n)`` at
    ``theta (p,)``, in one batch call; also returns the residual at ``theta``."""
    p = theta.size
    h = 1e-6 * np.maximum(np.abs(theta), 1e-3)
    steps = np.vstack([theta + np.diag(h), theta - np.diag(h)])
    r = residual(np.vstack([theta[None, :], steps]))
    r0, rp, rm = r[0], r[1 : p + 1], r[p + 1 :]
    return ((rp - rm) / (2 * h[:, None])).T, r0


def covariance_svd(J: np.ndarray, s2: float) -> tuple[np.ndarray, np.ndarray]:
    """``s2 (J^T J)^+`` by the SVD of ``J`` (scipy ``curve_fit``'s cut-off), and a mask of the
    parameters it determines.

    Parameters
    ----------
    J : ndarray (n, p)
        Jacobian of the residuals.
    s2 : float
        Residual variance.

    Returns
    -------
    cov : ndarray (p, p)
        Covariance; rows and columns of undetermined parameters are NaN.
    determined : ndarray of bool (p,)
    """
    p = J.shape[1]
    if not np.isfinite(J).all():
        return np.full((p, p), np.nan), np.zeros(p, dtype=bool)
    norms = np.linalg.norm(J, axis=0)
    norms[norms == 0] = 1.0  # a parameter without effect: a zero column, singular value 0
    _, s, VT = np.linalg.svd(J / norms, full_matrices=False)
    if s.size == 0 or s[0] == 0:
        return np.full((p, p), np.nan), np.zeros(p, dtype=bool)
    keep = s > np.finfo(float).eps * max(J.shape) * s[0]
    cov = s2 * ((VT[keep].T / s[keep] ** 2) @ VT[keep]) / np.outer(norms, norms)
    seen = VT[s > DETERMINED_RCOND * s[0]]
    determined = np.sum(seen**2, axis=0) >= 1.0 - DETERMINED_TOL
    cov[~determined, :] = np.nan
    cov[:, ~determined] = np.nan
    return cov, determined


def floored_covariance(
    cov: np.ndarray, plain_var: np.ndarray, determined: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A robust (sandwich) covariance never below the plain one: each variance raised to
    ``plain_var`` where that is larger, the correlations kept, and NaN rows and columns for
    the parameters not ``determined``. Returns (cov, stderr)."""
    with np.errstate(invalid="ignore"):
        var = np.maximum(np.diag(cov), plain_var)
        se = np.where(determined, np.sqrt(np.clip(var, 0, None)), np.nan)
        d = np.sqrt(np.clip(np.diag(cov), 0, None))
        cov = cov / np.outer(d, d) * np.outer(se, se)
    cov[~determined, :] = np.nan
    cov[:, ~determined] = np.nan
    return cov, se


def jacobian_uncertainty(
    residual: Callable[[np.ndarray], np.ndarray], theta: np.ndarray, n_obs: int
) -> tuple[np.ndarray, np.ndarray | None]:
    """Standard errors and covariance of ``theta`` from a central-difference Jacobian.

    Parameters
    ----------
    residual : callable
        Batch residuals ``(k, p) -> (k, n)``.
    theta : ndarray (p,)
        The optimum.
    n_obs : int
        Number of observations n.

    Returns
    -------
    stderr : ndarray (p,)
        NaN for a parameter the data do not determine (see :func:`covariance_svd`).
    cov : ndarray (p, p) or None
        None when there are no spare observations (``n <= p``) or nothing is determined.
    """
    p = theta.size
    nan = np.full(p, np.nan)
    dof = n_obs - p
    if p == 0 or dof <= 0:
        return nan, None
    J, r0 = jacobian(residual, theta)
    cov, determined = covariance_svd(J, float(r0 @ r0) / dof)
    if not determined.any():
        return nan, None
    return np.where(determined, np.sqrt(np.clip(np.diag(cov), 0.0, None)), np.nan), cov


def null_directions(J: np.ndarray, names: list[str]) -> list[str]:
    """The parameter combinations a Jacobian ``(n, p)`` cannot see, in words.

    A zero column is "``name`` has no effect"; another direction of a singular value below
    :data:`DETERMINED_RCOND` times the largest (columns scaled to unit length) is listed by its
    components above 0.1, e.g. "``tau_s`` (+0.71) and ``delta`` (-0.70) trade off".
    """
    if not np.isfinite(J).all():
        return ["the Jacobian is not finite"]
    norms = np.linalg.norm(J, axis=0)
    out = [f"{n} has no effect" for n, c in zip(names, norms, strict=True) if c == 0]
    live = norms > 0
    if live.sum() == 0:
        return out
    sub = [n for n, keep in zip(names, live, strict=True) if keep]
    _, s, VT = np.linalg.svd(J[:, live] / norms[live], full_matrices=False)
    for k in np.flatnonzero(s <= DETERMINED_RCOND * s[0]):
        v = VT[k] * np.sign(VT[k][np.argmax(np.abs(VT[k]))])
        parts = [f"{n} ({c:+.2f})" for n, c in zip(sub, v, strict=True) if abs(c) > 0.1]
        out.append(" and ".join(parts) + " trade off (a free combination)")
    return out


@dataclass
class Uncertainty:
    """What :func:`assess` found, per free parameter (arrays in free-parameter order).

    Attributes
    ----------
    stderr : ndarray (p,)
        Standard errors (Jacobian); NaN where there is no meaningful one.
    ci95 : ndarray (p,)
        The Jacobian's 95 % half-width ``t se``; NaN where there is no interval.
    low, high : ndarray (p,)
        The 95 % interval's ends, inside the search box; NaN where there is no interval.
    open : ndarray of bool (p, 2)
        Lower and upper side reach the bound (the data do not bound that side).
    cov : ndarray (p, p) or None
    method : str
        ``"profile"``, ``"jacobian"`` or ``""`` (no intervals).
    notes : dict of str to str
        Why a parameter has no interval, or why a side is open.
    identifiability : list of str
        One clause per parameter the data do not determine or bound ("do not determine ...",
        "do not bound ..."), for the warning.
    lower_sse : float
        The lowest SSE a profile re-fit found (below the fit's: not at the optimum), or NaN.
    shared : ndarray (p,) or None
        The share of each variance that comes from an error the samples share
        (:mod:`fricid.identify.static.shared_error`), or None when there is none.
    shared_cov : ndarray (p, p) or None
        That shared error's covariance of the free parameters (part of ``cov``), for the
        prediction interval, which adds it apart from the noise's share.
    """

    stderr: np.ndarray
    ci95: np.ndarray
    low: np.ndarray
    high: np.ndarray
    open: np.ndarray
    cov: np.ndarray | None = None
    method: str = ""
    notes: dict[str, str] = field(default_factory=dict)
    identifiability: list[str] = field(default_factory=list)
    lower_sse: float = float("nan")
    shared: np.ndarray | None = None
    shared_cov: np.ndarray | None = None


def _strongest(cov: np.ndarray | None, j: int, names: list[str]) -> str:
    if cov is None:
        return ""
    d = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
    r = cov[j] / (d[j] * d)
    r[j] = 0.0
    r = np.where(np.isfinite(r), r, 0.0)
    k = int(np.argmax(np.abs(r)))
    if abs(r[k]) < STRONG_CORREL:
        return ""
    return f"; correlated with {names[k]} ({r[k]:+.3f})"


def assess(
    problem,
    x: np.ndarray,
    *,
    converged: bool,
    reason: str = "",
    intervals: str = "auto",
    units: dict[str, str] | None = None,
    shared: np.ndarray | None = None,
    own: np.ndarray | None = None,
) -> Uncertainty:
    """Standard errors and 95 % intervals of a least-squares fit, or why there are none.

    Parameters
    ----------
    problem : IdentificationProblem
        The problem fitted (loss ``sse``).
    x : ndarray (p,)
        The fit's free parameters.
    converged : bool
        False: no standard error and no interval, the note says ``reason``.
    reason : str
        Why the fit did not converge (for the notes).
    intervals : {"auto", "profile", "jacobian", "none"}
        See :data:`INTERVALS`.
    units : dict, optional
        Parameter units, for the messages.
    shared : ndarray (n, n), optional
        The covariance of an error all the samples share, which their residuals cannot show
        (:func:`~fricid.identify.static.shared_error.shared_covariance`): propagated through
        the fit, added to the covariance, and each interval side widened by it in quadrature
        (Welch-Satterthwaite degrees of freedom).
    own : ndarray (n,), optional
        With ``shared``: the samples' own variances known apart from the residuals
        (:func:`~fricid.identify.static.shared_error.own_variance`), propagated and used where
        the residuals show nothing beyond the shared error (a law that fits its few samples
        exactly would otherwise claim no error of its own).

    Returns
    -------
    Uncertainty
    """
    names = problem.free_names
    p = len(names)
    nan = np.full(p, np.nan)
    none = Uncertainty(nan.copy(), nan.copy(), nan.copy(), nan.copy(), np.zeros((p, 2), bool))
    if not converged:
        why = "no interval: the fit did not converge" + (
            " (see the convergence block)" if reason else ""
        )
        none.notes = dict.fromkeys(names, why)
        return none
    dof = problem.n_obs - p
    if dof <= 0:
        none.notes = dict.fromkeys(names, "not determined: no spare samples (n <= p)")
        none.identifiability = [f"do not determine {', '.join(names)} (no spare samples: n <= p)"]
        return none
    J, r0 = jacobian(problem.residuals, x)
    cov, determined = covariance_svd(J, float(r0 @ r0) / dof)
    if not determined.all():
        why = "; ".join(null_directions(J, names)) or "singular Jacobian"
        free = [n for n, ok in zip(names, determined, strict=True) if not ok]
        none.notes = {
            n: (f"not determined: {why}" if not ok else f"no interval: degenerate optimum ({why})")
            for n, ok in zip(names, determined, strict=True)
        }
        none.identifiability = [
            f"do not determine {', '.join(free)} (degenerate optimum: {why}; no interval)"
        ]
        return none
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    half = se * float(stats.t.ppf(0.975, dof))
    lo_b, hi_b = problem.bounds[:, 0], problem.bounds[:, 1]
    out = Uncertainty(se, half, nan.copy(), nan.copy(), np.zeros((p, 2), bool), cov=cov)
    key = str(intervals).strip().lower()
    if key == "profile" or (key == "auto" and p <= PROFILE_AUTO_MAX):
        _profile(out, problem, x, float(r0 @ r0), checked=key == "auto")
    elif key != "none":
        out.low, out.high = np.maximum(x - half, lo_b), np.minimum(x + half, hi_b)
        out.open = np.column_stack([x - half <= lo_b, x + half >= hi_b])
        out.method = "jacobian"
    if shared is not None:
        w = problem.weights
        extra, seen, known = propagate(J, None if w is None else np.sqrt(w), shared, own)
        sse = float(r0 @ r0)
        share = max(sse - seen, 0.0) / sse if sse > 0 else 0.0
        # the known own variances only where the residuals leave none (they overstate the
        # samples' scatter elsewhere: 97-100 % coverage on bench_arm_sweeps as a floor)
        known = known if share == 0.0 else np.zeros_like(known)
        _add_shared(out, problem, x, extra, (float(stats.t.ppf(0.975, dof)), dof, share, known))
    if key != "none":
        _name_open_sides(out, problem, x, names, units or {})
    return out


def _add_shared(out: Uncertainty, problem, x: np.ndarray, extra: np.ndarray, scale: tuple) -> None:
    """``out`` with the shared error's covariance ``extra`` added. ``scale`` is ``(tq, dof,
    own, known)``: the fit's t point and degrees of freedom, the share of its residual variance
    that is its own (the part of the shared error the residuals do show taken out, so it is not
    counted twice), and each parameter's variance from the samples' known own variances, the
    floor of that part (where it binds, its degrees of freedom are infinite). Each interval
    side, read as ``tq`` times a standard error, becomes ``t_eff`` times that error (scaled by
    ``own``) and the shared one in quadrature, ``t_eff`` with the Welch-Satterthwaite degrees
    of freedom (the shared error comes from a fit of many samples, its own degrees of freedom
    taken as infinite), never shorter than it was; a side cut at the search box is open."""
    tq, dof, own_share, known = scale
    var = np.clip(np.diag(extra), 0.0, None)
    estimated = out.stderr**2 * own_share
    own = np.maximum(estimated, known)
    total = own + var
    with np.errstate(invalid="ignore", divide="ignore"):
        out.shared = np.where(total > 0, var / total, 0.0)
        nu = np.where(estimated > known, dof * (total / estimated) ** 2, np.inf)
    t_eff = np.asarray(stats.t.ppf(0.975, nu), dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(out.stderr > 0, np.sqrt(own) / out.stderr, 0.0)
    alone = np.diag(np.where(out.stderr > 0, 0.0, own))  # no residual-based row: known only
    out.cov = None if out.cov is None else out.cov * np.outer(ratio, ratio) + alone + extra
    out.shared_cov = 0.5 * (extra + extra.T)
    out.stderr = np.sqrt(total)
    out.ci95 = np.maximum(t_eff * out.stderr, out.ci95)
    if not out.method:
        return
    lo_b, hi_b = problem.bounds[:, 0], problem.bounds[:, 1]
    with np.errstate(invalid="ignore", divide="ignore"):
        k = np.where(estimated > 0, own / np.where(estimated > 0, estimated, 1.0), 0.0)
    k = k * own_share / tq**2  # each side's own part, scaled as its variance is
    floor = np.where(estimated > 0, 0.0, own)  # no residual scatter: the known part alone
    low = x - np.maximum(t_eff * np.sqrt((x - out.low) ** 2 * k + floor + var), x - out.low)
    high = x + np.maximum(t_eff * np.sqrt((out.high - x) ** 2 * k + floor + var), out.high - x)
    out.open = out.open | np.column_stack([low <= lo_b, high >= hi_b])
    out.low, out.high = np.maximum(low, lo_b), np.minimum(high, hi_b)


def _profile(out: Uncertainty, problem, x: np.ndarray, sse: float, checked: bool) -> None:
    """``out``'s interval ends by the profile likelihood: with ``checked``, the sides where
    the quadratic approximation holds at the Wald ends take its ends
    (:func:`~fricid.identify.static.curvature.checked_ends`) and only the others are profiled
    by re-fits; else every side is."""
    from .curvature import checked_ends
    from .profile import profile_intervals

    p = x.size
    ends, done, lowest = (
        checked_ends(problem, x, out.cov, sse)
        if checked and out.cov is not None
        else (np.full((p, 2), np.nan), np.zeros((p, 2), bool), sse)
    )
    out.low, out.high = ends[:, 0].copy(), ends[:, 1].copy()
    out.method = "profile"
    out.lower_sse = lowest
    if done.all():
        return
    prof = profile_intervals(problem, x, sides=~done)
    for j, n in enumerate(problem.free_names):
        iv = prof.get(n)
        if iv is None:
            continue
        if not done[j, 0]:
            out.low[j], out.open[j, 0] = iv.low, iv.low_open
        if not done[j, 1]:
            out.high[j], out.open[j, 1] = iv.high, iv.high_open
        out.lower_sse = min(out.lower_sse, iv.lower_sse)


def _name_open_sides(out: Uncertainty, problem, x, names: list[str], units) -> None:
    """Notes and identifiability clauses for the sides that reach a bound. A side open at a
    bound of 0 (friction amplitudes are not negative) means "consistent with zero" and is
    noted; any other open side (the data-scaled search box) means the data do not bound it."""
    for j, n in enumerate(names):
        lo, hi = problem.bounds[j]
        unit = units.get(n, "")
        unit = f" {unit}" if unit not in ("", "1") else ""
        sides = []
        if out.open[j, 0]:
            sides.append((lo, f"{n} >= {lo:.4g}{unit}"))
        if out.open[j, 1]:
            sides.append((hi, f"{n} <= {hi:.4g}{unit}"))
        if not sides:
            continue
        corr = _strongest(out.cov, j, names)
        at = (
            " (the estimate is at the bound)"
            if min(x[j] - lo, hi - x[j]) <= 1e-9 * (hi - lo)
            else ""
        )
        if len(sides) == 2:
            note = (
                f"not identified: the 95 % interval spans the whole search range "
                f"[{lo:.4g}, {hi:.4g}]{unit}{corr}"
            )
        else:
            note = f"reaches the bound {sides[0][1]}{at}{corr}"
        out.notes[n] = note
        if any(b != 0 for b, _ in sides):
            out.identifiability.append(f"do not bound {n} ({note})")
