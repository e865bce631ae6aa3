"""``fricid fleet`` on hostile folders and manifests: records are data, never instructions.

- A previous run's record never deletes a file outside ``--out``, nor one the fleet did not
  write (an absolute path, ``..``, a link, another joint's file): it is left, with a warning.
- Nothing is written through a symbolic link under ``--out``: refused in one line naming it.
- Names the file system cannot hold (``NAME_MAX``, ``PATH_MAX``, with every suffix and
  temporary name the fleet derives) are refused before any work, naming row and column.
- A YAML manifest of nested aliases is refused at once; so is one that refers to itself or
  nests without end.
- A manifest, record or log that is a FIFO, a device or a folder is refused before a byte is
  read: nothing blocks, nothing reads without end.
- The workers' warnings reach stderr as one line each, through the driver; an interrupt
  after the command finished still ends in the one-line message.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

import fricid
from fricid.cli import app
from fricid.errors import ConfigError, ConvergenceWarning, DataError, DataQualityWarning
from fricid.fleet import (
    JointJob,
    ProcessExecutor,
    SerialExecutor,
    read_manifest,
    run_fleet,
    run_job,
)
from fricid.fleet.hashing import RECORD_FORMAT
from fricid.fleet.job import JointOutcome, fit_row
from fricid.fleet.manifest import JointSpec
from fricid.fleet.store import FleetStore

runner = CliRunner()

SRC = Path(fricid.__file__).resolve().parents[1]
ENTRY = "from fricid.cli import main; main()"
PRECIOUS = "precious user data\n"


def _env() -> dict[str, str]:
    path = os.pathsep.join(p for p in (str(SRC), os.environ.get("PYTHONPATH", "")) if p)
    return {**os.environ, "PYTHONPATH": path}


def _with_deadline(call, fifo: Path, seconds: float = 10.0) -> dict[str, object]:
    """``call()`` in a thread: ``{"value": ...}`` or ``{"error": ...}``; a failure if it is
    still running after ``seconds`` (blocked on the FIFO ``fifo``, which is then opened for
    writing to release it)."""
    got: dict[str, object] = {}

    def target() -> None:
        try:
            got["value"] = call()
        except BaseException as exc:  # handed to the test
            got["error"] = exc

    thread = threading.Thread(target=target, daemon=True)
    thread.start()
    thread.join(seconds)
    if thread.is_alive():
        if fifo.is_fifo():
            with open(fifo, "w"):
                pass
        thread.join(seconds)
        pytest.fail(f"did not finish within {seconds} s (blocked on {fifo}?)")
    return got


@pytest.fixture
def site(tmp_path):
    """A manifest of one joint whose log is missing (it fails at once), an output folder,
    and a user's files outside it."""
    home = tmp_path / "userdir"
    home.mkdir()
    (home / "victim.txt").write_text(PRECIOUS)
    (home / "j1.json").write_text(PRECIOUS)
    (home / "j1.stribeck.json").write_text(PRECIOUS)
    manifest = tmp_path / "fleet.csv"
    manifest.write_text("robot,joint,log\nr1,j1,nowhere.csv\n", encoding="utf-8")
    return tmp_path, manifest, tmp_path / "out", home


def _snapshot(folder: Path) -> dict[str, tuple]:
    out = {}
    for path in sorted(folder.rglob("*")):
        info = os.lstat(path)
        body = path.read_bytes() if path.is_file() and not path.is_symlink() else None
        out[str(path.relative_to(folder))] = (info.st_mode, info.st_size, info.st_mtime_ns, body)
    return out


def _plant_record(out: Path, files, status: str = "failed", **extra) -> Path:
    path = out / "records" / "r1" / "j1.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    record = {
        "format": RECORD_FORMAT,
        "robot": "r1",
        "joint": "j1",
        "date": "2026-01-01",
        "status": status,
        "model_files": files,
        "rows": [],
        **extra,
    }
    path.write_text(json.dumps(record), encoding="utf-8")
    return path


# --------------------------------------------------------------------------- 1. deletion


