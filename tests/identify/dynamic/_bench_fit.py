"""A LuGre fit of a 10 s log of the independent simulator of ``benchmarks/bench_lugre.py``
(``benchmarks/_lugre_truth.py``), as that benchmark reads and identifies one."""

from __future__ import annotations

import sys
import warnings

from tests._paths import REPO

from fricid.identify import fit
from fricid.io import read_rawlog

sys.path.insert(0, str(REPO / "benchmarks"))
import _lugre_truth as lt


def fit_bench_log(truth: str, kind: str, rate: float, cpr: int, seed: int, tmp_path):
    """(the fitted model, the truth in fricid's names) of one log written as a CSV."""
    t = lt.TRUTHS[truth]
    path = lt.write_log(lt.simulate(t, kind, 10.0, rate, cpr, seed), tmp_path / "a.csv", t, {})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(read_rawlog(path), "lugre", seed=seed), t.fricid_names()
