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
