"""How the held-out simulation under a PD drive answers a small error of the model, through the
log's own encoder and through an ideal one (``bench_lugre.py``'s ``enc-held`` and
``sim-held`` columns); ``benchmarks/results/heldout_chaos.txt``.

Usage: ``python benchmarks/bench_heldout_chaos.py [--duration 10] [--seed 1011]``.

The truth of :mod:`_lugre_truth` with one parameter moved (J by 0.1 % and 1 %, sigma_0 by 2 %,
sigma_1 by 10 %, tau_c and sigma_2 by 0.3 %) is driven by the truth's own plan (PD-tracked
chirp and trapezoid), and its applied torque compared with the truth's log: ``enc`` through
the log's encoder (the held-out log's torque, noise included: the RMS over the noise is 1 for
the truth itself), ``ideal`` both joints through an ideal encoder (2^40 counts/rev) and the
log's noise added (1 for the truth). A quantised loop is chaotic in the parameters: where it
feeds the rounding back (2^17 counts/rev at 1 kHz), the count pattern of a joint 0.1 % off
soon differs from the truth's and each differing count costs the loop's gain times a count;
through the ideal encoder the same joint is within a few per cent of the noise.
"""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np

import _lugre_truth as lt
from bench_lugre import IDEAL_CPR

#: Parameters moved, by their relative change.
MOVES = (
    ("J", 1e-3),
    ("J", 1e-2),
    ("sigma0", 0.02),
    ("sigma1", 0.1),
    ("Fc", 3e-3),
    ("sigma2", 3e-3),
)


def ratios(truth: lt.Truth, kind: str, duration: float, rate: float, cpr: int, seed: int):
    """Per move: (through the log's encoder, through an ideal one), RMS over the noise."""
    held = lt.simulate(truth, kind, duration, rate, cpr, seed)
    ref = lt.simulate(truth, kind, duration, rate, IDEAL_CPR, seed)
    noise = held["torque"] - held["applied"]
    out = []
    for field, rel in MOVES:
        plant = dataclasses.replace(truth, **{field: getattr(truth, field) * (1 + rel)})
        enc = lt.simulate(truth, kind, duration, rate, cpr, seed, plant=plant)
        ideal = lt.simulate(truth, kind, duration, rate, IDEAL_CPR, seed, plant=plant)
        e_enc = enc["applied"] - held["torque"]
        e_ideal = ideal["applied"] - ref["applied"] - noise
        out.append(tuple(float(np.sqrt(np.mean(e**2)) / truth.noise) for e in (e_enc, e_ideal)))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=1011)
    a = ap.parse_args()
    head = " ".join(f"{f}+{r:g}".rjust(13) for f, r in MOVES)
    print(f"# {a.duration:g} s logs, seed {a.seed}; each cell: enc / ideal, RMS over the noise")
    print(f"{'truth kind rate counts/rev':40s} {head}")
    for name, truth in lt.TRUTHS.items():
        for kind in ("chirp_pd", "trapezoid_pd"):
            for rate, cpr in ((1000.0, 2**17), (1000.0, 2**20), (200.0, 2**17)):
                cells = ratios(truth, kind, a.duration, rate, cpr, a.seed)
                row = " ".join(f"{e:6.3g}/{i:<6.3g}" for e, i in cells)
                print(f"{name + ' ' + kind + f' {rate:g} {cpr}':40s} {row}", flush=True)


if __name__ == "__main__":
    main()
