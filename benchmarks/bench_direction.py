"""A symmetric law on friction that differs by direction: does the fit say so?

Usage: ``python benchmarks/bench_direction.py [--model lugre] [--seeds 4] [--first-seed 10]
[--negs 1.0,0.9,0.8] [--truths geared,slow_stribeck,cdw95] [--kinds chirp_pd,trapezoid_pd,
torque_steps] [--duration 10] [--cpr 1048576] [--jobs 2]``.

The logs come from the independent simulator of ``bench_lugre.py`` (:mod:`_lugre_truth`, its
own RK4 joint and drive, at 1 kHz), with the negative direction's Coulomb and break-away levels
``neg`` times the positive's (``neg`` 1: symmetric). Each is identified through
:func:`fricid.identify.fit` with a symmetric law (``lugre`` by default). Half the levels'
difference is a constant torque that a motion over a small part of the range cannot tell from
the gravity, so a symmetric fit puts it into p_x, p_y with intervals that hold only if the
friction is the same both ways (:func:`fricid.identify.dynamic._outcome.direction_caveat`).

Per truth, kind and ``neg`` it prints: the fits; how many carry the caveat that the friction
differs by direction (``differs``, p <= 1e-3) or may (``may``: the levels' difference two
standard errors from zero where the log cannot tell it from the gravity); how many carry the
gravity note (``note``: the log cannot tell; beside a caveat or alone); how many said nothing
(``silent``); the fits whose 95 % intervals of p_x and p_y both held the truth (``grav ok``);
and the fits that missed the gravity and said nothing (``silent miss``, the confident wrong
answer this check exists for). On symmetric truths ``differs`` and ``may`` are false alarms.

``--model lugre_asym`` fits the levels per direction instead (no direction check: it has a
level each way); ``levels ok`` counts the fits whose every Coulomb level's interval held its
truth (``tau_c``, or ``tau_c_pos`` and ``tau_c_neg``), ``apart`` those whose two Coulomb
intervals do not overlap (on symmetric truths a difference invented).
"""

from __future__ import annotations

import argparse
import dataclasses
import multiprocessing
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _lugre_truth as lt


def task(args: tuple) -> dict:
    truth, kind, neg, seed, duration, cpr, model = args
    from fricid.identify import fit
    from fricid.io import read_rawlog

    t = dataclasses.replace(lt.TRUTHS[truth], neg=neg)
    with tempfile.TemporaryDirectory() as tmp:
        log = lt.simulate(t, kind, duration, 1000.0, cpr, seed)
        path = lt.write_log(log, Path(tmp) / "log.csv", t, {})
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fitted = fit(read_rawlog(path), model, seed=seed)
        seconds = time.perf_counter() - t0
    info = fitted.provenance["trajectory"]
    caveats = info.get("caveats", [])
    truth_names = t.fricid_names()
    held = all(
        info["joint"][n]["ci95_low"] <= truth_names[n] <= info["joint"][n]["ci95_high"]
        for n in ("p_x", "p_y")
    )
    levels = {"tau_c_pos": t.Fc, "tau_c_neg": t.Fc * t.neg}
    if "tau_c_pos" not in fitted.parameters:
        levels = {"tau_c": t.Fc, **({"tau_c ": t.Fc * t.neg} if neg != 1.0 else {})}
    cis = {n: fitted.parameters[n.strip()].ci95 for n in levels}
    levels_ok = all(lo <= levels[n] <= hi for n, (lo, hi) in cis.items())
    (lo_a, hi_a), (lo_b, hi_b) = (cis.get(n, (0.0, 0.0)) for n in ("tau_c_pos", "tau_c_neg"))
    apart = "tau_c_pos" in cis and (hi_b < lo_a or hi_a < lo_b)
    claims = _claims(fitted, t) if model == "lugre_asym" or (model == "lugre" and neg == 1) else {}
    return {
        "key": (truth, kind, neg),
        "differs": any(c.startswith("the friction differs by direction") for c in caveats),
        "may": any(c.startswith("the friction may differ by direction") for c in caveats),
        "note": bool(info.get("gravity_note")),
        "held": held,
        "levels_ok": levels_ok,
        "apart": apart,
        "claims": claims,
        "seconds": seconds,
    }


