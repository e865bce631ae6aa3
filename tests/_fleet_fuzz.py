"""Hostile fleet manifests and output folders, and the oracle that judges a fleet run.

Shared by ``tests/fleet/test_fuzz_fleet.py`` (hypothesis draws the choices) and
``benchmarks/fuzz_fleet.py`` (a seeded generator draws them, longer, and counts outcomes).
Each case is a fresh folder: a manifest (CSV or YAML) of one to three joints with drawn
names (short, at and beyond the file system's limits, unicode, ``..``, separators, NUL,
line breaks), models and logs (missing, a FIFO, ``/dev/zero``, a folder, junk, a link to a
user's file, or a log the stand-in executor "fits"), a sentinel folder of a user's files
beside the output folder, and an output folder planted with what a results folder from a
stranger may hold: records naming absolute paths, ``..``, links, long and unicode paths;
records that are links, FIFOs, huge, of another joint, reusable with hostile rows; links in
place of the fleet's folders and files; a link named like a stale temporary file.

A case ends in one of four ways (:func:`run_case`):

- ``"error"``: a :class:`~fricid.errors.FricidError` on one line;
- ``"valid"``: the run finished and every joint's record is a regular file at its own path
  under ``--out`` (no link on the way);
- a traceback: any other exception, or a case that ran past :data:`CASE_SECONDS`
  (:class:`CaseTimeout`);
- :class:`WrongAnswer`: a file outside ``--out`` (the sentinel folder, the logs, the
  manifest) or a user's file inside it was created, changed or removed.

The fleet runs with a stand-in executor (:class:`StandInFits`): a joint whose log is named
``fit_me*`` gets a model file as a fitted joint does, without minutes of fitting; every other
joint runs the real :func:`fricid.fleet.run_job` (reading, hashing, failing).
"""

from __future__ import annotations

import contextlib
import csv
import hashlib
import io
import json
import os
import re
import signal
import stat
import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fricid.errors import FricidError
from fricid.fleet import run_fleet
from fricid.fleet.hashing import RECORD_FORMAT, input_hash, input_stat, settings_hash
from fricid.fleet.job import JointJob, JointOutcome, fit_row
from fricid.fleet.manifest import read_manifest
from fricid.io.atomic import HOST_TAG
from fuzzing import RngChooser

#: The most one case may take [s] (the issue's budget is 60 s; a case takes well under 1 s).
CASE_SECONDS = 30.0

NAME_KINDS = (
    "short",
    "short",
    "short",
    "long",
    "long",
    "unicode",
    "dots",
    "separator",
    "nul",
    "line_break",
    "blank",
    "suffix",
)
#: Lengths around the limits: 241 + ".stribeck.json" is 255 bytes, "robot=" + 249 too.
LONG = (100, 200, 236, 237, 240, 241, 242, 243, 248, 249, 250, 251, 255, 256, 300, 1000, 5000)
UNICODE = ("é", "日本", "\u202e", "\U0001f600", "\u2028", "\ufeff", "\udcff")
MODELS = ("stribeck", "coulomb_viscous", "stribeck_asym", "vlt", "stribeck", "msk_temp_asym")
LOG_KINDS = (
    "missing",
    "fifo",
    "dev_zero",
    "folder",
    "junk",
    "fit_me",
    "fit_me",
    "fit_me",
    "user_file",
)
PLANTS = (
    "record_paths",
    "record_paths",
    "record_paths",
    "record_link",
    "robot_records_link",
    "robot_models_link",
    "records_link",
    "models_link",
    "results_link",
    "results_csv_link",
    "lock_link",
    "record_fifo",
    "record_huge",
    "record_other_joint",
    "record_reusable",
    "record_junk",
    "model_file_link",
    "stale_temp_link",
)
YAML_KINDS = ("plain",) * 5 + ("defaults",) * 2 + ("bomb", "recursive", "deep")
_PLAIN = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,199}")


class WrongAnswer(AssertionError):
    """A file outside ``--out``, or a user's file inside it, was touched."""


class CaseTimeout(Exception):
    """A case ran past :data:`CASE_SECONDS`."""


# --------------------------------------------------------------------------- drawing


