"""Which runs and samples rows of an arm's sweeps belong to the arm fit's levels
(:func:`fricid.extract.arm.extract_arm`): a held joint's creep is no sweep
(:func:`held_runs`), each joint's samples rows are those the fit has a level for
(:func:`at_levels`), and a row holds its level's friction, count and gravity load
(:func:`with_load`)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..samples import FrictionSamples

__all__ = ["HELD_SHARE", "LEVEL_RTOL", "at_levels", "held_runs", "with_load"]

#: A joint whose longest steady run travels under this share of the longest run of any joint
#: is held, not swept (:func:`held_runs`).
HELD_SHARE = 0.02

#: A samples row belongs to a level within this share of its speed (:func:`at_levels`).
LEVEL_RTOL = 0.05


def _travel(record) -> float:
    """rad, how far a steady run moved."""
    return float(record.speed) * float(record.duration)


def held_runs(records: dict[str, list], asked: bool) -> tuple[dict[str, list], dict[str, str]]:
    """Each joint's runs that sweep, and what was left out as a held joint's creep: a run
    that travels under :data:`HELD_SHARE` of the longest run of any joint. A joint with no
    other run is left out whole (unless ``asked``: named by the caller); a swept joint keeps
    its other runs. The double pendulum's second joint, held by its PD drive while the first
    was swept over 1.5 rad, crept with the first joint's gravity: 37 "set-points" at 0.2-0.7
    mrad/s, none over 0.005 rad, with frictions against the motion (0.25 N m with the gravity
    identified); in a log of both joints' sweeps each held joint's creep (+-2 mrad/s) made
    set-points of its holding torque."""
    top = max(_travel(r) for recs in records.values() for r in recs)
    kept, notes = {}, {}
    for joint, recs in records.items():
        sweeps = [r for r in recs if _travel(r) >= HELD_SHARE * top]
        creep = [r for r in recs if _travel(r) < HELD_SHARE * top]
        longest = max(_travel(r) for r in creep) if creep else 0.0
        why = (
            f"travel at most {longest:.2g} rad, under {100 * HELD_SHARE:g} % of the longest "
            f"sweep's {top:.2g} rad: a held joint's creep"
        )
        if asked or (sweeps and not creep):
            kept[joint] = recs
        elif not sweeps:
            notes[joint] = (
                f"not swept, left out: its steady runs {why} (name it in joints= or --joints "
                "to extract it anyway)"
            )
        else:
            kept[joint] = sweeps
            speeds = sorted({round(float(r.speed) * r.direction, 4) for r in creep})
            shown = ", ".join(f"{v:+.3g}" for v in speeds[:8]) + (" ..." if len(speeds) > 8 else "")
            notes[joint] = (
                f"{len(creep)} steady run(s) at {shown} rad/s left out of its set-points: they "
                f"{why} while another joint was swept"
            )
    return kept, notes


def at_levels(samples: FrictionSamples, levels: list[dict], options: dict, *, combined: bool):
    """The rows of ``samples`` the arm fit has a level for: one of the row's direction (a
    combined row: either) within :data:`LEVEL_RTOL` of its speed and ``temperature_atol`` of
    its temperature. The others are runs the fit left out (a held joint's creep,
    :func:`held_runs`), which the joint's own extraction found again."""
    speed = np.array([abs(r["velocity"]) for r in levels])
    temp = np.array([r["temperature"] for r in levels])
    sign = np.array([r["direction"] for r in levels])
    keep = np.zeros(len(samples), dtype=bool)
    for i, (v, t) in enumerate(zip(samples.velocity, samples.temperature, strict=True)):
        near = np.abs(speed - abs(v)) <= LEVEL_RTOL * abs(v)
        near &= np.abs(temp - t) <= options["temperature_atol"]
        keep[i] = bool((near if combined else near & (sign == np.sign(v))).any())
    return samples if keep.all() or not keep.any() else samples.subset(keep)


def with_load(
    samples: FrictionSamples, levels: list[dict], meta: dict, *, combined: bool
) -> FrictionSamples:
    """``samples`` with each row's load the gravity torque of its level (the nearest in speed
    and temperature with the row's direction; for a combined row, the count-weighted mean of
    both directions' levels) and the arm's ``meta``.

    A per-direction row (``combined=False``) takes its level's friction and count as well
    (its own mean velocity, that direction's, is kept): the set-point the arm fit estimated,
    whose standard error and shared gravity error ``meta`` records. The row's own mean
    is of the median-filtered torque, over samples the filter's outlier test chose about the
    gravity-free torque, and differed from the level's by up to 0.7 of its standard error on
    the Panda's sweeps (``tests/_arm_sweeps.py``, seed 0)."""
    speed = np.array([abs(r["velocity"]) for r in levels])
    temp = np.array([r["temperature"] for r in levels])
    sign = np.array([r["direction"] for r in levels])
    load = np.array([r["load"] for r in levels])
    count = np.array([r["count"] for r in levels], dtype=float)
    out = np.zeros(len(samples))
    chosen = []
    n_rows = np.full(len(samples), -1.0) if samples.count is None else samples.count
    for i, (v, t) in enumerate(zip(samples.velocity, samples.temperature, strict=True)):
        near = np.abs(speed - abs(v)) / max(abs(v), 1e-12) + np.abs(temp - t)
        if not combined:  # the same set-point's samples: one count, speeds summarised apart
            near = near + (count != n_rows[i])
        signs = (1, -1) if combined else (1 if v > 0 else -1,)
        picks = [
            int(np.flatnonzero(sign == s)[np.argmin(near[sign == s])])
            for s in signs
            if (sign == s).any()
        ]
        if picks:
            out[i] = np.average(load[picks], weights=count[picks])
        chosen.append(picks[0] if len(picks) == 1 else -1)
    if combined:
        return replace(samples, load=out, meta={**samples.meta, **meta})
    friction = samples.friction.copy()
    rows = None if samples.count is None else samples.count.copy()
    chosen = np.array(chosen, dtype=np.intp)
    once = np.bincount(chosen[chosen >= 0], minlength=len(levels)) == 1
    for i, k in enumerate(chosen):
        if k >= 0 and once[k]:  # one row per level: never two rows made copies of one
            friction[i] = levels[k]["friction"]
            if rows is not None:
                rows[i] = count[k]
    return replace(
        samples,
        friction=friction,
        count=rows,
        load=out,
        meta={**samples.meta, **meta},
    )
