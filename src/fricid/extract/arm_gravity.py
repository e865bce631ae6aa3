"""Gravity of a whole arm and every joint's per-set-point friction, identified jointly from
constant-velocity sweeps.

On one joint, eq. 7 of the BAS-RBFNN paper models gravity as ``p_x cos q + p_y sin q`` of the
joint's own angle (:mod:`.joint_gravity`). On an arm the gravity torque of joint ``i`` depends
on the whole configuration (a double pendulum's second joint goes as ``sin(q1 + q2)``), so it
is computed from the rigid-body model at every sample: ``g(q) = Y_b(q) beta``, with ``Y_b``
the regressor of the base gravity parameters ``beta`` (:func:`fricid.robot.base_parameters`
with ``gravity_only=True``; a URDF's masses are approximate, so ``beta`` is identified from the
sweeps themselves). Every steady sample of joint ``j`` swept at set-point ``k`` obeys

    tau_i = F_k + w_i . beta,    w_i = Y_b(q_i)[j]

(eq. 8 with the motor torque ``tau = tau_f + g``: a set-point's friction is constant, gravity
varies along the sweep and with the other joints' positions). One friction level per (joint,
temperature, velocity, direction) and one ``beta`` shared by every joint: a linear model, the
arm's form of :func:`~.joint_gravity.fit_gravity_joint` (which it equals on a one-joint robot,
where ``w = (-cos q, sin q)`` up to a fixed linear map: eq. 7).

As there, the levels are eliminated (Schur complement): ``beta`` solves ``S beta = r`` with
``S``, ``r`` the within-set-point co-moments of ``(w, tau)``, which pool exactly over passes
(Chan's formulas), so each pass is reduced to its count, means and co-moments
(:func:`arm_moments`). Standard errors are the larger, per parameter, of the ordinary
least-squares ones and the cluster-robust (sandwich, CR1) ones with passes as clusters: the
samples of one pass share its offset and coloured noise.

Reading chosen: combinations of ``beta`` the sweeps do not inform (``S`` singular or nearly,
:data:`RCOND`: a joint never swept, or the other joints held at too few positions) keep the
URDF's values (the minimum-norm correction of the URDF's ``beta``), and are reported as
undetermined (standard error NaN). The load-dependent friction of the single-joint fit
(eq. 3) is not modelled: with both directions measured over the same configurations it
cancels from ``beta`` (as eq. 11 pairing cancels it), and its mean stays in each set-point's
friction.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import sparse

from ..errors import DataError

__all__ = ["ArmGravityFit", "ArmSolution", "arm_moments", "solve_levels"]

#: A direction of the scaled within-set-point information matrix whose eigenvalue is below
#: this fraction of the largest is not informed by the sweeps: the gravity torque it moves
#: varies along them by under 1 % (the square root) of the strongest direction's, so a model
#: error of 1 % of the gravity torque (a held joint creeping, a coupling torque misread)
#: moves it a hundredfold and more. Sweeping one joint of the double pendulum with the other
#: held (fricid's simulator) left two directions at 2e-7 to 1.2e-5, identified at -1.8 +- 0.86
#: for a URDF's (and the truth's) 0.043 and set-point frictions 0.03-0.05 N m off (one of
#: them of the wrong sign), or +1.05 +- 1.8 N m for 0.066 on a shorter log. Sweeps of every
#: joint with the others in three poses had none below 7e-2 (``tests/_arm_sweeps.py``: the
#: double pendulum and three joints of the Panda), the double pendulum's first joint swept
#: alone with the second at three poses none below 1.7e-2.
RCOND = 1e-4


def arm_moments(w, tau) -> np.ndarray:
    """The sufficient statistics of one pass for :func:`solve_levels`.

    Parameters
    ----------
    w : array_like
        ``(N, m)``, the regressor rows of the pass's steady samples (``Y_b(q)`` of the swept
        joint).
    tau : array_like
        ``(N,)`` N m, their motor torques.

    Returns
    -------
    numpy.ndarray
        ``1 + d + d * d`` numbers (``d = m + 1``): the count, the means of ``(w, tau)`` and
        their co-moment matrix about those means (two-pass, so exact in floating point).
    """
    x = np.column_stack([np.asarray(w, dtype=float), np.asarray(tau, dtype=float)])
    n, d = x.shape
    if n == 0:
        return np.zeros(1 + d + d * d)
    mean = x.mean(axis=0)
    x = x - mean
    return np.concatenate([[n], mean, (x.T @ x).ravel()])


def _unpack(stats: np.ndarray):
    """Per-pass moment vectors (P, 1 + d + d^2) -> counts (P,), means (P, d), co-moments
    (P, d, d)."""
    size = stats.shape[1]
    d = round(float(np.sqrt(size - 0.75)) - 0.5)  # size = 1 + d + d^2
    return stats[:, 0], stats[:, 1 : 1 + d], stats[:, 1 + d :].reshape(-1, d, d)


@dataclass(frozen=True, eq=False)
class ArmSolution:
    """What :func:`solve_levels` returns: ``beta`` and the levels, with their covariance.

    Attributes
    ----------
    beta, beta_se : numpy.ndarray
        ``(m,)``, the parameters and their standard errors (NaN where undetermined).
    determined : numpy.ndarray
        ``(m,)`` bool, which parameters the data determine.
    level, level_se : numpy.ndarray
        ``(K,)``, each level's constant (the friction) and its standard error.
    count, passes : numpy.ndarray
        ``(K,)``, samples and passes behind each level.
    level_load : numpy.ndarray
        ``(K,)``, the mean of ``w . beta`` over each level's samples (the gravity torque, the
        load of eq. 12).
    level_regressor : numpy.ndarray
        ``(K, m)``, the mean regressor row ``wbar`` of each level: a level's friction moves by
        ``-wbar . d_beta`` when ``beta`` does (the error the levels share).
    rss : numpy.ndarray
        ``(K,)``, each level's residual sum of squares.
    covariance : numpy.ndarray
        ``(K + m, K + m)``, the covariance of ``(levels, beta)`` whose diagonal gives the
        standard errors (the larger of ordinary and cluster-robust, per entry, on the
        diagonal; the cluster-robust matrix off it).
    """

    beta: np.ndarray
    beta_se: np.ndarray
    determined: np.ndarray
    level: np.ndarray
    level_se: np.ndarray
    count: np.ndarray
    passes: np.ndarray
    level_load: np.ndarray
    level_regressor: np.ndarray
    rss: np.ndarray
    covariance: np.ndarray = field(repr=False)


def _pool(n, mean, com, level, k):
    """Pool passes into levels: counts (K,), means (K, d), within co-moments (K, d, d)."""
    count = np.bincount(level, weights=n, minlength=k)
    total = np.zeros((k, mean.shape[1]))
    np.add.at(total, level, n[:, None] * mean)
    gmean = total / np.maximum(count, 1.0)[:, None]
    dev = mean - gmean[level]
    gcom = np.zeros((k, *com.shape[1:]))
    np.add.at(gcom, level, com + n[:, None, None] * dev[:, :, None] * dev[:, None, :])
    return count, gmean, gcom


def _pseudo_inverse(s: np.ndarray, rcond: float) -> tuple[np.ndarray, np.ndarray]:
    """``S^+`` over the informed directions of ``S`` (scaled to unit diagonal first), and
    which coordinates lie wholly in the informed space."""
    diag = np.diag(s).copy()
    scale = np.sqrt(np.where(diag > 0, diag, 1.0))
    lam, vec = np.linalg.eigh(s / np.outer(scale, scale))
    top = max(float(lam[-1]), 1e-300)
    keep = lam > rcond * top
    inv = (vec[:, keep] / lam[keep]) @ vec[:, keep].T
    null = vec[:, ~keep]
    determined = np.linalg.norm(null, axis=1) < 1e-6 if null.size else np.ones(s.shape[0], bool)
    return inv / np.outer(scale, scale), determined


def solve_levels(
    stats,
    level,
    *,
    prior=None,
    fixed: bool = False,
    source: str | None = None,
    rcond: float = RCOND,
) -> ArmSolution:
    """Least squares of ``tau_i = F_level(i) + w_i . beta`` from per-pass moments.

    Parameters
    ----------
    stats : array_like
        ``(P, 1 + d + d^2)``, each pass's :func:`arm_moments`.
    level : array_like of int
        ``(P,)``, each pass's level (0 .. K-1; a friction per level).
    prior : array_like, optional
        ``(m,)``, the values kept in the directions the data do not inform (module notes);
        default zero.
    fixed : bool
        Keep ``beta = prior`` (the URDF trusted): only the levels are estimated.
    source : str, optional
        File named in errors.
    rcond : float
        See :data:`RCOND`.

    Returns
    -------
    ArmSolution

    Raises
    ------
    DataError
        No steady samples, or no direction of ``beta`` informed (nothing varies within a
        set-point).

    Notes
    -----
    With ``S = sum_k M_k[w, w]`` and ``r = sum_k M_k[w, tau]``:
    ``beta = prior + S^+ (r - S prior)``, ``F_k = mean_k(tau) - mean_k(w) . beta``; the
    inverse normal matrix (the "bread") is ``P_bb = S^+``, ``P_Fb = -wbar_k S^+``,
    ``P_FF = diag(1 / n_k) + wbar_k S^+ wbar_l`` (:func:`~.joint_gravity.fit_gravity_joint`
    with general regressors).
    """
    stats = np.atleast_2d(np.asarray(stats, dtype=float))
    level = np.asarray(level, dtype=np.intp)
    has = stats[:, 0] > 0
    if not has.any():
        raise DataError("the arm gravity fit has no steady samples", file=source)
    stats, level = stats[has], level[has]
    k = int(level.max()) + 1
    n, mean, com = _unpack(stats)
    m = mean.shape[1] - 1
    count, gmean, gcom = _pool(n, mean, com, level, k)
    s = gcom[:, :m, :m].sum(axis=0)
    r = gcom[:, :m, m].sum(axis=0)
    if not fixed and not (np.diag(s) > 0).any():
        raise DataError(
            "the arm's gravity is not determined by the sweeps: no gravity torque varies "
            "within a set-point (sweep each joint over a range of positions)",
            file=source,
        )
    if fixed:
        s_inv, determined = np.zeros((m, m)), np.zeros(m, dtype=bool)
    else:
        s_inv, determined = _pseudo_inverse(s, rcond)
    prior = np.zeros(m) if prior is None else np.asarray(prior, dtype=float)
    beta = prior + s_inv @ (r - s @ prior)
    wbar = gmean[:, :m]
    load = wbar @ beta
    friction = gmean[:, m] - load
    quad = np.einsum("i,kij,j->k", beta, gcom[:, :m, :m], beta)
    rss_k = np.maximum(gcom[:, m, m] - 2 * gcom[:, :m, m] @ beta + quad, 0.0)
    informed = round(float(np.trace(s_inv @ s)))
    n_total = float(count.sum())
    dof = n_total - k - informed
    bread = np.empty((k + m, k + m))
    bread[:k, :k] = np.diag(1.0 / count) + wbar @ s_inv @ wbar.T
    bread[:k, k:] = -wbar @ s_inv
    bread[k:, :k] = bread[:k, k:].T
    bread[k:, k:] = s_inv
    cov_ols = (rss_k.sum() / dof if dof > 0 else np.nan) * bread
    cov = cov_ols
    if stats.shape[0] > 1 and dof > 0:
        cov = _cluster_robust(n, mean, com, level, friction, beta, bread, (n_total, informed))
    var = np.maximum(np.diag(cov_ols), np.diag(cov))
    se = np.sqrt(var)
    beta_se = np.where(determined, se[k:], np.nan)
    return ArmSolution(
        beta=beta,
        beta_se=beta_se,
        determined=determined,
        level=friction,
        level_se=se[:k],
        count=count,
        passes=np.bincount(level, minlength=k),
        level_load=load,
        level_regressor=wbar,
        rss=rss_k,
        covariance=cov,
    )


def _cluster_robust(n, mean, com, level, friction, beta, bread, sizes) -> np.ndarray:
    """Sandwich covariance with passes as clusters (CR1): each pass's score is ``n_c ebar_c``
    in its level's entry and ``n_c wbar_c ebar_c + M_c[w, tau] - M_c[w, w] beta`` in the
    others, with the pass's mean residual ``ebar_c = taubar_c - F_k - wbar_c . beta``."""
    n_total, informed = sizes
    m = beta.size
    k = friction.size
    wbar = mean[:, :m]
    ebar = mean[:, m] - friction[level] - wbar @ beta
    score_b = n[:, None] * wbar * ebar[:, None] + com[:, :m, m] - com[:, :m, :m] @ beta
    rows = n.size
    cols = np.column_stack([level, np.tile(np.arange(k, k + m), (rows, 1))]).ravel()
    vals = np.column_stack([n * ebar, score_b]).ravel()
    g = sparse.csr_matrix((vals, (np.repeat(np.arange(rows), m + 1), cols)), shape=(rows, k + m))
    meat = (g.T @ g).toarray()
    factor = rows / max(rows - 1, 1) * (n_total - 1) / max(n_total - k - informed, 1)
    return factor * bread @ meat @ bread


