"""Extraction's numbers, pinned bit for bit on the virtual joint and the real EPOS recordings.

Every number extraction returns (samples, per-direction samples, the gravity fit, the
quality table, the diagnostics, the notes) is put in a canonical form (floats by their exact
hexadecimal value) and hashed. The digests were taken from the extraction before it was made
faster; code that only makes extraction faster must leave them unchanged. A change in a digest
is a change in results: make it on purpose, and say why, when updating the digest here.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import warnings
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from fricid.extract import extract
from fricid.samples import RawLog
from fricid.sim import preset, simulate
from fricid.workflow import load_joint

#: The real lead-screw recordings, ``../shared/data/real/epos-leadscrew/`` beside the repo.
LEADSCREW = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "real"
LEADSCREW = LEADSCREW / "epos-leadscrew"


def canon(obj: Any) -> Any:
    """``obj`` as nested lists, dicts, strings and ints; floats by ``float.hex`` (exact)."""
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
    if isinstance(obj, bool) or obj is None or isinstance(obj, int):
        return obj
    if isinstance(obj, float):
        return float.hex(obj)
    return repr(obj)


def digest(obj: Any) -> str:
    """16 hexadecimal digits of the SHA-256 of :func:`canon` of ``obj``."""
    text = json.dumps(canon(obj), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


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
    return load_joint(LEADSCREW / name, "epos").extraction


#: name -> (what is extracted, its digest). Digests updated once, on purpose: the extraction's
#: meta records ``position_source`` (where the position came from, for the trust verdict's
#: gravity caveat); every number is the same. The EPOS digests once more when the recordings'
#: absolute path left the canonical form (CI checks out elsewhere): every number is the same.
#: Every digest once more when a row's standard error took the noise's correlation and the
#: removed gravity fit's error (:func:`fricid.extract.bins.cell_sem`,
#: :func:`fricid.extract.gravity.gravity_se`): only ``sem``, ``direction_sem`` and the
#: ``sem_method`` and ``sem_caveat`` texts (now saying which method the rows took) changed
#: (compared field by field), every friction is the same. paper2+faults once more when the
#: note of gravity 'none' on a log with positions was reworded (it may come from the log's
#: design metadata): with the old text the digest is the old one, every number the same.
#: The virtual joint's five once more when the settle cut at a run's ends took a thousandth of
#: a sample period of slack (:func:`fricid.extract.segment`: the cut had followed the clock's
#: rounding, so a shifted clock changed the samples): the per-direction frictions moved by at
#: most 0.09 % (paper2+faults, three set-points 10 samples larger), paper1's not at all (its
#: trimming counts did); the EPOS recordings' are unchanged.
CASES = {
    "paper1": (lambda: _simulated("paper1"), "d5946fcb1251c6ce"),
    "paper1+faults": (lambda: _simulated("paper1+faults", 7_777), "4cbc27f79a2e92b4"),
    "paper1 joint": (lambda: _simulated("paper1", gravity="joint"), "cd6df3ebeb9746be"),
    "paper2+faults": (lambda: _simulated("paper2+faults"), "517b95c6cae1396f"),
    "paper1 clipped": (_clipped, "20c0adfd25667556"),
    "epos 10.csv": (lambda: _epos("10.csv"), "bae2753ecf9dca6b"),
    "epos n200.csv": (lambda: _epos("n200.csv"), "61acd305ad52f130"),
}


def run_case(name: str) -> Any:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return CASES[name][0]()


@pytest.mark.parametrize("name", list(CASES))
def test_extraction_numbers_are_pinned(name):
    assert digest(run_case(name)) == CASES[name][1]
