"""Fuzz ``fricid fleet`` with hostile manifests and output folders (``tests/_fleet_fuzz.py``).

Every case ends in a clean error (one line) or a finished run whose records sit at their own
paths under ``--out``; no file outside ``--out`` (nor a user's file inside it) is created,
changed or removed, and no case runs past its time. Hypothesis draws the cases, a few dozen
here (a few seconds); ``benchmarks/fuzz_fleet.py`` runs the same cases longer from a seed and
prints the counts.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import _fleet_fuzz as ff
from fuzzing import HypothesisChooser, RngChooser

FUZZ = settings(
    max_examples=25,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)


@pytest.fixture(scope="module")
def folder():
    path = Path(tempfile.mkdtemp(prefix="fricid-fuzz-fleet-"))
    yield path
    shutil.rmtree(path, ignore_errors=True)


def _run(folder: Path, ch: RngChooser, n: list[int]) -> str:
    n[0] += 1
    root = folder / f"case{n[0]}"
    root.mkdir()
    try:
        case = ff.build_case(ff.draw_case(ch, root))
        outcome, _message = ff.run_case(case)
    finally:
        shutil.rmtree(root, ignore_errors=True)
    return outcome


@pytest.mark.slow  # 2 s measured under load (default run kept short)
@FUZZ
@given(data=st.data())
def test_a_hostile_fleet_ends_cleanly_and_touches_nothing_outside_out(folder, data):
    assert _run(folder, HypothesisChooser(data), _COUNT) in ("error", "valid")


_COUNT = [0]


@pytest.mark.parametrize(
    "plant", ["record_paths", "robot_records_link", "model_file_link", "record_reusable"]
)
def test_each_plant_on_a_fitted_joint(folder, plant):
    """Each hazard at least once on a joint that gets model files (a short hypothesis run
    need not draw every one): every hostile path of a record, links, a reusable record."""
    joint = ff.Joint("r1", "j1", ["stribeck"], "fit_me")
    paths = [("stribeck", which) for which in range(16)]
    case = ff.Case(folder / f"plant_{plant}", [joint], None, [plant], paths)
    case.root.mkdir()
    outcome, message = ff.run_case(ff.build_case(case))
    if plant.endswith("_link"):
        assert outcome == "error" and "symbolic link" in message
    else:
        assert outcome == "valid"