@dataclass(frozen=True, eq=False)
class ArmGravityFit:
    """The arm's base gravity parameters and every joint's per-set-point friction.

    Attributes
    ----------
    joints : tuple of str
        The model's joints (the columns of the gravity torque).
    names : tuple of str
        The base gravity parameters (:attr:`fricid.robot.BaseParameters.names`).
    beta, beta_se : numpy.ndarray
        Their identified values [kg m, or kg m^2 for a regrouped inertia; the gravity torque is
        in N m] and standard errors (NaN where the sweeps do not determine them).
    beta_urdf : numpy.ndarray
        Their values from the URDF.
    identified : bool
        False when ``beta`` was taken from the URDF (nothing identified).
    levels : list of dict
        One per (joint, temperature, velocity, direction): ``joint``, ``temperature`` [degC],
        ``velocity`` [rad/s, signed], ``direction``, ``friction`` and ``friction_se`` [N m,
        signed], ``load`` [N m, the mean gravity torque over its samples, ``tau_g = -g(q)``
        as in eq. 8], ``count``, ``passes``, ``regressor`` [the mean base regressor row over
        its samples: the friction moves by ``-regressor . d_beta``; a fit of the joint's law
        adds this shared error to its intervals, :mod:`fricid.identify.static.shared_error`].
    residual_rms : dict
        N m, per swept joint, the RMS residual of its steady samples.
    covariance : numpy.ndarray
        The covariance of ``beta`` (cluster-robust by pass).
    notes : tuple of str
        What to know about the fit (undetermined parameters).
    """

    joints: tuple[str, ...]
    names: tuple[str, ...]
    beta: np.ndarray
    beta_se: np.ndarray
    beta_urdf: np.ndarray
    identified: bool
    levels: list[dict] = field(repr=False)
    residual_rms: dict[str, float]
    covariance: np.ndarray = field(repr=False)
    notes: tuple[str, ...] = ()
    method: str = "arm"

    def torque(self, w: np.ndarray) -> np.ndarray:
        """The gravity torque [N m] from base regressor rows ``w`` (..., m): ``w . beta``."""
        return np.asarray(w, dtype=float) @ self.beta

    def joint_levels(self, joint: str) -> list[dict]:
        """The levels of one joint, in the order found."""
        return [row for row in self.levels if row["joint"] == joint]

    def as_meta(self) -> dict:
        """JSON-ready: the parameters with their standard errors and URDF values, the levels."""

        def num(x: float) -> float | None:
            return float(x) if np.isfinite(x) else None

        return {
            "method": self.method,
            "identified": self.identified,
            "joints": list(self.joints),
            "parameters": [
                {"name": name, "value": num(b), "se": num(se), "urdf": num(u)}
                for name, b, se, u in zip(
                    self.names, self.beta, self.beta_se, self.beta_urdf, strict=True
                )
            ],
            "covariance": [[num(x) for x in row] for row in self.covariance],
            "levels": [
                {k: (num(v) if isinstance(v, float) else v) for k, v in row.items()}
                for row in self.levels
            ],
            "residual_rms": {k: num(v) for k, v in self.residual_rms.items()},
            "notes": list(self.notes),
        }
