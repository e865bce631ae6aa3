"""CSV files as spreadsheets write them: ``;`` or tab between fields, a decimal comma."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from fricid.errors import ConfigError, DataError
from fricid.io import csv_dialect, read_samples
from fricid.io._dialect import detect_dialect
from fricid.samples import standstill_rows

finite = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_subnormal=False)
positive = st.floats(min_value=1e-4, max_value=1e3, allow_nan=False)


def _write(path, rows, delimiter, decimal):
    def cell(x: float) -> str:
        text = repr(float(x))
        return text.replace(".", ",") if decimal == "," else text

    header = delimiter.join(["velocity [rad/s]", "load [N m]", "friction [N m]"])
    lines = [header] + [delimiter.join(cell(x) for x in row) for row in rows]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    rows=st.lists(st.tuples(positive, finite, finite), min_size=1, max_size=12),
    dialect=st.sampled_from([(";", ","), ("\t", ","), (";", "."), ("\t", "."), (",", ".")]),
)
def test_delimiter_and_decimal_comma_are_detected(tmp_path, rows, dialect):
    want = np.array(rows, dtype=float)
    assume(not standstill_rows(want[:, 0], np.sign(want[:, 0])).any())  # dropped on read
    path = tmp_path / "table.csv"
    _write(path, rows, *dialect)
    s = read_samples(path)
    np.testing.assert_array_equal(s.velocity, want[:, 0])
    np.testing.assert_array_equal(s.load, want[:, 1])
    np.testing.assert_array_equal(s.friction, want[:, 2])


def test_a_bad_value_in_a_semicolon_file_is_located(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("velocity [rad/s];friction [N m]\n0,1;0,2\n0,2;zwei\n", encoding="utf-8")
    with pytest.raises(DataError, match=r"line 3.*friction|friction.*line 3|row 3"):
        read_samples(path)


def test_the_delimiter_can_be_given(tmp_path):
    path = tmp_path / "semi.csv"
    path.write_text("velocity [rad/s];friction [N m]\n0,5;0,25\n", encoding="utf-8")
    with csv_dialect(delimiter=";", decimal=","):
        assert read_samples(path).friction.tolist() == [0.25]
    with csv_dialect(delimiter=","), pytest.raises(DataError, match="--delimiter ';'"):
        read_samples(path)  # told wrong: the header is one column, and the error says why
    with pytest.raises(ConfigError, match="--delimiter"), csv_dialect(delimiter="|"):
        pass


def test_detection_prefers_the_split_the_data_line_agrees_with():
    assert detect_dialect("a,b", "1,2").delimiter == ","
    assert detect_dialect("a;b", "1,5;2,5") == detect_dialect("a;b", "1,5;2,5")
    assert (
        detect_dialect("a;b", "1,5;2,5").delimiter,
        detect_dialect("a;b", "1,5;2,5").decimal,
    ) == (";", ",")
    assert detect_dialect("a\tb", "1.5\t2").decimal == "."
    one = detect_dialect("velocity [rad/s]", "0,5")  # one column, a decimal comma
    assert (one.delimiter, one.decimal) == (";", ",")
    assert detect_dialect("velocity [rad/s]", "0.5") == detect_dialect("a", None)


@pytest.mark.slow  # 6 s measured under load (a fit, the command line)
def test_cli_reads_a_semicolon_file_and_takes_delimiter(tmp_path):
    from typer.testing import CliRunner

    from fricid.cli import app
    from fricid.identify import fit

    v = np.geomspace(0.05, 1.0, 6)
    samples = tmp_path / "s.csv"
    rows = "".join(f"{a!r};{0.1 + 0.02 * a!r}\n".replace(".", ",") for a in v.tolist())
    samples.write_text("velocity [rad/s];friction [N m]\n" + rows, encoding="utf-8")
    model = fit(read_samples(samples), "coulomb_viscous").save(tmp_path / "m.json")
    assert model.exists()
    points = tmp_path / "points.csv"
    points.write_text("velocity [rad/s]\n0,5\n", encoding="utf-8")  # one column, detected
    runner = CliRunner()
    for told in ([], ["--decimal", ",", "--delimiter", ";"]):  # detected, or told
        res = runner.invoke(app, [*told, "predict", str(model), "-i", str(points)])
        assert res.exit_code == 0, res.output
        assert res.stdout.splitlines()[1].startswith("0.5,")
    res = runner.invoke(app, ["--delimiter", "|", "predict", str(model), "-i", str(points)])
    assert res.exit_code == 2 and "--delimiter must be one of" in res.output
