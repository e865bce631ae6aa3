"""The derivative window from the encoder, for a static model's trajectory regression.

Usage: ``python benchmarks/bench_window.py [--first-seed 100] [--seeds 20]
[--counts 4096,16384,1048576]`` (the truth's law is Coulomb-viscous, and so is the model).

Logs of :mod:`_encoder_truth` (an open-loop joint along a multi-sine, not the virtual joint's
code), identified by :func:`fricid.identify.dynamic.trajectory.fit_trajectory` twice: with
the derivative window fixed at the default 21 ms (fricid before :mod:`fricid.identify.
dynamic._window`), and chosen from the encoder (now). Prints per encoder and way: the 95 %
intervals covering the truth per parameter, J's median and worst relative error, the median
window, the fits warned about (``DerivativeBiasWarning``) and the seconds per fit as a ratio
to the fixed window's.
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

from _encoder_truth import TRUTH, encoder_log
from fricid.identify.dynamic.trajectory import (
    DerivativeBiasWarning,
    DerivativeFilter,
    fit_trajectory,
)


def run(counts: float, seeds: range, model: str, fixed: bool) -> dict:
    """Coverage, J's errors, windows, warnings and seconds over ``seeds``."""
    cover = dict.fromkeys(TRUTH, 0)
    errors, windows, warned, seconds = [], [], 0, 0.0
    for seed in seeds:
        log = encoder_log(seed, counts)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            t0 = time.perf_counter()
            fitted = fit_trajectory(log, model, derivative=DerivativeFilter() if fixed else None)
            seconds += time.perf_counter() - t0
        warned += any(issubclass(w.category, DerivativeBiasWarning) for w in caught)
        rows = {n: (p.value, *p.ci95) for n, p in fitted.parameters.items()}
        traj = fitted.provenance["trajectory"]
        rows.update(
            {n: (r["value"], r["ci95_low"], r["ci95_high"]) for n, r in traj["joint"].items()}
        )
        for name in cover:
            _, low, high = rows[name]
            cover[name] += bool(low <= TRUTH[name] <= high)
        errors.append(rows["inertia"][0] / TRUTH["inertia"] - 1)
        windows.append(traj["derivative"]["window"])
    return {
        "cover": cover,
        "errors": np.abs(errors),
        "windows": windows,
        "warned": warned,
        "seconds": seconds,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--first-seed", type=int, default=100)
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--counts", default="4096,16384,1048576")
    a = ap.parse_args()
    seeds = range(a.first_seed, a.first_seed + a.seeds)
    print(
        f"# bench_window: {'coulomb_viscous'}, seeds {seeds.start}-{seeds.stop - 1}, 20 s at 1 kHz"
    )
    names = " ".join(f"{n:>8}" for n in TRUTH)
    print(f"{'counts':>9} {'window':>8} {names}  J med err  J max err  median ms  warned  time")
    for counts in (float(c) for c in a.counts.split(",")):
        base = None
        for fixed in (True, False):
            r = run(counts, seeds, "coulomb_viscous", fixed)
            base = base or r["seconds"]
            cov = " ".join(f"{r['cover'][n]:>4}/{len(seeds):<3}" for n in TRUTH)
            print(
                f"{counts:>9.0f} {'21 ms' if fixed else 'encoder':>8} {cov}  "
                f"{100 * np.median(r['errors']):>8.2f}%  {100 * r['errors'].max():>8.2f}%  "
                f"{1e3 * np.median(r['windows']):>9.0f}  {r['warned']:>6}  "
                f"{r['seconds'] / base:.2f}x"
            )


if __name__ == "__main__":
    main()