def draw_name(ch: RngChooser, prefix: str) -> str:
    """A robot or joint name, hostile or not."""
    kind = ch.choice(NAME_KINDS)
    if kind == "short":
        return f"{prefix}{ch.integer(0, 2)}"
    if kind == "long":
        return prefix + "x" * (ch.choice(LONG) - len(prefix))
    if kind == "unicode":
        return prefix + ch.choice(UNICODE) * ch.integer(1, 90)
    if kind == "dots":
        return ch.choice([".", "..", "...", "a..b", ".hidden", f"{prefix}."])
    if kind == "separator":
        return ch.choice(["a/b", "../x", "/abs", "a\\b", f"{prefix}/../..", "..%2F"])
    if kind == "nul":
        return f"{prefix}\x00x"
    if kind == "line_break":
        return ch.choice([f"{prefix}\n", f"{prefix}\r", f"{prefix}\nx"])
    if kind == "blank":
        return ch.choice(["", " ", f" {prefix}", f"{prefix} "])
    return prefix + ch.choice([".json", ".stribeck", ".lock", "-", "_"])


@dataclass
class Joint:
    robot: str
    joint: str
    models: list[str]
    log_kind: str
    log_text: str = ""


@dataclass
class Case:
    """One drawn case, built in ``root`` by :func:`build_case`."""

    root: Path
    joints: list[Joint]
    yaml_kind: str | None  # None: a CSV manifest
    plants: list[str]
    record_paths: list[tuple[Any, Any]] = field(default_factory=list)
    manifest: Path = Path()
    out: Path = Path()
    sentinel: Path = Path()
    protected: list[Path] = field(default_factory=list)


def draw_case(ch: RngChooser, root: Path) -> Case:
    """The choices of one case (nothing written yet). Half the cases draw hostile names;
    the other half short names, so that their runs reach the output folder's hazards."""
    hostile = bool(ch.integer(0, 1))
    joints = []
    for _ in range(ch.integer(1, 3)):
        models = [ch.choice(MODELS) for _ in range(ch.integer(1, 2))]
        if hostile and not ch.integer(0, 5):
            models.append("no_such_model")
        robot = draw_name(ch, "r") if hostile else f"r{ch.integer(0, 1)}"
        joint = draw_name(ch, "j") if hostile else f"j{ch.integer(0, 2)}"
        joints.append(Joint(robot, joint, list(dict.fromkeys(models)), ch.choice(LOG_KINDS)))
    yaml_kind = ch.choice(YAML_KINDS) if ch.integer(0, 1) else None
    plants = [ch.choice(PLANTS) for _ in range(ch.integer(0, 4))]
    paths = []
    if "record_paths" in plants:
        for _ in range(ch.integer(1, 4)):
            model = ch.choice(["stribeck", "coulomb_viscous", "x/../y", "", "..", 5, None])
            paths.append((model, ch.integer(0, 15)))  # which hostile path (:func:`_bad_path`)
    return Case(root, joints, yaml_kind, plants, paths)


# --------------------------------------------------------------------------- building


def _target(case: Case) -> tuple[str, str, str]:
    """The robot, joint and model plants go to: the first joint whose names are plain (so
    that the planted path is the one the fleet would use), else r1/j1."""
    for j in case.joints:
        if _PLAIN.fullmatch(j.robot) and _PLAIN.fullmatch(j.joint):
            return j.robot, j.joint, j.models[0]
    return "r1", "j1", "stribeck"


def _bad_path(case: Case, which: int) -> Any:
    robot, joint, model = _target(case)
    victim = case.sentinel / "victim.txt"
    options: list[Any] = [
        str(victim),
        "../" * 3 + "sentinel/victim.txt",
        "../" * 5 + "sentinel/victim.txt",
        f"models/{robot}/../../../sentinel/victim.txt",
        f"models/{robot}/{joint}.{model}.json",  # the fleet's own file: may go
        "models/zz9/j9.stribeck.json",  # another joint's (a user's file here)
        "notes.txt",
        "link/victim.txt",  # through a link planted in --out
        "é" * 300,
        "x" * 5000,
        "a\x00b",
        f"models/{'a' * 300}/b.json",
        5,
        None,
        ["models", robot],
        str(case.sentinel),
    ]
    return options[which % len(options)]


