"""The small workspace every documented command runs in (README, ``fricid extract --help``, the
documentation site under ``docs/``): the files those commands name, built once, small, and
how a documented command is made small where running it as written would take minutes.

:data:`SMALLER` lists the arguments added to make a command small (a smaller preset, a
budget), :data:`PARSE_ONLY` the commands that are only parsed (every option must exist)
because another test runs them at a small size; both say why.
"""

from __future__ import annotations

import re
import shlex
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np

from _paths import REPO

#: Arguments appended to run a README command on small data (the command as written runs
#: for minutes): why, each.
SMALLER: dict[str, tuple[list[str], str]] = {
    "fricid simulate --preset paper1 --size reduced --out log.parquet": (
        ["--size", "quick"],
        "the reduced campaign is 1.2 million rows; quick is the same chain",
    ),
    "fricid fit samples.csv --model stribeck --fix delta=1 --method rwsavsbas": (
        ["--max-evals", "3000"],
        "the default budget is 301,001 evaluations",
    ),
    "fricid fit samples.csv --model rbf --method bas --centers 40": (
        ["--max-evals", "4000", "--centers", "12"],
        "BAS-RBFNN's default epochs take half a minute; the quick campaign has 30 samples",
    ),
    "fricid compensate vlt.json --truth paper1": (
        ["--dt", "0.001"],
        "the default step of 0.2 ms simulates 5x the steps for the same check",
    ),
    "fricid robot design --robot panda --out design.json --csv traj.csv --ros-yaml traj.yaml": (
        [
            "--robot",
            "double_pendulum",
            "--max-evaluations",
            "300",
            "--duration",
            "10",
            "--rate",
            "50",
            "--yaml-rate",
            "10",
        ],
        "the Panda's design takes 10 s of CPU (tests/robot/test_excitation.py runs it, slow)",
    ),
    "fricid fleet manifest.csv --out results/ --cluster local:2": (
        ["--cluster", "", "--workers", "1"],
        "a Dask cluster takes seconds to start (tests/fleet/test_fleet.py runs one)",
    ),
}

#: Commands only parsed here (``--help`` appended: every option named must exist), because
#: they run for minutes even at their smallest, and the test that runs them instead.
PARSE_ONLY: dict[str, str] = {
    "fricid demo": "tests/cli/test_cli.py runs it (--size quick) and checks its outputs",
    "fricid fit leadscrew.csv --model auto --validate lovo": (
        "tests/identify/test_validation.py runs `fricid fit --model auto` (lovo, its default); "
        "on the "
        "lead screw it refits every family per held-out level: about 40 s on 2 shared cores"
    ),
    "fricid reproduce rwsavsbas --quick": "tests/experiments/test_reproduce.py runs it (--quick)",
    "fricid reproduce bas-rbfnn --quick": "tests/experiments/test_reproduce.py runs it (--quick)",
    "fricid bench stribeck": "tests/experiments/test_optim_study.py runs the study (runs=1, quick)",
    "fricid bench rbfnn --quick": (
        "tests/experiments/test_rbfnn_study.py runs it (--quick, fewer seeds)"
    ),
}


