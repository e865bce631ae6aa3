"""The speed of fricid's default fit paths (issue 14), as ratios against baselines in one run.

Usage: ``python benchmarks/bench_fitpath.py [--repeats 20]``. Prints four tables, each
against a baseline measured in the same process (timings on a shared machine are noisy; the
ratios are what to read):

1. ``fit --method rwsavsbas`` on the paper2 preset's 17 samples (Stribeck, delta = 1):
   compiled kernel path, numpy path (``jit=False``), against evaluating the same number of
   candidates in batches of 100,000 (numpy and kernel);
2. the default ``lm`` (``minimize(..., "lm")``: one start unless doubtful) and the old
   8-start ``lm`` against scipy's ``least_squares`` called directly on the same residuals from
   the same start: seconds per fit and the SSE reached;
3. the compile time of the compiled paths (RWSAVSBAS's outer iteration, the study's kernel and
   the models' kernel) in a first and a second process sharing a fresh numba cache;
4. GA's duplicate evaluations with and without ``dedupe``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from fricid.experiments.stribeck_problem import paper2_samples
from fricid.extract import extract
from fricid.identify import fit
from fricid.identify.problem import IdentificationProblem
from fricid.models import get_model
from fricid.optim import minimize
from fricid.optim._api import Objective
from fricid.optim._least_squares import LeastSquaresLM
from fricid.samples import FrictionSamples
from fricid.sim import preset, simulate

#: What a fresh process runs to compile the fast paths (time printed on its last line).
_CHILD = """
import time
t = time.perf_counter()
import numpy as np
from fricid.experiments.stribeck_problem import StribeckProblem, sse_objective
from fricid.identify.problem import IdentificationProblem
from fricid.models import get_model
from fricid.optim import minimize_runs
from fricid.optim import _rws_numba  # imports numba
from fricid.models import _kernels
t_import = time.perf_counter() - t
v = np.linspace(-1.0, 1.0, 17)
y = np.sign(v) * 0.3 + 0.01 * v
t = time.perf_counter()
study = StribeckProblem(v, y)
minimize_runs(sse_objective(study, jit=True), study.bounds, "rwsavsbas", seed=0, runs=8,
              options={"n_outer": 1})
data = (np.column_stack([v, 0 * v, 0 * v]), y)
problem = IdentificationProblem(get_model("stribeck"), data, fixed={"delta": 1.0})
minimize_runs(problem.objective(), problem.bounds, "rwsavsbas", seed=0, runs=1,
              options={"n_outer": 1})
