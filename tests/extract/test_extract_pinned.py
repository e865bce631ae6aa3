"""Extraction's numbers, pinned on the virtual joint and the real EPOS recordings.

Every number extraction returns (samples, per-direction samples, the gravity fit, the
quality table, the diagnostics, the notes) is put in a canonical form and kept in
``tests/data/extract_pinned/``. They were taken from the extraction before it was made
faster; code that only makes extraction faster must leave them unchanged. A change in them is
a change in results: make it on purpose (``python tests/extract/test_extract_pinned.py``
writes them again), and say why here.

Numbers, not a hash of their bits: numpy's vector kernels (exp, log, sums) round the last bit
differently on different processors (AVX-512 or AVX2), and digests taken bit for bit on one
machine failed on the next, the frictions 1e-14 apart and a gravity fit's covariance, whose
small entries are differences, 2e-10 of its own. A number must be within :data:`REL` of its
array's largest (of itself, alone), which keeps any change a result could show.
"""

from __future__ import annotations

import dataclasses
import gzip
import json
import math
import sys
import warnings
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from fricid.extract import extract
from fricid.io import read_epos
from fricid.samples import RawLog
from fricid.sim import preset, simulate

#: The real lead-screw recordings, ``../shared/data/real/epos-leadscrew/`` beside the repo.
LEADSCREW = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "real"
LEADSCREW = LEADSCREW / "epos-leadscrew"
#: Where the pinned numbers are kept, a gzipped JSON file per case.
PINNED = Path(__file__).resolve().parents[1] / "data" / "extract_pinned"
#: How near a number must be to its pinned value, relative to its array's largest.
REL = 1e-9


def canon(obj: Any) -> Any:
    """``obj`` as nested lists, dicts, strings, ints and floats."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {
            "__type__": type(obj).__name__,
            **{f.name: canon(getattr(obj, f.name)) for f in dataclasses.fields(obj)},
        }
    if isinstance(obj, np.ndarray):
        if obj.dtype == object:
            return ["object", list(obj.shape), [canon(x) for x in obj.ravel().tolist()]]
        return [str(obj.dtype), list(obj.shape), [canon(x) for x in obj.ravel().tolist()]]
    if isinstance(obj, dict):
        return {str(k): canon(v) for k, v in sorted(obj.items(), key=lambda kv: str(kv[0]))}
    if isinstance(obj, list | tuple):
        return [canon(x) for x in obj]
    if isinstance(obj, np.generic):
        return canon(obj.item())
    if isinstance(obj, str):
        # The recordings' absolute path differs from machine to machine; their name does not.
        return obj.replace(str(LEADSCREW), "<epos-leadscrew>")
    if isinstance(obj, bool) or obj is None or isinstance(obj, int | float):
        return obj
    return repr(obj)


def differences(got: Any, want: Any, where: str = "") -> list[str]:
    """Where ``got`` and ``want`` (canonical forms) differ: the structure, texts and ints
    exactly, floats to :data:`REL` of the largest in their list."""
    if isinstance(want, dict):
        if not isinstance(got, dict) or got.keys() != want.keys():
            return [f"{where}: keys {sorted(got) if isinstance(got, dict) else got!r}"]
        return [d for k in want for d in differences(got[k], want[k], f"{where}/{k}")]
    if isinstance(want, list):
        if not isinstance(got, list) or len(got) != len(want):
            return [f"{where}: {got!r:.80} against a list of {len(want)}"]
        floats = [abs(x) for x in want if isinstance(x, float) and math.isfinite(x)]
        scale = max(floats, default=0.0)
        out = []
        for i, (g, w) in enumerate(zip(got, want, strict=True)):
            if isinstance(w, float) and isinstance(g, float):
                out += _float(g, w, scale, f"{where}[{i}]")
            else:
                out += differences(g, w, f"{where}[{i}]")
        return out
    if isinstance(want, float) and isinstance(got, float):
        return _float(got, want, abs(want), where)
    return [] if type(got) is type(want) and got == want else [f"{where}: {got!r} != {want!r}"]


def _float(got: float, want: float, scale: float, where: str) -> list[str]:
    if math.isnan(want) and math.isnan(got):
        return []
    if got == want or abs(got - want) <= REL * max(scale, abs(want)):
        return []
    return [f"{where}: {got!r} != {want!r}"]


def pinned(name: str) -> Any:
    with gzip.open(PINNED / f"{_file(name)}.json.gz", "rt") as fh:
        return json.load(fh)


def _file(name: str) -> str:
    return name.replace(" ", "_").replace("+", "-").replace(".", "_")


def _chunks(name: str, rows: int) -> Iterator[RawLog]:
    """The virtual joint's campaign ``name`` (quick, seed 0), cut into chunks of ``rows``."""
    for log in simulate(preset(name, "quick"), seed=0, chunk="experiment"):
        for start in range(0, len(log), rows):
            yield log.slice(start, min(start + rows, len(log)))