def _write_manifest(case: Case) -> None:
    rows = [
        {"robot": j.robot, "joint": j.joint, "log": j.log_text, "model": ";".join(j.models)}
        for j in case.joints
    ]
    if case.yaml_kind is None:
        case.manifest = case.root / "fleet.csv"
        buf = io.StringIO()
        writer = csv.DictWriter(buf, ["robot", "joint", "log", "model"], lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)
        case.manifest.write_text(buf.getvalue(), encoding="utf-8", errors="surrogateescape")
        return
    import yaml

    case.manifest = case.root / "fleet.yaml"
    if case.yaml_kind == "bomb":
        levels, width = 3 + len(case.joints) * 2, 9
        lines = [f"a0: &a0 [{', '.join(['lol'] * width)}]"]
        lines += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * width)}]" for i in range(1, levels)]
        text = "\n".join(lines) + f"\njoints: *a{levels - 1}\n"
    elif case.yaml_kind == "recursive":
        text = "joints: &x [*x]\n"
    elif case.yaml_kind == "deep":
        depth = (10, 40, 1000, 5000)[len(case.joints)]
        text = "joints:\n  - " + "[" * depth + "]" * depth + "\n"
    elif case.yaml_kind == "defaults":  # merge keys: each joint takes the defaults' alias
        items = [
            "{<<: *d, "
            + ", ".join(f"{k}: {json.dumps(v)}" for k, v in r.items() if k != "model")
            + f", model: {json.dumps(r['model'].split(';'))}}}"
            for r in rows
        ]
        text = "defaults: &d {method: lm}\njoints:\n" + "".join(f"  - {i}\n" for i in items)
    else:
        body = [{**r, "model": r["model"].split(";")} for r in rows]
        text = yaml.safe_dump({"joints": body}, allow_unicode=True)
    case.manifest.write_bytes(text.encode("utf-8", "surrogateescape"))


def _write_log(case: Case, i: int, j: Joint) -> None:
    logs = case.root / "logs"
    name = {"fit_me": f"fit_me{i}.csv", "user_file": f"user{i}.csv"}.get(
        j.log_kind, f"{j.log_kind}{i}.csv"
    )
    path = logs / name
    if j.log_kind == "fifo":
        os.mkfifo(path)
    elif j.log_kind == "dev_zero":
        path.symlink_to("/dev/zero")
    elif j.log_kind == "folder":
        path.mkdir()
    elif j.log_kind == "junk":
        path.write_bytes(hashlib.sha256(name.encode()).digest() * 8)
    elif j.log_kind == "fit_me":
        path.write_text(f"a log of joint {i}\n")
    elif j.log_kind == "user_file":
        path.symlink_to(case.sentinel / "victim.txt")
    j.log_text = f"logs/{name}"


def _record(robot: str, joint: str, **extra: Any) -> dict[str, Any]:
    return {
        "format": RECORD_FORMAT,
        "robot": robot,
        "joint": joint,
        "date": "2026-01-01",
        "status": "failed",
        "model_files": {},
        "rows": [],
        **extra,
    }


