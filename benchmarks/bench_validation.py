"""Held-out RMSE of the selected model against the measurement scatter (issue 11, done-when).

Usage: ``python benchmarks/bench_validation.py [--real FOLDER] [--scheme lovo] [--quick]``.

For each data set, ``fit(samples, "auto")`` picks a model by held-out error
(:mod:`fricid.identify.select`), and the table prints: set, model, held-out RMSE (the scheme),
the measurement scatter with how it was estimated, and their ratio with the verdict. Sets:

* ``epos-leadscrew``: the real lead-screw recordings, extracted per direction by
  ``fricid extract FOLDER --format epos --by-direction`` (run as a subprocess, as a user
  would); the scatter twice, from the samples' ``std / sqrt(count)`` (a lower bound) and from
  the raw rows of each file with their autocorrelation taken into account;
* ``virtual paper2``: the RWSAVSBAS paper's virtual joint (``preset("paper2", "quick")``),
  extracted per direction; scatter between its repeated passes
  (``ExtractionResult.direction_sem``);
* ``virtual paper2+faults``: the same joint with rest between runs, settling, ramps, return
  moves, spike bursts and saturation (:mod:`fricid.sim.faults`) added to the log, which the
  extraction must catch (:data:`FAULT_PRESETS` is the hook for more fault mixes).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from fricid.extract import extract
from fricid.identify import fit, measurement_scatter
from fricid.io import read_epos, read_samples
from fricid.sim import preset, simulate

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


def virtual(name: str, size: str):
    """Per-direction samples of a virtual-joint preset and the scatter of its passes."""
    scenario = preset(name, size)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the faults' data-quality warnings: expected here
        result = extract(simulate(scenario, seed=0), **scenario.extract_options())
    return result.by_direction, result.direction_sem


def row(label: str, samples, scheme: str, scatters: dict) -> list[list[str]]:
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        first = next(iter(scatters.values()))
        fitted = fit(samples, "auto", scheme=scheme, scatter=first)
    rmse = fitted.validation["rmse"]
    secs = time.perf_counter() - t0
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
                "within noise" if ratio <= 1.2 else "misses",
                f"{secs:.0f}",
            ]
        )
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--real", type=Path, default=REAL, help="the epos-leadscrew folder")
    parser.add_argument("--scheme", default="lovo", help="lovo or kfold[:K]")
    parser.add_argument("--size", default="quick", help="virtual-joint preset size")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    rows = []
    if args.real.is_dir():
        with tempfile.TemporaryDirectory() as tmp:
            samples, raw = leadscrew(args.real, Path(tmp))
        scatters = {
            "within-run, autocorrelation": measurement_scatter(samples, raw=raw),
            "std/sqrt(count) (lower bound)": measurement_scatter(samples),
        }
        rows += row("epos-leadscrew", samples, args.scheme, scatters)
    else:
        print(f"skipped the lead screw: {args.real} not found", file=sys.stderr)
    for name in FAULT_PRESETS:
        samples, sem = virtual(name, args.size)
        scatters = {
            "between passes": measurement_scatter(samples, sem=sem),
            "std/sqrt(count) (lower bound)": measurement_scatter(samples),
        }
        rows += row(f"virtual {name}", samples, args.scheme, scatters)
    head = [
        "set",
        "model",
        f"held-out RMSE ({args.scheme}) [N m]",
        "scatter [N m]",
        "scatter from",
        "ratio",
        "verdict",
        "time [s]",
    ]
    widths = [max(len(r[i]) for r in [head, *rows]) for i in range(len(head))]
    for r in [head, *rows]:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)))
    print(f"total {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
