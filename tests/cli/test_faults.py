"""Faults: interrupts, signals, killed writers, files fricid did not write, reproducible files.

Issue 12, "Faults" and defect 3. The subprocess tests run the real command line and are
bounded in time: each waits for a point in the child's life (a temporary file appears, a
library is mapped, workers exist), sends a signal, and waits at most a few seconds for the
outcome; every process they start is killed in a ``finally``.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from typer.testing import CliRunner

import fricid
from fricid.cli import app
from fricid.cli._app import handle_errors, interrupt_exit
from fricid.fleet import SerialExecutor, run_fleet
from fricid.fleet.runner import FleetInterrupted
from fricid.fleet.store import FleetStore
from fricid.io.atomic import (
    HOST_TAG,
    atomic_dir,
    atomic_write,
    created_timestamp,
    is_stale_temp,
    remove_stale,
)

psutil = pytest.importorskip("psutil")

runner = CliRunner()

SRC = Path(fricid.__file__).resolve().parents[1]
ENTRY = "from fricid.cli import main; main()"

#: ``fricid`` with a hook inside every optimiser run: it creates the file named by
#: ``FRICID_TEST_READY`` and then waits (up to 120 s) before the run goes on, so an interrupt
#: sent once the file exists lands inside the fit, however loaded the machine is.
FITTING_ENTRY = """
import os, time
import fricid.optim._minimize as _m

_run = _m._solve


def _solve(solver, objective):
    open(os.environ["FRICID_TEST_READY"], "w").close()
    deadline = time.monotonic() + 120.0
    while time.monotonic() < deadline:  # the interrupt lands here, inside the fit
        time.sleep(0.01)
    return _run(solver, objective)


_m._solve = _solve
from fricid.cli import main
main()
"""
N_JOINTS = 6

#: Signals sent at set moments: run alone, after the parallel tests (Makefile).
pytestmark = pytest.mark.serial


# --------------------------------------------------------------------------- helpers


def _env(**extra: str) -> dict[str, str]:
    path = os.pathsep.join(p for p in (str(SRC), os.environ.get("PYTHONPATH", "")) if p)
    return {**os.environ, "PYTHONPATH": path, **extra}


def _start(
    args: list[str], cwd: Path, *, session: bool = False, entry: str = ENTRY, **env: str
) -> subprocess.Popen:
    """Run ``fricid ARGS`` (through ``entry``); stderr goes to a file (``proc.stderr_path``): a
    pipe would stay open as long as any orphaned grandchild holds it, and reading it would
    block."""
    fd, name = tempfile.mkstemp(prefix="fricid-test-stderr-", suffix=".txt")
    err = Path(name)
    with os.fdopen(fd, "wb") as fh:
        proc = subprocess.Popen(
            [sys.executable, "-c", entry, *args],
            cwd=cwd,
            env=_env(**env),
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=fh,
            start_new_session=session,  # its own process group, as a shell job has
        )
    proc.stderr_path = err  # type: ignore[attr-defined]
    return proc


def _wait_for(condition: Callable[[], bool], timeout: float, proc: subprocess.Popen) -> None:
    """Poll ``condition`` until it holds; fail if ``proc`` ended first or time runs out."""
    deadline = time.monotonic() + timeout
    while not condition():
        if proc.poll() is not None:
            err = proc.stderr_path.read_text(errors="replace")  # type: ignore[attr-defined]
            pytest.fail(f"the command ended first: {err[-2000:]}")
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout} s waiting for the command")
        time.sleep(0.02)


def _mapped(pid: int, library: str) -> bool:
    """Whether process ``pid`` has loaded a shared library whose path contains ``library``."""
    try:
        with open(f"/proc/{pid}/maps", encoding="ascii", errors="replace") as fh:
            return library in fh.read()
    except OSError:
        return False


def _marked(folder: Path) -> list[Path]:
    return sorted(folder.glob(".*.fricid-*.tmp"))


def _dead_pid() -> int:
    """The pid of a process that has ended."""
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait(timeout=30)
    return proc.pid


def _alive(procs: list) -> list:
    """The processes of ``procs`` still running (zombies count as ended)."""
    left = []
    for p in procs:
        try:
            if p.is_running() and p.status() != psutil.STATUS_ZOMBIE:
                left.append(p)
        except psutil.NoSuchProcess:
            pass
    return left


def _kill(procs: list) -> None:
    for p in procs:
        with contextlib.suppress(psutil.NoSuchProcess):
            p.kill()


def _finish(proc: subprocess.Popen, timeout: float) -> tuple[int, str]:
    """Wait (bounded) for ``proc``; its exit status and stderr. Kills it if it overstays."""
    try:
        proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(timeout=10)
    err = proc.stderr_path.read_text(errors="replace")  # type: ignore[attr-defined]
    proc.stderr_path.unlink()  # type: ignore[attr-defined]
    return proc.returncode, err


def _one_line(err: str) -> str:
    """The one line an interrupt ends with (after whatever progress the command printed)."""
    lines = [line for line in err.splitlines() if line.strip()]
    assert "Traceback" not in err and lines, err
    endings = [line for line in lines if line.startswith(("interrupted", "terminated"))]
    assert endings == lines[-1:], err
    return lines[-1]


@pytest.fixture(scope="module")
def data(tmp_path_factory) -> Path:
    """A quick simulated log, its samples, and a fleet manifest of its joints."""
    folder = tmp_path_factory.mktemp("faults")
    log, samples = folder / "log.parquet", folder / "samples.csv"
    for args in (
        ["simulate", "--preset", "paper2", "--size", "quick", "-o", str(log)],
        ["extract", str(log), "-o", str(samples)],
    ):
        result = runner.invoke(app, args)
        assert result.exit_code == 0, result.output
    rows = ["robot,joint,log,model,method,seed"]
    rows += [f"r0,j{i},log.parquet,stribeck,rwsavsbas,{i}" for i in range(N_JOINTS)]
    (folder / "fleet.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    return folder


# --------------------------------------------------------------------------- defect 3


def test_fleet_keeps_user_files_named_like_temporaries(data, tmp_path):
    """Opening an output folder removes fricid's own leftovers of dead writers, nothing else."""
    out = tmp_path / "out"
    (out / "records" / "r0").mkdir(parents=True)
    dead, alive = _dead_pid(), os.getppid()
    user = [
        out / ".notes.tmp",
        out / "records" / "r0" / ".draft.json.tmp",
        out / "records" / "r0" / ".j0.json.x1y2.tmp",  # mkstemp-like, but not fricid's mark
        out / ".results-backup" / "keep.csv",
        out / ".results-old-1" / "user.txt",
        out / f".results-old-{dead}" / "mine.txt",  # fricid's name, a user's content
        out / "records" / f".j1.json.fricid-{HOST_TAG}-{alive}-abcd1234.tmp",  # a live writer
        out / "records" / f".j1.json.fricid-00000000-{dead}-abcd1234.tmp",  # another host
    ]
    stale = [
        out / "records" / "r0" / f".j0.json.fricid-{HOST_TAG}-{dead}-abcd1234.tmp",
        out / f".results-new-{dead}-0123abcd" / "robot=r0" / "date=2026-03-01" / "part-0.parquet",
        out / f".results.fricid-{HOST_TAG}-{dead}-k9k9k9k9.tmp" / "robot=r0" / "part-0.parquet",
    ]
    for path in user + stale:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("data")
    with FleetStore(out):
        pass
    assert all(p.read_text() == "data" for p in user)
    assert not any(path.exists() for path in stale)
    assert not (out / f".results-new-{dead}-0123abcd").exists()
    assert _marked(out) == [] and _marked(out / "records" / "r0") == []


