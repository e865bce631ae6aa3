"""Held-out RMSE of the selected model against the measurement scatter (issue 11, done-when).

Usage: ``python benchmarks/bench_validation.py [--real FOLDER] [--scheme lovo] [--size reduced]
[--seeds 3]`` (about 2.5 minutes on 2 cores; ``--size quick`` about 45 s).

For each data set, ``fit(samples, "auto")`` picks a model by held-out error
(:mod:`fricid.identify.static.select`), and the first table prints: set, model, held-out RMSE (the
scheme), the measurement scatter with how it was estimated, and their ratio with the verdict.
Sets:

* ``epos-leadscrew``: the real lead-screw recordings, extracted per direction by
  ``fricid extract FOLDER --format epos --by-direction`` (run as a subprocess, as a user
  would); the scatter twice, from the samples' ``std / sqrt(count)`` (a lower bound) and from
  the raw rows of each file with their autocorrelation taken into account;
* ``virtual paper2``: the RWSAVSBAS paper's virtual joint (``preset("paper2", SIZE)``),
  extracted per direction, seeds 0 to ``--seeds - 1``; scatter between its repeated passes
  (``ExtractionResult.direction_sem``: the standard error of each per-direction MEAN, which is
  what a held-out residual carries, pooled over set-points as a root mean square);
* ``virtual paper2+faults``: the same joint with rest between runs, settling, ramps, return
  moves, spike bursts and saturation (:mod:`fricid.sim.faults`) added to the log, which the
  extraction must catch (:data:`FAULT_PRESETS` is the hook for more fault mixes).

The second table holds the virtual joint against its oracle: held-out RMSE over every fold and
over the interior folds only (:func:`fricid.identify.validate.interior_rmse`, the slowest and
fastest level left out: shown beside the full figure, the verdict stays on the full one), the
estimated scatter, the oracle's noise of the averaged samples
(:func:`fricid.sim.expected_noise_std`), the realised noise ``|F - truth|`` (root mean square of
extracted minus true friction, :func:`fricid.sim.true_samples`), and the ratios. The third line
gives each fold's held-out RMSE over the oracle noise.

What it showed (issue 11's clean virtual joint at 1.24x): the scatter is not biased low (over
30 seeds of the ``quick`` design it pools to 1.02x the oracle's noise and 0.99x the realised
one; ``tests/identify/test_scatter_oracle.py``), and ``auto`` picks the true family (Stribeck,
delta = 1) on every seed shown (on the ``quick`` design's seed 4 the free-shape Stribeck,
which contains it). The ``quick`` design (6 levels 0.01-2 rad/s, 3 passes) cannot
test a 4-parameter law by leave-one-level-out: holding out 0.01 or 2 rad/s is an extrapolation
over a factor of 3 in speed, and for the TRUE model with the noise known exactly (Gaussian
noise on the true friction, 40 draws) the held-out RMSE is 2.0x (slowest) and 4.5x (fastest
fold) the noise, 2.2x over all folds and 1.16x over the interior ones; seed 0's 1.24 was a
lucky draw (seed 1: 8.8, from the 2 rad/s fold). The ``reduced`` design (the paper's 17
levels, 10 passes) can: the same check gives 1.06x, so it is the default here.
"""

from __future__ import annotations

import argparse
import dataclasses
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from fricid.extract import extract
from fricid.identify import fit, measurement_scatter
from fricid.identify.validate import interior_rmse
from fricid.io import read_epos, read_samples
from fricid.metrics import NOISE_RATIO
from fricid.sim import expected_noise_std, preset, simulate, true_samples

REPO = Path(__file__).resolve().parents[1]
REAL = REPO.parent / "shared" / "data" / "real" / "epos-leadscrew"

#: Virtual-joint presets: the clean joint and the joint with the log faults of sim.faults.
#: HOOK: add presets here as fricid.sim gains fault kinds ("paper2+rest+spikes", ...).
FAULT_PRESETS = ("paper2", "paper2+faults")


def leadscrew(folder: Path, work: Path):
    """Per-direction samples by ``fricid extract --format epos`` and the raw torque of each
    row's file (outlier rows dropped as the reader drops them: beyond 8 robust sigmas)."""
    out, by_dir = work / "ls.csv", work / "ls_dir.csv"
    cmd = [sys.executable, "-c", "from fricid.cli import main; main()", "extract", str(folder)]
    cmd += ["--format", "epos", "--out", str(out), "--by-direction", str(by_dir)]
    subprocess.run(cmd, check=True, capture_output=True)
    samples = read_samples(by_dir)
    raw = []
    labels = {round(q["velocity"], 9): q["label"] for q in samples.meta["quality"]}
    for v in samples.velocity:
        tau = read_epos(folder / labels[round(float(v), 9)]).motor_torque
        med = np.median(tau)
        mad = 1.4826 * np.median(np.abs(tau - med))
        raw.append(tau[np.abs(tau - med) <= 8.0 * mad] if mad > 0 else tau)
    return samples, raw


def virtual(name: str, size: str, seed: int):
    """Per-direction samples of a virtual-joint preset, the scatter of its passes, and the
    oracle: the true noise of each averaged sample and the true friction."""
    scenario = preset(name, size)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the faults' data-quality warnings: expected here
        result = extract(simulate(scenario, seed=seed), **scenario.extract_options())
    noise = expected_noise_std(scenario, by_direction=True)
    truth = true_samples(scenario, by_direction=True)
    return result.by_direction, result.direction_sem, noise, truth


