"""Fleet benchmark: joints per minute serial against parallel, and drift found between dates.

A simulated fleet of ``--joints`` joints (six per robot) on the virtual joint: the paper1
preset (BAS-RBFNN paper: gravity, load and temperature effects) with a reduced design
(6 velocities 1-50 deg/s, 3 temperatures, 6 position bins, 2 repetitions: about 257,000 raw
samples per log), every joint with its own true friction law (``LoadTemperatureLaw`` with
levels drawn at random), and a few deliberately corrupted logs (truncated Parquet, garbage,
a non-numeric CSV value, a missing file). Each joint is extracted and fitted with the ``vlt``
model (eq. 4) by ``lm``.

Runs, all in this one process and on the same logs:

1. date 1, serial (``SerialExecutor``) - the reference;
2. date 1, a local process pool of ``--workers`` processes, compared bit for bit with 1
   (1 and 2 alternate ``--repeats`` times and the best time of each counts: the machine is
   shared, and each run also reports how many cores other processes took meanwhile);
3. date 1, a Dask ``LocalCluster`` of ``--workers`` workers, compared bit for bit with 1;
4. date 1 again on the pool: every joint unchanged, so every joint is skipped;
5. date 2 on the pool: new noise for every joint, and the true Coulomb level (x2.5) or
   viscous coefficient (x1.6) of ``--changed`` joints changed; the drift report against
   date 1 must flag exactly those joints.

Reports joints per minute, speed-up and parallel efficiency (speed-up / workers) from the best
times, the same efficiency from quiet runs only (other processes took under 0.15 cores; NaN
if none was quiet), the CPU the pool spent against serial (worker start-up), peak resident
memory per worker process, and the drift confusion counts.

    python benchmarks/bench_fleet.py                     # 200 joints, 2 workers
    python benchmarks/bench_fleet.py --joints 60         # quicker
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path

import numpy as np

_DEG = math.pi / 180.0


def fleet_scenario():
    """The reduced paper1 design of the benchmark."""
    from fricid.sim import preset

    sc = preset("paper1", "reduced")
    design = replace(
        sc.design,
        velocities=np.array([1.0, 2.0, 4.0, 9.0, 18.0, 50.0]) * _DEG,
        temperatures=np.array([10.0, 25.0, 40.0]),
        positions=np.arange(-60.0, -19.0, 8.0) * _DEG,
        repetitions=2,
    )
    return replace(sc, design=design, size="fleet")


def true_laws(n: int, changed: set[int], seed: int = 2026):
    """Per joint: the true law at date 1 and at date 2 (changed for the ``changed`` joints)."""
    from fricid.sim import LoadTemperatureLaw

    rng = np.random.default_rng(seed)
    laws = []
    for i in range(n):
        law = LoadTemperatureLaw(
            f_c=rng.uniform(0.03, 0.05),
            f_cl=rng.uniform(0.5, 0.7),
            f_s=rng.uniform(0.06, 0.10),
            f_sl=rng.uniform(0.2, 0.4),
            v_s=rng.uniform(1.5, 2.5) * _DEG,
            beta=rng.uniform(0.15, 0.25),
        )
        later = law
        if i in changed:  # wear raises Coulomb friction; aged grease raises viscous friction
            later = replace(law, f_c=2.5 * law.f_c) if i % 2 else replace(law, beta=1.6 * law.beta)
        laws.append((law, later))
    return laws


def write_log(args) -> str:
    """Simulate one joint's campaign and write it as a raw log (a pool task)."""
    from fricid.io import write_rawlog
    from fricid.sim import simulate

    law, seed, path = args
    sc = fleet_scenario()
    sc = replace(sc, joint=replace(sc.joint, law=law))
    opts = sc.extract_options()
    hints = {
        "gravity": opts["gravity"],
        "positions_rad": [float(p) for p in opts["positions"]],
        "bin_halfwidth_rad": float(opts["bin_halfwidth"]),
    }
    chunks = (replace(c, meta={**c.meta, "design": hints}) for c in simulate(sc, seed=seed))
    write_rawlog(chunks, path)
    return path


