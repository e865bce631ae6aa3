"""A joint's verdict in the whole-arm identification (:func:`fricid.identify.dynamic.arm.fit_arm`),
in :mod:`fricid.identify.trust`'s words and thresholds (``fricid.metrics.NOISE_RATIO``,
:data:`fricid.identify.trust.MISS_RATIO`)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ....metrics import NOISE_RATIO, verdict
from ...trust import MISS_RATIO
from ._solve import LEAK_MAX

__all__ = ["MIN_EFFECTIVE", "grade", "loose_levels", "unseen_rise_reasons"]

#: The fewest independent samples a joint's rows may hold for a verdict other than ``no``
#: (a double pendulum's joint that barely moved had 3, its noise 6e-16 N m and its held-out
#: ratio 6e13).
MIN_EFFECTIVE = 20


def _level(recs: Mapping[str, Mapping[str, Any]], name: str) -> float:
    """The Coulomb level beside load coefficient ``name`` (same direction), 0 if unknown."""
    rec = recs.get("f_c" + name[len("f_ck") :], {})
    return abs(rec.get("value") or 0.0)


def loose_levels(recs: Mapping[str, Mapping[str, Any]], noise: float, load_range=None) -> list[str]:
    """The Coulomb levels the data do not determine (not determined at all, or a 95 %
    interval wider, on either side, than both their value and the joint's torque noise):
    the data do not tell the joint's friction. A load coefficient ``f_ck`` counts by the
    torque it adds at the largest load of ``load_range``: loose when that torque's interval
    is wider than both the Coulomb level beside it and the noise (a coefficient of a small
    load is loose and harmless); one not determined because the joint carries no load is no
    part of its friction."""
    out = []
    top = max((abs(x) for x in load_range or ()), default=0.0)
    for name, rec in recs.items():
        load = name.startswith("f_ck")
        if not name.startswith(("f_c", "tau_c")) or (load and "carries no load" in rec["note"]):
            continue
        lo, hi = rec.get("ci95") or (None, None)
        if rec["not_determined"] or rec["value"] is None or lo is None:
            out.append(f"{name} not determined")
            continue
        scale, value = (top, _level(recs, name)) if load else (1.0, abs(rec["value"]))
        half = 0.5 * (hi - lo) * scale
        if half > max(value, noise):
            at = f" (at {top:.3g} N m of load)" if load else " N m"
            out.append(f"{name} {rec['value']:.3g} +- {half / scale:.2g}{at}")
    return out


def grade(
    ratio: float,
    nd: list[str],
    open_: list[str],
    source: str,
    moved: bool,
    loose: list[str] = (),
    problems: list[str] = (),
    effective: float = np.inf,
):
    """A joint's verdict in :mod:`fricid.identify.trust`'s words and thresholds; each of
    ``problems`` (channels that disagree, :mod:`._channels`) is a reason for ``no``, and so
    are fewer than :data:`MIN_EFFECTIVE` ``effective`` (independent) samples."""
    no, caveats = [f"the log's channels disagree: {p}" for p in problems], []
    if not moved:
        no.append(
            "no row of the joint's motion is left to fit (it does not move, or moves only near "
            "its reversals, which a closed-loop fit leaves out), so its friction is not "
            "determined"
        )
    elif effective < MIN_EFFECTIVE:
        no.append(
            f"the joint slides on only {effective:.0f} independent samples (at least "
            f"{MIN_EFFECTIVE} are needed to tell its friction and noise): make it move more"
        )
        ratio = np.nan  # a noise from so few samples grades nothing
    elif loose:
        no.append(
            "the data do not determine the joint's friction: its Coulomb level is not "
            "determined, or its 95 % interval is wider than the level and the noise "
            f"({'; '.join(loose)})"
        )
    if moved and nd:
        caveats.append(f"not determined by the data: {', '.join(nd)}")
    if open_:
        caveats.append(f"not bounded by the data: {', '.join(open_)}")
    if np.isfinite(ratio) and ratio > MISS_RATIO:
        no.append(f"the held-out error {verdict(ratio)} the measurement scatter")
    elif np.isfinite(ratio) and ratio > NOISE_RATIO:
        caveats.append(f"the held-out error {verdict(ratio)} the measurement scatter")
    elif not np.isfinite(ratio) and moved and effective >= MIN_EFFECTIVE:
        caveats.append("no held-out error to compare with the noise")
    if no:
        return "no", no + caveats
    if caveats:
        return "with caveats", caveats
    return "yes", [
        f"every parameter is determined and the held-out error ({source}) is within noise "
        f"({ratio:.2f}x the scatter)"
    ]


def unseen_rise_reasons(jf) -> list[str]:
    """What a joint's held-out error may hold that its fit could not know: the directions
    whose Stribeck rise the fitted rows did not see (``JointFriction.leaks`` above
    :data:`._solve.LEAK_MAX`), fitted without it."""
    unseen = [d.strip("_") or "both" for d, x in jf.leaks.items() if x > LEAK_MAX]
    if not unseen:
        return []
    return [
        f"no Stribeck rise fitted in direction(s) {', '.join(unseen)}: the rows fitted do not "
        "see it (it lies in the slow rows left out near the reversals), so slow sliding that "
        "way is predicted without it"
    ]
