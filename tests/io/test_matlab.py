"""fricid.io.matlab and ``fricid extract --format mat`` (issue 13: MATLAB files)."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest
import scipy.io
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import ConfigError, DataError
from fricid.io import mat_variables, read_mat, read_samples
from fricid.samples import FrictionSamples, RawLog

V = np.array([0.05, 0.1, 0.2, 0.5, 1.0, 2.0])  # rad/s, the set-points of the mean tables


def _tables() -> dict:
    """Per-direction mean tables as labs publish them: velocity, torque of 3 joints."""
    tau = np.column_stack([(0.3 + k * 0.1) + 0.05 * V for k in range(3)])  # (n, 3 joints)
    return {
        "fwd": {"v": V, "tau": tau},
        "bwd": {"v": -V, "tau": -tau * 1.1},
    }


def _v5(path: Path) -> Path:
    scipy.io.savemat(path, _tables())
    return path


def _v73(path: Path) -> Path:
    """A v7.3 file as MATLAB writes one: HDF5, structs as groups, arrays transposed."""
    with h5py.File(path, "w") as f:
        for name, struct in _tables().items():
            group = f.create_group(name)
            for field, value in struct.items():
                group.create_dataset(
                    field, data=np.atleast_2d(value.T) if value.ndim == 1 else value.T
                )
    return path


VARS = {"velocity": "fwd.v,bwd.v", "friction": "fwd.tau,bwd.tau"}
UNITS = {"velocity": "rad/s", "friction": "N m"}


@pytest.mark.parametrize("write", [_v5, _v73])
def test_mean_tables_read_straight_into_samples(tmp_path, write):
    path = write(tmp_path / "means.mat")
    samples = read_mat(path, VARS, UNITS, joint="2")
    assert isinstance(samples, FrictionSamples)
    np.testing.assert_allclose(samples.velocity, np.concatenate([V, -V]))
    tau = 0.4 + 0.05 * V
    np.testing.assert_allclose(samples.friction, np.concatenate([tau, -1.1 * tau]))
    np.testing.assert_array_equal(samples.direction, [1] * 6 + [-1] * 6)
    assert samples.measured == ("velocity",)  # load and temperature not measured
    assert set(mat_variables(path)) == {"fwd.v", "fwd.tau", "bwd.v", "bwd.tau"}


@pytest.mark.parametrize("write", [_v5, _v73])
def test_errors_name_the_variable(tmp_path, write):
    path = write(tmp_path / "means.mat")
    with pytest.raises(ConfigError, match=r"3 columns .* --joint 1\.\.3"):
        read_mat(path, VARS, UNITS)
    with pytest.raises(DataError, match="struct 'fwd' has 'tau', 'v'") as err:
        read_mat(path, {**VARS, "velocity": "fwd.qd"}, UNITS, joint="1")
    assert err.value.column == "fwd.qd"
    with pytest.raises(ConfigError, match="no unit for friction"):
        read_mat(path, VARS, {"velocity": "rad/s"}, joint="1")


def test_v5_log_with_units(tmp_path):
    t = np.arange(0, 1, 0.01)
    path = tmp_path / "log.mat"
    scipy.io.savemat(path, {"t": t * 1e3, "data": {"qd": np.full_like(t, 90.0), "i": t + 1}})
    log = read_mat(
        path,
        {"time": "t", "velocity": "data.qd", "current": "data.i"},
        {"time": "ms", "velocity": "deg/s", "current": "A"},
        temperature=30.0,
        torque_constant=0.2,
    )
    assert isinstance(log, RawLog)
    np.testing.assert_allclose(log.time, t)
    np.testing.assert_allclose(log.velocity, np.pi / 2)
    np.testing.assert_allclose(log.motor_torque, 0.2 * (t + 1))
    assert log.temperature_measured and float(log.temperature[0]) == 30.0
    # no temperature variable and none given: the log records none (not a made-up 25 degC)
    none = read_mat(
        path,
        {"time": "t", "velocity": "data.qd", "current": "data.i"},
        {"time": "ms", "velocity": "deg/s", "current": "A"},
        torque_constant=0.2,
    )
    assert not none.temperature_measured


def test_cli_reads_mean_tables_and_refuses_extraction_flags(tmp_path):
    path = _v73(tmp_path / "means.mat")
    out = tmp_path / "s.csv"
    args = [
        "extract",
        str(path),
        "--format",
        "mat",
        "--var",
        "velocity=fwd.v,bwd.v:rad/s",
        "--var",
        "friction=fwd.tau,bwd.tau:Nm",
        "--joint",
        "3",
        "-o",
        str(out),
    ]
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 0, res.output
    samples = read_samples(out)
    assert len(samples) == 12 and samples.directions() == (-1, 1)
    np.testing.assert_allclose(samples.friction[:6], 0.5 + 0.05 * V)
    res = CliRunner().invoke(app, [*args, "--median-window", "7"])
    assert res.exit_code == 2
    assert "--median-window does not apply to --format mat here" in res.output


def test_open_log_without_variables_lists_the_file_s(tmp_path):
    from fricid.io import open_log

    with pytest.raises(ConfigError, match=r"needs its variables by name.*bwd\.tau, bwd\.v"):
        open_log(_v5(tmp_path / "m.mat"), "mat")
    with pytest.raises(ConfigError, match="extraction options \\(median_window\\) do not apply"):
        from fricid.workflow import load_joint

        load_joint(
            tmp_path / "m.mat",
            "mat",
            reader_options={"variables": VARS, "units": UNITS, "joint": "1"},
            extract_options={"median_window": 7},
        )


def test_real_means_published_as_mat_tables_read_back_unchanged(leadscrew_dir, tmp_path):
    """The lead-screw recordings' per-direction means, published as a lab would (one struct
    per direction, v5 and v7.3), read straight into the same samples."""
    from fricid.io import epos_steady_samples

    ref = epos_steady_samples(leadscrew_dir, flip_sign=True)
    fwd, bwd = ref.direction > 0, ref.direction < 0
    tables = {
        "fwd": {"v": ref.velocity[fwd], "tau": ref.friction[fwd] * 1e3},
        "bwd": {"v": ref.velocity[bwd], "tau": ref.friction[bwd] * 1e3},
    }
    v5 = tmp_path / "v5.mat"
    scipy.io.savemat(v5, tables)
    v73 = tmp_path / "v73.mat"
    with h5py.File(v73, "w") as f:
        for name, struct in tables.items():
            for field, value in struct.items():
                f.create_dataset(f"{name}/{field}", data=np.atleast_2d(value))
    order = np.concatenate([np.flatnonzero(fwd), np.flatnonzero(bwd)])
    for path in (v5, v73):
        got = read_mat(path, VARS, {"velocity": "rad/s", "friction": "mNm"})
        np.testing.assert_allclose(got.velocity, ref.velocity[order], rtol=1e-12)
        np.testing.assert_allclose(got.friction, ref.friction[order], rtol=1e-12)
        np.testing.assert_array_equal(got.direction, ref.direction[order])
