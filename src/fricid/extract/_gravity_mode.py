"""Which gravity mode an extraction uses, why, and what its fit left behind.

Gravity is never left in silently: with a position channel it is removed by default (eq. 7
of the BAS-RBFNN paper, by eq. 11 pairing with position bins, else by the joint fit of
:mod:`.joint_gravity`); where it is not removed, one note says so and why. After the fit,
:mod:`.gravity_check` looks for a pattern along the position that eq. 7 does not explain.
"""

from __future__ import annotations

import numpy as np

from .gravity import GravityFit, gravity_se
from .gravity_check import GravityResidual, block_noise, check_joint, check_paired
from .joint_gravity import JointGravityFit

__all__ = ["AUTO", "explicit_none_note", "no_fit_note", "residual_check", "resolve"]

#: ``extract(..., gravity=AUTO)``: remove gravity whenever the log can tell it.
AUTO = "auto"

#: ``RawLog.meta["position_source"]`` of a log whose position was integrated from velocity.
INTEGRATED = "integrated velocity"


def resolve(binned: bool, position_source: str | None) -> tuple[str, str]:
    """The mode ``auto`` stands for, and the note when gravity is not removed ("" when it is):
    ``fit`` with position bins, ``joint`` with a position channel, else ``none``."""
    if binned:
        return "fit", ""
    if position_source == INTEGRATED:
        return "none", (
            "gravity not removed: the log has no position channel (position integrated from "
            "velocity), so eq. 7 cannot be fitted; the friction includes any gravity torque "
            "(a horizontal joint has none)"
        )
    return "joint", ""


def explicit_none_note(position_source: str | None) -> str:
    """The note for ``gravity="none"`` asked for on a log with a position channel."""
    if position_source == INTEGRATED:
        return ""
    return (
        "gravity not removed (gravity='none', asked for or in the log's design metadata): the "
        "log has a position channel, but the friction written includes any gravity torque; "
        "give --gravity joint (or fit, with --positions) to remove it"
    )


def no_fit_note(reason: str) -> str:
    """The note when ``auto`` tried the joint fit and eq. 7 was not determined."""
    first = reason.split(";")[0].rstrip(".")
    return (
        f"gravity not removed: {first}; the friction includes any gravity torque (give "
        "position bins with --positions, or --gravity none to accept this)"
    )


def residual_check(fit, kept, group, pooled, shape) -> GravityResidual | None:
    """Check ``fit``'s residuals along the position (:mod:`.gravity_check`).

    ``kept`` are the set-point records (with ``blocks``), ``group`` their set-point labels
    ``(t * nv + v) * 2 + forward``; ``pooled`` and ``shape`` (temperature, velocity, bin) are
    the pooled cells, for an eq. 11 fit. ``per_group`` is keyed by the same labels.
    """
    if isinstance(fit, JointGravityFit):
        blocks = np.array([r.blocks for r in kept])
        direction = np.array([r.direction for r in kept])
        return check_joint(blocks, group, direction, (fit.p_x, fit.p_y), fit.load_friction)
    if not isinstance(fit, GravityFit):
        return None
    nt, nv, nb = shape

    def grid(x: np.ndarray) -> np.ndarray:
        return x.reshape(nt * nv, 2, nb).transpose(0, 2, 1)  # (set-point, bin, direction)

    count, tau, sem, cos, sin = (
        grid(getattr(pooled, k)) for k in ("count", "torque", "sem", "cos", "sin")
    )
    both = (count > 0).all(axis=-1)
    tau_g = -0.5 * (tau[..., 1] + tau[..., 0])[both]
    se = 0.5 * np.sqrt(sem[..., 0] ** 2 + sem[..., 1] ** 2)[both]
    fitted = fit.p_x * cos[both].mean(axis=-1) - fit.p_y * sin[both].mean(axis=-1)
    noise = block_noise(np.array([r.blocks for r in kept]), (fit.p_x, fit.p_y))
    label = np.nonzero(both)[0]
    res = check_paired(tau_g, se, fitted, noise, group=label)
    per = {2 * k + fwd: v for k, v in res.per_group.items() for fwd in (0, 1)}
    return GravityResidual(res.pattern_rms, res.expected, res.noise, res.structured, per)