def corrupt(path: Path, how: str) -> None:
    """Damage a log: truncate it, replace it by garbage, or remove it."""
    if how == "truncated":
        data = path.read_bytes()
        path.write_bytes(data[: len(data) // 2])
    elif how == "garbage":
        path.write_bytes(b"\x00garbage\xff" * 1000)
    elif how == "missing":
        path.unlink()


def make_date(folder: Path, laws, date: int, corrupted: dict[int, str], workers: int) -> Path:
    """Logs and manifest of one date."""
    logs = folder / f"logs{date}"
    logs.mkdir(parents=True, exist_ok=True)
    tasks = [
        (pair[date - 1], 1000 * date + i, str(logs / f"j{i:03d}.parquet"))
        for i, pair in enumerate(laws)
    ]
    with ProcessPoolExecutor(workers) as pool:
        list(pool.map(write_log, tasks, chunksize=4))
    rows = ["robot,joint,log,model,method,seed"]
    for i in range(len(laws)):
        name = f"logs{date}/j{i:03d}.parquet"
        if corrupted.get(i) == "csv":  # a CSV raw log with one non-numeric value
            name = f"logs{date}/j{i:03d}.csv"
            (folder / name).write_text(
                "# format: fricid-rawlog/1\ntime [s],position [rad],velocity [rad/s],"
                "torque [N m],temperature [degC]\n0,0,0.1,0.2,25\n0.004,0.0004,oops,0.2,25\n",
                encoding="utf-8",
            )
        elif i in corrupted:
            corrupt(folder / name, corrupted[i])
        rows.append(f"r{i // 6:03d},j{i % 6 + 1},{name},vlt,lm,{i}")
    manifest = folder / f"fleet{date}.csv"
    manifest.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return manifest


def _busy_seconds() -> float:
    """CPU seconds the whole machine has been busy (all processes, all cores; Linux)."""
    with open("/proc/stat", encoding="ascii") as fh:
        fields = [int(x) for x in fh.readline().split()[1:]]
    user, nice, system, _idle, _iowait, irq, softirq, steal = fields[:8]
    return (user + nice + system + irq + softirq + steal) / os.sysconf("SC_CLK_TCK")


def _own_seconds() -> float:
    """CPU seconds of this process tree: itself, its reaped children (pool workers) and its
    live descendants (Dask nannies and workers)."""
    import psutil

    t = os.times()
    total = t.user + t.system + t.children_user + t.children_system
    for child in psutil.Process().children(recursive=True):
        try:
            c = child.cpu_times()
        except psutil.Error:
            continue
        total += c.user + c.system
    return total


#: A run is "quiet" when other processes used fewer cores than this meanwhile.
QUIET = 0.15

#: Wall time and CPU use of each run, filled by :func:`timed_run`.
RUNS: dict[str, dict[str, float]] = {}


def timed_run(label: str, manifest: Path, out: Path, executor, date: str):
    """Run the fleet; record wall time, own CPU and the CPU other processes took meanwhile."""
    from fricid.fleet import run_fleet

    busy0, own0, t0 = _busy_seconds(), _own_seconds(), time.perf_counter()
    run = run_fleet(manifest, out, executor=executor, date=date)
    wall = time.perf_counter() - t0
    own = _own_seconds() - own0
    others = max(_busy_seconds() - busy0 - own, 0.0)
    RUNS[label] = {"wall_s": wall, "own_cpu_s": own, "others_cores": others / wall}
    print(
        f"{label}: {wall:.1f} s, own CPU {own:.1f} s, other processes used "
        f"{others / wall:.2f} cores meanwhile",
        flush=True,
    )
    return run, wall


def same_results(a: Path, b: Path) -> bool:
    import pandas as pd

    from fricid.fleet import RUN_COLUMNS, read_results

    fa, fb = read_results(a), read_results(b)
    cols = [c for c in fa.columns if c not in RUN_COLUMNS]
    try:
        pd.testing.assert_frame_equal(fa[cols], fb[cols], check_exact=True)
    except AssertionError:
        return False
    return True


def peak_per_worker(run) -> dict[str, float]:
    table = run.table
    table = table[table["worker"].notna()]
    return {str(w): float(v) for w, v in table.groupby("worker")["peak_rss_mb"].max().items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--joints", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--changed", type=int, default=10, help="joints changed at date 2")
    parser.add_argument("--repeats", type=int, default=2, help="serial/pool runs, alternated")
    parser.add_argument("--dir", type=Path, default=None, help="work folder (default: temp)")
    parser.add_argument("--keep", action="store_true", help="keep the work folder")
    parser.add_argument("--json", type=Path, default=None, help="write the figures here")
    args = parser.parse_args()

    from fricid.fleet import ProcessExecutor, SerialExecutor, compare, read_results, write_drift
    from fricid.fleet._dask import DaskExecutor

    n, w = args.joints, args.workers
    work = args.dir or Path(tempfile.mkdtemp(prefix="bench-fleet-"))
    work.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(7)
    order = rng.permutation(n)
    kinds = ["truncated", "garbage", "csv", "missing"]
    corrupted1 = {int(i): kinds[k] for k, i in enumerate(order[:4])}
    corrupted2 = {int(i): kinds[k] for k, i in enumerate(order[4:8])}
    changed = {int(i) for i in order[8 : 8 + args.changed]}
    laws = true_laws(n, changed)
    figures: dict = {"joints": n, "workers": w, "cores": os.cpu_count(), "work": str(work)}

    t0 = time.perf_counter()
    m1 = make_date(work, laws, 1, corrupted1, w)
    m2 = make_date(work, laws, 2, corrupted2, w)
    figures["simulate_s"] = time.perf_counter() - t0
    print(f"simulated 2 x {n} logs in {figures['simulate_s']:.0f} s into {work}", flush=True)

    t_serial = t_pool = math.inf
    for rep in range(args.repeats):  # alternate, keep the best of each (a shared machine)
        serial, t = timed_run(
            f"serial#{rep}", m1, work / f"out-serial{rep}", SerialExecutor(), "2026-01-10"
        )
        t_serial = min(t_serial, t)
        pool, t = timed_run(
            f"pool#{rep}", m1, work / f"out-pool{rep}", ProcessExecutor(w), "2026-01-10"
        )
        t_pool = min(t_pool, t)
    t_start = time.perf_counter()
    with DaskExecutor.local(w) as dask:
        figures["dask_start_s"] = time.perf_counter() - t_start
        dask_run, t_dask = timed_run("dask", m1, work / "out-dask", dask, "2026-01-10")
    resumed, t_resume = timed_run("rerun", m1, pool.out, ProcessExecutor(w), "2026-01-10")
    later, t_later = timed_run("date2", m2, work / "out-date2", ProcessExecutor(w), "2026-07-10")

    drift = compare(read_results(later.out), read_results(serial.out))
    write_drift(drift, later.out)
    found = {
        int(j[1:]) - 1 + 6 * int(r[1:])
        for r, j in zip(drift.drifted["robot"], drift.drifted["joint"], strict=True)
    }
    compared = {
        int(j[1:]) - 1 + 6 * int(r[1:])
        for r, j in zip(drift.joints["robot"], drift.joints["joint"], strict=True)
    }
    truth = changed & compared

    quiet = {
        kind: min(
            (
                r["wall_s"]
                for label, r in RUNS.items()
                if label.startswith(kind + "#") and r["others_cores"] < QUIET
            ),
            default=math.nan,
        )
        for kind in ("serial", "pool")
    }
    best_cpu = {
        kind: min(r["own_cpu_s"] for label, r in RUNS.items() if label.startswith(kind + "#"))
        for kind in ("serial", "pool")
    }
    figures.update(
        {
            "runs": RUNS,
            "seconds_best": {
                "serial": t_serial,
                "pool": t_pool,
                "dask": t_dask,
                "rerun_all_skipped": t_resume,
                "date2_pool": t_later,
            },
            "joints_per_minute": {
                name: 60.0 * n / t
                for name, t in (("serial", t_serial), ("pool", t_pool), ("dask", t_dask))
            },
            "speedup_pool": t_serial / t_pool,
            "efficiency_pool": t_serial / t_pool / w,
            "speedup_dask": t_serial / t_dask,
            "efficiency_dask": t_serial / t_dask / w,
            "efficiency_pool_quiet_runs": quiet["serial"] / quiet["pool"] / w,
            "cpu_pool_over_serial": best_cpu["pool"] / best_cpu["serial"],
            "identical_pool": same_results(serial.out, pool.out),
            "identical_dask": same_results(serial.out, dask_run.out),
            "failed_date1": serial.failed,
            "failures_date1": [f"{r}/{j} {s}: {e[:80]}" for r, j, s, e in serial.failures],
            "rerun_skipped": resumed.skipped,
            "peak_rss_mb_serial_process": max(peak_per_worker(serial).values()),
            "peak_rss_mb_pool_workers": peak_per_worker(pool),
            "peak_rss_mb_dask_workers": peak_per_worker(dask_run),
            "drift": {
                "compared": len(compared),
                "changed_and_compared": len(truth),
                "flagged": len(found),
                "true_positive": len(found & truth),
                "false_positive": len(found - truth),
                "false_negative": len(truth - found),
                "exact": found == truth,
            },
        }
    )
    print(json.dumps(figures, indent=2))
    if args.json:
        args.json.write_text(json.dumps(figures, indent=2) + "\n", encoding="utf-8")
    if not args.keep and args.dir is None:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
