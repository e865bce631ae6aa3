"""LuGre identification with the simulations' rows in threads against one thread
(:func:`fricid.models.lugre.in_row_threads`), the same logs, the same code otherwise.

Usage: ``python benchmarks/bench_lugre_threads.py [--duration 60] [--repeats 2]``.

Logs from the independent simulator of ``benchmarks/_lugre_truth.py`` (the geared truth, a
PD-tracked chirp and trapezoid at 1 kHz, seed 0): at 2^17 counts/rev the filtered route is
refined by the output error (DIDIM: every evaluation a simulation of the joint), at 2^24 it is
not. Each identification runs ``--repeats`` times per setting, threads and one thread
alternating, after one untimed run that compiles the kernels; the table gives the best time
of each and their ratio, and checks that the estimates are the same bit for bit.
"""

from __future__ import annotations

import argparse
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

import _lugre_truth as lt
from fricid.identify import fit
from fricid.io import read_rawlog
from fricid.models import lugre


def _log(kind: str, cpr: int, duration: float):
    truth = lt.TRUTHS["geared"]
    with tempfile.TemporaryDirectory() as tmp:
        log = lt.simulate(truth, kind, duration, 1000.0, cpr, 0)
        meta = {"kind": kind, "rate_hz": 1000.0, "counts_per_rev": cpr, "seed": 0}
        return read_rawlog(lt.write_log(log, Path(tmp) / "log.csv", truth, meta))


def _identify(raw, threads: int | None) -> tuple[float, np.ndarray, str]:
    lugre.ROW_THREADS = threads
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit(raw, "lugre", seed=0)
    seconds = time.perf_counter() - t0
    values = np.array([p.value for p in fitted.parameters.values()])
    return seconds, values, fitted.provenance["trajectory"]["estimator"]["name"].split(":")[0]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--duration", type=float, default=60.0)
    p.add_argument("--repeats", type=int, default=2)
    args = p.parse_args()
    print(f"# {args.duration:g} s logs at 1 kHz; best of {args.repeats}; cores: {lugre._cores()}")
    head = f"{'log':28s} {'estimator':10s} {'threads s':>10s} {'1 thread s':>11s}"
    print(head + f" {'ratio':>6s} same")
    for kind in ("chirp_pd", "trapezoid_pd"):
        for cpr in (131072, 16777216):
            raw = _log(kind, cpr, args.duration)
            _identify(raw, None)  # compiles
            best = {None: np.inf, 1: np.inf}
            est = {}
            for _ in range(args.repeats):
                for threads in (None, 1):
                    s, est[threads], name = _identify(raw, threads)
                    best[threads] = min(best[threads], s)
            same = bool(np.array_equal(est[None], est[1]))
            label = f"{kind} 2^{int(np.log2(cpr))}"
            print(
                f"{label:28s} {name[:10]:10s} {best[None]:10.2f} {best[1]:11.2f} "
                f"{best[1] / best[None]:6.2f} {'yes' if same else 'NO'}",
                flush=True,
            )
    lugre.ROW_THREADS = None


if __name__ == "__main__":
    main()
