"""A velocity glitch in an EPOS recording is dropped and named, as a torque outlier is.

A new user's trial: the velocity of 5 of the 500 rows of n10.csv multiplied by 100 (a
recorder glitch) and the folder extracted: the -10 rpm point was written at -2.0847 rad/s
(about -20 rpm) without a word, the velocity being a plain mean while torque outliers were
dropped (8 robust sigmas) and warned about.
"""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import DataQualityWarning
from fricid.io import epos_steady_samples, read_samples

#: The data rows whose velocity is multiplied by 100 (0-based among the 500).
GLITCHES = (50, 120, 200, 333, 450)


def _glitched(leadscrew_dir: Path, folder: Path) -> list[int]:
    """The recordings copied to ``folder`` with n10.csv's velocity glitched; its 1-based line
    numbers of the glitched rows."""
    shutil.copytree(leadscrew_dir, folder)
    path = folder / "n10.csv"
    lines = path.read_bytes().decode().split("\r\n")
    first = next(i for i, line in enumerate(lines) if line.startswith("ms;")) + 1
    for row in GLITCHES:
        time, rpm, torque = lines[first + row].split(";")
        lines[first + row] = f"{time};{100 * float(rpm):g};{torque}"
    path.write_bytes("\r\n".join(lines).encode())
    return [first + row + 1 for row in GLITCHES]


def test_velocity_glitches_are_dropped_and_named(leadscrew_dir, tmp_path):
    glitched = tmp_path / "glitched"
    lines = _glitched(leadscrew_dir, glitched)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DataQualityWarning)  # the honest folder drops nothing
        honest = epos_steady_samples(leadscrew_dir, flip_sign=True)
    out = tmp_path / "s.csv"
    res = CliRunner().invoke(
        app, ["extract", str(glitched), "--format", "epos", "--flip-sign", "-o", str(out)]
    )
    assert res.exit_code == 0, res.output
    samples = read_samples(out)
    assert samples.meta["files"] == honest.meta["files"]  # the file keeps its place
    i = honest.meta["files"].index("n10.csv")
    assert samples.velocity[i] == pytest.approx(honest.velocity[i], rel=1e-3)
    assert samples.friction[i] == pytest.approx(honest.friction[i], abs=3 * honest.std[i] / 20)
    warned = [ln for ln in res.stderr.splitlines() if ln.startswith("warning (data quality)")]
    assert len(warned) == 1, res.stderr
    shown = ", ".join(str(n) for n in lines)
    assert f"n10.csv (-1.048 rad/s): dropped 5 outlier row(s) (line {shown})" in warned[0]
    assert "median velocity" in warned[0]
    assert samples.count[i] == 495 and samples.meta["quality"][i]["dropped_outlier"] == 5
    assert samples.meta["velocity_outlier_lines"] == {"n10.csv": lines}
    assert honest.meta["velocity_outlier_lines"] == {}
    others = np.arange(len(samples)) != i
    np.testing.assert_array_equal(samples.velocity[others], honest.velocity[others])
    np.testing.assert_array_equal(samples.friction[others], honest.friction[others])


def test_one_glitched_recording_gives_what_its_folder_gives(leadscrew_dir, tmp_path):
    glitched = tmp_path / "glitched"
    _glitched(leadscrew_dir, glitched)
    with pytest.warns(DataQualityWarning, match=r"n10\.csv .*5 outlier row.*median velocity"):
        one = epos_steady_samples(glitched / "n10.csv", flip_sign=True)
    with pytest.warns(DataQualityWarning, match=r"n10\.csv"):
        folder = epos_steady_samples(glitched, flip_sign=True)
    i = folder.meta["files"].index("n10.csv")
    assert one.velocity[0] == folder.velocity[i] and one.friction[0] == folder.friction[i]
