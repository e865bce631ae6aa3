"""Where users wait, in one run: each figure beside its baseline measured in the same run.

Sections (each a ratio against a floor measured alongside it, the machine's load average
printed with it; on a shared machine read the ratios, not the seconds):

1. **extraction** against a pyarrow streaming group-by of the same columns at three sizes
   (time, peak memory, CPU use): ``benchmarks/bench_extract.py``'s code, by import, on the
   reduced campaign (1.2 M rows) and 4x and 16x of it (``--extract-size full`` for the paper-1
   campaign: 79 M rows, about 20 minutes; ``--extract-size skip`` to leave it out);
2. **fits**: on the 17 samples of the paper2 preset (the RWSAVSBAS study's 4-parameter
   Stribeck law, delta = 1) and on the 660 per-direction samples of the paper1 reduced
   campaign, each against scipy's ``least_squares`` called directly on the same residuals
   from the same start (baseline): the default ``fit`` (intervals included), ``fit`` without
   intervals, ``varpro``, and ``auto`` (also against one default fit of the family it picks,
   which is the model of the other rows), with the SSE each reached over scipy's (fricid's
   ``lm`` restarts from other starts when its first start's residual is far above the
   measurement scatter, as for ``msk`` on the 660 samples); the minimum of ``--repeats``
   interleaved runs (pin the process with ``taskset`` for quieter figures);
3. **start-up** CPU (user + system) of ``fricid --help`` and ``fricid predict`` against
   ``python -c "import numpy, pandas"`` (``benchmarks/bench_startup.py``'s code);
4. **test suites**: with ``--suites`` the default suite (``pytest``, as ``make test`` runs it)
   and the full one (``pytest -m ""``, ``make test-all``), wall clock, once each, stored in
   ``build/bench_suites.json``; without it, the times that file holds, or "not run";
5. **make demo, fresh** (``--demo``): the repository cloned next to itself (so that
   ``../shared`` resolves as it does here), ``/usr/bin/time -v make demo`` in the clone (a new
   virtual environment, fricid installed; pip's wheel cache is used as pip allows), then
   ``make demo`` again (installed: the demo alone); the clone is removed afterwards.

Run from the repository root: ``python benchmarks/bench_speed.py [--repeats 5] [--suites]
[--demo] [--json PATH]`` (about 3 minutes without ``--suites`` and ``--demo`` on 2 cores).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time
import warnings
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

import bench_extract  # noqa: E402
import bench_startup  # noqa: E402

#: Where ``--suites`` stores the suites' times (``build/`` is not tracked).
SUITES_JSON = ROOT / "build" / "bench_suites.json"


def load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


# --------------------------------------------------------------------------- 1. extraction


def extraction(size: str, repeats: int) -> dict:
    results, sizes = bench_extract.run(size, None, repeats)
    print(f"min of {repeats} interleaved runs, each in a fresh process")
    print(bench_extract.table(results, sizes))
    rel = bench_extract.per_row(results, sizes)
    print("time per row, relative to the smallest log: " + ", ".join(f"{p:.2f}" for p in rel))
    out = {}
    for k, _ in sizes:
        f, e = results[k]["floor"], results[k]["extract"]
        fb, eb = min(f, key=lambda r: r["wall"]), min(e, key=lambda r: r["wall"])
        out[f"{k}x"] = {
            "rows": e[0]["rows"],
            "floor_s": fb["wall"],
            "extract_s": eb["wall"],
            "time_ratio": eb["wall"] / fb["wall"],
            "floor_mb": min(r["maxrss_mb"] for r in f),
            "extract_mb": min(r["maxrss_mb"] for r in e),
            "floor_cpu_use": fb["cpu"] / fb["wall"],
            "extract_cpu_use": eb["cpu"] / eb["wall"],
        }
        out[f"{k}x"]["memory_ratio"] = out[f"{k}x"]["extract_mb"] / out[f"{k}x"]["floor_mb"]
    out["time_per_row_relative"] = rel
    return out


# --------------------------------------------------------------------------- 2. fits


def problems():
    """(label, samples) of the two problems."""
    from fricid.extract import extract
    from fricid.sim import preset, simulate

    out = []
    for label, name, by_direction in (
        ("17 samples (paper2 reduced)", "paper2", False),
        ("660 per-direction samples (paper1 reduced)", "paper1", True),
    ):
        scenario = preset(name, "reduced")
        result = extract(simulate(scenario, seed=0), **scenario.extract_options())
        out.append((label, result.by_direction if by_direction else result.samples))
    return out


def _chosen(fitted) -> tuple[str, dict[str, float] | None]:
    """The model and fixed parameters of the family ``auto`` picked."""
    label = fitted.selection["chosen"]
    model = label.split(" ")[0]
    fixed = {n: p.value for n, p in fitted.parameters.items() if p.fixed} or None
    return model, fixed


def fits(repeats: int) -> dict:
    from scipy.optimize import least_squares

    from fricid.errors import FricidError
    from fricid.identify import fit
    from fricid.identify.problem import IdentificationProblem
    from fricid.models import get_model

    warnings.simplefilter("ignore")
    out = {}
    for label, samples in problems():
        model, fixed = _chosen(fit(samples, "auto"))  # also warms every path up
        problem = IdentificationProblem(get_model(model), samples, fixed=fixed)
        x0, (lo, hi) = problem.start(), problem.bounds.T

        def scipy_direct(problem=problem, x0=x0, lo=lo, hi=hi):
            return least_squares(lambda th: problem.residuals(th[None])[0], x0, bounds=(lo, hi))

        rows = {
            "scipy least_squares direct (baseline)": scipy_direct,
            "fit, default (lm, intervals)": lambda s=samples, m=model, f=fixed: fit(s, m, fixed=f),
            "fit, intervals='none'": lambda s=samples, m=model, f=fixed: fit(
                s, m, fixed=f, intervals="none"
            ),
            "fit, method='varpro'": lambda s=samples, m=model, f=fixed: fit(
                s, m, "varpro", fixed=f
            ),
            "fit, model='auto'": lambda s=samples: fit(s, "auto"),
        }
        for name, f in list(rows.items()):
            try:
                f()
            except FricidError as exc:  # varpro needs a model with linear parameters
                print(f"  {name}: not applicable ({exc})")
                del rows[name]
        times: dict[str, list[float]] = {name: [] for name in rows}
        sse: dict[str, float] = {}
        before = load()
        for _ in range(repeats):  # interleaved: the machine's load hits every row alike
            for name, f in rows.items():
                t = time.perf_counter()
                got = f()
                times[name].append(time.perf_counter() - t)
                sse[name] = 2.0 * got.cost if hasattr(got, "cost") else got.metrics["sse"]
        best = {name: min(t) for name, t in times.items()}
        base = best["scipy least_squares direct (baseline)"]
        one = best["fit, default (lm, intervals)"]
        print(f"\n{label}: {model}{' ' + str(fixed) if fixed else ''} (the family auto picks)")
        print(f"  load average {before} before, {load()} after; min of {repeats} interleaved")
        print(f"  {'':38s} {'ms':>9s} {'x scipy':>8s} {'x one fit':>9s} {'SSE / scipy':>11s}")
        ref = sse["scipy least_squares direct (baseline)"]
        for name, sec in best.items():
            print(
                f"  {name:38s} {sec * 1e3:9.2f} {sec / base:8.2f} {sec / one:9.2f} "
                f"{sse[name] / ref:11.4f}"
            )
        out[label] = {
            "model": model,
            "fixed": fixed,
            "n": len(samples),
            "seconds": best,
            "sse": sse,
            "x_scipy": {name: sec / base for name, sec in best.items()},
            "auto_x_one_fit": best.get("fit, model='auto'", float("nan")) / one,
        }
    return out


# --------------------------------------------------------------------------- 3. start-up


def startup(repeats: int) -> dict:
    got = bench_startup.measure(repeats)
    floor = got["cpu"]["import numpy, pandas"]
    print(f"min of {repeats} interleaved runs; load average {got['load_before']:.2f} before")
    for name, t in got["cpu"].items():
        print(f"  {name:<22} {t:6.3f} s CPU   {t / floor:5.2f}x the floor")
    got["ratio"] = {name: t / floor for name, t in got["cpu"].items()}
    return got


# --------------------------------------------------------------------------- 4. suites


def suites(run: bool) -> dict:
    if run:
        env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
        got = {"measured": datetime.now(UTC).isoformat(timespec="seconds")}
        got["load_before"] = load()
        for name, marks in (("default (make test)", []), ("full (make test-all)", ["-m", ""])):
            t = time.perf_counter()
            done = subprocess.run(
                [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *marks],
                cwd=ROOT,
                env=env,
                check=False,
                stdout=subprocess.DEVNULL,
            )
            got[name] = {"wall_s": time.perf_counter() - t, "exit_status": done.returncode}
        got["load_after"] = load()
        SUITES_JSON.parent.mkdir(exist_ok=True)
        SUITES_JSON.write_text(json.dumps(got, indent=1))
    elif SUITES_JSON.exists():
        got = json.loads(SUITES_JSON.read_text())
        print(f"  (from {SUITES_JSON.relative_to(ROOT)}, measured {got['measured']})")
    else:
        print("  not run (--suites runs them: minutes)")
        return {}
    for name in ("default (make test)", "full (make test-all)"):
        r = got[name]
        print(f"  {name:<22} {r['wall_s']:7.1f} s wall  (exit status {r['exit_status']})")
    print(f"  load average {got['load_before']} before, {got['load_after']} after")
    return got


# --------------------------------------------------------------------------- 5. demo


def _time_v(text: str) -> dict:
    """Wall, user, system seconds and peak memory from ``/usr/bin/time -v``."""

    def field(name: str) -> str:
        return re.search(rf"{re.escape(name)}: (.+)", text).group(1).strip()

    wall = 0.0
    for part in field("Elapsed (wall clock) time (h:mm:ss or m:ss)").split(":"):
        wall = 60 * wall + float(part)
    return {
        "wall_s": wall,
        "user_s": float(field("User time (seconds)")),
        "system_s": float(field("System time (seconds)")),
        "peak_mb": float(field("Maximum resident set size (kbytes)")) / 1024,
    }


def demo() -> dict:
    clone = ROOT.parent / f"{ROOT.name}-demo-clone"
    if clone.exists():
        raise SystemExit(f"{clone} exists: remove it first")
    out = {"load_before": load()}
    try:
        subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
        for key in ("fresh", "installed"):
            done = subprocess.run(
                ["/usr/bin/time", "-v", "make", "demo"],
                cwd=clone,
                env=env,
                capture_output=True,
                text=True,
                check=False,
            )
            out[key] = {**_time_v(done.stderr), "exit_status": done.returncode}
        out["load_after"] = load()
    finally:
        shutil.rmtree(clone, ignore_errors=True)
    for key, label in (("fresh", "fresh clone (venv, install, demo)"), ("installed", "again")):
        r = out[key]
        print(
            f"  make demo, {label:<34} {r['wall_s']:6.1f} s wall, "
            f"{r['user_s'] + r['system_s']:6.1f} s CPU, peak {r['peak_mb']:.0f} MB "
            f"(exit status {r['exit_status']})"
        )
    print(f"  load average {out['load_before']} before, {out['load_after']} after")
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="interleaved runs (min taken)")
    parser.add_argument("--extract-size", choices=("reduced", "full", "skip"), default="reduced")
    parser.add_argument("--extract-repeats", type=int, default=2)
    parser.add_argument("--suites", action="store_true", help="run the test suites (minutes)")
    parser.add_argument("--demo", action="store_true", help="time make demo in a fresh clone")
    parser.add_argument("--json", help="also write the figures to this file")
    args = parser.parse_args()
    t0 = time.perf_counter()
    report = {"load_start": load(), "cores": os.cpu_count(), "cpus": len(os.sched_getaffinity(0))}
    print(
        f"fricid speed; load average {report['load_start']}; cores {report['cores']}, "
        f"{report['cpus']} usable by this process"
    )
    if args.extract_size != "skip":
        print("\n1. extraction against the pyarrow streaming floor")
        report["extraction"] = extraction(args.extract_size, args.extract_repeats)
    print("\n2. fits against scipy least_squares called directly")
    report["fits"] = fits(args.repeats)
    print("\n3. start-up CPU against importing numpy and pandas")
    report["startup"] = startup(args.repeats)
    print("\n4. test suites")
    report["suites"] = suites(args.suites)
    if args.demo:
        print("\n5. make demo")
        report["demo"] = demo()
    report["total_s"] = time.perf_counter() - t0
    print(f"\ntotal {report['total_s']:.0f} s; load average {load()}")
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=1, default=float))


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