@pytest.mark.parametrize(
    "rel",
    [
        "ABS",  # the absolute path of the user's file
        "../../../userdir/victim.txt",
        "models/r1/../../../userdir/victim.txt",
        "models/r1/j1.stribeck.json/../../../../userdir/victim.txt",
        "models/r2/j9.stribeck.json",  # another joint's model file, inside --out
        "models/r1/j1.vlt.json",  # the path of another model than the record says
    ],
)
def test_a_record_never_deletes_what_the_fleet_did_not_write(site, rel):
    _root, manifest, out, home = site
    victim = home / "victim.txt" if "victim" in rel or rel == "ABS" else None
    other = out / "models" / "r2" / "j9.stribeck.json"
    other.parent.mkdir(parents=True)
    other.write_text(PRECIOUS)
    wrong = out / "models" / "r1" / "j1.vlt.json"
    wrong.parent.mkdir(parents=True)
    wrong.write_text(PRECIOUS)
    _plant_record(out, {"stribeck": str(home / "victim.txt") if rel == "ABS" else rel})
    before = _snapshot(home)
    with pytest.warns(DataQualityWarning, match="not deleting the model file"):
        run = run_fleet(manifest, out, executor=SerialExecutor())
    assert run.failed == 1  # the joint ran (its log is missing) and its record was rewritten
    assert _snapshot(home) == before
    assert other.read_text() == PRECIOUS and wrong.read_text() == PRECIOUS
    if victim is not None:
        assert victim.read_text() == PRECIOUS


def test_a_record_cannot_delete_through_a_linked_models_folder(site):
    _root, manifest, out, home = site
    (out / "models").mkdir(parents=True)
    (out / "models" / "r1").symlink_to(home)  # models/r1/j1.stribeck.json is the user's
    _plant_record(out, {"stribeck": "models/r1/j1.stribeck.json"})
    with pytest.raises(ConfigError, match="is a symbolic link"):
        run_fleet(manifest, out, executor=SerialExecutor())
    assert (home / "j1.stribeck.json").read_text() == PRECIOUS


def test_the_fleets_own_stale_model_file_is_still_removed(site):
    _root, manifest, out, _home = site
    stale = out / "models" / "r1" / "j1.stribeck.json"
    stale.parent.mkdir(parents=True)
    stale.write_text("{}")
    _plant_record(out, {"stribeck": "models/r1/j1.stribeck.json"})
    run_fleet(manifest, out, executor=SerialExecutor())
    assert not stale.exists()  # the joint failed now: its old model file no longer belongs


@pytest.mark.parametrize(
    "record",
    [
        {"model_files": ["/etc/passwd"]},
        {"model_files": {"stribeck": 5}},
        {"robot": "../../userdir", "joint": "victim"},  # a record of another joint
        {"date": "../../" + "x" * 300},
        {"rows": [{"robot": "r1", "joint": "j1", "date": "2026-01-01", "n_samples": "lots"}]},
        {"rows": "not rows"},
    ],
)
def test_a_record_of_the_wrong_shape_is_ignored_with_a_warning(site, record):
    _root, manifest, out, home = site
    path = _plant_record(out, {}, **record)
    before = _snapshot(home)
    with pytest.warns(DataQualityWarning, match="ignoring the record"):
        run = run_fleet(manifest, out, executor=SerialExecutor())
    assert run.failed == 1 and _snapshot(home) == before
    assert json.loads(path.read_text())["robot"] == "r1"  # rewritten by this run


def test_a_record_naming_another_joint_cannot_redirect_a_write(site):
    """A reused record (ok, same settings, same content) used to be rewritten at the robot
    and joint it names: ``../../home`` wrote over the user's ``home/j1.json``."""
    from fricid.fleet.hashing import input_hash, settings_hash

    root, manifest, out, home = site
    (root / "nowhere.csv").write_text("t\n")
    spec = read_manifest(manifest).joints[0]
    _plant_record(
        out,
        {},
        status="ok",
        robot="../../userdir",
        settings_hash=settings_hash(spec.settings()),
        input_hash=input_hash(spec.log, spec.reader, spec.reader_options),
        input_stat="changed since",
    )
    before = _snapshot(home)
    with pytest.warns(DataQualityWarning, match="record of another joint"):
        run_fleet(manifest, out, executor=SerialExecutor())
    assert _snapshot(home) == before
    assert json.loads((out / "records" / "r1" / "j1.json").read_text())["robot"] == "r1"


# --------------------------------------------------------------------------- 2. links


