"""The README's measured numbers, its real-data example's output and its picture of a report,
regenerated: every number the README shows comes from a JSON file this script (or another
benchmark) writes into ``benchmarks/results/``, and ``tests/project/test_readme_numbers.py``
checks the README against those files (``benchmarks/readme_numbers.py`` renders them).

- ``quickstart``: the README's Quick start on the real lead-screw recordings
  (``../shared/data/real/epos-leadscrew``): ``fricid extract`` then ``fricid fit``, each
  command's stdout and stderr (``--quiet``: no progress lines) and wall time, into
  ``benchmarks/results/quickstart.json``; then ``fricid report`` on that model, and a
  screenshot of its ``report.html`` (title, summary, first figure) in headless Chromium
  (Selenium; Debian's ``chromium`` and ``chromium-driver``), scaled down, into
  ``docs/img/report.png``.
- ``demo``: ``fricid demo`` (the default, reduced size) in a fresh folder, wall and CPU time of
  the process, into ``benchmarks/results/demo.json``. A fresh clone's ``make demo`` creates
  ``.venv`` and installs the dependencies first; that time is the ``fresh_make_demo`` entry,
  kept from the last ``fresh`` run.
- ``fresh``: ``make demo`` in a fresh clone of the repository (``bench_speed.demo``: wall, CPU
  and peak memory from ``/usr/bin/time -v``, the load average before and after), into the
  ``fresh_make_demo`` entry of ``benchmarks/results/demo.json``; minutes, so not by default.

Run from the repository root: ``python benchmarks/bench_readme.py [quickstart] [demo] [fresh]``
(both by default), then ``python benchmarks/readme_numbers.py --write`` to update the README.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
PICTURE = ROOT / "docs" / "img" / "report.png"
LEADSCREW = ROOT.parent / "shared" / "data" / "real" / "epos-leadscrew"
#: The Quick start's real-data commands, as the README shows them (the recordings' path as a
#: reader of the README, in the repository's root, types it).
QUICKSTART = (
    "fricid extract ../shared/data/real/epos-leadscrew --format epos --flip-sign "
    "--out leadscrew.csv",
    "fricid fit leadscrew.csv --model stribeck_asym --out leadscrew.json",
)
#: Width of the README's picture [px], and its palette's size.
PICTURE_WIDTH = 720
PICTURE_COLOURS = 96


def _fricid(args: list[str], cwd: Path) -> tuple[str, str, float, float]:
    """Run ``fricid ARGS`` in ``cwd`` with this checkout's sources: stdout, stderr, wall and
    CPU time [s] of the process."""
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "COLUMNS": "100"}
    code = "import sys; from fricid.cli import main; sys.argv[0] = 'fricid'; main()"
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    res = subprocess.run(
        [sys.executable, "-c", code, *args], cwd=cwd, env=env, capture_output=True, text=True
    )
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if res.returncode != 0:
        raise SystemExit(f"fricid {' '.join(args)}: exit {res.returncode}\n{res.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return res.stdout, res.stderr, wall, cpu


def _machine() -> dict:
    return {
        "cpus": os.cpu_count(),
        "load_average": [round(x, 2) for x in os.getloadavg()],
        "python": platform.python_version(),
        "date": time.strftime("%Y-%m-%d", time.gmtime()),
    }


def _write(name: str, record: dict) -> Path:
    RESULTS.mkdir(parents=True, exist_ok=True)
    path = RESULTS / name
    path.write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
    print(f"wrote {path.relative_to(ROOT)}")
    return path


def screenshot(html: Path, png: Path, width: int = PICTURE_WIDTH) -> None:
    """The report as a browser shows it, ``width`` pixels wide, into ``png``: its title and
    summary table (the verdict first), above its first figure."""
    import io

    from PIL import Image
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By

    binary = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    if binary is None or driver is None:
        raise SystemExit("the picture needs chromium and chromedriver (Debian's packages)")
    opts = webdriver.ChromeOptions()
    opts.binary_location = binary
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"):
        opts.add_argument(arg)
    opts.add_argument("--window-size=1100,1400")
    drv = webdriver.Chrome(options=opts, service=Service(driver))
    try:
        drv.get(html.resolve().as_uri())
        time.sleep(2)  # the interactive figures draw after the page has loaded
        top = Image.open(io.BytesIO(drv.get_screenshot_as_png())).convert("RGB")
        table = drv.find_element(By.TAG_NAME, "table")
        scale = top.width / drv.execute_script("return window.innerWidth")
        bottom = round((table.location["y"] + table.size["height"] + 16) * scale)
        top = top.crop((0, 0, top.width, min(bottom, top.height)))
        figure = drv.find_element(By.TAG_NAME, "figure")
        drv.execute_script("arguments[0].scrollIntoView();", figure)
        time.sleep(0.5)
        fig = Image.open(io.BytesIO(figure.screenshot_as_png)).convert("RGB")
    finally:
        drv.quit()
    sheet = Image.new("RGB", (top.width, top.height + fig.height), "white")
    sheet.paste(top, (0, 0))
    sheet.paste(fig, ((top.width - fig.width) // 2, top.height))
    small = sheet.resize((width, round(sheet.height * width / sheet.width)), Image.LANCZOS)
    png.parent.mkdir(parents=True, exist_ok=True)
    small = small.quantize(colors=PICTURE_COLOURS, method=Image.Quantize.FASTOCTREE)
    small.save(png, optimize=True)  # a small file in the repository
    print(f"wrote {png} ({png.stat().st_size // 1024} KiB)")


def quickstart() -> None:
    if not LEADSCREW.is_dir():
        raise SystemExit(f"the real recordings are not at {LEADSCREW}")
    with tempfile.TemporaryDirectory() as tmp:
        # the folder the reader is in: the repository's root, the recordings beside it
        work = Path(tmp) / "repo"
        work.mkdir()
        shared = Path(tmp) / "shared" / "data" / "real"
        shared.mkdir(parents=True)
        (shared / "epos-leadscrew").symlink_to(LEADSCREW, target_is_directory=True)
        runs = []
        for command in QUICKSTART:
            out, err, wall, cpu = _fricid(["--quiet", *command.split()[1:]], work)
            runs.append(
                {"command": command, "stdout": out, "stderr": err, "wall_s": wall, "cpu_s": cpu}
            )
            print(f"{command}: {wall:.1f} s")
        _write("quickstart.json", {"commands": runs, "machine": _machine()})
        _fricid(["--quiet", "report", "leadscrew.json", "leadscrew.csv", "--out", "rep"], work)
        screenshot(work / "rep" / "report.html", PICTURE)


def demo() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        _, _, wall, cpu = _fricid(["--quiet", "demo"], Path(tmp))
    print(f"fricid demo: {wall:.1f} s wall, {cpu:.1f} s CPU")
    previous = RESULTS / "demo.json"
    fresh = None
    if previous.is_file():  # keep a fresh-clone time measured by another run
        fresh = json.loads(previous.read_text(encoding="utf-8")).get("fresh_make_demo")
    record = {
        "fricid_demo": {"command": "fricid demo", "wall_s": wall, "cpu_s": cpu},
        "fresh_make_demo": fresh,
        "machine": _machine(),
    }
    _write("demo.json", record)


def fresh() -> None:
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from bench_speed import demo as make_demo_in_a_clone

    out = make_demo_in_a_clone()
    if out["fresh"]["exit_status"] != 0:
        raise SystemExit("make demo failed in the fresh clone: nothing written")
    path = RESULTS / "demo.json"
    record = json.loads(path.read_text(encoding="utf-8")) if path.is_file() else {}
    r = out["fresh"]
    record["fresh_make_demo"] = {
        "command": "make demo (fresh clone: venv, install, demo)",
        "wall_s": r["wall_s"],
        "cpu_s": r["user_s"] + r["system_s"],
        "peak_mb": r["peak_mb"],
        "load_before": [float(x) for x in out["load_before"].split()],
        "load_after": [float(x) for x in out["load_after"].split()],
        "machine": _machine(),
    }
    _write("demo.json", record)


PARTS = {"quickstart": quickstart, "demo": demo, "fresh": fresh}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("parts", nargs="*", help="quickstart, demo, fresh (default: the first two)")
    parts = ap.parse_args().parts or ["quickstart", "demo"]
    if set(parts) - set(PARTS):
        ap.error(f"unknown part(s): {sorted(set(parts) - set(PARTS))}")
    for name, part in PARTS.items():
        if name in parts:
            part()


if __name__ == "__main__":
    main()
