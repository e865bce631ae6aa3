"""Does eq. 7 explain the position dependence? A check of the gravity fit's residuals.

Eq. 7 of the BAS-RBFNN paper, ``tau_g = p_x cos(theta) - p_y sin(theta)``, is the gravity of
one link about one joint. When other joints move (a second link's gravity ``sin(q1 + q2)``),
or something else depends on the position (cogging, a cable), the torque still varies with
the position after eq. 7 is removed. That pattern is not noise: it biases every friction
averaged over the positions it covers. fricid does not model multi-joint gravity; this
module only detects the pattern and says so.

What is compared (reading chosen: not in the paper):

- joint fit (:mod:`.joint_gravity`): each pass's kept samples are cut into :data:`BLOCKS`
  consecutive blocks (:func:`block_stats`); a block's residual is its mean torque minus
  eq. 7's (and the load-dependent friction's) share, minus its pass's mean residual (the
  friction level). Binned by position, the part both directions share is kept (what is odd
  in the direction is friction, as in eq. 11). Without a pattern it is the noise of block
  means, ``sigma / sqrt(n)``, with ``sigma`` the samples' scatter about eq. 7 within the
  blocks (from their co-moments); with one it follows the position.
- eq. 11 pairing (:mod:`.gravity`): the residual of eq. 7 at each paired bin against the
  bins' standard errors.

The pattern is called structured when its RMS exceeds both :data:`STRUCTURE_SIGMAS` times its
expected noise and :data:`STRUCTURE_FRACTION` of the samples' own scatter (larger than the
noise, not merely significant).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .joint_gravity import MOMENT_SIZE, moments_of, regressors

__all__ = [
    "BLOCKS",
    "BLOCK_SIZE",
    "STRUCTURE_FRACTION",
    "STRUCTURE_SIGMAS",
    "GravityResidual",
    "block_noise",
    "block_stats",
    "block_stats_of",
    "check_joint",
    "check_paired",
]

#: Consecutive blocks a pass's kept samples are cut into for :func:`check_joint`.
BLOCKS = 16

#: Columns of a :func:`block_stats` row: mean position, then the block's
#: :func:`~.joint_gravity.moments` (count, means of ``(-cos, sin, tau)``, their co-moments).
BLOCK_SIZE = 1 + MOMENT_SIZE

#: The residual pattern must exceed this many times its expected noise...
STRUCTURE_SIGMAS = 4.0

#: ... and this share of the samples' scatter about eq. 7 (so it is larger than the noise).
STRUCTURE_FRACTION = 1.0


def block_stats(theta, tau, blocks: int = BLOCKS) -> np.ndarray:
    """Per-block statistics of one pass's kept samples, shape ``(blocks, BLOCK_SIZE)``.

    The samples (in time order) are cut into ``blocks`` consecutive parts of nearly equal
    count; an empty part has count 0.
    """
    theta = np.asarray(theta, dtype=float)
    return block_stats_of(theta, regressors(np.cos(theta), np.sin(theta), tau), blocks)


def block_stats_of(theta: np.ndarray, x: np.ndarray, blocks: int = BLOCKS) -> np.ndarray:
    """:func:`block_stats` of the samples at positions ``theta`` whose
    :func:`~.joint_gravity.regressors` are ``x`` (computed once for the whole pass)."""
    out = np.zeros((blocks, BLOCK_SIZE))
    n = theta.size
    for k in range(min(blocks, n)):  # a loop over the few blocks, not over samples
        a, b = (k * n) // blocks, ((k + 1) * n) // blocks
        if b > a:
            out[k, 0] = np.add.reduce(theta[a:b]) / (b - a)  # ``theta[a:b].mean()``
            out[k, 1:] = moments_of(x[:, a:b])
    return out


@dataclass(frozen=True, eq=False)
class GravityResidual:
    """The outcome of a residual check.

    Attributes
    ----------
    pattern_rms : float
        N m, RMS of the residuals along the position (see the module docstring).
    expected : float
        N m, what noise alone would give.
    noise : float
        N m, the samples' own scatter (standard deviation about their block or bin mean).
    structured : bool
        The pattern exceeds both thresholds.
    per_group : dict of int to float
        N m, the pattern's RMS per set-point label (as given), for the quality table.
    """

    pattern_rms: float
    expected: float
    noise: float
    structured: bool
    per_group: dict[int, float] = field(default_factory=dict)

    def message(self) -> str:
        """One line for the user (empty when nothing was found)."""
        if not self.structured:
            return ""
        return (
            f"the gravity fit (eq. 7, one link) leaves a residual pattern along the position of "
            f"{self.pattern_rms:.3g} N m RMS, against {self.expected:.2g} N m from noise (sample "
            f"scatter {self.noise:.2g} N m): something else depends on the position (gravity "
            "of other joints, e.g. sin(q1 + q2), cogging, a cable, friction not linear in the "
            "load); fricid does not model it, and each friction averages it over the positions "
            "its set-point covered"
        )

    def as_meta(self) -> dict:
        """JSON-ready (plain floats)."""
        return {
            "pattern_rms": _plain(self.pattern_rms),
            "expected": _plain(self.expected),
            "noise": _plain(self.noise),
            "structured": bool(self.structured),
        }


def _plain(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def _decide(pattern: float, expected: float, noise: float, per_group) -> GravityResidual:
    structured = bool(
        np.isfinite(pattern)
        and pattern > STRUCTURE_SIGMAS * expected
        and pattern > STRUCTURE_FRACTION * noise
    )
    return GravityResidual(pattern, expected, noise, structured, per_group)


def check_joint(blocks, group, direction, p, q=None) -> GravityResidual:
    """Check the joint fit (``tau = F_k + z . p + s z . q``, :mod:`.joint_gravity`).

    Parameters
    ----------
    blocks : array_like
        ``(n_passes, BLOCKS, BLOCK_SIZE)``, each pass's :func:`block_stats`.
    group : array_like of int
        ``(n_passes,)``, each pass's set-point label.
    direction : array_like
        ``(n_passes,)``, +1 or -1.
    p, q : array_like
        N m, ``(p_x, p_y)`` and the load-dependent friction's ``(q_x, q_y)`` (None: zero).
    """
    b = np.asarray(blocks, dtype=float)
    if b.ndim != 3 or b.shape[0] == 0:
        return _decide(np.nan, np.nan, np.nan, {})
    group = np.asarray(group)
    s = np.where(np.asarray(direction, dtype=float) < 0, -1.0, 1.0)
    coef = np.asarray(p, dtype=float)[None, :] + (
        0.0 if q is None else s[:, None] * np.asarray(q, dtype=float)[None, :]
    )
    n = b[..., 1]
    z = b[..., 2:4]  # (pass, block, 2): means of (-cos, sin)
    r = b[..., 4] - np.einsum("pbk,pk->pb", z, coef)
    has = n > 0
    w = np.where(has, n, 0.0)
    pass_mean = (w * np.where(has, r, 0.0)).sum(axis=1) / np.maximum(w.sum(axis=1), 1.0)
    use = has & (has.sum(axis=1) >= 2)[:, None]
    resid = np.where(use, r - pass_mean[:, None], 0.0)
    if not use.any():
        return _decide(np.nan, np.nan, np.nan, {})
    noise = _within_noise(b, coef, use)
    block_noise = noise / np.sqrt(np.median(n[use]))
    pattern, expected = _even_pattern(b[..., 0][use], resid[use], (s[:, None] * use)[use])
    expected *= block_noise
    per_group = {}
    for g in np.unique(group[use.any(axis=1)]):
        sel = use & (group == g)[:, None]
        per_group[int(g)] = float(np.sqrt((resid[sel] ** 2).mean()))
    return _decide(pattern, expected, noise, per_group)


def _within_noise(b: np.ndarray, coef: np.ndarray, use: np.ndarray) -> float:
    """N m, the samples' scatter about eq. 7 within the blocks ``use``: ``var(tau - z . c)``
    from each block's co-moments, pooled (``coef`` per pass, ``(n_passes, 2)``)."""
    c = b[..., 5:]  # z1z1, z1z2, z2z2, z1tau, z2tau, tautau
    c1, c2 = coef[:, None, 0], coef[:, None, 1]
    m2 = c[..., 5] - 2 * (c1 * c[..., 3] + c2 * c[..., 4])
    m2 = m2 + c1 * c1 * c[..., 0] + 2 * c1 * c2 * c[..., 1] + c2 * c2 * c[..., 2]
    dof = (b[..., 1][use] - 1.0).clip(min=0).sum()
    return float(np.sqrt(m2[use].clip(min=0).sum() / dof)) if dof > 0 else np.nan


