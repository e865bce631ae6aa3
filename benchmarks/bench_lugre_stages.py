"""Where the time of one LuGre identification from a trajectory goes, and how the output-error
search's SSE falls with its evaluations (issue 26's speed goal: 10 s for 60 s at 1 kHz).

Run: ``python benchmarks/bench_lugre_stages.py [--truth geared] [--kind chirp_pd]
[--duration 60] [--rate 1000] [--cpr 131072] [--seed 10]``. The log comes from the
independent simulator of ``bench_lugre.py`` (:mod:`_lugre_truth`). Prints the seconds at
which each stage of the fit began (its progress lines), each route's seconds and evaluations,
then the output error's best SSE after so many evaluations and the stretches of evaluations
in which it gained nothing (under 1e-6 of itself). Run it alone: the seconds are wall time.
"""

from __future__ import annotations

import argparse
import itertools
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import _lugre_truth as lt

#: A gain smaller than this share of the SSE counts as none.
NO_GAIN = 1e-6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--truth", default="geared")
    ap.add_argument("--kind", default="chirp_pd")
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--rate", type=float, default=1000.0)
    ap.add_argument("--cpr", type=int, default=2**17)
    ap.add_argument("--seed", type=int, default=10)
    a = ap.parse_args()

    import fricid.identify.dynamic._output as output
    from fricid.identify import fit
    from fricid.io import read_rawlog

    traces: list[list[tuple[float, float]]] = []  # one per output-error problem built
    plain = output.ResidualProblem

    class Traced(plain):  # every residual vector evaluated, with its time and SSE
        def __init__(self, residuals, *args, **kwargs):
            t0, trace = time.perf_counter(), []
            traces.append(trace)

            def traced(U):
                R = residuals(U)
                trace.extend((time.perf_counter() - t0, float(r @ r)) for r in np.atleast_2d(R))
                return R

            super().__init__(traced, *args, **kwargs)

    output.ResidualProblem = Traced
    truth = lt.ALL_TRUTHS[a.truth]
    log = lt.simulate(truth, a.kind, a.duration, a.rate, a.cpr, a.seed)
    marks: list[tuple[float, str]] = []
    with tempfile.TemporaryDirectory() as tmp:
        raw = read_rawlog(lt.write_log(log, Path(tmp) / "log.csv", truth, {}))
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fitted = fit(
                raw,
                "lugre",
                seed=a.seed,
                settings={
                    "progress": lambda i, n, label: marks.append((time.perf_counter(), label))
                },
            )
        total = time.perf_counter() - t0
    print(f"# {a.truth} {a.kind} {a.duration:g} s at {a.rate:g} Hz, {a.cpr} counts/rev, "
          f"seed {a.seed}: {total:.1f} s")  # fmt: skip
    print("## stages (seconds from the start at which each began)")
    for t, label in marks:
        print(f"{t - t0:8.2f}  {label}")
    print("## routes")
    routes = fitted.provenance["trajectory"]["routes"]
    for name, row in routes.items():
        print(
            f"{name:14s} {row.get('seconds', float('nan')):8.2f} s  {row.get('nfev')} evaluations"
        )
    if not traces:
        print("## no output error ran")
        return
    print("## output-error problems (the identification's, then the checks' re-identifications)")
    for i, trace in enumerate(traces):
        print(
            f"{i:3d}  {len(trace):6d} evaluations  {trace[-1][0]:8.1f} s"
            if trace
            else f"{i:3d}  none"
        )
    tr = np.array(traces[0])
    best = np.minimum.accumulate(tr[:, 1])
    print(f"## the identification's output error: best SSE {best[-1]:.6g}")
    for k in (11, 50, 100, 200, 500, 1000, 1500, 2000, 3000):
        if k <= len(tr):
            print(f"{k:6d} evaluations {tr[k - 1, 0]:8.1f} s  best {best[k - 1]:.6g}")
    gains = np.flatnonzero(np.diff(best) < -NO_GAIN * best[1:]) + 1
    edges = np.concatenate([[0], gains, [len(best) - 1]])
    stalls = [(int(b - a_), int(a_), int(b)) for a_, b in itertools.pairwise(edges)]
    print("## its longest stretches without a gain (evaluations, from, to)")
    for length, start, end in sorted(stalls, reverse=True)[:5]:
        print(f"{length:6d}  {start + 1} -> {end + 1}  best {best[start]:.6g}")


if __name__ == "__main__":
    main()
