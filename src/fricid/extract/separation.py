"""Step 4 of :func:`fricid.extract.extract`: friction and gravity separated per operating point
(BAS-RBFNN paper eq. 9-12), and the sample tables (combined and per direction).

The gravity torque comes from eq. 11 pairing and the eq. 7 fit (:mod:`.gravity`), or, when the
two directions do not cover the same positions, from the joint fit of :mod:`.joint_gravity`.
"""

from __future__ import annotations

import numpy as np

from ..errors import DataError
from ..samples import FrictionSamples
from .gravity import GravityFit, fit_gravity, gravity_se, separate
from .joint_gravity import JointGravityFit

__all__ = [
    "SEM_CAVEAT",
    "SEM_METHOD",
    "SEM_SINGLE",
    "assemble",
    "missing_message",
    "sem_meta",
    "sem_values",
]

#: How the extraction estimates a row's standard error (``samples.meta["sem_method"]``):
#: measured in several passes, and in one (:func:`fricid.extract.bins.cell_sem`).
SEM_METHOD = "between passes (scatter of the per-pass means)"
SEM_SINGLE = "within one pass (autocorrelation-corrected, about the trend in position)"

#: What the single-pass estimate leaves out (``samples.meta["sem_caveat"]``).
SEM_CAVEAT = "offsets between runs are not in a single pass's standard error"


def sem_meta(sem: np.ndarray, passes: np.ndarray | None = None) -> dict:
    """The samples' ``meta`` entries of the per-row standard errors [N m] (``sem``, None where
    not finite; ``sem_method``, ``sem_caveat``), which
    :func:`fricid.identify.validate.measurement_scatter` prefers to its own estimates;
    ``passes`` (per row, the fewest of its directions) says which method the rows took."""
    values = sem_values(sem)
    many = None if passes is None else np.asarray(passes) > 1
    if many is not None and many.all():
        return {"sem": values, "sem_method": SEM_METHOD, "sem_caveat": ""}
    if many is not None and not many.any():
        return {"sem": values, "sem_method": SEM_SINGLE, "sem_caveat": SEM_CAVEAT}
    method = f"{SEM_METHOD} where a row has several; {SEM_SINGLE} where one"
    return {"sem": values, "sem_method": method, "sem_caveat": SEM_CAVEAT}


def sem_values(sem: np.ndarray) -> list[float | None]:
    """The per-row standard errors as ``meta["sem"]`` holds them (None where not finite)."""
    return [float(x) if np.isfinite(x) else None for x in np.asarray(sem, dtype=float)]


def missing_message(has: np.ndarray, t_set, v_set) -> str:
    """Describe the (temperature, velocity) set-points where one direction is missing;
    ``has`` is (temperature, velocity, direction, bin)."""
    lines = []
    for it, iv in zip(*np.nonzero((has[:, :, 0] ^ has[:, :, 1]).any(axis=-1)), strict=True):
        back, fwd = has[it, iv, 0], has[it, iv, 1]
        parts = []
        for name, mine, other in (("negative", back, fwd), ("positive", fwd, back)):
            lacking = int((other & ~mine).sum())
            if lacking:
                parts.append(f"no {name}-direction data in {lacking} of {int(other.sum())} bins")
        v = v_set[iv]
        lines.append(
            (f"{t_set[it]:.4g} degC, " if np.isfinite(t_set[it]) else "")
            + f"{v:.4g} rad/s ({np.degrees(v):.4g} deg/s): "
            + ", ".join(parts)
        )
    more = f"; and {len(lines) - 5} more" if len(lines) > 5 else ""
    return (
        "eq. 11 separates friction from gravity with both directions of motion at every "
        f"operating point, but {len(lines)} set-point(s) lack one: "
        + "; ".join(lines[:5])
        + more
        + " (for a horizontal joint use gravity='none')"
    )


