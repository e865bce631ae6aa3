"""Gravity and per-set-point friction identified jointly, without pairing the two directions.

Eq. 11 of the BAS-RBFNN paper separates friction from gravity by pairing both directions of
motion at the same position; when the two directions do not cover the same positions (forward
runs on one half of the range, backward runs on the other) there is nothing to pair. Every
steady sample still obeys eq. 8 with eq. 7,

    tau_m = tau_f - tau_g = F_k - p_x cos(theta) + p_y sin(theta),

with one constant friction ``F_k`` (signed, N m) per set-point ``k`` (temperature, velocity,
direction): a linear model in ``(F_1 .. F_K, p_x, p_y)``. Its least-squares solution needs no
pairing: gravity is what makes the torque vary with position *within* a set-point, friction is
the set-point's level.

Friction grows with the load (BAS-RBFNN paper eq. 3, after Bittencourt and Gunnarsson), and
the load is the gravity torque (eq. 12), so within one direction the torque's slope along the
position is ``(1 -+ mu)`` times gravity's: one direction alone cannot tell gravity from
load-dependent friction (eq. 11 cancels it by pairing). With ``load_friction=True`` (default)
the model is ``tau = F_k + z . p + s_k z . q`` (``z = (-cos theta, sin theta)``, ``s_k`` the
direction): ``q`` is the load-dependent friction, odd in the direction and linear in the
gravity torque, common to all set-points; gravity is then what the two directions share,
and it is determined when both directions are measured (not necessarily at the same
positions: at different positions their slopes differ). Reading chosen: the friction's load
coefficient is taken as one for the whole log (it varies mildly with velocity and
temperature in the paper's data) and the load keeps one sign over the range (|L| = +-L).

The design matrix is sparse (one friction column per sample) and its normal equations have a
block structure; eliminating the ``F_k`` (Schur complement) leaves a 4 x 4 (2 x 2 without
``q``) system built from the *within-set-point* co-moments of ``(-cos theta, sin theta,
tau)``. Those co-moments pool exactly over passes and chunks (Chan's
parallel formulas), so a campaign of any length is reduced to ten numbers per pass
(:func:`moments`), in bounded memory.

Standard errors: the samples of one pass share its offset and coloured noise, so the
ordinary least-squares covariance would be far too small (it treats 10^5 correlated samples
as independent). The covariance reported is the larger, per parameter, of the ordinary one
and the cluster-robust (sandwich) one with passes as clusters (CR1 small-sample factor); the
latter is computed from the same per-pass moments.

Reading chosen (not in the paper): a friction that differs between directions (asymmetry) is
kept, one ``F_k`` per direction; an offset of the torque sensor is indistinguishable from it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import sparse

from ..errors import DataError

__all__ = [
    "MOMENT_SIZE",
    "JointGravityFit",
    "fit_gravity_joint",
    "moments",
    "moments_of",
    "regressors",
]

#: Length of a pass's moment vector: count, means of (z1, z2, tau), co-moments
#: (z1 z1, z1 z2, z2 z2, z1 tau, z2 tau, tau tau), with z = (-cos theta, sin theta).
MOMENT_SIZE = 10

# index pairs of the co-moment entries, in the order stored
_PAIRS = ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2))
_ROWS, _COLS = (np.array(k) for k in zip(*_PAIRS, strict=True))


def moments(theta, tau) -> np.ndarray:
    """The sufficient statistics of one pass for :func:`fit_gravity_joint`.

    Parameters
    ----------
    theta : array_like
        rad, positions of the pass's steady samples.
    tau : array_like
        N m, their motor torques.

    Returns
    -------
    numpy.ndarray
        Shape ``(MOMENT_SIZE,)``: the count, the means of ``(-cos theta, sin theta, tau)`` and
        their sums of cross-products about those means (two-pass, so exact in floating point).
    """
    theta = np.asarray(theta, dtype=float)
    return moments_of(regressors(np.cos(theta), np.sin(theta), tau))


def regressors(cos: np.ndarray, sin: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """The rows ``(-cos theta, sin theta, tau)`` of :func:`moments_of`, shape ``(3, n)``."""
    x = np.empty((3, np.size(tau)))
    np.negative(cos, out=x[0])
    x[1] = sin
    x[2] = tau
    return x


def moments_of(x: np.ndarray) -> np.ndarray:
    """:func:`moments` of the samples whose :func:`regressors` are ``x`` (shape ``(3, n)``,
    any view: it is not modified)."""
    n = x.shape[1]
    out = np.zeros(MOMENT_SIZE)
    out[0] = n
    if n == 0:
        return out
    mean = np.add.reduce(x, axis=1) / n  # ``x.mean(axis=1)``, bit for bit, without its wrapper
    d = x - mean[:, None]
    c = d @ d.T
    out[1:4] = mean
    out[4:] = c[_ROWS, _COLS]
    return out
    mean = x.mean(axis=1)
    d = x - mean[:, None]
    out[1:4] = mean
    out[4:] = [d[i] @ d[j] for i, j in _PAIRS]
    return out


def _matrix(m: np.ndarray) -> np.ndarray:
    """Co-moment vectors (..., 6) -> symmetric matrices (..., 3, 3)."""
    out = np.empty((*m.shape[:-1], 3, 3))
    for k, (i, j) in enumerate(_PAIRS):
        out[..., i, j] = out[..., j, i] = m[..., k]
    return out


def _pool(stats: np.ndarray, group: np.ndarray, n_groups: int):
    """Pool per-pass moments into groups: counts (G,), means (G, 3), co-moments (G, 3, 3)."""
    n = stats[:, 0]
    mean = stats[:, 1:4]
    comoment = _matrix(stats[:, 4:])
    count = np.bincount(group, weights=n, minlength=n_groups)
    total = np.zeros((n_groups, 3))
    np.add.at(total, group, n[:, None] * mean)
    gmean = total / np.maximum(count, 1.0)[:, None]
    d = mean - gmean[group]
    within = comoment + n[:, None, None] * d[:, :, None] * d[:, None, :]
    gcomoment = np.zeros((n_groups, 3, 3))
    np.add.at(gcomoment, group, within)
    return count, gmean, gcomoment


def _lift(zz, zy, zbar, sign, load_friction: bool):
    """Co-moments and means of the global regressors ``w``: ``z``, and ``s z`` with
    ``load_friction`` (``s`` the direction, +-1), from those of ``z``."""
    if not load_friction:
        return zz, zy, zbar
    s = np.asarray(sign, dtype=float)
    ww = np.empty((*zz.shape[:-2], 4, 4))
    ww[..., :2, :2] = ww[..., 2:, 2:] = zz
    ww[..., :2, 2:] = ww[..., 2:, :2] = s[..., None, None] * zz
    wy = np.concatenate([zy, s[..., None] * zy], axis=-1)
    wbar = np.concatenate([zbar, s[..., None] * zbar], axis=-1)
    return ww, wy, wbar


@dataclass(frozen=True, eq=False)
class JointGravityFit:
    """Gravity (eq. 7) and per-set-point friction identified jointly (:func:`fit_gravity_joint`).

    Attributes
    ----------
    p_x, p_y : float
        N m, the coefficients of ``tau_g = p_x cos(theta) - p_y sin(theta)`` (eq. 7).
    p_x_se, p_y_se : float
        N m, their standard errors (the larger of ordinary and per-pass cluster-robust).
    residual_rms : float
        N m, RMS of the samples' residuals.
    n : int
        Samples fitted.
    friction : numpy.ndarray
        N m, each set-point's mean friction (signed; the torque's mean plus the gravity
        torque's mean over its samples), in the order of ``group``.
    friction_se : numpy.ndarray
        N m, its standard error.
    group : numpy.ndarray
        The set-point label of each friction (as given to :func:`fit_gravity_joint`).
    count, passes : numpy.ndarray
        Samples and passes behind each friction.
    load_friction : numpy.ndarray or None
        N m, ``q`` (module docstring): the load-dependent friction's coefficients, or None
        when not modelled; ``load_friction_se`` their standard errors.
    covariance : numpy.ndarray
        Cluster-robust covariance of ``(F_1 .. F_K, p_x, p_y[, q_x, q_y])`` (the ordinary one
        for a single pass); the standard errors are the larger of the two.
    method : str
        ``"joint"``.
    """

    p_x: float
    p_y: float
    p_x_se: float
    p_y_se: float
    residual_rms: float
    n: int
    friction: np.ndarray = field(repr=False)
    friction_se: np.ndarray = field(repr=False)
    group: np.ndarray = field(repr=False)
    count: np.ndarray = field(repr=False)
    passes: np.ndarray = field(repr=False)
    covariance: np.ndarray = field(repr=False)
    load_friction: np.ndarray | None = field(default=None, repr=False)
    load_friction_se: np.ndarray | None = field(default=None, repr=False)
    method: str = "joint"

    def torque(self, theta) -> np.ndarray:
        """The fitted gravity torque [N m] at ``theta`` [rad] (eq. 7); it is the load (eq. 12)."""
        theta = np.asarray(theta, dtype=float)
        return self.p_x * np.cos(theta) - self.p_y * np.sin(theta)

    def as_meta(self) -> dict:
        """The coefficients and the per-set-point frictions, JSON-ready (plain floats/lists)."""
        out = {
            "method": self.method,
            "p_x": self.p_x,
            "p_y": self.p_y,
            "p_x_se": self.p_x_se,
            "p_y_se": self.p_y_se,
            "residual_rms": self.residual_rms,
            "n": self.n,
            "friction": self.friction.tolist(),
            "friction_se": self.friction_se.tolist(),
        }
        if self.load_friction is not None:
            out["load_friction"] = self.load_friction.tolist()
            out["load_friction_se"] = self.load_friction_se.tolist()
        return out


def fit_gravity_joint(
    stats,
    group,
    direction,
    *,
    load_friction: bool = True,
    source: str | None = None,
    min_spread: float = 1e-6,
) -> JointGravityFit:
    """Identify eq. 7's ``p_x, p_y`` and one friction per set-point from per-pass moments.

    Parameters
    ----------
    stats : array_like
        ``(n_passes, MOMENT_SIZE)``, each pass's :func:`moments`.
    group : array_like of int
        ``(n_passes,)``, the set-point (temperature, velocity, direction) of each pass; any
        integer labels.
    direction : array_like
        ``(n_passes,)``, each pass's direction of motion (+1 or -1).
    load_friction : bool
        Model the load-dependent friction ``q`` (module docstring); False fits the plain
        ``tau = F_k + z . p``, which is biased when friction depends on the load and one
        direction dominates a range of positions.
    source : str, optional
        File named in errors.
    min_spread : float
        Smallest ratio of the within-set-point information matrix's eigenvalues for the
        coefficients to count as determined.

    Returns
    -------
    JointGravityFit

    Raises
    ------
    DataError
        No samples; or gravity not determined: positions within the set-points spread too
        little, or (with ``load_friction``) one direction only, where gravity cannot be told
        from load-dependent friction.

    Notes
    -----
    Solves the normal equations of ``tau_i = F_k(i) + w_i . b`` (``w = z`` or ``(z, s z)``)
    by block elimination: with ``S = sum_k M_k[w, w]`` (within-set-point co-moments),
    ``b = S^-1 sum_k M_k[w, tau]`` and ``F_k = mean_k(tau) - mean_k(w) . b``; the inverse of
    the normal matrix is ``P_bb = S^-1``, ``P_Fb = -wbar_k S^-1``,
    ``P_FF = diag(1 / n_k) + wbar_k S^-1 wbar_l``.
    """
    stats = np.atleast_2d(np.asarray(stats, dtype=float))
    labels, group = np.unique(np.asarray(group), return_inverse=True)
    sign = np.where(np.asarray(direction, dtype=float) < 0, -1.0, 1.0)
    has = stats[:, 0] > 0
    stats, group, sign = stats[has], group[has], sign[has]
    k = labels.size
    if not has.any():
        raise DataError("the joint gravity fit has no steady samples", file=source)
    count, gmean, gcom = _pool(stats, group, k)
    gsign = np.zeros(k)
    gsign[group] = sign
    ww, wy, wbar = _lift(gcom[:, :2, :2], gcom[:, :2, 2], gmean[:, :2], gsign, load_friction)
    s = ww.sum(axis=0)
    r = wy.sum(axis=0)
    m = s.shape[0]
    scale = np.sqrt(np.diag(s))
    eig = np.linalg.eigvalsh(s / np.outer(scale, scale)) if (scale > 0).all() else np.zeros(m)
    if eig[0] <= min_spread * max(eig[-1], 1e-300):
        both = "" if np.unique(gsign).size > 1 else "; only one direction of motion was measured"
        raise DataError(
            "gravity (eq. 7) is not determined by the joint fit: within the set-points the "
            "positions span too little of the (cos, sin) plane to separate gravity from the "
            f"friction levels and its load dependence{both}; measure both directions over a "
            "wider range of positions, or for a horizontal joint use gravity='none'",
            file=source,
        )
    s_inv = np.linalg.inv(s)
    b = s_inv @ r
    level = gmean[:, 2] - wbar @ b  # F_k
    n_total = round(float(count.sum()))
    rss = max(float(gcom[:, 2, 2].sum() - b @ r), 0.0)
    dof = n_total - k - m
    bread = np.empty((k + m, k + m))
    bread[:k, :k] = np.diag(1.0 / count) + wbar @ s_inv @ wbar.T
    bread[:k, k:] = -wbar @ s_inv
    bread[k:, :k] = bread[:k, k:].T
    bread[k:, k:] = s_inv
    cov_ols = (rss / dof if dof > 0 else np.nan) * bread
    cov = cov_ols
    if stats.shape[0] > 1 and dof > 0:
        cov = _cluster_robust(stats, group, sign, level, b, bread, load_friction, n_total)
    # each set-point's mean friction: F_k + s_k zbar_k . q = mean(tau) - zbar_k . p
    lin = np.zeros((k, k + m))
    lin[:, :k] = np.eye(k)
    if load_friction:
        lin[:, k + 2 :] = gsign[:, None] * gmean[:, :2]
    full = np.eye(k + m)
    full[:k] = lin
    var = np.maximum(np.diag(full @ cov_ols @ full.T), np.diag(full @ cov @ full.T))
    se = np.sqrt(var)
    return JointGravityFit(
        p_x=float(b[0]),
        p_y=float(b[1]),
        p_x_se=float(se[k]),
        p_y_se=float(se[k + 1]),
        residual_rms=float(np.sqrt(rss / max(n_total, 1))),
        n=n_total,
        friction=gmean[:, 2] - gmean[:, :2] @ b[:2],
        friction_se=se[:k],
        group=labels,
        count=count,
        passes=np.bincount(group, minlength=k),
        covariance=full @ cov @ full.T,
        load_friction=b[2:].copy() if load_friction else None,
        load_friction_se=se[k + 2 :].copy() if load_friction else None,
    )


def _cluster_robust(stats, group, sign, level, b, bread, load_friction, n_total) -> np.ndarray:
    """Sandwich covariance with passes as clusters (CR1), from the per-pass moments.

    Each pass's score is ``A_c^T e_c``: ``n_c ebar_c`` in its set-point's friction entry and
    ``n_c wbar_c ebar_c + M_c[w, tau] - M_c[w, w] b`` in the others, with the pass's mean
    residual ``ebar_c = taubar_c - F_k - wbar_c . b``.
    """
    n = stats[:, 0]
    com = _matrix(stats[:, 4:])
    ww, wy, wbar = _lift(com[:, :2, :2], com[:, :2, 2], stats[:, 1:3], sign, load_friction)
    ebar = stats[:, 3] - level[group] - wbar @ b
    score_b = n[:, None] * wbar * ebar[:, None] + wy - ww @ b
    rows, (k, m) = stats.shape[0], (level.size, b.size)
    cols = np.column_stack([group, np.tile(np.arange(k, k + m), (rows, 1))]).ravel()
    vals = np.column_stack([n * ebar, score_b]).ravel()
    g = sparse.csr_matrix((vals, (np.repeat(np.arange(rows), m + 1), cols)), shape=(rows, k + m))
    meat = (g.T @ g).toarray()
    factor = rows / (rows - 1) * (n_total - 1) / max(n_total - k - m, 1)
    return factor * bread @ meat @ bread
