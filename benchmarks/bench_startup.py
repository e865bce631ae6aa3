"""Start-up cost of the command line, against importing numpy and pandas.

Prints the process CPU time (user + system, of the child process) of ``fricid --help`` and of
``fricid predict`` on a small model file, against ``python -c "import numpy, pandas"``: the
minimum of ``--repeats`` runs, the three commands interleaved so that a change of load hits each
alike, and each command's ratio to the floor (goal: at most 1.3). The machine's load average is
printed beside them.

With ``--suites`` it also times ``make test`` (the default suite) and ``make test-all`` (the
whole suite, as CI runs it), wall clock, once each: they take minutes, so not by default.

Run: ``python benchmarks/bench_startup.py [--repeats 5] [--suites]`` from the repository root.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from fricid.errors import FricidWarning  # noqa: E402
from fricid.identify import fit  # noqa: E402
from fricid.samples import FrictionSamples  # noqa: E402

#: The command line as the console script runs it.
CLI = "from fricid.cli import main; main()"


def child_cpu(argv: list[str], env: dict[str, str]) -> float:
    """CPU seconds (user + system) of one child process running ``argv``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(argv, env=env, check=True, stdout=subprocess.DEVNULL, cwd=ROOT)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def model_file(folder: Path) -> Path:
    """A Coulomb-viscous model fitted on 12 synthetic points, saved in ``folder``."""
    v = np.repeat(np.linspace(0.1, 2.0, 6), 2) * np.tile([1.0, -1.0], 6)
    f = np.sign(v) * 0.4 + 0.1 * v
    samples = FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=f)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FricidWarning)
        fitted = fit(samples, "coulomb_viscous")
    path = folder / "model.json"
    fitted.save(path)
    return path


def startup(repeats: int) -> None:
    got = measure(repeats)
    times, floor = got["cpu"], got["cpu"]["import numpy, pandas"]
    print(f"start-up CPU (user + system), min of {repeats} interleaved runs")
    print(
        f"  load average: {got['load_before']:.2f} before, {got['load_after']:.2f} after "
        f"(1 min); cores: {os.cpu_count()}"
    )
    for name, t in times.items():
        print(f"  {name:<22} {t:6.3f} s   {t / floor:5.2f}x the floor")


def measure(repeats: int) -> dict:
    """The minimum CPU seconds of each command over ``repeats`` interleaved runs (``cpu``,
    by name; the floor is ``"import numpy, pandas"``) and the 1-minute load average before
    and after."""
    load = os.getloadavg()[0]
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    with tempfile.TemporaryDirectory() as tmp:
        model = model_file(Path(tmp))
        cases = {
            "import numpy, pandas": [sys.executable, "-c", "import numpy, pandas"],
            "fricid --help": [sys.executable, "-c", CLI, "--help"],
            "fricid predict": [sys.executable, "-c", CLI, "predict", str(model), "-v", "0.5"],
        }
        for argv in cases.values():  # warm the file cache (and numba's, pyc files) once
            child_cpu(argv, env)
        times: dict[str, list[float]] = {name: [] for name in cases}
        for _ in range(repeats):
            for name, argv in cases.items():
                times[name].append(child_cpu(argv, env))
    return {
        "cpu": {name: min(t) for name, t in times.items()},
        "load_before": load,
        "load_after": os.getloadavg()[0],
    }


def suites() -> None:
    print("test suites (wall clock, once each)")
    for target in ("test", "test-all"):
        start = time.perf_counter()
        done = subprocess.run(["make", target], cwd=ROOT, check=False)
        wall = time.perf_counter() - start
        print(f"  make {target:<9} {wall:7.1f} s  (exit status {done.returncode})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="runs per command (min taken)")
    parser.add_argument("--suites", action="store_true", help="also time make test/test-all")
    args = parser.parse_args()
    startup(args.repeats)
    if args.suites:
        suites()


if __name__ == "__main__":
    main()