def assemble(pooled, shape, t_set, v_set, gravity, source, meta, joint_fit, notes):
    """Step 4: eq. 11 per operating point, the eq. 7 fit (or the joint fit, ``joint_fit()``,
    also when eq. 11 pairing is impossible: then a note is appended to ``notes``), loads
    (eq. 12), sample tables."""
    nt, nv, nb = shape

    def grid(x: np.ndarray) -> np.ndarray:
        return x.reshape(nt, nv, 2, nb).transpose(0, 1, 3, 2)  # (t, v, bin, direction)

    count, tau, std, sem, passes = (
        grid(getattr(pooled, k)) for k in ("count", "torque", "std", "sem", "passes")
    )
    pos, vel, temp, cos, sin = (
        grid(getattr(pooled, k)) for k in ("position", "velocity", "temperature", "cos", "sin")
    )
    has = count > 0
    both = has[..., 0] & has[..., 1]
    any_ = has[..., 0] | has[..., 1]
    fit: GravityFit | JointGravityFit | None = None
    if gravity == "fit" and (any_ & ~both).any():
        missing = missing_message(has.transpose(0, 1, 3, 2), t_set, v_set)
        try:
            fit = joint_fit()
        except DataError as exc:
            raise DataError(
                f"{missing}; nor can gravity='joint' stand in: {exc.message}", file=source
            ) from None
        notes.append(
            f"{missing.split(' (for a horizontal')[0]}; so gravity and friction were "
            "identified jointly without pairing (gravity='joint')"
        )
    elif gravity == "fit":
        _, tau_g = separate(tau[both][:, 1], tau[both][:, 0])
        theta = 0.5 * (pos[both][:, 0] + pos[both][:, 1])
        mean_cos = 0.5 * (cos[both][:, 0] + cos[both][:, 1])
        mean_sin = 0.5 * (sin[both][:, 0] + sin[both][:, 1])
        fit = fit_gravity(theta, tau_g, source=source, cos=mean_cos, sin=mean_sin)
    elif gravity == "joint":
        fit = joint_fit()

    rows = np.argwhere(any_)  # (t, v, bin), C order = sorted
    sel = tuple(rows.T)
    # per row, columns (backward, forward): count, torque, std, sem, position, velocity, temp
    c_, t_, s_, e_, p_, v_, T_, cos_, sin_, k_ = (
        a[sel] for a in (count, tau, std, sem, pos, vel, temp, cos, sin, passes)
    )
    h = has[sel]
    b2 = h[:, 0] & h[:, 1]
    n_tot = c_.sum(axis=1)
    with np.errstate(invalid="ignore"):
        # combined (direction 0): eq. 11 where both directions exist, else the one measured
        friction = np.where(b2, 0.5 * (t_[:, 1] - t_[:, 0]), np.where(h[:, 1], t_[:, 1], -t_[:, 0]))
        velocity = np.where(b2, 0.5 * (v_[:, 1] - v_[:, 0]), np.where(h[:, 1], v_[:, 1], -v_[:, 0]))
        position = np.nansum(np.where(h, p_ * c_, 0.0), axis=1) / n_tot
        temperature = np.nansum(np.where(h, T_ * c_, 0.0), axis=1) / n_tot
        m2 = np.where(h, s_**2 * np.maximum(c_ - 1, 0), 0.0).sum(axis=1)
        std_c = np.sqrt(m2 / np.maximum(n_tot - h.sum(axis=1), 1))
        sem_c = np.where(
            b2,
            0.5 * np.sqrt(e_[:, 0] ** 2 + e_[:, 1] ** 2),
            np.nanmax(np.where(h, e_, np.nan), axis=1),
        )
    if fit is not None:
        # the gravity torque averaged over each cell's samples (eq. 7 is linear in cos and sin),
        # not taken at the cell's mean position: a wide cell (a whole traverse) would keep
        # gravity's curvature in the friction
        load_dir = fit.p_x * cos_ - fit.p_y * sin_
        with np.errstate(invalid="ignore"):
            load = np.nansum(np.where(h, load_dir * c_, 0.0), axis=1) / n_tot
        friction_dir = t_ + load_dir
        e_ = np.sqrt(e_**2 + gravity_se(fit, cos_, sin_) ** 2)
        # a row measured in one direction: its friction with the fitted gravity removed,
        # which its standard error holds too
        friction = np.where(
            b2, friction, np.where(h[:, 1], friction_dir[:, 1], -friction_dir[:, 0])
        )
        with np.errstate(invalid="ignore"):
            sem_c = np.where(b2, sem_c, np.nanmax(np.where(h, e_, np.nan), axis=1))
    else:
        load = np.zeros_like(position)
        friction_dir = t_
        load_dir = np.zeros_like(p_)
    meta = {
        **meta,
        "gravity": None
        if fit is None
        else (fit.as_meta() if isinstance(fit, JointGravityFit) else vars(fit)),
    }
    by_sem = e_.ravel()[h.ravel()]
    by_passes = k_.ravel()[h.ravel()]
    row_passes = np.where(h, k_, np.inf).min(axis=1)
    samples = FrictionSamples(
        velocity=velocity,
        load=load,
        temperature=temperature,
        friction=friction,
        direction=np.zeros_like(friction),
        count=n_tot,
        std=std_c,
        source=source,
        meta={**meta, **sem_meta(sem_c, row_passes)},
    )
    dsel = h.ravel()  # (row, direction) pairs present, -1 before +1
    sign = np.tile([-1.0, 1.0], len(rows))
    by_direction = FrictionSamples(
        velocity=v_.ravel()[dsel],
        load=load_dir.ravel()[dsel],
        temperature=T_.ravel()[dsel],
        friction=friction_dir.ravel()[dsel],
        direction=sign[dsel],
        count=c_.ravel()[dsel],
        std=s_.ravel()[dsel],
        source=source,
        meta={**meta, **sem_meta(by_sem, by_passes)},
    )
    one_way = not b2.any() and (h[:, 0].all() or h[:, 1].all())
    if one_way:  # nothing to combine: that direction's samples, not "both directions combined"
        word, sign = ("forwards", "+1") if h[:, 1].all() else ("backwards", "-1")
        notes.append(
            f"every set-point was measured {word} only: the samples are that direction's "
            f"(direction {sign}), not both directions combined; the other side was not measured"
        )
        samples = by_direction
    return samples, by_direction, fit, sem_c, by_sem, position
