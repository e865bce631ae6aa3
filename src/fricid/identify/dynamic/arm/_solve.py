"""The whole-arm regression: stacking, weighted least squares, the Stribeck shapes by
variable projection, and covariances that respect correlated residuals.

Rows are one joint at one (decimated) instant, ``(t, j)``; columns are the base inertial
parameters (Gautier 1991; :func:`fricid.robot.base_parameters`) then each joint's friction
(:mod:`._friction`), zero on the other joints' rows. A joint's rows slower than its
velocity threshold, or within a period of the cut-off of such a sample or a reversal, are
left out (``arm._moving``): a joint at rest holds any torque within its static friction, which
no law of velocity says, and the low-pass spreads a reversal over its neighbours.

* Weighted least squares (Gautier and Poignet 2001): each joint's noise ``sigma_j`` is
  estimated from its ordinary least-squares residuals, ``sigma_j^2 = SSE_j / (m_j - p m_j /
  m)``, and its rows are divided by it.
* The Stribeck shapes ``(w_s, delta)`` of each joint and direction are found by variable
  projection (Golub and Pereyra 1973) one block at a time: with every other column fixed, the
  sum of squares with the excess column ``x`` is ``SSE_0 - (x' r_0)^2 / (x' (I - P_0) x)``,
  evaluated for a grid of shapes at once (the current shapes among them, so that no step
  loses), a shape whose best excess ``tau_s - tau_c`` is below zero gaining nothing (the
  Stribeck rise is a static level above the Coulomb one; on a PD-tracked Panda such dips,
  fitted where the closed loop's reversals left no rows, held out at 3 to 8 times the
  noise), and a shape whose best excess is above what the log allows
  (:func:`._friction.excess_cap`) no candidate; the blocks are swept :data:`SWEEPS` times,
  after the first refined by Newton steps over ``(log w_s, delta)`` from the grid's best
  (:func:`_newton`). The directions of a joint are coupled near its reversals (the low-pass
  spreads both over them), so the descent converges slowly along a curved valley;
  noise-free, three sweeps leave the shapes a few per cent to tens of per cent off, and
  :mod:`._polish` then moves all of them (and the torque's delay) together. The final
  solve holds each excess between zero and that cap (:func:`bounded_lstsq`), at zero where
  the fitted rows do not see the rise (:func:`unseen_rises`).
* Covariance (:func:`arm_covariance`): residuals of low-passed signals are correlated over
  about ``1 / f_c``, so 60 000 samples are far fewer independent ones. The correlation length
  ``L`` is the first lag at which the residuals' autocorrelation (averaged over the joints)
  falls below :data:`RHO_END`; the effective sample size per joint is ``m_j / (1 + 2 sum_{k
  <= L} rho_k)``; the covariance is the sandwich of Newey and West (1987) with Bartlett
  weights over :data:`LAGS_OVER_L` ``L`` instants (:func:`hac_covariance`), never below the
  plain estimate. That sandwich alone came out too narrow (the filtered noise stays
  correlated over several periods of the cut-off): the covariance is the one the filter's
  own correlation of white noise gives (:mod:`._filter_cov`), each interval widened to the
  Newey-West one where that is wider. (The cluster-robust sandwich over contiguous blocks
  that :mod:`._data` uses for one joint needs blocks many times ``L`` long and many of them;
  a 15 s log has too few, and its intervals came out too narrow.)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.stats

from ...static.uncertainty import covariance_svd, floored_covariance
from ._filter_cov import filter_covariance
from ._friction import DELTA_BOX, W_S_BOX, JointFriction
from ._signals import ArmSignals
from ._sticks import stick_basis

__all__ = [
    "Stack",
    "arm_covariance",
    "bounded_lstsq",
    "excess_bounds",
    "excess_index",
    "search_shapes",
    "shape_profiles",
    "shape_rows",
    "stack",
    "unseen_rises",
    "wls",
]

#: The largest share of a Stribeck column on the fitted rows leaked in (:func:`unseen_rises`).
LEAK_MAX = 0.5
#: The autocorrelation below which residuals count as uncorrelated.
RHO_END = 0.05
#: The covariance's lags over the correlation length.
LAGS_OVER_L = 5
#: The first grid of Stribeck shapes.
W_S_GRID = np.geomspace(2e-3, 0.6, 14)
DELTA_GRID = np.array([0.5, 0.75, 1.0, 1.5, 2.0, 3.0])
#: ``chi2_1(0.95)``: the profile region's drop of the sum of squares (:func:`shape_profiles`).
CHI2_1 = 3.841458820694124
#: Sweeps over the Stribeck blocks (the first on the grid alone).
SWEEPS = 3
#: Full-rate candidate columns computed at once.
CHUNK = 64
#: Newton's finite-difference step and tolerance in (log w_s, delta), and most iterations.
NEWTON_STEP = 0.01
NEWTON_TOL = 1e-3
NEWTON_ITERATIONS = 30


@dataclass
class Stack:
    """The stacked regression (module notes), each joint's rows with its stick columns
    (:mod:`._sticks`) projected out."""

    A: np.ndarray  # (m, p) unweighted
    y: np.ndarray  # (m,)
    row_joint: np.ndarray  # (m,)
    row_time: np.ndarray  # (m,) index of the decimated instant
    offsets: list[int]  # first friction column of each joint
    n_base: int
    #: each joint's orthonormal basis of its stick columns on its rows (or None)
    bases: list[np.ndarray | None] = field(default_factory=list)

    def weighted(self, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        w = 1.0 / sigma[self.row_joint]
        return self.A * w[:, None], self.y * w

    def _basis(self, j: int) -> np.ndarray | None:
        return self.bases[j] if j < len(self.bases) else None

    def lost(self, j: int) -> int:
        """The degrees of freedom joint ``j``'s stick columns take."""
        Q = self._basis(j)
        return 0 if Q is None else Q.shape[1]

    def project(self, j: int, X: np.ndarray) -> np.ndarray:
        """``X`` (rows of joint ``j``, in the stack's order) with its stick columns out."""
        Q = self._basis(j)
        return X if Q is None else X - Q @ (Q.T @ X)

    def residualise(self, X: np.ndarray) -> np.ndarray:
        """``X`` (the stack's rows) with each joint's stick columns out."""
        out = np.array(X, dtype=float, copy=True)
        for j in range(len(self.bases)):
            rows = np.flatnonzero(self.row_joint == j)
            out[rows] = self.project(j, out[rows])
        return out


