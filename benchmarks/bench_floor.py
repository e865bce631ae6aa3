"""Held-out RMSE / noise of every model family on issue 15's held-out laws, the paper-1 preset's
unseen region (BAS-RBFNN paper Fig. 10), and training times.

Usage: ``python benchmarks/bench_floor.py [--seeds 3] [--no-gp]`` (a few minutes on 2 idle
cores; BLAS is held to one thread, see below).

Part 1, for each kind of :mod:`fricid.sim.heldout_laws` (``grid``, ``asym_arrhenius``,
``sigmoid``) and each of its REPORTING seeds (1001-1003, never used to choose a default; the
tuning seeds are 0-99): train on the noisy design grid, predict the held-out set (random points
in the grid's box, with their own noise), and print the mean over seeds of held-out RMSE /
noise (1.0 = a model equal to the truth) and the training seconds, for

* ``best analytic``: the best held-out ratio among the analytic families the hybrid's backbone
  selection tries (:func:`fricid.identify.hybrid.backbone_candidates`: those
  :func:`fricid.identify.select.candidates` lists the data support, and their ``*_temp``
  variants when the temperature varies): an oracle choice among them, flattering them;
* ``rbf plain``: ``fit(samples, "rbf", network={"linear_tail": False, "velocity_scale":
  None})``: no structure, the size, widths and penalty still cross-validated;
* ``rbf``: ``fit(samples, "rbf")``, ``fricid fit --model rbf``'s defaults: structured (linear
  tail, asinh velocity warp) with its structure chosen by cross-validation;
* ``hybrid``: ``fit(samples, "hybrid")``, ``fricid fit --model hybrid``'s defaults: the
  analytic backbone with the smallest BIC (temperature variants included) plus an RBF
  residual cross-validated as ``rbf``'s. This is THE DEFAULT learned model the goals refer
  to (:data:`DEFAULT`; the CLI's help names it the learned model to start with);
* ``gp``: ``fit(samples, "gp")``, fricid's Gaussian process (inducing subset of 400 points
  above 400 samples);
* ``sklearn GP``: scikit-learn's ``GaussianProcessRegressor`` with an ARD RBF kernel plus
  white noise (as issue 15's table; its configuration and default optimiser unchanged),
  timed on every reporting seed like the others;
* ``MLP``: scikit-learn's ``MLPRegressor`` with two hidden layers of 64.

Both scikit-learn models get the structure the fricid models get (the same for every model:
fair): standardised inputs ``asinh(|v| / v_min)``, the other measured inputs and the direction
(per-direction samples), target ``sign(v) F``, prediction ``sign(v) g``.

Goals (issue 15): the default model <= 1.10 x noise on each kind; its training time <= 0.1 x
the GP's on the same data, reported against both references: fricid's ``gp`` and issue 15's
scikit-learn GP (the mean seconds over the same seeds, in the same run; every timed family is
fitted once on a tuning draw first, so that no timing includes numba's compilation).

Part 2: the paper-1 preset (``paper1``, full design, the oracle's Gaussian noise on the true
friction, :func:`fricid.experiments.rbfnn_study.paper1_data`, seed 1001) against the true
friction in Fig. 10's unseen region (52-60 deg/s, positions -22 to -10 deg, 45-55 degC:
:func:`~fricid.experiments.rbfnn_study.unseen_region`): mean / max absolute error [mN m] and
training seconds of ``vlt``, ``rbf``, ``hybrid`` and ``gp``. Goal: the default's mean error <= 2
x the averaged samples' noise (the RMS of :func:`fricid.sim.expected_noise_std`).

What it showed (``python benchmarks/bench_floor.py``, 2026-11-22 23:40 UTC, the machine shared
with one other job, 116 s; held-out RMSE / noise, mean over seeds 1001-1003, mean training
seconds over the same seeds in brackets). The plain ``rbf`` scores its structure by random
folds and folds of whole speed levels; the hybrid's residual by random folds with the ridge
penalty's one-standard-error rule (:mod:`fricid.identify._rbf_folds` notes why each):

==============  ===================  ====================  ================
family          grid (1848 points)   asym_arrhenius (150)  sigmoid (540)
==============  ===================  ====================  ================
best analytic   10.52 (msk_temp)     0.98 (stribeck_temp_  0.99 (msk_asym)
                                     asym)
rbf plain       19.49 [0.326 s]      9.37 [0.038 s]        10.14 [0.072 s]
rbf             1.16 [0.845 s]       1.36 [0.054 s]        1.10 [0.098 s]
hybrid          **1.08** [0.568 s]   **1.01** [0.080 s]    **0.99** [0.110 s]
gp              1.24 [2.004 s]       1.13 [0.103 s]        0.99 [1.111 s]
sklearn GP      1.43 [24.197 s]      1.12 [0.044 s]        1.16 [0.906 s]
MLP             16.41 [0.077 s]      16.73 [0.016 s]       9.53 [0.034 s]
==============  ===================  ====================  ================

The default learned model (``hybrid``) meets 1.10 on every kind. Over the tuning seeds 0-49
the grid's hybrid is 1.110 mean, 1.106 median, 1.172 max (``python
benchmarks/bench_learned_tuning.py --random-folds-only``): with the best-scoring penalty
instead of the rule it was 1.37 mean, 7 of 50 seeds at 2.3-4.3x (the reporting seeds' 1.08
then was luck), and with level folds for the residual 1.19 mean, 1.20 median. In the paper-1
unseen region the hybrid's mean / max error is 0.80 / 2.49 mN m with the ``msk_temp``
backbone, 1.55 x the averaged samples' noise of 0.51 mN m (goal 2 x: met; ``vlt`` 8.50 /
12.70, ``gp`` 0.56 / 1.73, the BAS-RBFNN paper 1.2 / 6.3). ``rbf`` there: 4.86 / 15.09 with
level folds (2.28 / 4.60 with random folds only, before them): the level folds cost the plain
network's extrapolation; not examined further.

Training time, hybrid / GP (goal <= 0.1), the same run:

==============  ============  ==============  ============  ==============
reference       grid          asym_arrhenius  sigmoid       paper-1 (6615)
==============  ============  ==============  ============  ==============
fricid ``gp``   0.283 MISSED  0.776 MISSED    0.099 met     0.743 MISSED
sklearn GP      0.023 met     1.807 MISSED    0.121 MISSED  (not run)
==============  ============  ==============  ============  ==============

Earlier runs of the same bench (22:16-23:34 UTC, other loads) gave sigmoid ratios 0.097-0.121
against ``gp`` and 0.120-0.165 against scikit-learn's: it sits at the goal and passes or
fails with the load. Before the lean backbone path the hybrid took 2.8 / 1.6 / 1.0 s.
The hybrid's seconds go (sigmoid, wall-clock per phase, before the level folds): about
40 % to the backbone's lean least-squares fits (8 candidates, one ``lm`` start each, and the
winner's certified fit), 55 % to the residual network's cross-validated structure (about 25
candidates per direction: k-means placements, a third of the total, and ridge solves); on the
grid over 80 % to the latter (400-centre candidates, six of them: Gram matrices and Cholesky
factorisations of 400 x 400). Why the rest is missed: fricid's ``gp`` trains on an inducing
subset of 400 points, so it is itself fast on the grid and the paper-1 preset; on 150 points
both GPs take 45-110 ms (150 x 150 Cholesky factorisations), less than the fixed cost of a
dozen backbone fits and fifty cross-validation candidates.

Timings: the machine this was written on was shared (2 cores): read the seconds as ratios
within one run. OpenBLAS and OpenMP are held to one thread (``OPENBLAS_NUM_THREADS=1``,
``OMP_NUM_THREADS=1`` set before numpy loads, unless already set): on a loaded machine
OpenBLAS's threads made a 400 x 400 Cholesky factorisation 300 times slower, and OpenMP's
made scikit-learn's k-means (the RBF networks' centres) 6 to 150 times slower (1848 points
and 400 centres to 270 points and 5 centres, measured 2026-11-22).
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
from fricid.identify.hybrid import backbone_candidates
from fricid.models import MODELS, STATEFUL
from fricid.sim.heldout_laws import KINDS, REPORTING_SEEDS, draw

GOAL_RATIO = 1.10
GOAL_TIME = 0.1
GOAL_UNSEEN = 2.0


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


def _ratio(predict, d) -> float:
    r = predict(d.test.X) - d.test.y
    return float(np.sqrt(np.mean(r * r)) / d.noise)


def _sk_inputs(samples):
    """The structured inputs the scikit-learn models get: ``asinh(|v| / v_min)``, the other
    measured inputs, and the direction for per-direction samples; their target is
    ``sign(v) F`` (friction opposes motion), their prediction ``sign(v) g``."""
    cols = [["velocity", "load", "temperature"].index(n) for n in samples.measured]
    v_min = float(np.min(np.abs(samples.velocity[samples.velocity != 0])))
    both = samples.directions() != (0,)

    def pick(X):
        Z = np.asarray(X, dtype=float)[:, cols].copy()
        v = Z[:, 0].copy()
        Z[:, 0] = np.arcsinh(np.abs(v) / v_min)
        return np.column_stack([Z, np.sign(v)]) if both else Z

    return pick


def _analytic(d):
    """Best held-out ratio among the analytic candidates, its name, and the seconds of all."""
    names = backbone_candidates(d.train)
    best, seconds = (np.inf, "-"), 0.0
    for name, fixed in names:
        try:
            m, dt = _timed(lambda name=name, fixed=fixed: fit(d.train, name, fixed=fixed or None))
        except Exception:
            continue
        seconds += dt
        ratio = _ratio(lambda X, m=m: m.predict(X, warn=False), d)
        best = min(best, (ratio, m.model))
    return best[0], best[1], seconds


def _fricid(d, name, **kw):
    m, dt = _timed(lambda: fit(d.train, name, seed=0, **kw))
    return _ratio(lambda X: m.predict(X, warn=False), d), dt


def _sklearn(d, which: str):
    from sklearn.gaussian_process import GaussianProcessRegressor
    from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel
    from sklearn.neural_network import MLPRegressor
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    pick = _sk_inputs(d.train)
    X = pick(d.train.X)
    t = np.sign(d.train.velocity) * d.train.y
    if which == "gp":
        k = X.shape[1]
        kernel = ConstantKernel() * RBF(np.ones(k), (1e-2, 1e3)) + WhiteKernel(1e-2, (1e-6, 1))
        est = make_pipeline(
            StandardScaler(),
            GaussianProcessRegressor(kernel, normalize_y=True, random_state=0),
        )
    else:
        est = make_pipeline(
            StandardScaler(),
            MLPRegressor(hidden_layer_sizes=(64, 64), max_iter=2000, random_state=0),
        )
    _, dt = _timed(lambda: est.fit(X, t))

    def predict(Xq):
        return np.sign(np.asarray(Xq)[:, 0]) * est.predict(pick(Xq))

    return _ratio(predict, d), dt


#: The default learned model the goals refer to (``fricid fit --model hybrid``).
DEFAULT = "hybrid"

FAMILIES = ("best analytic", "rbf plain", "rbf", "hybrid", "gp", "sklearn GP", "MLP")


def _warm_up() -> None:
    """Fit every timed fricid family once on a tuning draw (seed 0) of each kind, untimed, so
    that no timing below includes numba's compilation or first imports."""
    for kind in KINDS:
        d = draw(kind, 0)
        for name in ("rbf", "hybrid", "gp"):
            if name != "gp" or "gp" in STATEFUL or "gp" in MODELS:
                fit(d.train, name, seed=0)