def selected(samples, scheme: str, scatter):
    """``fit(samples, "auto")`` and its time [s]."""
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = fit(samples, "auto", settings={"scheme": scheme, "scatter": scatter})
    return fitted, time.perf_counter() - t0


def row(label: str, samples, scheme: str, scatters: dict) -> list[list[str]]:
    fitted, secs = selected(samples, scheme, next(iter(scatters.values())))
    rmse = fitted.validation["rmse"]
    out = []
    for name, sc in scatters.items():
        ratio = rmse / sc.value
        out.append(
            [
                label,
                fitted.selection["chosen"],
                f"{rmse:.3g}",
                f"{sc.value:.3g}",
                name,
                f"{ratio:.2f}",
                "within noise" if ratio <= NOISE_RATIO else "misses",
                f"{secs:.0f}",
            ]
        )
    return out


def oracle_row(
    name: str, size: str, seed: int, scheme: str, folds: dict
) -> tuple[list, list, float]:
    """One seed of a virtual-joint preset: a row of the main table and one of the oracle
    table; the per-fold held-out errors over the oracle noise are added to ``folds``."""
    samples, sem, noise, truth = virtual(name, size, seed)
    scatter = measurement_scatter(samples, sem=sem)
    fitted, secs = selected(samples, scheme, scatter)
    v = fitted.validation
    full, inner = v["rmse"], interior_rmse(v["folds"]) if scheme == "lovo" else float("nan")
    oracle = float(np.sqrt(np.mean(noise**2)))
    actual = float(np.sqrt(np.mean((samples.y - truth.y) ** 2)))
    for f in v["folds"]:
        if f["rmse"] is not None:
            folds.setdefault(name, {}).setdefault(f"{f['speed']:.3g}", []).append(f["rmse"] ** 2)
    label = f"virtual {name} (seed {seed})"
    ratio = full / scatter.value
    first = [label, fitted.selection["chosen"], f"{full:.3g}", f"{scatter.value:.3g}"]
    first += ["between passes", f"{ratio:.2f}"]
    first += ["within noise" if ratio <= NOISE_RATIO else "misses", f"{secs:.0f}"]
    extra = [label, f"{full:.3g}", f"{inner:.3g}", f"{scatter.value:.3g}", f"{oracle:.3g}"]
    extra += [f"{actual:.3g}", f"{full / scatter.value:.2f}", f"{full / oracle:.2f}"]
    extra += [f"{inner / scatter.value:.2f}", f"{inner / oracle:.2f}", f"{full / actual:.2f}"]
    return first, extra, oracle


def table(head: list[str], rows: list[list[str]]) -> None:
    widths = [max(len(r[i]) for r in [head, *rows]) for i in range(len(head))]
    for r in [head, *rows]:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip())


def without_sem(samples):
    """``samples`` without the standard errors stored in their meta (``sem*`` keys)."""
    meta = {k: v for k, v in samples.meta.items() if not k.startswith("sem")}
    return dataclasses.replace(samples, meta=meta)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--real", type=Path, default=REAL, help="the epos-leadscrew folder")
    parser.add_argument("--scheme", default="lovo", help="lovo or kfold[:K]")
    parser.add_argument("--size", default="reduced", help="virtual-joint preset size")
    parser.add_argument("--seeds", type=int, default=3, help="virtual-joint seeds 0..N-1")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    rows = []
    if args.real.is_dir():
        with tempfile.TemporaryDirectory() as tmp:
            samples, raw = leadscrew(args.real, Path(tmp))
        scatters = {
            "within-run, autocorrelation": measurement_scatter(samples, raw=raw),
            # the samples' own stored standard errors left out, to show the naive estimate
            "std/sqrt(count) (lower bound)": measurement_scatter(without_sem(samples)),
        }
        rows += row("epos-leadscrew", samples, args.scheme, scatters)
    else:
        print(f"skipped the lead screw: {args.real} not found", file=sys.stderr)
    extras, folds, oracles = [], {}, {}
    for name in FAULT_PRESETS:
        for seed in range(args.seeds):
            main_row, extra, oracles[name] = oracle_row(name, args.size, seed, args.scheme, folds)
            rows.append(main_row)
            extras.append(extra)
    scheme = args.scheme
    table(
        [
            *("set", "model", f"held-out RMSE ({scheme}) [N m]", "scatter [N m]"),
            *("scatter from", "ratio", "verdict", "time [s]"),
        ],
        rows,
    )
    print(f"\nvirtual joint ({args.size}) against its oracle [N m]:")
    table(
        [
            *("set", f"{scheme} RMSE", "interior RMSE", "scatter", "oracle noise", "|F - truth|"),
            *("ratio/scatter", "ratio/oracle", "interior/scatter", "interior/oracle"),
            f"{scheme}/|F - truth|",
        ],
        extras,
    )
    print("\nheld-out RMSE per fold over the oracle noise (root mean square over the seeds):")
    for name, per in folds.items():
        cells = [f"{speed}: {np.sqrt(np.mean(m)) / oracles[name]:.2f}" for speed, m in per.items()]
        print(f"  {name}: " + ", ".join(cells))
    print(f"total {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
