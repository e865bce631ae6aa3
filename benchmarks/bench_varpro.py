"""``method="varpro"`` against ``lm`` and the other optimisers, on the same objective code.

Usage: ``python benchmarks/bench_varpro.py [--repeats 3] [--quick]``.

Every method goes through :func:`fricid.identify.fit` (one
:class:`~fricid.identify.problem.IdentificationProblem`, its convergence certificate
included; ``intervals="none"`` so that the table times the fit, not the profile intervals).
For each problem the table gives each method's wall time (the median of ``--repeats`` runs,
and its ratio to ``lm`` measured in the same process), evaluations (``nfev``: residual
vectors; for ``varpro`` the grid's model evaluations plus its polishes') and the SSE over the
best SSE any method found (``1`` is the optimum; the reference adds a 64-start ``lm``). The
Stribeck study row also checks against the study's own optimum
(:func:`fricid.experiments.stribeck_problem.global_optimum`).

Problems: the RWSAVSBAS Stribeck study (17 samples, delta = 1, the study's box), the paper2
preset with delta free, the paper1 preset's ``vlt`` and ``msk``, the real lead-screw
recordings (``stribeck_asym``, when ``../shared/data/real/`` is there) and three held-out
analytic laws (parameters drawn at random, 1 % noise) the defaults never saw.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from fricid.errors import FricidWarning
from fricid.experiments import stribeck_problem as sp
from fricid.extract import extract
from fricid.identify import fit
from fricid.models import get_model
from fricid.samples import FrictionSamples
from fricid.sim import preset, simulate

METHODS = ("varpro", "lm", "trf", "bas+lm", "de")
REAL = Path(__file__).resolve().parents[1] / ".." / "shared" / "data" / "real" / "epos-leadscrew"


def _preset(name: str, size: str) -> FrictionSamples:
    scenario = preset(name, size)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FricidWarning)
        return extract(simulate(scenario, seed=0), **scenario.extract_options()).samples


def heldout(name: str, seed: int) -> FrictionSamples:
    """Samples of ``name`` with parameters drawn in [0.3, 1.7] x the defaults, 1 % noise,
    30 velocity levels per direction (load and temperature drawn where the model uses them)."""
    rng = np.random.default_rng(seed)
    m = get_model(name)
    v = np.concatenate([np.geomspace(0.005, 2.0, 30), -np.geomspace(0.005, 2.0, 30)])
    load = rng.uniform(-5, 5, v.size) if "load" in m.inputs else np.zeros(v.size)
    temp = rng.uniform(20, 50, v.size) if "temperature" in m.inputs else np.full(v.size, 25.0)
    X = np.column_stack([v, load, temp])
    theta = m.defaults(X, np.ones(1)) * rng.uniform(0.3, 1.7, m.n_params)
    y = m.predict(theta, X)
    y = y + rng.normal(0.0, 0.01 * np.abs(y).max(), y.size)
    return FrictionSamples(velocity=v, load=load, temperature=temp, friction=y)


def problems(quick: bool) -> list[tuple[str, FrictionSamples, str, dict]]:
    """``(label, samples, model, fit keywords)`` of every benchmark problem."""
    v, y = sp.paper2_samples(0)
    study = FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=y)
    names = [n for n in get_model("stribeck").param_names if n != "delta"]
    box = {n: tuple(b) for n, b in zip(names, sp.BOUNDS, strict=True)}
    out = [
        ("stribeck study (RWSAVSBAS)", study, "stribeck", {"fixed": {"delta": 1.0}, "bounds": box})
    ]
    size = "quick" if quick else "reduced"
    out.append(("paper2 stribeck, delta free", _preset("paper2", size), "stribeck", {}))
    paper1 = _preset("paper1", "quick")
    out += [("paper1 vlt", paper1, "vlt", {}), ("paper1 msk", paper1, "msk", {})]
    if REAL.is_dir():
        from fricid.io import epos_steady_samples

        out.append(("lead screw stribeck_asym", epos_steady_samples(REAL), "stribeck_asym", {}))
    for k, name in enumerate(("stribeck", "msk", "coulomb_viscous")):
        out.append((f"held-out {name} #{k}", heldout(name, 100 + k), name, {}))
    return out


def run(samples, model, method, kw) -> tuple[float, float, int]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FricidWarning)
        t = time.perf_counter()
        f = fit(samples, model, method, intervals="none", **kw)
        return time.perf_counter() - t, float(f.metrics["sse"]), int(f.optimizer.nfev)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="quick presets, 1 repeat")
    args = parser.parse_args(argv)
    repeats = 1 if args.quick else args.repeats
    t0 = time.perf_counter()
    print(
        f"{'problem':30s} {'method':7s} {'time ms':>9s} {'/ lm':>6s} {'nfev':>7s} {'SSE/best':>10s}"
    )
    for label, samples, model, kw in problems(args.quick):
        rows = {}
        for method in METHODS:
            times, sse, nfev = [], np.inf, 0
            for _ in range(repeats):
                dt, sse, nfev = run(samples, model, method, kw)
                times.append(dt)
            rows[method] = (statistics.median(times), sse, nfev)
        ref = run(samples, model, "lm", {**kw, "options": {"n_starts": 64}, "max_evals": 400_000})
        best = min([ref[1]] + [r[1] for r in rows.values()])
        if label.startswith("stribeck study"):
            best = min(best, sp.global_optimum(sp.StribeckProblem(samples.X[:, 0], samples.y))[1])
        for method, (dt, sse, nfev) in rows.items():
            ratio = dt / rows["lm"][0]
            print(
                f"{label:30s} {method:7s} {1e3 * dt:9.1f} {ratio:6.2f} {nfev:7d} {sse / best:10.6f}"
            )
        print(flush=True)
    print(f"total {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