def _link(path: Path, target: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    if not os.path.lexists(path):
        path.symlink_to(target)


def _plant(case: Case, plant: str) -> None:
    robot, joint, model = _target(case)
    out, sentinel = case.out, case.sentinel
    record = out / "records" / robot / f"{joint}.json"
    if plant in ("record_paths", "record_other_joint", "record_reusable", "record_junk"):
        if os.path.lexists(record) or not _real_dirs(out, record.parent):
            return
        record.parent.mkdir(parents=True, exist_ok=True)
    if plant == "record_paths":
        files = {}
        for key, which in case.record_paths:
            files[key if isinstance(key, str) else str(key)] = _bad_path(case, which)
        doc = _record(robot, joint, model_files=files)
        if case.record_paths and case.record_paths[0][1] % 3 == 0:
            doc["model_files"] = [_bad_path(case, w) for _, w in case.record_paths]
        _link(out / "link", sentinel)
        record.write_text(json.dumps(doc))
    elif plant == "record_other_joint":
        record.write_text(json.dumps(_record("../../sentinel", "victim", status="ok")))
    elif plant == "record_reusable":
        _plant_reusable(case, record, robot, joint)
    elif plant == "record_junk":
        record.write_bytes(b"\xff{" + b"[" * 100_000)
    elif plant == "record_link":
        _link(record, sentinel / "victim.txt")
    elif plant == "robot_records_link":
        _link(out / "records" / robot, sentinel)
    elif plant == "robot_models_link":
        _link(out / "models" / robot, sentinel)
    elif plant in ("records_link", "models_link", "results_link"):
        _link(out / plant.removesuffix("_link"), sentinel)
    elif plant == "results_csv_link":
        _link(out / "results.csv", sentinel / "victim.txt")
    elif plant == "lock_link":
        _link(out / ".lock", sentinel / "victim.txt")
    elif plant == "record_fifo":
        if _real_dirs(out, record.parent) and not os.path.lexists(record):
            record.parent.mkdir(parents=True, exist_ok=True)
            os.mkfifo(record)
    elif plant == "record_huge":
        if _real_dirs(out, record.parent) and not os.path.lexists(record):
            record.parent.mkdir(parents=True, exist_ok=True)
            with open(record, "wb") as fh:
                fh.truncate(20 * 2**20)  # sparse
    elif plant == "model_file_link":
        path = out / "models" / robot / f"{joint}.{model}.json"
        if _real_dirs(out, path.parent):
            _link(path, sentinel / f"{joint}.{model}.json")
    elif plant == "stale_temp_link":
        _link(out / f".x.json.fricid-{HOST_TAG}-4194303-abcdefgh.tmp", sentinel / "victim.txt")


def _real_dirs(root: Path, folder: Path) -> bool:
    """Whether ``folder`` under ``root`` is (or can be made) of real folders only."""
    path = root
    for part in folder.relative_to(root).parts:
        path = path / part
        if os.path.islink(path) or (os.path.lexists(path) and not path.is_dir()):
            return False
    return True


def _plant_reusable(case: Case, record: Path, robot: str, joint: str) -> None:
    """A record the run reuses (ok, same settings, same content) with hostile contents."""
    try:
        spec = next(s for s in read_manifest(case.manifest) if (s.robot, s.joint) == (robot, joint))
        digest = input_hash(spec.log, spec.reader, spec.reader_options)
        stat_sig = input_stat(spec.log, spec.reader, spec.reader_options)
    except (FricidError, OSError, StopIteration):
        return
    row = {"robot": robot, "joint": joint, "date": "../../sentinel", "model": "x" * 300}
    doc = _record(
        robot,
        joint,
        status="ok",
        settings_hash=settings_hash(spec.settings()),
        input_hash=digest,
        input_stat=stat_sig if len(case.plants) % 2 else "stale",
        rows=[row, {**row, "date": "2026-01-01", "n_samples": "lots", "param_x": 10**400}],
        model_files={"stribeck": str(case.sentinel / "victim.txt")},
    )
    record.write_text(json.dumps(doc))


def build_case(case: Case) -> Case:
    """Write the case's folders: sentinel, logs, manifest, output folder with its plants."""
    case.sentinel = case.root / "sentinel"
    case.out = case.root / "out"
    (case.sentinel / "sub").mkdir(parents=True)
    (case.root / "logs").mkdir()
    case.out.mkdir()
    (case.sentinel / "victim.txt").write_text("a user's file\n")
    (case.sentinel / "sub" / "victim.json").write_text("{}\n")
    for j in case.joints:
        for name in (f"{j.joint}.json", *(f"{j.joint}.{m}.json" for m in j.models)):
            with contextlib.suppress(OSError, ValueError):  # an unusable name: no such file
                if _PLAIN.fullmatch(name.removesuffix(".json")):
                    (case.sentinel / name).write_text("a user's file\n")
    for i, j in enumerate(case.joints):
        _write_log(case, i, j)
    _write_manifest(case)
    for plant in case.plants:
        _plant(case, plant)
    notes = case.out / "notes.txt"
    notes.write_text("a user's notes\n")
    case.protected = [notes]
    other = case.out / "models" / "zz9" / "j9.stribeck.json"
    if _real_dirs(case.out, other.parent):
        other.parent.mkdir(parents=True, exist_ok=True)
        other.write_text("another joint's model, kept\n")
        case.protected.append(other)
    return case


# --------------------------------------------------------------------------- running


class StandInFits:
    """An executor that "fits" the joints whose log is named ``fit_me*`` at once (a model
    file per model, as a fitted joint has) and runs :func:`run_job` for the others."""

    name = "stand-in"
    workers = 1

    def run(self, fn, items) -> Iterator[tuple[int, Any]]:
        for i, job in enumerate(items):
            yield i, (_fitted(job) if job.spec.log.name.startswith("fit_me") else fn(job))

    def close(self) -> None:
        """Nothing to release."""


def _fitted(job: JointJob) -> JointOutcome:
    spec = job.spec
    rows = [{**fit_row(spec, m, None, None), "status": "ok", "stage": None} for m in spec.models]
    digest = input_hash(spec.log, spec.reader, spec.reader_options)
    models = {m: {"model": m, "params": {}} for m in spec.models}
    return JointOutcome(spec.robot, spec.joint, "ok", input_hash=digest, rows=rows, models=models)


def snapshot(root: Path, skip: Path, keep: list[Path]) -> dict[str, tuple]:
    """Every file and folder under ``root`` but ``skip`` (not followed through links), and
    the files ``keep``: kind, size, modification time, content or link target."""
    found: dict[str, tuple] = {}
    paths: list[str] = [str(p) for p in keep]
    for folder, dirs, files in os.walk(root):
        if Path(folder) == skip:
            dirs[:] = []
            continue
        paths += [os.path.join(folder, n) for n in dirs + files if Path(folder, n) != skip]
    for path in paths:
        try:
            info = os.lstat(path)
        except FileNotFoundError:
            found[path] = ("missing",)
            continue
        if stat.S_ISLNK(info.st_mode):
            body: Any = os.readlink(path)
        elif stat.S_ISREG(info.st_mode):
            with open(path, "rb") as fh:
                body = hashlib.sha256(fh.read()).hexdigest()
        else:
            body = None
        found[path] = (stat.S_IFMT(info.st_mode), info.st_size, info.st_mtime_ns, body)
    return found


@contextlib.contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Raise :class:`CaseTimeout` in the body after ``seconds`` (main thread, POSIX)."""

    def expire(signum, frame):
        raise CaseTimeout(f"the case ran past {seconds} s")

    old = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def _check_records(case: Case, run: Any) -> None:
    """A valid run: each joint's record is a regular file at its own path, no link on it."""
    for record in run.records:
        path = case.out / "records" / record["robot"] / f"{record['joint']}.json"
        here = case.out
        for part in path.relative_to(case.out).parts:
            here = here / part
            if here.is_symlink():
                raise WrongAnswer(f"a record was written through the link {here}")
        if not path.is_file():
            raise WrongAnswer(f"no record at {path}")


def run_case(case: Case) -> tuple[str, str]:
    """Run the fleet on a built case: ``("error", message)`` or ``("valid", "")``.

    Raises :class:`WrongAnswer` if a file outside ``--out`` (or a user's file inside it)
    changed, :class:`CaseTimeout` past :data:`CASE_SECONDS`; any other exception is a
    traceback.
    """
    before = snapshot(case.root, case.out, case.protected)
    try:
        with time_limit(CASE_SECONDS), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                run = run_fleet(case.manifest, case.out, executor=StandInFits(), date="2026-03-01")
            except FricidError as exc:
                message = str(exc)
                if "\n" in message or "\r" in message:
                    raise WrongAnswer(f"a message of several lines: {message!r}") from None
                return "error", message
        _check_records(case, run)
        return "valid", ""
    finally:
        after = snapshot(case.root, case.out, case.protected)
        changed = sorted(k for k in before.keys() | after.keys() if before.get(k) != after.get(k))
        if changed:
            raise WrongAnswer(f"touched outside --out: {changed[:5]}")