def test_stale_temporaries_are_fricids_and_of_dead_writers_only(tmp_path):
    dead = _dead_pid()
    mine = tmp_path / f".x.json.fricid-{HOST_TAG}-{dead}-a_b1.tmp"
    assert is_stale_temp(mine)
    assert not is_stale_temp(tmp_path / f"x.json.fricid-{HOST_TAG}-{dead}-a_b1.tmp")  # not hidden
    assert not is_stale_temp(tmp_path / f".x.json.fricid-{HOST_TAG}-{os.getppid()}-a.tmp")
    assert not is_stale_temp(tmp_path / f".x.json.{dead}.tmp")
    mine.write_text("{half")
    (tmp_path / ".x.json.user.tmp").write_text("keep")
    assert remove_stale(tmp_path, name="y.json") == []
    assert remove_stale(tmp_path) == [mine]
    assert (tmp_path / ".x.json.user.tmp").exists()


def test_atomic_writers_leave_nothing_on_failure(tmp_path):
    target = tmp_path / "a.json"
    with pytest.raises(KeyboardInterrupt), atomic_write(target) as fh:
        fh.write("{half")
        assert _marked(tmp_path)  # the temporary is fricid's
        raise KeyboardInterrupt
    assert list(tmp_path.iterdir()) == []
    folder = tmp_path / "results"
    with atomic_dir(folder) as tmp:
        (tmp / "one.txt").write_text("1")
    with pytest.raises(RuntimeError), atomic_dir(folder) as tmp:
        (tmp / "two.txt").write_text("2")
        raise RuntimeError("stop")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results"]
    assert [p.name for p in folder.iterdir()] == ["one.txt"]
    with atomic_dir(folder) as tmp:
        (tmp / "three.txt").write_text("3")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results"]
    assert [p.name for p in folder.iterdir()] == ["three.txt"]