def _write_bag(path: Path, log) -> None:
    """``log`` recorded as /joint_states of joint 'elbow' with effort = motor current [A]."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    joint_state = ts.types["sensor_msgs/msg/JointState"]
    header, stamp = ts.types["std_msgs/msg/Header"], ts.types["builtin_interfaces/msg/Time"]
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        conn = w.add_connection("/joint_states", joint_state.__msgtype__, typestore=ts)
        for i in range(len(log)):
            ns = 1_700_000_000_000_000_000 + round(log.time[i] * 1e9)
            msg = joint_state(
                header=header(stamp=stamp(sec=ns // 10**9, nanosec=ns % 10**9), frame_id=""),
                name=["elbow"],
                position=np.array([log.position[i]]),
                velocity=np.array([log.velocity[i]]),
                effort=np.array([log.current[i]]),
            )
            w.write(conn, ns, ts.serialize_cdr(msg, joint_state.__msgtype__))


def _urdf(path: Path, p_x: float, p_y: float, mass: float = 2.0) -> None:
    """A URDF whose joint 'elbow' has eq. 7's p_x, p_y (fricid.io.urdf's conventions)."""
    from fricid.io.urdf import STANDARD_GRAVITY as G

    x, z = p_x / (mass * G), -p_y / (mass * G)
    path.write_text(
        f"""<robot name="arm"><link name="base"/>
  <link name="arm"><inertial><origin xyz="{x!r} 0 {z!r}"/><mass value="{mass!r}"/></inertial>
  </link>
  <joint name="elbow" type="continuous"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/></joint></robot>"""
    )


def _csv(path: Path, columns: dict[str, np.ndarray]) -> None:
    """A plain CSV of ``columns`` (name: values)."""
    import pandas as pd

    pd.DataFrame({n: np.asarray(v, dtype=float) for n, v in columns.items()}).to_csv(
        path, index=False, float_format="%.10g"
    )


def _real_files(ws: Path, leadscrew: Path) -> None:
    """The files made of the real lead-screw recordings (:data:`NEEDS_REAL`)."""
    from fricid.io import write_samples
    from fricid.io.epos import epos_steady_samples

    (ws / "recordings").symlink_to(leadscrew, target_is_directory=True)
    resaved = ws / "resaved"  # as a spreadsheet re-saves them, with a bad row
    shutil.copytree(leadscrew, resaved)
    first = sorted(resaved.glob("*.csv"))[0]
    lines = first.read_text(encoding="latin-1").splitlines(keepends=True)
    lines[-5] = "oops;;\n"
    first.write_text("".join(lines), encoding="latin-1")
    # the real lead screw's samples, every other velocity level (16 of 32: small data)
    real = epos_steady_samples(leadscrew, flip_sign=True)
    levels = np.unique(np.abs(real.velocity))
    write_samples(real.subset(np.isin(np.abs(real.velocity), levels[::2])), ws / "leadscrew.csv")


def build_workspace(ws: Path, leadscrew: Path) -> None:
    """Every file the README's and the help's commands name, small."""
    import scipy.io

    from fricid.cli.simulate import design_hints
    from fricid.extract import extract
    from fricid.identify import fit
    from fricid.io import write_rawlog, write_samples
    from fricid.samples import FrictionSamples, RawLog
    from fricid.sim import preset, simulate, true_gravity

    s1 = preset("paper1", "quick")
    hints = design_hints(s1)
    chunks = [replace(c, meta={**c.meta, "design": hints}) for c in simulate(s1, seed=0)]
    write_rawlog(iter(chunks), ws / "log.parquet")
    result = extract(iter(chunks), **s1.extract_options())
    write_samples(result.samples, ws / "samples.csv")
    write_samples(result.by_direction, ws / "dir.csv")
    fit(result.samples, "vlt", seed=0, intervals="none").save(ws / "vlt.json")
    d = result.by_direction
    vf = FrictionSamples(
        velocity=d.velocity, load=None, temperature=None, friction=d.friction, direction=d.direction
    )
    write_samples(vf, ws / "velocity_friction.csv")
    fit(vf, "stribeck", seed=0, intervals="none").save(ws / "stribeck.json")
    spiky = np.array(result.samples.friction, dtype=float)
    spiky[3] += 0.3  # one spike
    write_samples(replace(result.samples, friction=spiky), ws / "spiky.csv")

    # a log with a joint torque sensor beside the current (K and the gear efficiency)
    log = RawLog.concatenate(chunks[:2])  # one temperature, two velocities: small
    tau = log.current * log.torque_constant
    cur = np.where(tau * log.velocity > 0, tau / (0.9 * 0.08), 0.9 * tau / 0.08)
    cols = {"t": log.time, "q": log.position, "dq": log.velocity, "i": cur, "tau_j": tau}
    _csv(ws / "log.csv", {**cols, "temperature": log.temperature})
    _csv(
        ws / "vendor.csv",
        {"t": 1e3 * log.time, "q": log.position, "dq": np.rad2deg(log.velocity), "tau": tau},
    )
    shutil.copy(ws / "vendor.csv", ws / "run.csv")

    # a ROS 2 bag of the current-only log (two runs), and the URDF of its gravity load
    bag_log = RawLog.concatenate(chunks[:2])
    _write_bag(ws / "run1", bag_log)
    (ws / "bag").symlink_to(ws / "run1", target_is_directory=True)
    _urdf(ws / "robot.urdf", *true_gravity(s1))

    if leadscrew.is_dir():
        _real_files(ws, leadscrew)

    # per-channel files and MATLAB mean tables
    runs_dir = ws / "runs"
    runs_dir.mkdir()
    for speed in (5, 10, 20, 40):
        w, n, dt = np.deg2rad(speed), 1500, 0.002
        t = np.arange(2 * n) * dt
        v = np.where(np.arange(2 * n) < n, w, -w)
        for name, values in (("vel", v), ("tau", np.sign(v) * 0.2 + 0.05 * v)):
            path = runs_dir / f"run_{name}1_{speed}.t"
            path.write_text("".join(f"{a:.6f} {b:.9g}\n" for a, b in zip(t, values, strict=True)))
    vel = np.deg2rad([5.0, 10, 20, 40, 80])
    tau3 = np.column_stack([(0.3 + k * 0.1) + 0.05 * vel for k in range(3)])
    scipy.io.savemat(
        ws / "means.mat", {"fwd": {"v": vel, "tau": tau3}, "bwd": {"v": -vel, "tau": -tau3}}
    )

    # a trajectory of any motion (LuGre truth) and its identified model, as simulate/fit write
    from fricid.cli.simulate import _trajectory_log
    from fricid.identify.dynamic.trajectory import fit_trajectory

    traj = _trajectory_log("multisine", 10.0, 0)
    write_rawlog(traj, ws / "traj.parquet")
    fit_trajectory(traj, "lugre").save(ws / "lugre.json")

    # a fleet of two joints
    (ws / "manifest.csv").write_text(
        "robot,joint,log,model,fix\nr0,j0,log.parquet,stribeck,delta=1\n"
        "r0,j1,log.parquet,coulomb_viscous,\n"
    )


#: The real lead-screw recordings (tests/conftest.py's ``leadscrew_dir``), which the commands
#: naming one of :data:`NEEDS_REAL` read; they are skipped, with the reason, where absent.
LEADSCREW = REPO.parent / "shared" / "data" / "real" / "epos-leadscrew"
NEEDS_REAL = ("epos-leadscrew", "leadscrew.csv", "recordings/", "resaved/")


def command_args(command: str, leadscrew: Path) -> list[str]:
    """The command's arguments, the real recordings' path resolved, smaller where listed."""
    words = shlex.split(command)[1:]
    words = [str(leadscrew) if w.endswith("data/real/epos-leadscrew") else w for w in words]
    if command in SMALLER:
        extra = SMALLER[command][0]
        for flag, value in zip(extra[::2], extra[1::2], strict=True):
            if flag in words:  # replace the value given ("" removes the flag)
                i = words.index(flag)
                del words[i : i + 2]
            if value:
                words += [flag, value]
    return words


# ------------------------------------------------------------------- the site's code blocks

#: The documentation site's pages (``mkdocs.yml``'s ``docs_dir``).
DOCS = REPO / "docs"
#: Fenced blocks the site test runs: shell commands, and Python.
SHELL, PYTHON = ("sh", "bash", "console"), ("python", "py", "pycon")
#: Fences that are not examples to run: diagrams (no language), and data files checked by
#: their own tests (the manifest's CSV and YAML, ``test_docs.py``).
NOT_RUN = ("", "text", "csv", "yaml", "json")


def site_blocks(page: Path) -> list[tuple[str, str]]:
    """The fenced code blocks of one page, in order: ``(language, code)``."""
    text = page.read_text(encoding="utf-8")
    return [
        (lang.strip().lower(), code)
        for lang, code in re.findall(r"^```([\w+-]*)[^\n]*\n(.*?)^```", text, re.S | re.M)
    ]


def shell_lines(code: str) -> list[str]:
    """The commands of a shell block, continuation lines joined, comments dropped."""
    out = []
    for line in code.replace("\\\n", " ").splitlines():
        words = shlex.split(line, comments=True)
        if words:
            out.append(shlex.join(words))
    return out


def site_pages() -> list[Path]:
    """Every Markdown page of the site, sorted."""
    return sorted(DOCS.rglob("*.md"))


def site_commands() -> list[str]:
    """Every ``fricid`` command in the site's shell blocks."""
    return [
        cmd
        for page in site_pages()
        for lang, code in site_blocks(page)
        if lang in SHELL
        for cmd in shell_lines(code)
        if cmd.startswith("fricid ")
    ]
