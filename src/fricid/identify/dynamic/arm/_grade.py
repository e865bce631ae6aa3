"""A joint's verdict in the whole-arm identification (:func:`fricid.identify.dynamic.arm.fit_arm`),
in :mod:`fricid.identify.trust`'s words and thresholds (``fricid.metrics.NOISE_RATIO``,
:data:`fricid.identify.trust.MISS_RATIO`)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ....metrics import NOISE_RATIO, verdict
from ...trust import MISS_RATIO

__all__ = ["grade", "loose_levels"]


def loose_levels(recs: Mapping[str, Mapping[str, Any]], noise: float) -> list[str]:
    """The Coulomb levels the data do not determine (not determined at all, or a 95 %
    interval wider, on either side, than both their value and the joint's torque noise):
    the data do not tell the joint's friction."""
    out = []
    for name, rec in recs.items():
        if not name.startswith(("f_c", "tau_c")):
            continue
        lo, hi = rec.get("ci95") or (None, None)
        if rec["not_determined"] or rec["value"] is None or lo is None:
            out.append(f"{name} not determined")
            continue
        half = 0.5 * (hi - lo)
        if half > max(abs(rec["value"]), noise):
            out.append(f"{name} {rec['value']:.3g} +- {half:.2g} N m")
    return out


def grade(
    ratio: float,
    nd: list[str],
    open_: list[str],
    source: str,
    moved: bool,
    loose: list[str] = (),
):
    """A joint's verdict in :mod:`fricid.identify.trust`'s words and thresholds."""
    no, caveats = [], []
    if not moved:
        no.append("the joint does not move in the log, so its friction is not determined")
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
    elif not np.isfinite(ratio) and moved:
        caveats.append("no held-out error to compare with the noise")
    if no:
        return "no", no + caveats
    if caveats:
        return "with caveats", caveats
    return "yes", [
        f"every parameter is determined and the held-out error ({source}) is within noise "
        f"({ratio:.2f}x the scatter)"
    ]