@pytest.mark.parametrize(
    ("link", "target"),
    [
        ("records/r1", "userdir"),  # the record would land in the user's folder
        ("records", "userdir"),
        ("records/r1/j1.json", "userdir/j1.json"),
        ("models/r1", "userdir"),
        ("results.csv", "userdir/victim.txt"),
        ("results", "userdir"),
        (".lock", "userdir/victim.txt"),
    ],
)
def test_nothing_is_written_through_a_link_under_out(site, link, target):
    root, manifest, out, home = site
    path = out / link
    path.parent.mkdir(parents=True, exist_ok=True)
    path.symlink_to(root / target)
    before = _snapshot(home)
    with pytest.raises(ConfigError, match="symbolic link") as info:
        run_fleet(manifest, out, executor=SerialExecutor())
    assert str(path) in str(info.value) and "\n" not in str(info.value)
    assert _snapshot(home) == before


def test_a_link_under_out_is_one_line_through_the_cli(site):
    _root, manifest, out, home = site
    (out / "records").mkdir(parents=True)
    (out / "records" / "r1").symlink_to(home)
    result = runner.invoke(app, ["fleet", str(manifest), "--out", str(out), "-j", "1"])
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "is a symbolic link" in lines[0], result.stderr
    assert (home / "j1.json").read_text() == PRECIOUS


@pytest.mark.parametrize("kind", ["fifo", "folder"])
def test_a_record_that_is_not_a_file_is_refused(site, kind):
    _root, manifest, out, _home = site
    path = out / "records" / "r1" / "j1.json"
    path.parent.mkdir(parents=True)
    os.mkfifo(path) if kind == "fifo" else path.mkdir()
    got = _with_deadline(lambda: run_fleet(manifest, out, executor=SerialExecutor()), path)
    assert isinstance(got.get("error"), ConfigError), got
    assert "where fricid writes a file" in str(got["error"])


def test_a_huge_record_is_not_read(site):
    _root, manifest, out, _home = site
    path = _plant_record(out, {})
    with open(path, "r+b") as fh:
        fh.truncate(64 * 2**20)  # sparse: 64 MiB of zeros, no disk used
    with pytest.warns(DataQualityWarning, match="larger than"):
        run = run_fleet(manifest, out, executor=SerialExecutor())
    assert run.failed == 1 and path.stat().st_size < 2**20


# --------------------------------------------------------------------------- 3. names


def _manifest(tmp_path: Path, robot: str, joint: str, model: str = "stribeck") -> Path:
    path = tmp_path / "m.csv"
    path.write_text(f"robot,joint,log,model\n{robot},{joint},x.csv,{model}\n", encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("robot", "joint", "model", "column"),
    [
        ("r1", "j" * 300, "stribeck", "joint"),
        ("r1", "j" * 242, "stribeck", "joint"),  # j...j.stribeck.json is 256 bytes
        ("r1", "j" * 237, "stribeck_asym", "joint"),
        ("r" * 256, "j1", "stribeck", "robot"),
        ("r" * 250, "j1", "stribeck", "robot"),  # its partition folder robot=r...r is 256
    ],
)
def test_names_the_file_system_cannot_hold_are_refused_first(tmp_path, robot, joint, model, column):
    path = _manifest(tmp_path, robot, joint, model)
    with pytest.raises(DataError, match="too long") as info:
        read_manifest(path)
    assert (info.value.row, info.value.column) == (2, column)
    assert "\n" not in str(info.value) and "255 bytes" in str(info.value)


def test_the_longest_names_that_fit_are_accepted_and_written(tmp_path):
    """The limit is exact: a joint of 241 characters with ``.stribeck.json`` is 255 bytes, a
    robot of 249 makes ``robot=<249>``, 255 bytes: both written, record, model and table."""
    from fricid.fleet.table import results_table, write_results

    spec = read_manifest(_manifest(tmp_path, "r" * 249, "j" * 241)).joints[0]
    row = {**fit_row(spec, "stribeck", None, None), "status": "ok", "stage": None}
    outcome = JointOutcome(
        spec.robot, spec.joint, "ok", rows=[row], models={"stribeck": {"model": "stribeck"}}
    )
    out = tmp_path / "out"
    with FleetStore(out) as store:
        store.check(spec)
        record = store.save(
            spec, outcome, date="2026-03-01", settings={}, settings_hash="x", input_stat=None
        )
    write_results(results_table([record]), out)
    model = out / "models" / spec.robot / f"{spec.joint}.stribeck.json"
    assert len(model.name) == 255 and model.is_file()
    assert (out / "results" / f"robot={spec.robot}").is_dir()


