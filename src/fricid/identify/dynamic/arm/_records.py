"""Each joint's friction parameters as the fit file records them: value, standard error,
95 % interval, and why a parameter is not determined (:func:`fricid.identify.dynamic.arm.fit_arm`).
"""

from __future__ import annotations

import numpy as np

from ._friction import DELTA_BOX, W_S_BOX, split_direction
from ._solve import LEAK_MAX, excess_index

__all__ = [
    "friction_records",
    "held_at_bound",
    "interval",
    "mark_held",
    "shapes_follow_rises",
    "widen",
]


#: Friction levels [N m, N m s/rad]: physically never below zero. Any parameter below zero
#: beyond its interval is not determined (friction that drives the joint); a level is not
#: determined below zero within its interval too, while a load coefficient may be (at a small
#: load it is loose and harmless: :func:`._grade.loose_levels`).
_LEVELS = ("f_c", "tau_c", "tau_s", "beta", "tau_v")


def interval(value, se, t):
    return [value - t * se, value + t * se] if np.isfinite(se) else [None, None]


def friction_records(frictions, theta, cov, st, joints, t, sig, moving, models_units):
    out = {}
    for j, (name, jf) in enumerate(zip(joints, frictions, strict=True)):
        lo = st.offsets[j]
        k = len(jf.linear_names)
        idx = list(range(lo, lo + k))
        values = theta[idx]
        if jf.stribeck:
            shape_idx = [
                st.A.shape[1] + sum(2 * len(f.directions) for f in frictions[:j] if f.stribeck) + i
                for i in range(2 * len(jf.directions))
            ]
            idx += shape_idx
            values = np.concatenate([values, [x for d in jf.directions for x in jf.shapes[d]]])
        sub = cov[np.ix_(idx, idx)]
        fam_values, fam_cov = jf.to_family(values, sub)
        se = np.sqrt(np.clip(np.diag(fam_cov), 0, None))
        params = {}
        for i, pname in enumerate(jf.names):
            nd = not np.isfinite(se[i])
            note = ""
            if nd:
                # the direction's Coulomb column is empty when the joint never moves that way
                _, d = split_direction(pname)
                coulomb = jf.names.index(("tau_c" if jf.stribeck else "f_c") + d)
                still = not np.isfinite(se[coulomb])
                note = (
                    "not determined: the joint does not move in this direction"
                    if still
                    else "not determined: the data do not inform it"
                )
                if jf.unloaded and pname.startswith("f_ck"):
                    note = "not determined: the joint carries no load (|load| <= 1e-9 N m)"
            rec = {
                "value": None if nd else float(fam_values[i]),
                "unit": models_units[jf.family].get(pname, ""),
                "stderr": None if nd else float(se[i]),
                "ci95": [None, None] if nd else interval(fam_values[i], se[i], t),
                "not_determined": nd,
                "note": note,
            }
            level = split_direction(pname)[0] in _LEVELS
            if not nd and (rec["ci95"][1] < 0 or (level and fam_values[i] < 0)):
                # a friction level below zero: friction that drives the joint. Beyond its
                # interval, the family does not describe this joint's data (or the joint
                # barely moves); within it, the data say the level is small, not what it is.
                # Either way no number to predict or export with.
                why = (
                    "the family does not describe this joint's data"
                    if rec["ci95"][1] < 0
                    else "its interval reaches zero: the data say it is small, not how small"
                )
                rec.update(
                    value=None,
                    stderr=None,
                    ci95=[None, None],
                    not_determined=True,
                    note=(
                        f"not determined: estimated {fam_values[i]:.4g} +- {t * se[i]:.2g}, "
                        f"a friction level below zero ({why})"
                    ),
                )
                params[pname] = rec
                continue
            if level and not nd and rec["ci95"][0] < 0:  # a level is never below zero
                rec["ci95"] = [0.0, rec["ci95"][1]]
            if pname.startswith(("w_s", "delta")) and not nd:
                box = W_S_BOX if pname.startswith("w_s") else DELTA_BOX
                lo_, hi_ = rec["ci95"]
                if lo_ < box[0] or hi_ > box[1] or se[i] > abs(fam_values[i]):
                    rec["note"] = (
                        "not bounded by the data (its interval reaches the searched range's "
                        f"limit, {box[0]:g} to {box[1]:g})"
                    )
                # no shape outside the box was searched: the interval ends at its faces
                rec["ci95"] = [max(lo_, box[0]), min(hi_, box[1])]
            params[pname] = rec
        if jf.stribeck:
            shapes_follow_rises(params, jf.directions)
        v = sig.dq[moving[:, j], j]
        out[name] = {
            "family": jf.family,
            "parameters": params,
            "velocity_range": [float(v.min()), float(v.max())] if v.size else [0.0, 0.0],
        }
        if jf.load:  # the load the rows saw [N m]
            load = sig.full_load[sig.rows()[moving[:, j]], j]
            out[name]["load_range"] = [float(load.min()), float(load.max())] if v.size else [0, 0]
    return out


