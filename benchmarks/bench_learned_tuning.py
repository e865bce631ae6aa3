"""Held-out RMSE / noise of the learned defaults (``rbf``, ``hybrid``) on TUNING seeds of
:mod:`fricid.sim.heldout_laws` (never the reporting seeds 1001-1003 of ``bench_floor.py``):
what the structure search's folds (:mod:`fricid.identify.learned._rbf_folds`) were chosen with.

Usage: ``python benchmarks/bench_learned_tuning.py [--seeds 50] [--kinds grid,sigmoid]
[--random-folds-only] [--fit-seed 0]`` (about 2 minutes for 50 seeds on 2 idle cores;
``--random-folds-only`` deals no level folds, as for data with too few speed levels).

What it showed (seeds 0-49, mean / median / 90th percentile / max of held-out RMSE / noise,
2026-11-22, the machine shared by four engineers and an integrator):

==============  ==================================  ==================================
kind, family    random folds only (before)          random + level folds (now)
==============  ==================================  ==================================
grid rbf        1.196 / 1.195 / 1.247 / 1.287       1.196 / 1.199 / 1.241 / 1.287
grid hybrid     1.370 / 1.119 / 2.327 / 4.294       1.194 / 1.196 / 1.242 / 1.266
asym rbf        1.315 / 1.267 / 1.500 / 1.952       1.315 / 1.267 / 1.500 / 1.952
asym hybrid     1.050 / 1.047 / 1.112 / 1.144       1.050 / 1.047 / 1.112 / 1.144
sigmoid rbf     1.128 / 1.127 / 1.187 / 1.225       1.128 / 1.127 / 1.187 / 1.225
sigmoid hybrid  1.033 / 1.035 / 1.077 / 1.167       1.033 / 1.035 / 1.077 / 1.167
==============  ==================================  ==================================

Level folds alone were rejected: with one end level kept in training they doubled the grid
``rbf``'s error (mean 2.11, worse on all 50 seeds); with two, grid ``hybrid`` 1.205 and
``rbf`` 1.225 (median 1.20 for both). Scoring ``max(random, levels / 4)`` instead of ``/ 2``:
grid ``hybrid`` 1.234, ``rbf`` 1.196.

The grid hybrid's tails under random folds were the ridge penalty (the 6 seeds above 2.2 took
1e-11, the others 1e-8, all the same backbone and structure: notes of
:mod:`fricid.identify.learned.hybrid`). With random folds only (data with too few speed levels) the
penalty is now chosen by the one-standard-error rule
(:func:`fricid.identify.learned._rbf_folds.choose_penalty`); ``--random-folds-only``, 23:32-23:36
UTC,
same seeds, the machine shared (load 2-2.5 on 2 cores):

==============  ==================================  ==================================
kind, family    random folds, best score (before)   random folds, one-SE rule (now)
==============  ==================================  ==================================
grid rbf        1.196 / 1.195 / 1.247 / 1.287       1.196 / 1.195 / 1.247 / 1.287
grid hybrid     1.370 / 1.119 / 2.327 / 4.294       1.110 / 1.106 / 1.152 / 1.172
asym rbf        1.315 / 1.267 / 1.500 / 1.952       1.308 / 1.259 / 1.500 / 1.860
asym hybrid     1.050 / 1.047 / 1.112 / 1.144       1.050 / 1.045 / 1.112 / 1.144
sigmoid rbf     1.128 / 1.127 / 1.187 / 1.225       1.130 / 1.124 / 1.192 / 1.225
sigmoid hybrid  1.033 / 1.035 / 1.077 / 1.167       1.033 / 1.035 / 1.077 / 1.167
==============  ==================================  ==================================

With level folds (the default here: every kind has 12-18 speeds) the rule is not applied and
the first table's right-hand column stands. Applied on top of level folds it was no better (grid
``hybrid`` 1.190 / 1.192 / 1.242 / 1.266, ``rbf`` 1.199 / 1.199 / 1.241 / 1.403: seed 18 went
from 1.26 to 1.40), and the level folds' weight does not move the grid's median (``levels /
3``: hybrid median 1.187, ``/ 4``: 1.195, with the rule).

After these runs the hybrid's residual was set to random folds with the rule
(``level_folds=False`` in :func:`fricid.identify.learned.hybrid.fit_hybrid`; checked against the
truth on the demo's design too, :mod:`fricid.identify.learned._rbf_folds` notes), the plain ``rbf``
keeping both fold kinds: the default run now deals the hybrid as in the second table's right
column and the ``rbf`` as in the first's (the code paths of those runs; this script was not
re-run as a whole after the change).

Since the compiled k-means++ seeding (:mod:`fricid.identify.learned._kmeans_kernel`, 2026-11-23: the
same draws, exact ties resolved by other rounding), the default run gives every ``hybrid`` row
and the ``asym`` and ``sigmoid`` ``rbf`` rows to within 0.001 of the tables above, and grid
``rbf`` 1.225 / 1.212 / 1.285 / 1.345. That is no loss: the fits' seed 0, with which the
defaults above were chosen, was a lucky one for the plain network on the grid. With fit seeds
1 and 2 the code before the change gave grid ``rbf`` 1.310 and 1.281 mean (the same fits and
ratios, a one-off script on commit 7c69422); with it, 1.301 and 1.287. The hybrid does not
depend on it: grid ``hybrid`` 1.110 / 1.083 / 1.085 / 1.076 mean with fit seeds 0 / 1 / 2 / 3
(``--kinds grid --fit-seed K``).
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import time
import warnings

import numpy as np

from fricid.identify import fit
from fricid.identify.learned import _rbf_folds
from fricid.sim.heldout_laws import KINDS, TUNING_SEEDS, draw


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=50)
    ap.add_argument("--kinds", default=",".join(KINDS))
    ap.add_argument("--fit-seed", type=int, default=0, help="the fits' random seed")
    ap.add_argument(
        "--random-folds-only",
        action="store_true",
        help="deal no level folds (as for data with fewer than MIN_LEVELS speed levels)",
    )
    args = ap.parse_args()
    if args.random_folds_only:
        _rbf_folds.MIN_LEVELS = 10**9
    warnings.simplefilter("ignore")
    seeds = TUNING_SEEDS[: args.seeds]
    print(f"seeds {seeds[0]}-{seeds[-1]}: held-out RMSE / noise, mean / median / p90 / max")
    for kind in args.kinds.split(","):
        fit(draw(kind, 0).train, "hybrid", seed=0)  # numba compiled, imports done
        for family in ("rbf", "hybrid"):
            ratios, seconds = [], []
            for seed in seeds:
                d = draw(kind, seed)
                t0 = time.perf_counter()
                m = fit(d.train, family, seed=args.fit_seed)
                seconds.append(time.perf_counter() - t0)
                r = m.predict(d.test.X, warn=False) - d.test.y
                ratios.append(float(np.sqrt(np.mean(r * r)) / d.noise))
            q = np.asarray(ratios)
            print(
                f"{kind:<15}{family:<8}{q.mean():.3f} / {np.median(q):.3f} / "
                f"{np.quantile(q, 0.9):.3f} / {q.max():.3f}  [{np.mean(seconds):.3f} s]",
                flush=True,
            )


if __name__ == "__main__":
    main()