t_compile = time.perf_counter() - t
stats = _rws_numba.outer_iteration.stats
print(sum(stats.cache_hits.values()), sum(stats.cache_misses.values()), t_import, t_compile)
"""


def _best(f, repeats: int) -> float:
    """Best wall time of ``repeats`` calls (other processes' load hits every method alike)."""
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def rwsavsbas_table(samples: FrictionSamples, problem: IdentificationProblem) -> None:
    kw = {"fixed": {"delta": 1.0}, "intervals": "none", "seed": 0}
    fit(samples, "stribeck", "rwsavsbas", options={"n_outer": 2}, **kw)  # compile / load
    t = time.perf_counter()
    fast = fit(samples, "stribeck", "rwsavsbas", **kw)
    t_fast = time.perf_counter() - t
    t = time.perf_counter()
    slow = fit(samples, "stribeck", "rwsavsbas", options={"jit": False}, **kw)
    t_slow = time.perf_counter() - t
    n = fast.optimizer.nfev
    lo, hi = problem.bounds[:, 0], problem.bounds[:, 1]
    X = lo + np.random.default_rng(0).random((n, problem.n_free)) * (hi - lo)
    chunks = np.array_split(X, max(1, n // 100_000))
    compiled = problem.objective()
    t_np = _best(lambda: [problem.evaluate(c) for c in chunks], 3)
    t_k = _best(lambda: [compiled(c) for c in chunks], 3)
    # the floor of any path that calls the numpy objective once per inner iteration (3
    # candidates): n / 3 such calls, timed on 10,000 and scaled
    three = X[:3].copy()
    t = time.perf_counter()
    for _ in range(10_000):
        problem.evaluate(three)
    t_floor = (time.perf_counter() - t) * (n / 3) / 10_000
    same = max(abs(fast.params[k] - slow.params[k]) for k in fast.params)
    print(f"\n1. fit --method rwsavsbas, 17 samples, {n} evaluations per fit")
    print(f"{'path':44s} {'seconds':>8s} {'x batch numpy':>14s}")
    for label, sec in (
        ("batched evaluation, numpy (baseline)", t_np),
        ("batched evaluation, compiled kernel", t_k),
        ("fit, compiled kernel (fricid's default)", t_fast),
        ("fit, numpy path (jit=False)", t_slow),
        ("numpy objective alone, 3 candidates per call", t_floor),
    ):
        print(f"{label:44s} {sec:8.3f} {sec / t_np:14.2f}")
    print(f"largest parameter difference compiled vs numpy: {same:.2e}")
    print(
        "(RWSAVSBAS is sequential: one call of 3 candidates per inner iteration; the last row "
        "is the floor of any numpy path)"
    )


def lm_table(
    problem: IdentificationProblem,
    repeats: int,
    extracted: FrictionSamples,
    bare: FrictionSamples,
) -> None:
    x0 = problem.start()
    lo, hi = problem.bounds[:, 0], problem.bounds[:, 1]

    def scipy_direct():
        return least_squares(lambda th: problem.residuals(th[None])[0], x0, bounds=(lo, hi))

    def fricid_lm(**opts):
        return minimize(
            problem.evaluate,
            problem.bounds,
            "lm",
            x0=x0,
            residuals=problem.residuals,
            seed=0,
            options=opts,
        )

    rows = {
        "scipy least_squares direct (baseline)": scipy_direct,
        "lm, default (one start unless doubtful)": fricid_lm,
        "lm, 8 starts (before issue 14)": lambda: fricid_lm(restart="always"),
    }
    sse = {}
    times: dict[str, list[float]] = {label: [] for label in rows}
    for label, f in rows.items():
        r = f()
        sse[label] = 2.0 * r.cost if hasattr(r, "cost") else float(r.fun)
    for _ in range(repeats):  # interleaved, so the machine's load hits all alike
        for label, f in rows.items():
            times[label].append(_best(f, 1))
    secs = {label: float(np.median(t)) for label, t in times.items()}
    base = "scipy least_squares direct (baseline)"
    print(
        "\n2. default lm against scipy least_squares on the same residuals, same start "
        f"(median of {repeats}, interleaved)"
    )
    print(f"{'method':44s} {'ms/fit':>8s} {'x scipy':>8s} {'SSE':>22s} {'SSE / scipy - 1':>16s}")
    for label in rows:
        print(
            f"{label:44s} {secs[label] * 1e3:8.2f} {secs[label] / secs[base]:8.2f} "
            f"{sse[label]:22.17g} {sse[label] / sse[base] - 1:16.2e}"
        )
    # the residual function scipy calls: fricid's wrapper (unit box, counting, best point)
    # against the bare residuals scipy gets when called directly
    solver = LeastSquaresLM({}, dim=problem.n_free, residuals=problem.residuals)
    solver.bind(Objective(problem.evaluate, problem.bounds, 10**9), [np.random.default_rng(0)])
    wrapped = solver._residual_fun()
    u0 = (x0 - lo) / (hi - lo)
    t_wrap = _best(lambda: [wrapped(u0) for _ in range(1000)], 5) / 1000
    t_raw = _best(lambda: [problem.residuals(x0[None])[0] for _ in range(1000)], 5) / 1000
    print(
        f"one residual vector: {t_raw * 1e6:.1f} us called directly, {t_wrap * 1e6:.1f} us "
        f"through lm's wrapper ({t_wrap / t_raw:.2f}x)"
    )
    for label, smp in (("extracted samples (scatter known)", extracted), ("bare arrays", bare)):
        t = time.perf_counter()
        f = fit(smp, "stribeck", fixed={"delta": 1.0}, intervals="none")
        print(
            f"whole fit() with lm on {label}: {time.perf_counter() - t:.3f} s, "
            f"{f.optimizer.nfev} evaluations ({f.optimizer.message[:60]})"
        )


def compile_table() -> None:
    env = {**os.environ}
    src = Path(__file__).resolve().parents[1] / "src"
    env["PYTHONPATH"] = os.pathsep.join([str(src), env.get("PYTHONPATH", "")])
    print("\n3. compiling the fast paths (RWSAVSBAS outer iteration, study and model kernels)")
    print(
        f"{'process (fresh numba cache)':44s} {'import s':>9s} {'compile s':>10s} "
        f"{'cache hits':>10s} {'misses':>7s}"
    )
    with tempfile.TemporaryDirectory() as cache:
        env["NUMBA_CACHE_DIR"] = cache
        seconds = []
        for label in ("first process (cold cache)", "second process"):
            out = subprocess.run(
                [sys.executable, "-c", _CHILD], env=env, capture_output=True, text=True
            )
            if out.returncode:
                print(out.stderr)
                raise SystemExit(out.returncode)
            hits, misses, t_import, t_compile = out.stdout.split()[-4:]
            seconds.append(float(t_compile))
            print(
                f"{label:44s} {float(t_import):9.2f} {float(t_compile):10.2f} {hits:>10s} "
                f"{misses:>7s}"
            )
    print(f"second / first: {seconds[1] / seconds[0]:.3f}")


def ga_table(problem: IdentificationProblem) -> None:
    print("\n4. GA (default budget 4000) on the same problem: duplicate evaluations")
    print(f"{'setting':44s} {'evaluated':>9s} {'duplicates':>11s} {'best SSE':>12s}")
    for label, opts in (("dedupe=False (before issue 14)", {"dedupe": False}), ("default", {})):
        seen: list[tuple] = []

        def fun(X: np.ndarray, seen: list[tuple] = seen) -> np.ndarray:
            seen.extend(map(tuple, X))
            return problem.evaluate(X)

        r = minimize(fun, problem.bounds, "ga", seed=0, options=opts)
        dup = 1.0 - len(set(seen)) / len(seen)
        print(f"{label:44s} {len(seen):9d} {dup:11.2%} {r.fun:12.4g}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20, help="timing repeats (best of)")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    warnings.simplefilter("ignore")
    extracted = extract(simulate(preset("paper2"), seed=0), gravity="none").samples
    v, y = paper2_samples(0)
    samples = FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=y)
    problem = IdentificationProblem(get_model("stribeck"), samples, fixed={"delta": 1.0})
    print("fricid fit paths (issue 14); 2 shared cores: read the ratios")
    rwsavsbas_table(samples, problem)
    lm_table(problem, args.repeats, extracted, samples)
    compile_table()
    ga_table(problem)
    print(f"\ntotal {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