def shapes_follow_rises(recs: dict, directions) -> None:
    """A direction whose ``tau_s`` is not determined has no shape ``w_s``, ``delta`` either
    (a double pendulum's joint had printed ``w_s`` 0.12 [0.088, 0.161] beside a ``tau_c``
    and ``tau_s`` not determined), in place."""
    for d in directions:
        if not recs["tau_s" + d]["not_determined"]:
            continue
        for shape in ("w_s", "delta"):
            if not recs[shape + d]["not_determined"]:
                recs[shape + d].update(
                    value=None,
                    stderr=None,
                    ci95=[None, None],
                    not_determined=True,
                    note=f"not determined: tau_s{d} is not, so its shape is not either",
                )


def widen(recs: dict, d: str, prof: dict, cap: float = np.inf) -> None:
    """Direction ``d``'s Stribeck intervals widened to their profile region
    (:func:`._solve.shape_profiles`), ``tau_s`` by the region's excess over ``tau_c``, and
    ended where the search ends: ``tau_s`` at zero and at ``tau_c`` plus the largest excess
    the log allows (``cap``, :func:`._friction.excess_cap`). A ``tau_s`` whose ``w_s`` the data
    do not bound is not bounded either (its excess trades against the shape)."""
    tau_c = recs["tau_c" + d]["value"]
    ranges = {"w_s": prof["w_s"], "delta": prof["delta"]}
    if tau_c is not None:
        ranges["tau_s"] = (tau_c + prof["excess"][0], tau_c + prof["excess"][1])
    for name, (lo, hi) in ranges.items():
        rec = recs[name + d]
        if rec["value"] is not None and rec["ci95"][0] is not None:
            rec["ci95"] = [min(rec["ci95"][0], lo), max(rec["ci95"][1], hi)]
    rec = recs["tau_s" + d]
    if tau_c is None or rec["value"] is None or rec["ci95"][0] is None:
        return
    rec["ci95"] = [max(rec["ci95"][0], 0.0), min(rec["ci95"][1], tau_c + cap)]
    if recs["w_s" + d]["note"].startswith("not bounded") and not rec["note"]:
        rec["note"] = "not bounded by the data (nor is its Stribeck velocity w_s)"


def held_at_bound(recs: dict, d: str, excess: float, cap: float, leak: float = 0.0) -> None:
    """Direction ``d``'s Stribeck records when its excess ``tau_s - tau_c`` was held at a
    bound (:func:`._solve.bounded_lstsq`): at zero the data show no rise the search allows
    (nor a shape to it), or the fitted rows do not see it (``leak`` above
    :data:`._solve.LEAK_MAX`: :func:`._solve.unseen_rises`); at ``cap`` one as large as the
    log allows; no estimate either way."""
    if excess <= 0.0:
        rise = (
            f"the rows fitted do not see the Stribeck rise ({leak:.0%} of its column there "
            "leaks in through the low-pass from the slow rows left out)"
            if leak > LEAK_MAX
            else "the data show no Stribeck rise"
        )
        why = {
            "tau_s": f"not determined: {rise}; its excess held at zero",
            "w_s": "not determined: no Stribeck rise fitted, so no shape to it",
            "delta": "not determined: no Stribeck rise fitted, so no shape to it",
        }
    else:
        why = {
            "tau_s": (
                f"not determined: its excess reached the largest the log allows ({cap:.4g} N m, "
                "the largest torque beyond gravity)"
            )
        }
    for name, note in why.items():
        recs[name + d].update(
            value=None, stderr=None, ci95=[None, None], not_determined=True, note=note
        )
    if excess <= 0.0:  # the law fitted is the one without a rise (ArmFit.joint_model)
        recs["tau_s" + d]["held_at"] = 0.0


def mark_held(fric: dict, frictions, st, theta: np.ndarray, held: list[int], joints) -> None:
    """Every direction whose excess column (``st``'s) is among ``held``: its records by
    :func:`held_at_bound`."""
    for j, jf in enumerate(frictions):
        for k, d in enumerate(jf.directions if jf.stribeck else ()):
            if (col := excess_index(st, j, k)) in held:
                recs = fric[joints[j]]["parameters"]
                held_at_bound(recs, d, theta[col], jf.excess_max, jf.leaks.get(d, 0.0))
