"""One parser of NAME=VALUE, NAME=LOW:HIGH and position grids (fricid.io.options), shared by
the command line and the fleet manifest: properties, refusals, and that both places agree."""

from __future__ import annotations

import itertools
import math

import pytest
import typer
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from fricid.cli import _options as cli_options
from fricid.cli import app
from fricid.errors import ConfigError, DataError
from fricid.fleet import read_manifest
from fricid.io.options import (
    MAX_GRID,
    parse_assignments,
    parse_grid,
    parse_number,
    parse_pairs,
    parse_range,
    parse_ranges,
)

names = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,11}", fullmatch=True)
finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
non_finite = st.sampled_from(["nan", "inf", "-inf", "NaN", "Infinity"])

#: Property tests without a per-example deadline (the machine is shared and loaded).
quick = settings(deadline=None, max_examples=60)


@quick
@given(st.dictionaries(names, finite, min_size=1, max_size=6))
def test_assignments_round_trip_as_flags_and_as_a_cell(values):
    items = [f"{k}={v!r}" for k, v in values.items()]
    assert parse_assignments(items) == values
    assert parse_assignments("; ".join(items)) == values
    assert parse_assignments(values) == values  # a YAML mapping


@quick
@given(st.dictionaries(names, st.tuples(finite, finite).filter(lambda p: p[0] < p[1]), min_size=1))
def test_ranges_round_trip(values):
    items = [f"{k}={lo!r}:{hi!r}" for k, (lo, hi) in values.items()]
    assert parse_ranges(items) == values
    assert parse_ranges(";".join(items)) == values
    assert parse_ranges({k: list(v) for k, v in values.items()}) == values


@quick
@given(names, finite, finite)
def test_a_range_needs_low_below_high(name, a, b):
    if a < b:
        assert parse_range(f"{a!r}:{b!r}") == (a, b)
    else:
        with pytest.raises(ConfigError, match="LOW < HIGH"):
            parse_ranges([f"{name}={a!r}:{b!r}"])


@quick
@given(names, non_finite)
def test_non_finite_numbers_are_refused_everywhere(name, bad):
    with pytest.raises(ConfigError, match="not a finite number"):
        parse_assignments([f"{name}={bad}"])
    with pytest.raises(ConfigError, match="not a finite number"):
        parse_ranges([f"{name}={bad}:1"])
    with pytest.raises(ConfigError, match="not a finite number"):
        parse_grid(f"0:{bad}:1")  # refused as a malformed grid
    with pytest.raises(ConfigError, match="not a finite number"):
        parse_number(bad)


@quick
@given(names, finite, finite)
def test_a_name_is_given_once(name, a, b):
    with pytest.raises(ConfigError, match=f"'{name}' is given twice"):
        parse_assignments([f"{name}={a!r}", f"{name}={b!r}"])


@quick
@given(st.text(max_size=20).filter(lambda t: "=" not in t and t.strip()))
def test_an_item_without_equals_is_refused(text):
    if ";" in text and not text.replace(";", "").strip():
        return
    with pytest.raises(ConfigError, match="expected NAME=VALUE"):
        parse_assignments([text])


@quick
@given(
    st.floats(-1e3, 1e3),
    st.floats(0.0, 1e3),
    st.floats(0.1, 1e2),
)
def test_grid_includes_start_and_stop_on_the_grid(start, span, step):
    points = parse_grid(f"{start!r}:{start + span!r}:{step!r}")
    assert points[0] == start
    assert len(points) == math.floor(((start + span) - start) / step + 1e-9) + 1
    assert all(b > a for a, b in itertools.pairwise(points))
    assert points[-1] <= start + span + 1e-9 * max(1.0, abs(start + span))


@quick
@given(st.lists(finite, min_size=1, max_size=8))
def test_grid_lists_in_every_spelling(values):
    text = [repr(v) for v in values]
    assert parse_grid(",".join(text)) == values
    assert parse_grid(";".join(text)) == values
    assert parse_grid(" ".join(text)) == values
    assert parse_grid(values) == values


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("1:0:1", "step > 0 and stop >= start"),
        ("0:1:0", "step > 0 and stop >= start"),
        ("0:1", "START:STOP:STEP"),
        ("0:1:x", "START:STOP:STEP"),
        ("0:1:1e-9", f"at most {MAX_GRID}"),
        (";", "names no position"),
    ],
)
def test_bad_grids(text, message):
    with pytest.raises(ConfigError, match=message):
        parse_grid(text)