def block_noise(blocks, p) -> float:
    """N m, the samples' scatter about eq. 7 (coefficients ``p``) within the blocks of every
    pass (``(n_passes, BLOCKS, BLOCK_SIZE)``, :func:`block_stats`): the noise an eq. 11 fit's
    residuals are compared with (a position bin's own scatter holds gravity's slope)."""
    b = np.asarray(blocks, dtype=float)
    if b.ndim != 3 or b.shape[0] == 0:
        return np.nan
    coef = np.broadcast_to(np.asarray(p, dtype=float), (b.shape[0], 2))
    return _within_noise(b, coef, b[..., 1] > 1)


def _even_pattern(theta, resid, sign) -> tuple[float, float]:
    """RMS over position bins of the residuals' part common to both directions (about its
    mean), and its expected value per unit block noise. Load-dependent friction is odd in the
    direction and cancels here, as it does in eq. 11; gravity (any joint's), cogging and
    cables are even and stay. Bins: :data:`BLOCKS` of equal width over the blocks' positions;
    only bins both directions visited count."""
    lo, hi = float(theta.min()), float(theta.max())
    if not hi > lo:
        return np.nan, np.nan
    edge = np.minimum(((theta - lo) / (hi - lo) * BLOCKS).astype(np.intp), BLOCKS - 1)
    fwd = (sign > 0).astype(np.intp)
    cell = edge * 2 + fwd
    count = np.bincount(cell, minlength=2 * BLOCKS).reshape(BLOCKS, 2)
    total = np.bincount(cell, weights=resid, minlength=2 * BLOCKS).reshape(BLOCKS, 2)
    both = (count > 0).all(axis=1)
    if both.sum() < 3:
        return np.nan, np.nan
    mean = total[both] / count[both]
    even = 0.5 * mean.sum(axis=1)
    even -= even.mean()
    # per unit block noise: var(even_j) = (1/n0 + 1/n1) / 4, less the mean removed
    var = 0.25 * (1.0 / count[both]).sum(axis=1)
    k = both.sum()
    expected = float(np.sqrt(var.mean() * (k - 1) / k))
    return float(np.sqrt(np.mean(even**2))), expected


def check_paired(tau_g, se, fitted, noise: float, group=None) -> GravityResidual:
    """Check an eq. 7 fit to eq. 11's gravity torques ``tau_g`` [N m] with their standard
    errors ``se`` [N m]; ``fitted`` is the torque eq. 7 gives at their positions, ``noise``
    the samples' scatter, ``group`` an optional set-point label per point."""
    r = np.asarray(tau_g, dtype=float) - np.asarray(fitted, dtype=float)
    se = np.asarray(se, dtype=float)
    ok = np.isfinite(r) & np.isfinite(se)
    if ok.sum() < 3:
        return _decide(np.nan, np.nan, noise, {})
    pattern = float(np.sqrt(np.mean(r[ok] ** 2)))
    # two coefficients fitted: the residuals keep (n - 2) / n of the noise's variance
    expected = float(np.sqrt(np.mean(se[ok] ** 2) * (ok.sum() - 2) / ok.sum()))
    per_group = {}
    if group is not None:
        group = np.asarray(group)
        for g in np.unique(group[ok]):
            per_group[int(g)] = float(np.sqrt(np.mean(r[ok & (group == g)] ** 2)))
    return _decide(pattern, expected, noise, per_group)
