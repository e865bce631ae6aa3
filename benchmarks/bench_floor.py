"""Held-out RMSE / noise of every model family on issue 15's held-out laws, the paper-1 preset's
unseen region (BAS-RBFNN paper Fig. 10), and training times.

Usage: ``python benchmarks/bench_floor.py [--seeds 3] [--repeats 3] [--no-gp]`` (6 minutes on
2 idle cores, a third of it scikit-learn's GP on the grid; BLAS is held to one thread, see
below; ``--no-gp`` skips scikit-learn's GP, about 4 GB on the paper-1 preset).

Part 1, for each kind of :mod:`fricid.sim.heldout_laws` (``grid``, ``asym_arrhenius``,
``sigmoid``) and each of its REPORTING seeds (1001-1003, never used to choose a default; the
tuning seeds are 0-99): train on the noisy design grid, predict the held-out set (random points
in the grid's box, with their own noise), and print the mean over seeds of held-out RMSE /
noise (1.0 = a model equal to the truth) and the training seconds, for

* ``best analytic``: the best held-out ratio among the analytic families the hybrid's backbone
  selection tries (:func:`fricid.identify.learned.hybrid.backbone_candidates`: those
  :func:`fricid.identify.static.select.candidates` lists the data support, and their ``*_temp``
  variants when the temperature varies): an oracle choice among them, flattering them;
* ``rbf plain``: ``fit(samples, "rbf", settings={"network": {"linear_tail": False, "velocity_scale":
  None}})``: no structure, the size, widths and penalty still cross-validated;
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

What it showed (``python benchmarks/bench_floor.py``, 2026-11-23 01:18 UTC, the machine idle
but for this run, 360 s; held-out RMSE / noise, mean over seeds 1001-1003, training seconds in
brackets: the fastest of 3 fits, mean over the same seeds). The plain ``rbf`` scores its
structure by random folds and folds of whole speed levels; the hybrid's residual by random
folds with the ridge penalty's one-standard-error rule (:mod:`fricid.identify.learned._rbf_folds`
notes why each):

==============  ===================  ====================  ================
family          grid (1848 points)   asym_arrhenius (150)  sigmoid (540)
==============  ===================  ====================  ================
best analytic   10.52 (msk_temp)     0.98 (stribeck_temp_  0.99 (msk_asym)
                                     asym)
rbf plain       19.49 [0.298 s]      9.37 [0.029 s]        10.14 [0.053 s]
rbf             1.19 [0.855 s]       1.36 [0.039 s]        1.10 [0.074 s]
hybrid          **1.08** [0.554 s]   **1.01** [0.068 s]    **0.99** [0.092 s]
gp              1.24 [2.270 s]       1.13 [0.106 s]        0.99 [1.119 s]
sklearn GP      1.43 [22.902 s]      1.12 [0.045 s]        1.16 [0.942 s]
MLP             16.41 [0.073 s]      16.73 [0.018 s]       9.53 [0.035 s]
==============  ===================  ====================  ================

The default learned model (``hybrid``) meets 1.10 on every kind, the grid only on average: seed
1001 alone is 1.15 (the ``--full-gp`` run below). Over the tuning seeds 0-49 the grid's hybrid
is 1.110 mean, 1.106 median, 1.172 max with the fits' seed 0 and 1.076-1.085 mean with seeds 1-3
(``python benchmarks/bench_learned_tuning.py [--fit-seed K]``): with the best-scoring penalty
instead of the one-standard-error rule it was 1.37 mean, 7 of 50 seeds at 2.3-4.3x (the
reporting seeds' 1.08 then was luck), and with level folds for the residual 1.19 mean, 1.20
median. In the paper-1 unseen region the hybrid's mean / max error is 0.80 / 2.49 mN m with the
``msk_temp`` backbone, 1.55 x the averaged samples' noise of 0.51 mN m (goal 2 x: met; ``vlt``
8.50 / 12.70, ``gp`` 0.56 / 1.73, the BAS-RBFNN paper 1.2 / 6.3; scikit-learn's exact GP 0.44 /
0.82 after 934 s: ``--seeds 1 --repeats 1 --full-gp``, 2026-11-23 01:27 UTC, the machine shared
with the test suite). ``rbf`` there: 4.86 / 15.09 with level folds (2.28 / 4.60 with random
folds only, before them): the level folds cost the plain network's extrapolation; not examined
further.

Training time, hybrid / GP (goal <= 0.1), the same run; on the paper-1 preset scikit-learn's
GP is not fitted (its optimiser needs tens of likelihood gradients of 6615 x 6615 x 6 at half a
minute and 4 GB each; ``--full-gp`` fits it: 934 s, against which the hybrid's 1.40 s is
0.0015): the bench times the least it needs (:func:`_sklearn_gp_lower_bound`, 37.9 s), so the
ratio printed is an upper bound:

==============  ============  ==============  ============  ==============
reference       grid          asym_arrhenius  sigmoid       paper-1 (6615)
==============  ============  ==============  ============  ==============
sklearn GP      0.024 met     1.497 MISSED    0.097 met     <= 0.037 met
fricid ``gp``   0.244 MISSED  0.641 MISSED    0.082 met     0.835 MISSED
==============  ============  ==============  ============  ==============

The sigmoid kind sits at the goal: the ``--full-gp`` run (seed 1001, one fit per timing, the
machine shared) gave 0.106, and earlier runs (2026-11-22 22:16-23:40 UTC, before the compiled
k-means++ seeding, other loads) 0.120-0.165 against scikit-learn's GP. Before the lean backbone
path the hybrid took 2.8 / 1.6 / 1.0 s. The hybrid's seconds go (sigmoid, wall-clock per phase,
a one-off timing of seed 1001): about 45 % to the backbone's lean least-squares fits (8
candidates, one ``lm`` start each, and the winner's certified fit), 50 % to the residual
network's cross-validated structure (about 20 candidates per direction: k-means placements and
ridge solves); on the grid over 80 % to the latter (400-centre candidates: Gram matrices and
Cholesky factorisations of 400 x 400). Why the 150-point kind is missed: there scikit-learn's
exact GP trains in 45 ms (150 x 150 Cholesky factorisations), and the least a BIC-chosen
backbone costs, one least-squares fit of the family the hybrid chose (``stribeck_temp_asym``, 11
parameters, from its default start), took 8.7 ms, 0.19 x the GP's, before the eleven other
candidates, the certified refit and the residual network (the bench prints this floor for every
kind). fricid's ``gp`` trains on an inducing subset of 400 points, so it is itself fast on the
grid and the paper-1 preset.

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
from fricid.identify.learned.hybrid import backbone_candidates
from fricid.models import MODELS, STATEFUL
from fricid.sim.heldout_laws import KINDS, REPORTING_SEEDS, draw

GOAL_RATIO = 1.10
GOAL_TIME = 0.1
GOAL_UNSEEN = 2.0


#: Fits per timing (``--repeats``): every timed family's seconds are the fastest of these
#: (the others lost to the machine's other work, not to the family).
REPEATS = 3


def _timed(fn, repeats: int | None = None):
    """``fn()`` and its seconds: the fastest of ``repeats`` calls (default :data:`REPEATS`)."""
    best = np.inf
    for _ in range(REPEATS if repeats is None else repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return out, best


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
            m, dt = _timed(
                lambda name=name, fixed=fixed: fit(d.train, name, fixed=fixed or None), 1
            )
        except Exception:
            continue
        seconds += dt
        ratio = _ratio(lambda X, m=m: m.predict(X, warn=False), d)
        best = min(best, (ratio, m.model))
    return best[0], best[1], seconds


def _fricid(d, name, **kw):
    """Held-out ratio, training seconds and the fitted model."""
    m, dt = _timed(lambda: fit(d.train, name, seed=0, **kw))
    return _ratio(lambda X: m.predict(X, warn=False), d), dt, m


def _sklearn_gp(k: int, optimizer="fmin_l_bfgs_b"):
    """Issue 15's scikit-learn GP on ``k`` standardised inputs: ARD RBF plus white noise,
    scikit-learn's default optimiser (``optimizer=None``: the kernel's initial values)."""
    from sklearn.gaussian_process import GaussianProcessRegressor
    from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    kernel = ConstantKernel() * RBF(np.ones(k), (1e-2, 1e3)) + WhiteKernel(1e-2, (1e-6, 1))
    return make_pipeline(
        StandardScaler(),
        GaussianProcessRegressor(kernel, normalize_y=True, random_state=0, optimizer=optimizer),
    )


def _sklearn(d, which: str):
    from sklearn.neural_network import MLPRegressor
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    pick = _sk_inputs(d.train)
    X = pick(d.train.X)
    t = np.sign(d.train.velocity) * d.train.y
    if which == "gp":
        est = _sklearn_gp(X.shape[1])
    else:
        est = make_pipeline(
            StandardScaler(),
            MLPRegressor(hidden_layer_sizes=(64, 64), max_iter=2000, random_state=0),
        )
    _, dt = _timed(lambda: est.fit(X, t))

    def predict(Xq):
        return np.sign(np.asarray(Xq)[:, 0]) * est.predict(pick(Xq))

    return _ratio(predict, d), dt


def _one_backbone_fit(samples, m) -> float:
    """Seconds of the least a BIC-chosen backbone costs: one lean least-squares fit
    (:func:`fricid.identify.learned.hybrid._lean_fit`) of the family the hybrid ``m`` chose on
    ``samples``, from its default start, before any other candidate, the certified refit or
    the residual network."""
    from fricid.identify.learned.hybrid import _lean_fit

    name = m.state["backbone"]["model"]
    rows = [r for r in m.state["backbone_selection"] if r["model"] == name and r["bic"]]
    fixed = min(rows, key=lambda r: r["bic"])["fixed"]
    return _timed(lambda: _lean_fit(samples, name, fixed))[1]


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
                _fricid(
                    d, "rbf", settings={"network": {"linear_tail": False, "velocity_scale": None}}
                )
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
        t_one = np.mean(
            [
                _one_backbone_fit(draw(kind, seed).train, v[2])
                for seed, v in zip(seeds, acc[DEFAULT], strict=True)
            ]
        )
        verdict.append(
            f"  its chosen backbone's one least-squares fit alone: {t_one:.4f} s = "
            + "; ".join(_time_verdict(t_one, acc, ref) for ref in REFERENCES)
        )
    for f in FAMILIES:
        print(f"{f:<16}" + "".join(f"{c:>26}" for c in rows[f]))
    print("\nGoals:")
    for line in verdict:
        print("  " + line)


def _sklearn_gp_lower_bound(samples) -> float:
    """Seconds that issue 15's scikit-learn GP needs at least to train on ``samples``: its fit
    at the kernel's initial values (one factorisation, which the optimised fit ends with) plus
    one evaluation of the log marginal likelihood and its gradient there (the optimiser's first
    step). The optimised fit repeats that evaluation tens of times; on the paper-1 preset one
    takes half a minute and needs about 4 GB, so the bench times this bound instead."""
    pick = _sk_inputs(samples)
    X = pick(samples.X)
    t = np.sign(samples.velocity) * samples.y
    est, t_fit = _timed(lambda: _sklearn_gp(X.shape[1], optimizer=None).fit(X, t), 1)
    gp = est[-1]
    _, t_grad = _timed(lambda: gp.log_marginal_likelihood(gp.kernel_.theta, eval_gradient=True), 1)
    return t_fit + t_grad


def part2(seed: int, with_gp: bool, full_gp: bool = False) -> None:
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
        f"{GOAL_UNSEEN}); paper's BAS-RBFNN 1.2/6.3, issue 15's GP 0.53/1.18"
    )
    print(
        f"  training {ratio:.3f} x fricid gp's {times['gp']:.3f} s "
        f"({'meets' if ratio <= GOAL_TIME else 'MISSES'} <= {GOAL_TIME})"
    )
    if full_gp:
        pick = _sk_inputs(samples)
        X, t = pick(samples.X), np.sign(samples.velocity) * samples.y
        est, t_gp = _timed(lambda: _sklearn_gp(X.shape[1]).fit(X, t), 1)
        pred = np.sign(unseen.X[:, 0]) * est.predict(pick(unseen.X))
        err = np.abs(pred - unseen.friction) * 1e3
        print(f"{'sklearn GP':<22}{err.mean():>8.2f}{err.max():>8.2f}{t_gp:>9.1f}")
        print(
            f"  training {times[DEFAULT] / t_gp:.4f} x sklearn GP's {t_gp:.1f} s "
            f"({'meets' if times[DEFAULT] / t_gp <= GOAL_TIME else 'MISSES'} <= {GOAL_TIME})"
        )
    elif with_gp:
        bound = _sklearn_gp_lower_bound(samples)
        ratio = times[DEFAULT] / bound
        print(
            f"  training <= {ratio:.3f} x sklearn GP's, which needs at least {bound:.1f} s "
            "(its fit at the initial kernel plus one likelihood gradient) "
            f"({'meets' if ratio <= GOAL_TIME else 'MISSES'} <= {GOAL_TIME})"
        )


def main() -> None:
    global REPEATS
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=len(REPORTING_SEEDS))
    ap.add_argument("--no-gp", action="store_true", help="skip the sklearn GP reference")
    ap.add_argument(
        "--full-gp",
        action="store_true",
        help="fit scikit-learn's GP on the paper-1 preset in full (15 minutes, 4 GB) "
        "instead of timing its lower bound",
    )
    ap.add_argument(
        "--repeats", type=int, default=REPEATS, help="fits per timing, the fastest kept"
    )
    args = ap.parse_args()
    seeds = REPORTING_SEEDS[: args.seeds]
    REPEATS = max(1, args.repeats)
    warnings.simplefilter("ignore")
    t0 = time.perf_counter()
    part1(seeds, not args.no_gp)
    part2(REPORTING_SEEDS[0], not args.no_gp, args.full_gp)
    print(f"\n(total {time.perf_counter() - t0:.0f} s; machine shared, timings are ratios)")


if __name__ == "__main__":
    main()