# --------------------------------------------------------------------------- killed writers


@pytest.mark.slow  # a fixed sleep to land mid-write: timing-sensitive
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL])
def test_simulate_killed_mid_write_then_rerun(tmp_path, sig):
    """SIGTERM: no temporary left, one line, status 143. SIGKILL: the temporary stays (nothing
    can run), and the next run removes it; user files of similar names stay."""
    decoys = [tmp_path / ".big.parquet.x1y2.tmp", tmp_path / ".notes.tmp"]
    for path in decoys:
        path.write_text("mine")
    args = ["simulate", "--preset", "paper2", "--size", "reduced", "-o", "big.parquet"]
    proc = _start(args, tmp_path)
    try:
        _wait_for(lambda: bool(_marked(tmp_path)), 60, proc)
        time.sleep(0.2)  # mid-write
        proc.send_signal(sig)
    finally:
        code, err = _finish(proc, 20)
    assert not (tmp_path / "big.parquet").exists()
    if sig == signal.SIGTERM:
        assert code == 143
        assert _one_line(err).startswith("terminated (SIGTERM)")
        assert _marked(tmp_path) == []
    else:
        assert code == -signal.SIGKILL
        assert len(_marked(tmp_path)) == 1
    rerun = runner.invoke(
        app,
        ["simulate", "--preset", "paper2", "--size", "quick", "-o", str(tmp_path / "big.parquet")],
    )
    assert rerun.exit_code == 0, rerun.output
    assert _marked(tmp_path) == [] and (tmp_path / "big.parquet").exists()
    assert all(p.read_text() == "mine" for p in decoys)


# --------------------------------------------------------------------------- fleet


@pytest.fixture
def busy_fleet(data, tmp_path) -> Iterator[tuple[subprocess.Popen, list, Path]]:
    """``fricid fleet`` on two worker processes (a process group of its own), once both
    workers exist and have started."""
    out = tmp_path / "out"
    args = ["fleet", str(data / "fleet.csv"), "--out", str(out), "--workers", "2"]
    proc = _start(args, data, session=True)
    parent = psutil.Process(proc.pid)
    children: list = []
    try:

        def workers() -> list:
            return [c for c in parent.children() if "spawn" in " ".join(c.cmdline())]

        _wait_for(lambda: len(workers()) >= 2, 60, proc)
        time.sleep(1.0)  # the workers import and take their first joints
        children = parent.children(recursive=True)
        yield proc, children, out
    finally:  # whatever the test saw, leave no process behind
        _kill([parent, *children])
        proc.wait(timeout=10)


@pytest.mark.slow  # busy_fleet waits a fixed second for the workers: timing-sensitive
def test_fleet_sigterm_tears_the_pool_down(busy_fleet):
    proc, children, out = busy_fleet
    assert len(children) >= 2
    proc.send_signal(signal.SIGTERM)
    code, err = _finish(proc, 20)
    assert code == 143
    line = _one_line(err)
    assert line.startswith("terminated (SIGTERM); kept ") and f"of {N_JOINTS} joints" in line
    assert "run the same command again" in line and str(out / "records") in line
    _gone, alive = psutil.wait_procs(children, timeout=5)
    assert _alive(alive) == []
    assert list(out.rglob("*.tmp")) == []


@pytest.mark.slow  # busy_fleet waits a fixed second for the workers: timing-sensitive
def test_fleet_ctrl_c_in_a_terminal(busy_fleet):
    """Ctrl-C reaches the whole process group: the workers ignore it, the driver stops them
    and says in one line what it kept."""
    proc, children, out = busy_fleet
    os.killpg(proc.pid, signal.SIGINT)
    code, err = _finish(proc, 20)
    assert code == 130
    line = _one_line(err)
    assert line.startswith("interrupted; kept ") and "run the same command again" in line
    _gone, alive = psutil.wait_procs(children, timeout=5)
    assert _alive(alive) == []
    assert list(out.rglob("*.tmp")) == []


@pytest.mark.slow  # busy_fleet waits a fixed second for the workers: timing-sensitive
def test_fleet_sigkill_takes_the_workers_along(busy_fleet):
    proc, children, _out = busy_fleet
    proc.send_signal(signal.SIGKILL)
    assert _finish(proc, 10)[0] == -signal.SIGKILL
    _gone, alive = psutil.wait_procs(children, timeout=5)
    assert _alive(alive) == [], [p.cmdline() for p in _alive(alive)]


