"""Fuzz every reader with damaged files: each outcome is a clean error or a valid result.

Issue 12, "Bad input": a reader given a hostile or clumsy file ends in one of two ways only.

- A :class:`~fricid.errors.FricidError` on one line that names the file given.
- A valid result: finite values in SI within the physical ranges of
  :data:`fricid.samples.LIMITS`, consistent row counts, time increasing; and when the file
  was changed only in ways that do not change its data (a BOM, CRLF line ends, blank
  trailing fields), the very values of the undamaged file.

Anything else (another exception, a RuntimeWarning, a multi-line message, a value outside
the invariants, a flood of log lines) fails. Mutations are drawn by hypothesis here, bounded
so the module runs in well under a minute; ``benchmarks/fuzz_readers.py`` runs the same
cases longer from a seed and prints the counts (cases, clean errors, valid results,
tracebacks, wrong answers, peak memory, time).

Issue 25 adds MATLAB v5 and v7.3 files (headers, dimensions, compressed elements and bombs,
types), per-channel folders (file sets and patterns: every file a pattern matches read once)
and byte flips in Parquet and MCAP files with checksums (an error, or the very values); every
case within 2 GB of peak memory and 60 s.
"""

from __future__ import annotations

import json
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fricid.io import read_rawlog, read_samples
from fricid.samples import SAMPLE_COLUMNS
from fuzzing import (
    READERS,
    HypothesisChooser,
    RngChooser,
    Workspace,
    channels_case,
    classify,
    mutate,
    same_values,
)
from fuzzing_structures import run_trajectory, run_urdf

# --------------------------------------------------------------------------- the tests

FUZZ = settings(
    max_examples=40,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)


@pytest.fixture(scope="module")
def workspace():
    folder = Path(tempfile.mkdtemp(prefix="fricid-fuzz-"))
    yield Workspace(folder)
    shutil.rmtree(folder, ignore_errors=True)


@pytest.mark.parametrize("name", list(READERS))
@FUZZ
@given(data=st.data())
def test_damaged_files_give_a_clean_error_or_a_valid_result(workspace, name, data):
    workspace.run(READERS[name], HypothesisChooser(data))


@pytest.mark.parametrize("name", list(READERS))
def test_benign_changes_read_the_same_values(workspace, name):
    reader = READERS[name]
    if reader.suffix in (".parquet", ".mcap", ".mat"):
        pytest.skip("binary format")
    data, expected = workspace.baseline(reader)
    for kinds in (["bom"], ["crlf"], ["bom", "crlf"]):
        damaged = data
        for kind in kinds:
            damaged = mutate(damaged, kind, RngChooser(np.random.default_rng(0)))
        path = workspace.folder / f"benign_{name}{reader.suffix}"
        path.write_bytes(damaged)
        outcome, result = classify(lambda p=path: reader.read(p), path)
        assert outcome == "valid" and same_values(result, expected), (kinds, result)


@FUZZ
@given(data=st.data())
def test_per_channel_folders(workspace, data):
    """Random file sets and patterns: a clean error, or runs that read every matched file
    once (no run dropped, no file read as two channels)."""
    workspace.n += 1
    channels_case(workspace.folder / f"channels{workspace.n}", HypothesisChooser(data))


json_values = st.recursive(
    st.none()
    | st.booleans()
    | st.integers()
    | st.floats()
    | st.text(max_size=8)
    | st.sampled_from(["garbage", "N m/A", "mNm/A", "rad/s", "fricid-samples/1"]),
    lambda inner: (
        st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner, max_size=3)
    ),
    max_leaves=8,
)
meta_docs = st.dictionaries(
    st.sampled_from(["format", "source", "joint", "torque_constant", "units", "meta"]),
    json_values
    | st.dictionaries(st.sampled_from([*SAMPLE_COLUMNS, "torque_constant"]), json_values),
    max_size=4,
)


@pytest.mark.parametrize("kind", ["samples", "rawlog"])
@FUZZ
@given(doc=meta_docs | st.binary(max_size=20).map(lambda b: b"\xff" + b))
def test_parquet_schema_metadata(workspace, kind, doc):
    """Bad schema metadata: torque constant "abc" or [1, 2], units "garbage", not JSON."""
    raw = doc if isinstance(doc, bytes) else json.dumps(doc, allow_nan=True).encode()
    table = pa.table(
        {
            "time": np.arange(5.0),
            "position": np.zeros(5),
            "velocity": np.full(5, 0.1),
            "temperature": np.full(5, 25.0),
            "current": np.ones(5),
            "load": np.zeros(5),
            "friction": np.full(5, 0.2),
        }
    ).replace_schema_metadata({b"fricid": raw})
    path = workspace.folder / f"meta_{kind}.parquet"
    pq.write_table(table, path)
    classify(lambda: (read_samples if kind == "samples" else read_rawlog)(path), path)


@pytest.mark.parametrize(
    ("doc", "words"),
    [
        ({"torque_constant": "abc"}, "'torque_constant' must be a positive number"),
        ({"torque_constant": [1, 2]}, "'torque_constant' must be a positive number"),
        ({"units": "garbage"}, "'units' must map column names to unit strings"),
        ({"units": {"velocity": "garbage"}}, "unknown velocity unit 'garbage'"),
        ({"format": 5}, "'format' must be a string"),
    ],
)
def test_parquet_metadata_regressions(tmp_path, doc, words):
    table = pa.table({n: np.ones(3) for n in ("velocity", "load", "temperature", "friction")})
    path = tmp_path / "bad.parquet"
    pq.write_table(table.replace_schema_metadata({b"fricid": json.dumps(doc).encode()}), path)
    outcome, message = classify(lambda: read_samples(path), path)
    assert outcome == "error" and words in message


# --------------------------------------------------------------------------- structures

#: Seconds any generated case may take (every case within 60 s; these are small). Peak
#: memory is measured by ``benchmarks/fuzz_readers.py`` (tracing it here would make the
#: cases several times slower).
CASE_SECONDS = 20.0


@settings(FUZZ, max_examples=60)
@given(data=st.data())
def test_generated_urdfs(workspace, data):
    """Random trees with cycles, self-loops, second parents, missing links, hostile numbers
    (1e308, 1e-320 kg, 0_1, NaN), DOCTYPEs and encodings (UTF-16, UTF-32, Latin-1): a clean
    error for every defect, else eq. 7 as the structure gives it (``fuzzing_structures``)."""
    workspace.n += 1
    start = time.perf_counter()
    run_urdf(workspace.folder, HypothesisChooser(data), workspace.n)
    assert time.perf_counter() - start < CASE_SECONDS


@pytest.mark.slow  # 2 s measured under load (default run kept short)
@settings(FUZZ, max_examples=10)
@given(data=st.data())
def test_damaged_trajectory_logs(workspace, data):
    """The virtual joint's 2 s multi-sine with holes, moved or repeated stamps, lost rows and
    stuck currents: a clean error for every defect, else an inertia and static friction
    within a factor 1.5 of the truth."""
    workspace.n += 1
    start = time.perf_counter()
    run_trajectory(workspace.folder, HypothesisChooser(data), workspace.n)
    assert time.perf_counter() - start < CASE_SECONDS