#: The training-time references: fricid's ``gp`` and issue 15's scikit-learn GP.
REFERENCES = ("gp", "sklearn GP")


def _time_verdict(t_def: float, acc, ref: str) -> str:
    vals = acc[ref]
    if not vals:
        return f"{ref}: not timed"
    t_ref = float(np.mean([v[1] for v in vals]))
    ratio = t_def / t_ref
    return (
        f"{ratio:.3f} x {ref}'s {t_ref:.3f} s "
        f"({'meets' if ratio <= GOAL_TIME else 'MISSES'} <= {GOAL_TIME})"
    )


def part1(seeds, with_gp: bool) -> None:
    _warm_up()
    print(
        "Held-out RMSE / noise (mean over reporting seeds), mean training seconds in brackets "
        "(every seed timed, numba compiled beforehand)\n"
    )
    head = f"{'family':<16}" + "".join(f"{k:>26}" for k in KINDS)
    print(head)
    rows: dict[str, list[str]] = {f: [] for f in FAMILIES}
    verdict = []
    for kind in KINDS:
        acc: dict[str, list[tuple[float, float]]] = {f: [] for f in FAMILIES}
        best_names = set()
        for seed in seeds:
            d = draw(kind, seed)
            r, name, dt = _analytic(d)
            acc["best analytic"].append((r, dt))
            best_names.add(name)
            acc["rbf plain"].append(
                _fricid(d, "rbf", network={"linear_tail": False, "velocity_scale": None})
            )
            acc["rbf"].append(_fricid(d, "rbf"))
            acc["hybrid"].append(_fricid(d, "hybrid"))
            if "gp" in STATEFUL or "gp" in MODELS:
                acc["gp"].append(_fricid(d, "gp"))
            if with_gp:
                acc["sklearn GP"].append(_sklearn(d, "gp"))
            acc["MLP"].append(_sklearn(d, "mlp"))
        for f in FAMILIES:
            vals = acc[f]
            if not vals:
                cell = "(not available)" if f == "gp" else "-"
            else:
                r = np.mean([v[0] for v in vals])
                t = np.mean([v[1] for v in vals])
                cell = f"{r:.2f} [{t:.3f} s]"
                if f == "best analytic":
                    cell = f"{r:.2f} {'/'.join(sorted(best_names))[:11]} [{t:.2f}s]"
            rows[f].append(cell)
        default = np.mean([v[0] for v in acc[DEFAULT]])
        t_def = float(np.mean([v[1] for v in acc[DEFAULT]]))
        verdict.append(
            f"{kind}: default ({DEFAULT}) {default:.2f} x noise "
            f"({'meets' if default <= GOAL_RATIO else 'MISSES'} <= {GOAL_RATIO}); training "
            f"{t_def:.3f} s = " + "; ".join(_time_verdict(t_def, acc, ref) for ref in REFERENCES)
        )
    for f in FAMILIES:
        print(f"{f:<16}" + "".join(f"{c:>26}" for c in rows[f]))
    print("\nGoals:")
    for line in verdict:
        print("  " + line)