@pytest.mark.slow  # 4 s measured under load (default run kept short)
def test_fleet_interrupt_says_what_was_kept(data, tmp_path):
    """Ctrl-C after two joints: their records stay, and the line says so and how to resume."""
    manifest = tmp_path / "fleet.csv"
    rows = ["robot,joint,log,model,seed"]
    rows += [f"r0,j{i},{data / 'log.parquet'},stribeck,{i}" for i in range(4)]
    manifest.write_text("\n".join(rows) + "\n", encoding="utf-8")
    seen = []

    def progress(event):
        seen.append(event)
        if len(seen) == 2:
            raise KeyboardInterrupt

    with pytest.raises(FleetInterrupted) as info:
        run_fleet(manifest, tmp_path / "out", executor=SerialExecutor(), progress=progress)
    assert (info.value.kept, info.value.total) == (2, 4)
    assert len(list((tmp_path / "out" / "records").rglob("*.json"))) == 2
    code, line = interrupt_exit(info.value)
    assert code == 130 and "no partial output" not in line
    assert line.startswith("interrupted; kept 2 of 4 joints finished in ")
    assert "run the same command again to resume" in line


# --------------------------------------------------------------------------- Ctrl-C


@pytest.mark.slow  # 21 s measured under load; the interrupt's landing depends on load
@pytest.mark.parametrize(
    ("args", "library", "delay"),
    [
        pytest.param(
            ["fit", "samples.csv", "--method", "rwsavsbas"],
            "_multiarray_umath",
            0.0,
            id="importing",
        ),
        pytest.param(
            ["bench", "stribeck", "--quick", "--runs", "1"],
            "llvmlite",
            0.3,
            id="numba-compiling",
            marks=pytest.mark.slow,  # a sleep: the interrupt may miss the compilation under load
        ),
    ],
)
def test_ctrl_c_is_one_line_and_130(data, tmp_path, args, library, delay):
    out = tmp_path / "model.json"
    cmd = [*args, "-o", str(out if args[0] == "fit" else tmp_path / "bench")]
    proc = _start(cmd, data, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    try:
        _wait_for(lambda: _mapped(proc.pid, library), 60, proc)
        time.sleep(delay)
        proc.send_signal(signal.SIGINT)
    finally:
        code, err = _finish(proc, 20)
    assert code == 130, err
    assert _one_line(err).startswith("interrupted; ")
    assert not out.exists() and _marked(tmp_path) == []


@pytest.mark.slow  # 1.8 s, quiet machine (default run kept short)
def test_ctrl_c_while_fitting_is_one_line_and_130(data, tmp_path):
    """Ctrl-C inside the optimiser's run (a hook holds the run until the signal lands, so
    neither a sleep nor the machine's load decides where it lands)."""
    out = tmp_path / "model.json"
    ready = tmp_path / "fitting.ready"
    args = ["fit", "samples.csv", "--method", "rwsavsbas", "-o", str(out)]
    proc = _start(
        args,
        data,
        entry=FITTING_ENTRY,
        NUMBA_CACHE_DIR=str(tmp_path / "numba"),
        FRICID_TEST_READY=str(ready),
    )
    try:
        _wait_for(ready.exists, 120, proc)
        proc.send_signal(signal.SIGINT)
    finally:
        code, err = _finish(proc, 60)
    assert code == 130, err
    assert _one_line(err).startswith("interrupted; ")
    assert not out.exists() and _marked(tmp_path) == []


def test_errors_chained_from_an_interrupt_are_the_interrupt(capsys):
    """numba after Ctrl-C during compilation: RuntimeError('no compiled object yet')."""

    @handle_errors
    def command() -> None:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise RuntimeError("no compiled object yet for <Library 'x'>") from None

    with pytest.raises(SystemExit) as info:
        command()
    assert info.value.code == 130
    assert _one_line(capsys.readouterr().err) == "interrupted; no file was left half-written"


# --------------------------------------------------------------------------- reproducible


@pytest.mark.slow  # 3 s measured under load (default run kept short)
def test_identical_runs_give_identical_model_files(data, tmp_path, monkeypatch):
    def fit(name: str, *options: str) -> bytes:
        path = tmp_path / name
        args = [*options, "fit", str(data / "samples.csv"), "-o", str(path)]
        result = runner.invoke(app, args)
        assert result.exit_code == 0, result.output
        return path.read_bytes()

    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    first = fit("a.json", "--reproducible")
    time.sleep(1.1)  # a clock-stamped file would differ by now
    assert fit("b.json", "--reproducible") == first
    assert json.loads(first)["provenance"]["created"] == "1970-01-01T00:00:00+00:00"
    assert "SOURCE_DATE_EPOCH" not in os.environ  # the flag does not leak
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1767225600")
    assert created_timestamp() == "2026-01-01T00:00:00+00:00"
    again = fit("c.json")
    assert json.loads(again)["provenance"]["created"] == "2026-01-01T00:00:00+00:00"
    assert again.replace(b"2026-01-01T00:00:00", b"1970-01-01T00:00:00") == first
