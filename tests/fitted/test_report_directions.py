"""The fit report names what a reader cannot guess: the per-direction suffixes, and an
interval open at the search range where no note says why (a new user's ``lugre_asym`` fit
printed w_s 0.0098 [0.0002, 0.0219] for 0.03 with no tag, while the trust line said "not
bounded by the data: w_s")."""

from __future__ import annotations

from dataclasses import replace

from fricid.fitted import FittedModel
from fricid.fitted._report import DIRECTIONS

LEVELS = {"f_c": 0.3, "beta": 0.05}
RANGE = {"velocity": [-1.0, 1.0], "load": [0.0, 0.0], "temperature": [25.0, 25.0]}


def model(name: str, values: dict) -> FittedModel:
    return FittedModel.from_values(name, values, operating_range=RANGE)


def test_a_per_direction_model_says_what_pos_and_neg_mean():
    both = {f"{k}{s}": v for s in ("_pos", "_neg") for k, v in LEVELS.items()}
    assert f"    {DIRECTIONS}" in model("coulomb_viscous_asym", both).report().splitlines()
    assert DIRECTIONS not in model("coulomb_viscous", dict(LEVELS)).report()


def test_an_interval_open_at_the_search_range_is_flagged_where_nothing_says_why():
    f = model("coulomb_viscous", dict(LEVELS))
    p = f.parameters["beta"]
    f.parameters["beta"] = replace(p, stderr=0.02, ci95=(0.0, 0.09), low_open=True)
    line = next(ln for ln in f.report().splitlines() if ln.lstrip().startswith("beta:"))
    assert "[not bounded by the data: the interval reaches the search range's lower end]" in line
    noted = replace(f.parameters["beta"], note="not determined: said elsewhere")
    f.parameters["beta"] = noted
    line = next(ln for ln in f.report().splitlines() if ln.lstrip().startswith("beta:"))
    assert "not bounded by the data" not in line  # the note says why