def test_a_path_longer_than_path_max_is_refused_before_any_work(tmp_path):
    manifest = _manifest(tmp_path, "r1", "j" * 200)
    out = tmp_path.joinpath(*(["d" * 200] * 19))  # some 3900 bytes
    with pytest.raises(DataError, match="makes a path of") as info:
        run_fleet(manifest, out, executor=SerialExecutor())
    assert (info.value.row, info.value.column) == (2, "joint")
    assert not (tmp_path / ("d" * 200)).exists()  # nothing made


# --------------------------------------------------------------------------- 4. YAML


def _laughs(levels: int, width: int = 10) -> str:
    lines = [f"a0: &a0 [{', '.join(['lol'] * width)}]"]
    for i in range(1, levels):
        lines.append(f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * width)}]")
    return "\n".join(lines) + f"\njoints: *a{levels - 1}\n"


def test_a_billion_laughs_manifest_is_refused_at_once(tmp_path):
    path = tmp_path / "m.yaml"
    path.write_text(_laughs(9), encoding="utf-8")  # 10**9 values in some 500 bytes
    assert path.stat().st_size < 600
    t0 = time.perf_counter()
    with pytest.raises(DataError, match="aliases stand for"):
        read_manifest(path)
    assert time.perf_counter() - t0 < 2.0


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("joints: &x [*x]\n", "refers to a value that contains it"),
        ("joints:\n  - " + "[" * 2000 + "]" * 2000 + "\n", "nest"),
        ("joints:\n  - " + "{a: " * 200 + "1" + "}" * 200 + "\n", "nested more than 32"),
    ],
)
def test_a_self_referring_or_endless_yaml_manifest_is_refused(tmp_path, text, words):
    path = tmp_path / "m.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(DataError, match=words):
        read_manifest(path)


def test_yaml_aliases_of_a_normal_manifest_still_work(tmp_path):
    path = tmp_path / "m.yaml"
    path.write_text(
        "base: &base {model: [msk, vlt], method: lm}\njoints:\n"
        + "".join(f"  - {{<<: *base, robot: R1, joint: j{i}, log: a.csv}}\n" for i in range(50)),
        encoding="utf-8",
    )
    with pytest.raises(DataError, match="unknown top-level key 'base'"):
        read_manifest(path)  # a manifest has no such key; the aliases were expanded fine
    path.write_text(
        "defaults: &d {method: lm}\njoints:\n"
        + "".join(f"  - {{robot: R1, joint: j{i}, log: a.csv, seed: {i}}}\n" for i in range(50)),
        encoding="utf-8",
    )
    assert len(read_manifest(path)) == 50


# --------------------------------------------------------------------------- 5. special files


@pytest.mark.parametrize("kind", ["fifo", "dev_zero", "folder"])
def test_a_manifest_that_is_not_a_regular_file_is_refused_unread(tmp_path, kind):
    path = tmp_path / "m.csv"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "dev_zero":
        path.symlink_to("/dev/zero")
    else:
        path.mkdir()
    got = _with_deadline(lambda: read_manifest(path), path)
    assert isinstance(got.get("error"), DataError), got
    assert "not a regular file" in str(got["error"])


def test_a_manifest_larger_than_the_cap_is_refused_unread(tmp_path):
    path = tmp_path / "m.csv"
    with open(path, "wb") as fh:
        fh.truncate(17 * 2**20)
    with pytest.raises(DataError, match="larger than 16 MiB"):
        read_manifest(path)


