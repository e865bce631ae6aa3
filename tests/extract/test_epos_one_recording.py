"""One EPOS recording at one steady velocity gives the sample its folder gives for it.

A new user's trial: ``fricid extract n2.csv --format epos --flip-sign`` went through the
constant-velocity extraction of a log, whose set-point search took the recorder's 1 rpm steps
at -2 rpm for rest (186 rows dropped): it printed a set-point of 0.1047 rad/s, wrote 0.227 rad/s
and 3.483 mN m where the folder gives 3.555 mN m for that file, and wrote the backward-only
recording as direction 0 with a positive velocity ("both directions combined").
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.cli.trajectory import read_trajectory_log
from fricid.io import read_samples
from fricid.workflow import load_joint

runner = CliRunner()
RPM = 2 * math.pi / 60


def run(*args):
    return runner.invoke(app, [str(a) for a in args])


@pytest.fixture(scope="module")
def folder_samples(leadscrew_dir, tmp_path_factory):
    out = tmp_path_factory.mktemp("folder") / "all.csv"
    res = run("extract", leadscrew_dir, "--format", "epos", "--flip-sign", "-o", out)
    assert res.exit_code == 0, res.output
    return read_samples(out)


@pytest.mark.parametrize("name", ["n2.csv", "2.csv", "n200.csv"])
def test_one_steady_recording_gives_the_sample_of_its_folder(
    name, leadscrew_dir, folder_samples, tmp_path
):
    out, by_direction = tmp_path / "one.csv", tmp_path / "dir.csv"
    res = run(
        "extract", leadscrew_dir / name, "--format", "epos", "--flip-sign", "-o", out,
        "--by-direction", by_direction,
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    i = folder_samples.meta["files"].index(name)
    for path in (out, by_direction):
        one = read_samples(path)
        assert len(one) == 1
        for column in ("velocity", "friction", "direction", "count", "std"):
            assert getattr(one, column)[0] == pytest.approx(getattr(folder_samples, column)[i])
    one = read_samples(out)
    assert one.direction[0] == (-1 if name.startswith("n") else 1)  # as the name says
    assert "both directions combined" not in res.output
    printed = re.search(r"([-+][\d.e+-]+) rad/s", res.output)
    assert printed is not None, res.output
    assert float(printed.group(1)) == pytest.approx(one.velocity[0], rel=1e-3)  # as written


def _epos(path: Path, rpm: np.ndarray, percent: float = 30.0) -> Path:
    rows = [f"{10.0 * i:.3f};{v:g};{np.sign(v) * percent:.1f}" for i, v in enumerate(rpm)]
    head = "Sampling period:;10.000\r\n;Velocity actual value averaged;Torque actual value\r\n"
    path.write_bytes((head + "ms;rpm;%\r\n" + "\r\n".join(rows) + "\r\n").encode())
    return path


def test_only_a_recording_at_one_steady_velocity_is_read_as_one_point(tmp_path):
    from fricid.io.epos import steady_recording

    steady = _epos(tmp_path / "steady.csv", np.full(200, 10.0))
    assert steady_recording(steady)
    assert load_joint(steady, "epos").extraction is None
    both_ways = _epos(tmp_path / "both.csv", np.r_[np.full(200, 10.0), np.full(200, -10.0)])
    staircase = _epos(tmp_path / "stairs.csv", np.r_[np.full(200, 10.0), np.full(200, 20.0)])
    from_rest = _epos(tmp_path / "rest.csv", np.r_[np.zeros(100), np.full(200, 10.0)])
    for path in (both_ways, staircase, from_rest):
        assert not steady_recording(path), path.name
    data = load_joint(both_ways, "epos", extract_options={"gravity": "none"})
    assert data.extraction is not None  # extracted as a log
    assert sorted(data.by_direction.direction) == [-1, 1]
    assert not steady_recording(tmp_path)  # a folder is not one recording


def test_a_trajectory_reads_a_steady_recording_as_a_time_series(leadscrew_dir):
    log = read_trajectory_log(leadscrew_dir / "10.csv", "epos", {"flip_sign": True})
    assert len(log) == 500
    assert np.mean(log.velocity) == pytest.approx(10 * RPM, rel=0.01)