def part2(seed: int) -> None:
    from fricid.experiments.rbfnn_study import paper1_data, unseen_region

    samples, _, floor = paper1_data("full", seed=seed, data="oracle")
    unseen = unseen_region("full")
    print(
        f"\nPaper-1 preset (full design, {len(samples)} samples, oracle noise, seed {seed}): "
        f"unseen region (Fig. 10, {len(unseen)} points), |error| [mN m]; averaged samples' "
        f"noise {1e3 * floor:.2f} mN m"
    )
    print(f"{'family':<22}{'mean':>8}{'max':>8}{'train s':>9}")
    mean_default = np.nan
    times = {}
    for name in ("vlt", "rbf", "hybrid", "gp"):
        m, times[name] = _timed(lambda name=name: fit(samples, name, seed=0))
        err = np.abs(m.predict(unseen.X, warn=False) - unseen.friction) * 1e3
        label = name + (f" ({m.state['backbone']['model']})" if name == "hybrid" else "")
        print(f"{label:<22}{err.mean():>8.2f}{err.max():>8.2f}{times[name]:>9.3f}")
        if name == DEFAULT:
            mean_default = float(err.mean())
    ok = mean_default <= GOAL_UNSEEN * 1e3 * floor
    ratio = times[DEFAULT] / times["gp"]
    print(
        f"Goal: default ({DEFAULT}) mean {mean_default:.2f} mN m = "
        f"{mean_default / (1e3 * floor):.2f} x the noise ({'meets' if ok else 'MISSES'} <= "
        f"{GOAL_UNSEEN}); training {ratio:.3f} x the gp's "
        f"({'meets' if ratio <= GOAL_TIME else 'MISSES'} <= {GOAL_TIME}); paper's BAS-RBFNN "
        "1.2/6.3, issue 15's GP 0.53/1.18"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=len(REPORTING_SEEDS))
    ap.add_argument("--no-gp", action="store_true", help="skip the sklearn GP reference")
    args = ap.parse_args()
    seeds = REPORTING_SEEDS[: args.seeds]
    warnings.simplefilter("ignore")
    t0 = time.perf_counter()
    part1(seeds, not args.no_gp)
    part2(REPORTING_SEEDS[0])
    print(f"\n(total {time.perf_counter() - t0:.0f} s; machine shared, timings are ratios)")


if __name__ == "__main__":
    main()