def _claims(fitted, t) -> dict[str, list[int]]:
    """Per parameter (both directions' under the symmetric name), [covered, claimed]: the
    closed 95 % intervals (not open at the search box, not flagged not determined) and those
    that held the truth (``neg`` times the forward Coulomb and break-away levels backwards)."""
    truth = t.fricid_names()
    back = {"tau_c": t.neg, "tau_s": t.neg}
    out: dict[str, list[int]] = {}
    rows = [
        (n, p.ci95, p.low_open or p.high_open or p.not_determined)
        for n, p in fitted.parameters.items()
    ]
    joint = fitted.provenance["trajectory"]["joint"]
    rows += [(n, (r["ci95_low"], r["ci95_high"]), False) for n, r in joint.items()]
    for name, (lo, hi), open_ in rows:
        base = name.removesuffix("_pos").removesuffix("_neg")
        if open_ or not (np.isfinite(lo) and np.isfinite(hi)) or base not in truth:
            continue
        value = truth[base] * (back.get(base, 1.0) if name.endswith("_neg") else 1.0)
        row = out.setdefault(base, [0, 0])
        row[0] += int(lo <= value <= hi)
        row[1] += 1
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", default="lugre")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--first-seed", type=int, default=10)
    ap.add_argument("--negs", default="1.0,0.9,0.8")
    ap.add_argument("--truths", default="geared,slow_stribeck,cdw95")
    ap.add_argument("--kinds", default="chirp_pd,trapezoid_pd,torque_steps")
    ap.add_argument("--duration", type=float, default=10.0)
    ap.add_argument("--cpr", type=int, default=2**20)
    ap.add_argument("--jobs", type=int, default=2)
    a = ap.parse_args()
    tasks = [
        (truth, kind, float(neg), seed, a.duration, a.cpr, a.model)
        for truth in a.truths.split(",")
        for kind in a.kinds.split(",")
        for neg in a.negs.split(",")
        for seed in range(a.first_seed, a.first_seed + a.seeds)
    ]
    t0 = time.perf_counter()
    if a.jobs > 1:
        with multiprocessing.get_context("spawn").Pool(a.jobs) as pool:
            rows = pool.map(task, tasks)
    else:
        rows = [task(x) for x in tasks]
    print(
        f"# bench_direction: {len(rows)} fits of {a.model}, {time.perf_counter() - t0:.0f} s wall"
    )
    print(f"# {a.duration:g} s logs at 1 kHz, {a.cpr} counts/rev, seeds {a.first_seed}-"
          f"{a.first_seed + a.seeds - 1}")  # fmt: skip
    head = ("setting", "fits", "differs", "may", "note", "silent", "grav ok", "silent miss")
    head = (*head, "levels ok", "apart")
    print(f"{head[0]:<34}" + "".join(f"{h:>12}" for h in head[1:]))
    groups: dict = {}
    for r in rows:
        groups.setdefault(r["key"], []).append(r)
    totals: dict = {}
    for key, rs in groups.items():
        counts = _counts(rs)
        for k, v in counts.items():
            totals.setdefault(key[2], {}).setdefault(k, 0)
            totals[key[2]][k] += v
        print(f"{f'{key[0]} {key[1]} neg {key[2]:g}':<34}" + _cells(counts))
    print()
    for neg, counts in totals.items():
        print(f"{f'all neg {neg:g}':<34}" + _cells(counts))
    claims: dict = {}
    for r in rows:
        for name, (c, n) in r["claims"].items():
            row = claims.setdefault(name, [0, 0])
            row[0], row[1] = row[0] + c, row[1] + n
    if claims:
        c, n = (sum(v[i] for v in claims.values()) for i in (0, 1))
        print("\n# the closed 95 % intervals that held the truth (per direction under one name)")
        print("  ".join(f"{k} {v[0]}/{v[1]}" for k, v in claims.items()) + f"; all {c}/{n}")


def _counts(rs: list[dict]) -> dict:
    silent = [not (r["differs"] or r["may"] or r["note"]) for r in rs]
    return {
        "fits": len(rs),
        "differs": sum(r["differs"] for r in rs),
        "may": sum(r["may"] for r in rs),
        "note": sum(r["note"] for r in rs),
        "silent": sum(silent),
        "grav ok": sum(r["held"] for r in rs),
        "silent miss": sum(s and not r["held"] for s, r in zip(silent, rs, strict=True)),
        "levels ok": sum(r["levels_ok"] for r in rs),
        "apart": sum(r["apart"] for r in rs),
    }


def _cells(counts: dict) -> str:
    return "".join(f"{v:>12}" for v in counts.values())


if __name__ == "__main__":
    main()