def friction_block(sig: ArmSignals, jf: JointFriction, j: int) -> np.ndarray:
    """Joint ``j``'s friction columns at the log's rate, parallel-filtered and decimated."""
    return sig.parallel(sig.friction_columns(jf, j))


def stack(
    Yb: np.ndarray, sig: ArmSignals, frictions: list[JointFriction], mask: np.ndarray
) -> Stack:
    """Stack ``Yb`` (N, n, r) and the friction columns on the rows ``mask`` (N, n) keeps,
    each joint's stick columns (``sig.stick``) projected out of its rows."""
    N, n, r = Yb.shape
    widths = [len(jf.linear_names) for jf in frictions]
    offsets = list(r + np.concatenate([[0], np.cumsum(widths)[:-1]]).astype(int))
    A = np.zeros((N, n, r + sum(widths)))
    A[:, :, :r] = Yb
    for j, jf in enumerate(frictions):
        A[:, j, offsets[j] : offsets[j] + widths[j]] = friction_block(sig, jf, j)
    t_idx, j_idx = np.nonzero(mask)
    st = Stack(A[t_idx, j_idx], sig.tau[t_idx, j_idx], j_idx, t_idx, offsets, r)
    if sig.stick is not None:
        st.bases = [
            stick_basis(sig.stick[j][t_idx[j_idx == j]]) if (j_idx == j).any() else None
            for j in range(n)
        ]
        st.A, st.y = st.residualise(st.A), st.residualise(st.y)
    return st