@pytest.mark.slow
def test_special_logs_fail_their_joint_without_blocking(tmp_path):
    """A FIFO, /dev/zero and a folder as logs fail their joints at once (stage read); the
    fleet finishes. A subprocess, so that a fleet blocked on the FIFO can be stopped."""
    os.mkfifo(tmp_path / "fifo.csv")
    (tmp_path / "zero.csv").symlink_to("/dev/zero")
    (tmp_path / "folder.csv").mkdir()
    (tmp_path / "m.csv").write_text(
        "robot,joint,log\nr1,j1,fifo.csv\nr1,j2,zero.csv\nr1,j3,folder.csv\n", encoding="utf-8"
    )
    args = ["fleet", "m.csv", "--out", "out", "-j", "1", "--quiet"]
    proc = subprocess.run(
        [sys.executable, "-c", ENTRY, *args],
        cwd=tmp_path,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 1, proc.stderr
    folder = tmp_path / "out" / "records" / "r1"
    records = [json.loads((folder / f"j{i}.json").read_text()) for i in (1, 2, 3)]
    assert [r["stage"] for r in records] == ["read"] * 3
    assert "FIFO" in records[0]["error"] and "character device" in records[1]["error"]
    assert "a folder" in records[2]["error"]


# --------------------------------------------------------------------------- 7. minor


def _slow_log(tmp_path: Path) -> Path:
    """A simulated log whose fit with a 5-evaluation budget warns (not converged)."""
    from test_fleet import scenario, write_log

    return write_log(scenario(), 0, tmp_path / "log.parquet")


@pytest.mark.slow
def test_worker_warnings_travel_with_the_outcome(tmp_path, capfd):
    """A warning raised in a pool worker is not printed there (Python's raw format, with the
    source line) but returned, and recorded with the joint."""
    log = _slow_log(tmp_path)
    spec = JointSpec("r1", "j1", log, str(log), models=("coulomb_viscous",), max_evals=5)
    results = dict(ProcessExecutor(1).run(run_job, [JointJob(spec)]))
    outcome = results[0]
    assert outcome.status == "ok"
    assert [w["category"] for w in outcome.warnings] == ["fricid.errors:ConvergenceWarning"]
    err = capfd.readouterr().err
    assert "ConvergenceWarning" not in err and "warnings.warn" not in err, err


def test_the_driver_shows_worker_warnings_in_one_line(tmp_path):
    log = _slow_log(tmp_path)
    manifest = tmp_path / "m.csv"
    manifest.write_text(
        f"robot,joint,log,model,max_evals\nr1,j1,{log},coulomb_viscous,5\n", encoding="utf-8"
    )
    result = runner.invoke(
        app, ["fleet", str(manifest), "--out", str(tmp_path / "out"), "-j", "1", "--quiet"]
    )
    assert result.exit_code == 0, result.output
    lines = [ln for ln in result.stderr.splitlines() if "warning" in ln]
    assert len(lines) == 1 and lines[0].startswith("warning (convergence): r1/j1: fitting")
    record = json.loads((tmp_path / "out/records/r1/j1.json").read_text())
    assert record["warnings"][0].startswith("ConvergenceWarning: fitting 'coulomb_viscous'")
    with pytest.warns(ConvergenceWarning, match="r1/j1: fitting"):
        run_fleet(manifest, tmp_path / "out2", executor=SerialExecutor())


def test_a_signal_after_the_command_is_one_line_and_130(tmp_path):
    """The console script's last exit hook: a SIGINT that arrived after the command says so
    and ends the process with 130 (before, the interpreter's teardown killed it silently)."""
    script = (
        "import os, signal, time\n"
        "from fricid.cli import _app\n"
        "with _app.signal_handlers(until_exit=True):\n"
        "    pass\n"
        "os.kill(os.getpid(), signal.SIGINT)\n"
        "time.sleep(0.2)\n"
        "_app.end_process(0)\n"
        "print('not reached')\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", script], env=_env(), capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 130, proc.stderr
    assert proc.stderr == "interrupted; no file was left half-written\n"
    assert "not reached" not in proc.stdout


@pytest.mark.slow
def test_ctrl_c_just_after_wrote_is_never_silent(site):
    """SIGINT as soon as "wrote" appears: the process ends either with the command's own
    status (it had finished) or with the one-line message and 130, never killed silently."""
    root, manifest, _out, _home = site
    args = ["fleet", str(manifest), "--out", str(root / "out"), "-j", "1", "--quiet"]
    proc = subprocess.Popen(
        [sys.executable, "-c", ENTRY, *args],
        cwd=root,
        env=_env(),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    err = b""
    while b"wrote" not in err:
        chunk = proc.stderr.read1(4096)
        if not chunk:
            break
        err += chunk
    time.sleep(0.01)
    with contextlib.suppress(ProcessLookupError):  # it may have ended already
        proc.send_signal(signal.SIGINT)
    err += proc.stderr.read()
    code = proc.wait(timeout=60)
    text = err.decode()
    assert code in (1, 130), (code, text)
    assert (code == 130) == ("interrupted; no file was left half-written" in text), text