def std_about_gravity(fit, kept, group) -> dict[int, tuple[float, float]]:
    """N m, each set-point's sample scatter about eq. 7 (and the load-dependent friction of a
    joint fit) instead of about its mean torque, and the standard error of its friction, by
    set-point label: ``(std, sem)``; ``sem`` as :func:`~.bins.pool_cells` defines it (the
    scatter of the passes' mean residuals, or for one pass its cells' :func:`~.bins.cell_sem`,
    else ``std / sqrt(n)``).

    With one position bin per traverse the torque of a pass sweeps the whole gravity curve;
    its standard deviation about the mean is gravity's range, not noise. The residual
    ``e = tau - z . c`` (``z = (-cos, sin)``, ``c = p`` or ``p + s q``) of each pass is pooled
    from the pass's :func:`~.joint_gravity.moments` (Chan's formulas): its within-pass
    co-moments give ``sum (e - ebar)^2`` exactly.
    """
    stats = np.array([r.moments for r in kept])
    sign = np.where(np.array([r.direction for r in kept]) < 0, -1.0, 1.0)
    p = np.array([fit.p_x, fit.p_y])
    q = getattr(fit, "load_friction", None)
    coef = p[None, :] + (0.0 if q is None else sign[:, None] * np.asarray(q)[None, :])
    n = stats[:, 0]
    mean = stats[:, 3] - np.einsum("pk,pk->p", stats[:, 1:3], coef)
    c = stats[:, 4:]  # z1z1, z1z2, z2z2, z1tau, z2tau, tautau
    c1, c2 = coef[:, 0], coef[:, 1]
    m2 = c[:, 5] - 2 * (c1 * c[:, 3] + c2 * c[:, 4])
    m2 = (m2 + c1 * c1 * c[:, 0] + 2 * c1 * c2 * c[:, 1] + c2 * c2 * c[:, 2]).clip(min=0)
    out = {}
    for g in np.unique(group):
        sel = (group == g) & (n > 0)
        total = n[sel].sum()
        if total < 2:
            continue
        grand = (n[sel] * mean[sel]).sum() / total
        between = (n[sel] * (mean[sel] - grand) ** 2).sum()
        std = float(np.sqrt((m2[sel].sum() + between) / (total - 1)))
        passes = int(sel.sum())
        if passes > 1:
            sem = np.sqrt(between / total / (passes - 1))
        else:
            sem = _pass_sem(kept[int(np.flatnonzero(sel)[0])].cells, std / np.sqrt(total))
        cos, sin = _mean_trig([kept[i].cells for i in np.flatnonzero(sel)])
        sem = np.hypot(sem, gravity_se(fit, cos, sin))  # the removed eq. 7's own error
        out[int(g)] = (std, float(sem))
    return out


def _mean_trig(cells: list) -> tuple[float, float]:
    """The mean ``cos`` and ``sin`` of the position over the samples of these passes."""
    n = np.concatenate([c.count for c in cells])
    total = max(float(n.sum()), 1.0)
    cos, sin = (
        np.concatenate([np.nan_to_num(getattr(c, k)) for c in cells]) for k in ("cos", "sin")
    )
    return float(n @ cos / total), float(n @ sin / total)


def _pass_sem(cells, fallback: float) -> float:
    """The standard error of one pass's mean torque from its cells'
    (:func:`~.bins.cell_sem`, independent bins), never below ``fallback`` (``std / sqrt(n)``,
    as :func:`~.bins.pool_cells` takes the larger), which it is when a cell has none."""
    n = cells.count
    has = n > 0
    sem = None if cells.sem is None else cells.sem[has]
    if sem is None or not has.any() or not np.isfinite(sem).all():
        return fallback
    return max(float(np.sqrt(np.sum((n[has] * sem) ** 2)) / n[has].sum()), fallback)