def shape_rows(
    sig: ArmSignals,
    frictions: list[JointFriction],
    st: Stack,
    theta: np.ndarray,
    sigma: np.ndarray,
    joints: list[int],
    log_w: bool = False,
) -> np.ndarray:
    """The Stribeck shapes' columns of ``joints`` on the stack's weighted rows: d friction /
    d (w_s, delta) per direction (d / d log w_s with ``log_w``), through the torque's filters,
    each joint's stick columns out, divided by its ``sigma``; shape (m, 2 directions per
    joint)."""
    widths = [2 * len(frictions[j].directions) for j in joints]
    out = np.zeros((st.A.shape[0], sum(widths)))
    col = 0
    for j, width in zip(joints, widths, strict=True):
        jf = frictions[j]
        c = sig.parallel(jf.shape_jacobian(sig.full_dq[:, j], theta[st.offsets[j] :]))
        if log_w:
            for k, d in enumerate(jf.directions):
                c[:, 2 * k] *= jf.shapes[d][0]
        rows = np.flatnonzero(st.row_joint == j)
        out[rows, col : col + width] = st.project(j, c[st.row_time[rows]]) / sigma[j]
        col += width
    return out


def lstsq(A: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Least squares with the columns scaled to unit norm (zero columns left at 0)."""
    norms = np.linalg.norm(A, axis=0)
    norms[norms == 0] = 1.0
    x, *_ = np.linalg.lstsq(A / norms, y, rcond=1e-10)
    return x / norms


def noise(st: Stack, theta: np.ndarray, n: int) -> np.ndarray:
    """Each joint's noise from the residuals (module notes); NaN for a joint without rows."""
    res = st.y - st.A @ theta
    m, p = st.A.shape
    out = np.full(n, np.nan)
    for j in range(n):
        rj = res[st.row_joint == j]
        if rj.size:
            out[j] = np.sqrt(rj @ rj / max(rj.size * (1 - p / m) - st.lost(j), 1.0))
    return out


def excess_index(st: Stack, j: int, k: int) -> int:
    """The column of joint ``j``'s Stribeck excess in direction ``k`` (:mod:`._friction`)."""
    return st.offsets[j] + 3 * k + 1


def excess_bounds(st: Stack, frictions: list[JointFriction]) -> dict[int, tuple[float, float]]:
    """Column -> (lower, upper) of each Stribeck excess ``tau_s - tau_c``: from zero (a rise,
    not a dip: module notes) to what the log allows (:func:`._friction.excess_cap`); zero
    where the fitted rows do not see the rise (:func:`unseen_rises`)."""
    return {
        excess_index(st, j, k): (0.0, 0.0 if jf.leaks.get(d, 0.0) > LEAK_MAX else jf.excess_max)
        for j, jf in enumerate(frictions)
        if jf.stribeck
        for k, d in enumerate(jf.directions)
    }


def unseen_rises(sig: ArmSignals, frictions: list[JointFriction], mask: np.ndarray) -> None:
    """Each Stribeck direction's leak (``JointFriction.leaks``), in place: the share of its
    column's energy on the rows ``mask`` keeps that comes through the filters from rows it
    leaves out (near the closed loop's reversals, the slow ones where the rise is). On a
    PD-tracked Panda (``bench_robot.py --truth sim --friction stribeck_asym``, seed 6) joint
    1's positive rise leaked 100 %, went to the cap (13 N m) and missed by 326x held out."""
    rows = sig.rows()
    nearest = np.clip(np.searchsorted(rows, np.arange(sig.full_dq.shape[0])), 0, rows.size - 1)
    for j, jf in enumerate(frictions):
        if not jf.stribeck or not mask[:, j].any():
            continue
        keep = mask[nearest, j]
        for d in jf.directions:
            raw = jf.excess_column(sig.full_dq[:, j], d, [jf.shapes[d][0]], [jf.shapes[d][1]])
            full = sig.parallel(raw[:, 0])[mask[:, j]]
            leak = full - sig.parallel(raw[:, 0] * keep)[mask[:, j]]
            energy = float(full @ full)
            jf.leaks[d] = float(leak @ leak) / energy if energy > 0 else 1.0


def bounded_lstsq(A: np.ndarray, y: np.ndarray, bounds: dict[int, tuple[float, float]]):
    """:func:`lstsq` with the columns of ``bounds`` held within them: a coefficient beyond
    its bound is fixed there and the rest solved again, until none is (an active set that
    only grows: the excesses are few and a shape's excess at a bound stays there)."""
    x = lstsq(A, y)
    fixed: dict[int, float] = {}
    while True:
        out = {
            k: min(max(x[k], lo), hi)
            for k, (lo, hi) in bounds.items()
            if k not in fixed and not lo <= x[k] <= hi
        }
        if not out:
            return x
        fixed.update(out)
        keys = np.array(sorted(fixed))
        free = np.setdiff1d(np.arange(A.shape[1]), keys)
        x = np.empty(A.shape[1])
        x[keys] = [fixed[k] for k in keys]
        x[free] = lstsq(A[:, free], y - A[:, keys] @ x[keys])


def wls(st: Stack, n: int, bounds: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Gautier's weighted least squares: (theta, sigma per joint); with ``bounds``
    (:func:`excess_bounds`), the Stribeck excesses held within them (:func:`bounded_lstsq`)."""
    bounds = bounds or {}
    theta = bounded_lstsq(st.A, st.y, bounds)
    sigma = noise(st, theta, n)
    safe = np.where(np.isfinite(sigma) & (sigma > 0), sigma, 1.0)
    theta = bounded_lstsq(*st.weighted(safe), bounds)
    return theta, noise(st, theta, n)


def _projector(A: np.ndarray, y: np.ndarray, k: int, rows: np.ndarray, cap: float = np.inf):
    """The drop of the sum of squares when column ``k`` of ``A`` is each column of ``X``
    (non-zero on ``rows`` only; module notes), as a function of ``X``: none where the
    column's coefficient is below zero, and ``-inf`` (not a candidate) where it exceeds
    ``cap``."""
    Am = np.delete(A, k, axis=1)
    norms = np.linalg.norm(Am, axis=0)
    norms[norms == 0] = 1.0
    As = Am / norms
    beta, *_ = np.linalg.lstsq(As, y, rcond=1e-10)
    r0 = y[rows] - As[rows] @ beta
    G = np.linalg.pinv(As.T @ As, rcond=1e-12, hermitian=True)
    Ar = As[rows]

    def gain(X: np.ndarray, coefficients: bool = False):
        C = Ar.T @ X
        xx = np.einsum("ik,ik->k", X, X)
        den = xx - np.einsum("ik,ij,jk->k", C, G, C)
        xr = X.T @ r0  # the sign of the column's coefficient
        with np.errstate(divide="ignore", invalid="ignore"):
            coef = np.where(xr > 0, xr / den, 0.0)
            out = np.where(den > 1e-12 * xx, np.where(xr > 0, xr**2 / den, 0.0), -np.inf)
            out = np.where(coef > cap, -np.inf, out)
            return (out, coef) if coefficients else out

    return gain


def _candidates(
    sig: ArmSignals, jf: JointFriction, j: int, d: str, w: np.ndarray, e: np.ndarray
) -> np.ndarray:
    return sig.parallel(jf.excess_column(sig.full_dq[:, j], d, w, e))


def _block_gains(sig, Yb, frictions, mask, sigma, j, k, d):
    """The drop of the weighted sum of squares for shapes ``(w, e)`` (arrays) of joint
    ``j``'s direction ``d``, every other column as it is."""
    jf = frictions[j]
    st = stack(Yb, sig, frictions, mask)
    A, y = st.weighted(sigma)
    rows = np.flatnonzero(st.row_joint == j)
    gain = _projector(A, y, excess_index(st, j, k), rows, jf.excess_max)
    t_rows = st.row_time[rows]

    def gains(w: np.ndarray, e: np.ndarray, coefficients: bool = False):
        out, coef = np.empty(np.size(w)), np.empty(np.size(w))
        for s in range(0, out.size, CHUNK):  # bounded memory: CHUNK full-rate columns
            cols = _candidates(sig, jf, j, d, w[s : s + CHUNK], e[s : s + CHUNK])
            x = st.project(j, cols[t_rows]) / sigma[j]
            out[s : s + CHUNK], coef[s : s + CHUNK] = gain(x, True)
        return (out, coef) if coefficients else out

    return gains


def shape_profiles(sig, Yb, frictions, mask, sigma, inflation) -> dict:
    """(joint, direction) -> the ranges of ``w_s``, ``delta`` and the Stribeck excess over
    the shapes of the grid (and the current ones) whose weighted sum of squares, every linear
    parameter fitted again, is within ``chi2_1(0.95)`` times the joint's ``inflation`` (its
    rows over its effective samples) of the current shapes': a profile-likelihood region
    (Venzon and Moolgavkar 1988) on the grid, for shapes the data determine only along a
    curved valley, where the linearised interval is too narrow."""
    out = {}
    w_grid, e_grid = (g.ravel() for g in np.meshgrid(W_S_GRID, DELTA_GRID))
    for j, jf in enumerate(frictions):
        if not jf.stribeck or not mask[:, j].any():
            continue
        for k, d in enumerate(jf.directions):
            gains = _block_gains(sig, Yb, frictions, mask, sigma, j, k, d)
            w = np.append(w_grid, jf.shapes[d][0])
            e = np.append(e_grid, jf.shapes[d][1])
            g, c = gains(w, e, coefficients=True)
            if not np.isfinite(g[-1]):
                continue
            near = g >= g[-1] - CHI2_1 * inflation[j]
            out[j, d] = {
                "w_s": (float(w[near].min()), float(w[near].max())),
                "delta": (float(e[near].min()), float(e[near].max())),
                "excess": (float(c[near].min()), float(c[near].max())),
            }
    return out


def _newton(gains, x0: np.ndarray, g0: float) -> np.ndarray:
    """Maximise a block's gain over ``x = (log w_s, delta)`` from ``x0`` by Newton steps on a
    3 x 3 finite-difference stencil (one vectorised evaluation per step: the valley of the
    sum of squares is a long curved ridge that coordinate grids and simplexes crawl along),
    halving a step that does not gain; ``x0`` itself if nothing gains."""
    lo = np.array([np.log(W_S_BOX[0]), DELTA_BOX[0]])
    hi = np.array([np.log(W_S_BOX[1]), DELTA_BOX[1]])
    h = np.array([NEWTON_STEP, NEWTON_STEP])
    offsets = np.array([(a, b) for a in (-1, 0, 1) for b in (-1, 0, 1)], dtype=float)
    x, best = x0.copy(), g0
    for _ in range(NEWTON_ITERATIONS):
        pts = np.clip(x + offsets * h, lo, hi)
        v = gains(np.exp(pts[:, 0]), pts[:, 1]).reshape(3, 3)
        if not np.isfinite(v).all():
            break
        grad = np.array([(v[2, 1] - v[0, 1]) / (2 * h[0]), (v[1, 2] - v[1, 0]) / (2 * h[1])])
        hxx = (v[2, 1] - 2 * v[1, 1] + v[0, 1]) / h[0] ** 2
        hyy = (v[1, 2] - 2 * v[1, 1] + v[1, 0]) / h[1] ** 2
        hxy = (v[2, 2] - v[2, 0] - v[0, 2] + v[0, 0]) / (4 * h[0] * h[1])
        H = np.array([[hxx, hxy], [hxy, hyy]])
        if np.all(np.linalg.eigvalsh(H) < 0):
            step = -np.linalg.solve(H, grad)
        else:  # not concave here: a gradient step of the stencil's size
            step = grad / max(np.linalg.norm(grad / h), 1e-300)
        for _ in range(6):
            trial = np.clip(x + step, lo, hi)
            gt = gains(np.exp(trial[:1]), trial[1:])[0]
            if np.isfinite(gt) and gt > best:
                break
            step = step / 2
        else:
            break
        done = np.all(np.abs(trial - x) < NEWTON_TOL)
        x, best = trial, gt
        if done:
            break
    return x


def _block(sig, Yb, frictions, mask, sigma, j, k, d, polish: bool) -> None:
    """One joint and direction's shapes: a grid, then (``polish``) a local polish (module
    notes)."""
    jf = frictions[j]
    gains = _block_gains(sig, Yb, frictions, mask, sigma, j, k, d)

    w_grid, e_grid = (g.ravel() for g in np.meshgrid(W_S_GRID, DELTA_GRID))
    # the current shapes are a candidate too, so that no step loses (coordinate descent)
    w_grid = np.append(w_grid, jf.shapes[d][0])
    e_grid = np.append(e_grid, jf.shapes[d][1])
    g = gains(w_grid, e_grid)
    if not np.isfinite(g).any():
        return
    best = int(np.argmax(g))
    x0 = np.array([np.log(w_grid[best]), e_grid[best]])
    if not polish:
        jf.shapes[d] = (float(w_grid[best]), float(e_grid[best]))
        return
    x = _newton(gains, x0, float(g[best]))
    jf.shapes[d] = (float(np.exp(x[0])), float(x[1]))


def search_shapes(
    sig: ArmSignals,
    Yb: np.ndarray,
    frictions: list[JointFriction],
    mask: np.ndarray,
    sigma: np.ndarray,
    sweeps: int | None = None,
) -> None:
    """Set each Stribeck joint's shapes by variable projection (module notes), in place."""
    sweeps = SWEEPS if sweeps is None else sweeps
    for sweep in range(sweeps):
        for j, jf in enumerate(frictions):
            if not jf.stribeck or not mask[:, j].any():
                continue
            for k, d in enumerate(jf.directions):
                _block(sig, Yb, frictions, mask, sigma, j, k, d, polish=sweep > 0)


def correlation_length(res: np.ndarray, row_joint: np.ndarray, row_time: np.ndarray, n: int):
    """(L, effective samples per joint) from the residuals' autocorrelation (module notes)."""
    T = int(row_time.max()) + 1 if row_time.size else 1
    series = np.zeros((T, n))
    series[row_time, row_joint] = res
    counts = np.bincount(row_joint, minlength=n)
    max_lag = max(2, T // 20)
    rho = np.zeros((max_lag + 1, n))
    for j in range(n):
        x = series[:, j]
        if counts[j] < 10 or not np.any(x):
            continue
        f = np.fft.rfft(x, 2 * T)
        ac = np.fft.irfft(f * np.conj(f))[: max_lag + 1]
        rho[:, j] = ac / ac[0]
    used = counts >= 10
    mean = rho[:, used].mean(axis=1) if used.any() else np.zeros(max_lag + 1)
    below = np.flatnonzero(mean < RHO_END)
    L = int(below[0]) if below.size else max_lag
    L = max(L, 1)
    inflation = 1 + 2 * np.clip(rho[1 : L + 1], 0, None).sum(axis=0)
    return L, counts / inflation


def hac_covariance(J: np.ndarray, res: np.ndarray, times: np.ndarray, lags: int):
    """Heteroscedasticity- and autocorrelation-consistent covariance (Newey and West 1987,
    Bartlett weights over ``lags`` instants; each instant's score sums its joints' rows, so the
    correlation between joints counts), never below the plain estimate; NaN where the data do
    not determine a parameter. Returns (cov, stderr)."""
    m, p = J.shape
    plain, determined = covariance_svd(J, float(res @ res) / max(m - p, 1))
    bread, _ = covariance_svd(J, 1.0)
    bread = np.nan_to_num(bread)
    T = int(times.max()) + 1
    scores = np.zeros((T, p))
    np.add.at(scores, times, J * res[:, None])
    meat = scores.T @ scores
    for lag in range(1, lags + 1):
        gamma = scores[lag:].T @ scores[:-lag]
        meat += (1 - lag / (lags + 1)) * (gamma + gamma.T)
    cov = bread @ meat @ bread * m / max(m - p, 1)
    return floored_covariance(cov, np.nan_to_num(np.diag(plain)), determined)


def arm_covariance(J: np.ndarray, res: np.ndarray, st: Stack, n: int, rho: np.ndarray):
    """(cov, stderr, t, clusters, L, effective samples) of the weighted problem: the covariance
    from the filter's correlation (:mod:`._filter_cov`) with the quantile of the normal, each
    standard error raised where the residuals' own autocorrelation (:func:`hac_covariance`,
    with Student's quantile over its clusters) gives a wider interval (module notes)."""
    L, n_eff = correlation_length(res, st.row_joint, st.row_time, n)
    lags = LAGS_OVER_L * L
    T = int(st.row_time.max()) + 1
    clusters = max(T // (lags + 1), 2)
    _, se_h = hac_covariance(J, res, st.row_time, lags)
    lost = np.array([st.lost(j) for j in range(n)])
    cov, se = filter_covariance(J, res, st.row_joint, st.row_time, n, rho, lost)
    z = float(scipy.stats.norm.ppf(0.975))
    t_h = float(scipy.stats.t.ppf(0.975, clusters - 1))
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.where(np.isfinite(se) & (se > 0), np.fmax(t_h * se_h / (z * se), 1.0), 1.0)
    return cov * np.outer(scale, scale), se * scale, z, clusters, L, n_eff