def _simulated(name: str, rows: int = 50_000, **options) -> Any:
    scenario = preset(name, "quick")
    return extract(_chunks(name, rows), **{**scenario.extract_options(), **options})


def _clipped() -> Any:
    """The virtual joint with spikes and a current sensor clipping the fastest set-points'
    steady torque (a rail under 0.6 of the typical range)."""
    scenario = preset("paper1+spikes+saturation", "quick")
    faults = replace(scenario.faults, current_range=0.6 * scenario.faults.current_range)
    scenario = replace(scenario, faults=faults)
    return extract(simulate(scenario, seed=0), **scenario.extract_options())


def _epos(name: str) -> Any:
    if not LEADSCREW.is_dir():
        pytest.skip(f"real recordings not found at {LEADSCREW}")
    return extract(read_epos(LEADSCREW / name), gravity="auto")


#: name -> what is extracted. Pinned as digests of the bits until they moved to a new machine; the
#: numbers kept since are that machine's (no code changed). Digests updated once, on purpose: the
#: extraction's meta records ``position_source`` (where the position came from, for the trust
#: verdict's gravity caveat); every number is the same. The EPOS digests once more when the
#: recordings' absolute path left the canonical form (CI checks out elsewhere): every number is the
#: same. Every digest once more when a row's standard error took the noise's correlation and the
#: removed gravity fit's error (:func:`fricid.extract.bins.cell_sem`,
#: :func:`fricid.extract.gravity.gravity_se`): only ``sem``, ``direction_sem`` and the
#: ``sem_method`` and ``sem_caveat`` texts (now saying which method the rows took) changed (compared
#: field by field), every friction is the same. paper2+faults once more when the note of gravity
#: 'none' on a log with positions was reworded (it may come from the log's design metadata): with
#: the old text the digest is the old one, every number the same. The virtual joint's five once more
#: when the settle cut at a run's ends took a thousandth of a sample period of slack
#: (:func:`fricid.extract.segment`: the cut had followed the clock's rounding, so a shifted clock
#: changed the samples): the per-direction frictions moved by at most 0.09 % (paper2+faults, three
#: set-points 10 samples larger), paper1's not at all (its trimming counts did); the EPOS
#: recordings' are unchanged. The EPOS pins once more when a single recording given no
#: temperature stopped recording a made-up 25 degC: its samples' and quality table's temperature,
#: the diagnostics' temperature set-point and the set-point labels' "25 degC" are gone, and the
#: samples' meta says ``temperature_source``; every other number is the same. The EPOS cases call
#: :func:`fricid.extract.extract` on the recording since ``load_joint`` reads a steady recording
#: as its folder does (one operating point, no extraction): the same extraction, same numbers.
#: The EPOS pins once more when a log measured in one direction only stopped being written as
#: "both directions combined" (direction 0, the backward recording's velocity and friction made
#: positive): its samples are that direction's (+1 for 10.csv, -1 with both signs kept for
#: n200.csv), with a note saying so; every magnitude is the same.
CASES = {
    "paper1": lambda: _simulated("paper1"),
    "paper1+faults": lambda: _simulated("paper1+faults", 7_777),
    "paper1 joint": lambda: _simulated("paper1", gravity="joint"),
    "paper2+faults": lambda: _simulated("paper2+faults"),
    "paper1 clipped": _clipped,
    "epos 10.csv": lambda: _epos("10.csv"),
    "epos n200.csv": lambda: _epos("n200.csv"),
}


def run_case(name: str) -> Any:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return CASES[name]()


@pytest.mark.parametrize("name", list(CASES))
def test_extraction_numbers_are_pinned(name):
    # through JSON as the pins went, so that a tuple and a list compare alike
    got = json.loads(json.dumps(canon(run_case(name))))
    found = differences(got, pinned(name))
    assert not found, f"{len(found)} differences, the first: " + "; ".join(found[:5])


def test_a_changed_number_is_a_difference():
    want = {"x": ["float64", [3], [1.0, 2.0, 1e-12]], "n": 3}
    assert not differences({"x": ["float64", [3], [1.0, 2.0, 1.1e-12]], "n": 3}, want)
    assert differences({"x": ["float64", [3], [1.0, 2.000001, 1e-12]], "n": 3}, want)
    assert differences({"x": ["float64", [3], [1.0, 2.0, 1e-12]], "n": 4}, want)
    assert differences({"x": ["float64", [2], [1.0, 2.0]], "n": 3}, want)


if __name__ == "__main__":  # write the pins again (a change made on purpose: say why above)
    PINNED.mkdir(parents=True, exist_ok=True)
    for case in sys.argv[1:] or CASES:
        with gzip.open(PINNED / f"{_file(case)}.json.gz", "wt") as fh:
            json.dump(canon(run_case(case)), fh, sort_keys=True)
