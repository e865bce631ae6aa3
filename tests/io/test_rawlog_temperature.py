"""A raw-log table without a temperature column: refused with how to give one, read with a
constant temperature given (``read_rawlog``, ``iter_rawlog``, ``open_log``, the command
line), and the option refused beside a column."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import ConfigError, DataError
from fricid.io import iter_rawlog, open_log, read_rawlog


def _table(path, temperature: bool):
    t = np.arange(200) * 0.01
    head = "time [s],position [rad],velocity [rad/s],torque [N m]"
    cols = [t, np.sin(t), np.cos(t), 0.3 * np.sign(np.cos(t))]
    if temperature:
        head += ",temperature [degC]"
        cols.append(np.full(t.size, 31.0))
    rows = "\n".join(",".join(repr(float(x)) for x in row) for row in zip(*cols, strict=True))
    path.write_text(f"{head}\n{rows}\n")
    return path


def test_no_temperature_column_says_how_to_give_one(tmp_path):
    path = _table(tmp_path / "nt.csv", temperature=False)
    with pytest.raises(DataError, match="--temperature 25") as err:
        read_rawlog(path)
    assert err.value.column == "temperature"
    assert "fricid report: --reader-option temperature=25" in str(err.value)  # report too
    log = read_rawlog(path, temperature=22.5)
    np.testing.assert_array_equal(log.temperature, 22.5)
    chunks = list(iter_rawlog(path, chunk_rows=64, temperature=22.5))
    assert sum(len(c) for c in chunks) == 200
    (opened,) = list(open_log(path, "table", {"temperature": 22.5}))
    assert float(opened.temperature[0]) == 22.5


def test_the_option_beside_a_column_is_refused(tmp_path):
    path = _table(tmp_path / "t.csv", temperature=True)
    assert float(read_rawlog(path).temperature[0]) == 31.0
    with pytest.raises(ConfigError, match="has a temperature column"):
        read_rawlog(path, temperature=20.0)


def test_extract_takes_the_temperature_of_a_table_without_one(tmp_path):
    path = _table(tmp_path / "nt.csv", temperature=False)
    res = CliRunner().invoke(app, ["extract", str(path), "-o", str(tmp_path / "s.csv")])
    assert res.exit_code == 2 and "--temperature 25" in res.output, res.output


def test_a_mapped_log_without_temperature_records_none(tmp_path):
    """A vendor table (``--format generic``) without a temperature column and without
    ``--temperature``: the log's column is a placeholder and the samples record no
    temperature, not the 25 degC the option's default once made up."""
    from fricid.io import read_samples, read_table_log
    from fricid.samples import NO_TEMPERATURE_SOURCE

    path = tmp_path / "vendor.csv"
    t = np.arange(4000) * 0.005
    v = np.where((t // 5) % 2 == 0, 0.5, -0.5) * (1 + (t // 10))
    rows = "\n".join(
        f"{a:.6f},{b:.6f},{0.2 * np.sign(b) + 0.05 * b:.6f}" for a, b in zip(t, v, strict=True)
    )
    path.write_text("t,dq,tau\n" + rows + "\n")
    mapping = {"time": "t", "velocity": "dq", "torque": "tau"}
    units = {"time": "s", "velocity": "rad/s", "torque": "N m"}
    log = read_table_log(path, mapping, units)
    assert not log.temperature_measured
    assert log.meta["temperature_source"] == NO_TEMPERATURE_SOURCE
    assert read_table_log(path, mapping, units, temperature=31.0).temperature_measured
    maps = ["--map", "time=t:s", "--map", "velocity=dq:rad/s", "--map", "torque=tau:N m"]
    base = ["extract", str(path), "--format", "generic", *maps, "--gravity", "none"]
    res = CliRunner().invoke(app, [*base, "-o", str(tmp_path / "s.csv")])
    assert res.exit_code == 0, res.output
    assert "temperature" not in read_samples(tmp_path / "s.csv").measured
    res = CliRunner().invoke(app, [*base, "--temperature", "31", "-o", str(tmp_path / "w.csv")])
    assert res.exit_code == 0, res.output
    warm = read_samples(tmp_path / "w.csv")
    assert "temperature" in warm.measured and np.all(warm.temperature == 31.0)