@pytest.mark.parametrize(
    ("items", "message"),
    [
        (["=1"], "expected NAME=VALUE"),
        (["a="], "expected NAME=VALUE"),
        (["a b=1"], "'a b' is not a name"),
        (["a=x"], "'x' is not a number"),
        (["a=true"], "is not a number"),
    ],
)
def test_bad_assignments(items, message):
    with pytest.raises(ConfigError, match=message):
        parse_assignments(items)


def test_booleans_are_not_numbers():
    with pytest.raises(ConfigError, match="not a number"):
        parse_number(True)
    with pytest.raises(ConfigError, match="not a number"):
        parse_assignments({"a": True})


def test_pairs_keep_text_values():
    assert parse_pairs(["time=t:ms", "torque=tau [N m]"]) == {
        "time": "t:ms",
        "torque": "tau [N m]",
    }


# --------------------------------------------------------------------------- both places agree


@pytest.mark.parametrize(
    ("cell", "flags", "words"),
    [
        ("a=nan", ["a=nan"], "not a finite number"),
        ("a=2:1", ["a=2:1"], "LOW < HIGH"),
        ("a=1;a=2", ["a=1", "a=2"], "given twice"),
        ("a=1:x", ["a=1:x"], "'x' is not a number"),
    ],
)
def test_cli_and_manifest_refuse_the_same_values(tmp_path, cell, flags, words):
    column = "bound" if ":" in cell else "fix"
    path = tmp_path / "m.csv"
    path.write_text(f"robot,joint,log,{column}\nr,j,x.csv,{cell}\n", encoding="utf-8")
    with pytest.raises(DataError, match=words) as info:
        read_manifest(path)
    assert (info.value.row, info.value.column) == (2, column)
    parse = cli_options.parse_ranges if column == "bound" else cli_options.parse_assignments
    with pytest.raises(typer.BadParameter, match=words):
        parse(flags, f"--{column}")


def test_fit_flag_errors_are_one_line_exit_2(tmp_path):
    samples = tmp_path / "s.csv"
    samples.write_text(
        "velocity [rad/s],load [N m],temperature [degC],friction [N m]\n0.1,0,25,0.2\n"
    )
    for args, words in (
        (["--fix", "delta=nan"], "not a finite number"),
        (["--bound", "w_s=1:0.1"], "LOW < HIGH"),
        (["--fix", "delta=1", "--fix", "delta=2"], "given twice"),
    ):
        res = CliRunner().invoke(app, ["fit", str(samples), *args, "-o", str(tmp_path / "m.json")])
        assert res.exit_code == 2, res.output
        assert words in res.output and "Traceback" not in res.output


def test_extract_positions_use_the_same_grid(tmp_path):
    from fricid.cli.extract import parse_positions

    assert parse_positions("-60:-20:20", "deg") == pytest.approx(
        [math.radians(x) for x in parse_grid("-60:-20:20")]
    )
    with pytest.raises(ConfigError, match="--positions takes START:STOP:STEP"):
        parse_positions("0:1:1e-9", "deg")


def test_extract_column_map_uses_the_pair_parser():
    from fricid.cli.extract import parse_column_map

    assert parse_column_map(["time=t:ms", "velocity=dq [deg/s]", "torque=a:b:N m"]) == (
        {"time": "t", "velocity": "dq [deg/s]", "torque": "a:b"},
        {"time": "ms", "torque": "N m"},
    )
    with pytest.raises(ConfigError, match=r"--map takes QUANTITY=COLUMN.*'time' is given twice"):
        parse_column_map(["time=t", "time=u"])
    with pytest.raises(ConfigError, match=r"--map takes QUANTITY=COLUMN\[:UNIT\]"):
        parse_column_map(["velocity"])
