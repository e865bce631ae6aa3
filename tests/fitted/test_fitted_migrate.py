"""Model files of schema version 1 (``fricid.fitted._migrate``): files an earlier fricid wrote
load, predict the same numbers, print the same fit report, exports, parameter table, fleet
row and trust lists as that fricid did (``tests/data/model_files_v1``), and save again in the
current layout.

The same numbers to :data:`REL`: not bit for bit, since numpy's vector kernels (exp, tanh,
sums) round the last bit differently on different processors (AVX-512 or AVX2), and the
predictions and a LuGre export's numbers came out 4e-14 apart on the next machine."""

from __future__ import annotations

import json
import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from _paths import TEST_DATA
from fricid.errors import DataError
from fricid.export import (
    c_code,
    file_sha256,
    mjcf_text,
    ros2_yaml_text,
    urdf_text,
    validate_model_dict,
)
from fricid.export.mjcf import FRICTIONLOSS_LINES, STIFF_SOLIMP
from fricid.fitted import SCHEMA_VERSION, FittedModel
from fricid.fleet.job import fit_row
from fricid.fleet.manifest import JointSpec
from fricid.fleet.table import VERDICT_COLUMNS
from fricid.identify._diagnostics import not_determined, open_sides
from fricid.report.model import parameter_table

V1_FILES = TEST_DATA / "model_files_v1"
EXPECTED = json.loads((V1_FILES / "expected.json").read_text())
FAMILIES = sorted(EXPECTED)

#: Fields of version 1 that version 2 holds in ``parameters`` and ``optimizer``.
V1_ONLY = {"params", "units", "fixed", "stderr", "ci95", "at_bound", "method", "seed", "nfev"}
V1_ONLY |= {"history", "bounds", "status", "message", "init", "ci95_low", "ci95_high"}
V1_ONLY |= {"ci_open", "uncertainty_note"}


def v1_doc(family: str) -> dict:
    return json.loads((V1_FILES / f"{family}.json").read_text())


def load(family: str) -> FittedModel:
    return FittedModel.load(V1_FILES / f"{family}.json")


def quiet(call, *args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return call(*args, **kw)


def exports(fitted: FittedModel, path: Path) -> dict[str, str]:
    """What fricid exports for the model of ``path``, as ``make_v1.py.txt`` recorded it."""
    sha, out = file_sha256(path), {}
    for target, build in (("urdf", urdf_text), ("mjcf", mjcf_text), ("yaml", ros2_yaml_text)):
        out[target] = quiet(build, fitted, source=path.name, sha256=sha)
    try:
        code = quiet(c_code, fitted, source=path.name, sha256=sha)
        out["c"] = code.header + "\n//--\n" + code.source
    except Exception as exc:  # the recorded text of a model the C export refuses
        out["c"] = f"error: {type(exc).__name__}: {exc}"
    return out


#: The exports' comment lines changed since the files were written, and how each was written
#: then: a trajectory model's fit error says of which residual (and its estimator is named, on
#: a line of its own, where the file records one), and an input the model does not read has
#: no range (it had "load 0 to 0 N m"). A static MJCF joint carries a stiffer
#: solimpfriction, said in its comment, and the C export's refusal of a dynamic model names
#: the targets that take it (:data:`_NOW_THEN`).
_THEN_FRICTIONLOSS = (
    "MuJoCo applies frictionloss as a soft constraint (solreffriction, solimpfriction; default "
    "solref 0.02 s): below frictionloss the joint creeps instead of sticking; a smaller time "
    "constant (at least 2 timesteps) holds it closer"
)
_LABEL = (
    ", of the residual the estimator fitted: low-passed and decimated, or a simulation's; "
    "fricid report gives the torque error on a log)"
)


_NOW_THEN = (
    (FRICTIONLOSS_LINES[0], _THEN_FRICTIONLOSS),
    (
        "copy frictionloss [N m], damping [N m s/rad] and solimpfriction onto your <joint>",
        "copy frictionloss [N m] and damping [N m s/rad] onto your <joint>",
    ),
    (f' solimpfriction="{STIFF_SOLIMP}"', ""),
    (
        "stribeck, msk, vlt, rbf, hybrid and gp); nothing was written; a dynamic model exports "
        "--to mjcf (MuJoCo's friction), yaml or urdf (its Coulomb-viscous projection)",
        "stribeck, msk, vlt and rbf); nothing was written",
    ),
    (  # "passive" was the actuator's (no input), read as the friction's: it says which now
        "dcmotor actuator without a control input (input none, motorconst 0 0: no electrical "
        "branch; resistance 1 is required and unused): lugre = sigma_0 sigma_1 tau_c tau_s w_s",
        "dcmotor actuator, passive (input none, motorconst 0 0: no electrical branch; "
        "resistance 1 is required and unused): lugre = sigma_0 sigma_1 tau_c tau_s w_s",
    ),
)
#: Lines added to the exports since (left out before comparing).
_ADDED = (
    "estimator: ",
    "the LuGre model is passive",
    "the LuGre model is NOT passive",
    "trust verdict: not recorded in the model file",  # said now, where it had been left out
)


def exports_as_before(fitted: FittedModel, path: Path) -> dict[str, str]:
    """:func:`exports` with the comment lines changed since as they were written then."""
    trajectory = "trajectory" in (fitted.provenance or {})
    out = {}
    for target, text in exports(fitted, path).items():
        assert (_LABEL in text) == (trajectory and "fit on its data" in text), target
        text = text.replace(_LABEL, ")")
        for now, then in _NOW_THEN:
            text = text.replace(now, then)
        text = "\n".join(ln for ln in text.split("\n") if not any(a in ln for a in _ADDED))
        if "load: not read by the model" in text:
            text = text.replace("load: not read by the model", "load 0 to 0 N m")
            text = re.sub(r"(at velocity \S+ rad/s), (temperature )", r"\1, load 0 N m, \2", text)
        out[target] = text
    return out


def as_before(fitted) -> str:
    """The fit report without the lines added since the files were written (the RMSE, from
    the file's own metrics, and a per-direction model's legend, checked here), to compare
    with what that fricid printed."""
    from fricid.fitted._report import DIRECTIONS

    lines = fitted.report().splitlines()
    added = [ln for ln in lines if ln.startswith("    RMSE [N m]         = ")]
    assert len(added) == (fitted.metrics.get("rmse") is not None)
    for ln in added:
        assert float(ln.split("=")[1]) == pytest.approx(fitted.metrics["rmse"], rel=1e-7)
    legend = [ln for ln in lines if ln == f"    {DIRECTIONS}"]
    assert len(legend) == any(n.endswith("_pos") for n in fitted.parameters)
    return "\n".join(ln for ln in lines if ln not in added + legend)


#: How near a number must be to the one that fricid printed or predicted: a relative error,
#: and in a text an absolute one for numbers that are rounding (a projection's rms error of
#: 1.05e-16 printed 1.09e-16 with numpy's plain kernels).
REL, TINY = 1e-12, 1e-12

_NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


_UNIT_ONE = re.compile(r"^(    \w+:\s+\S+) 1(?= |$)", re.MULTILINE)


def printed_now(report: str) -> str:
    """A report as printed then, in today's form: a dimensionless parameter's unit "1" after
    its value is no longer printed ("delta: 4 1 +/- 19.5" was read as one number)."""
    return _UNIT_ONE.sub(r"\1", report)


def same_text(a: str, b: str) -> bool:
    """``a`` and ``b`` alike but for the last bits of their numbers (:data:`REL`)."""
    if _NUMBER.split(a) != _NUMBER.split(b):
        return False
    pairs = zip(_NUMBER.findall(a), _NUMBER.findall(b), strict=True)  # as many: same split
    return all(math.isclose(float(u), float(v), rel_tol=REL, abs_tol=TINY) for u, v in pairs)


_ROUNDING_MAX = re.compile(r"max (\S+) N m at velocity \S+ rad/s")


def _at_rounding(text: str) -> str:
    """``text`` without the place of a maximum error that is rounding (an exact projection's:
    the processor's last bits choose it)."""

    def drop(m: re.Match) -> str:
        return f"max {m[1]} N m" if abs(float(m[1])) < TINY else m[0]

    return _ROUNDING_MAX.sub(drop, text)


def same(a, b) -> bool:
    both_nan = isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b)
    return both_nan or a == b


@pytest.mark.parametrize("family", FAMILIES)
def test_version_1_files_predict_and_print_as_before(family):
    expected, path = EXPECTED[family], V1_FILES / f"{family}.json"
    fitted = load(family)
    y = quiet(fitted.predict, np.array(expected["X"]))
    np.testing.assert_allclose(y, np.array(expected["y"]), rtol=REL, atol=0)
    assert same_text(as_before(fitted), printed_now(expected["report"]))
    exported = exports_as_before(fitted, path)
    assert exported.keys() == expected["exports"].keys()
    for target, text in exported.items():
        assert same_text(_at_rounding(text), _at_rounding(expected["exports"][target])), target
    table = parameter_table(fitted).to_csv(index=False) if fitted.parameters else ""
    assert table == expected["parameter_table"]
    spec = JointSpec(robot="r", joint="j", log=Path("/nonexistent/log.csv"), log_text="log.csv")
    row = quiet(fit_row, spec, family, fitted, None)
    # the verdict columns come from the trust record alone now (none given here), and the
    # row names the model fitted ("chosen": the family where "auto" was asked): the rest of
    # the row is the old row
    want = {k: v for k, v in expected["fleet_row"].items() if k not in VERDICT_COLUMNS}
    assert row.pop("chosen") == fitted.model
    # the rows now give the file's interval by its ends, and no half-width where an end is
    # open (the search bound): a symmetric width had misstated it
    for p in fitted.parameters.values():
        low, high = row.pop(f"ci95_low_{p.name}"), row.pop(f"ci95_high_{p.name}")
        if p.fixed:
            continue
        assert same(low, None if p.low_open else p.ci95[0])
        assert same(high, None if p.high_open else p.ci95[1])
        if p.low_open or p.high_open:
            assert row[f"ci95_{p.name}"] is None
            want[f"ci95_{p.name}"] = None
    assert row.keys() == want.keys()
    assert all(same(row[k], v) for k, v in want.items()), family
    assert not_determined(fitted) == expected["not_determined"]
    assert open_sides(fitted, include_zero=True) == expected["open_sides"]


@pytest.mark.parametrize("family", FAMILIES)
def test_version_1_files_save_in_the_current_layout(family, tmp_path):
    fitted = load(family)
    d = fitted.to_dict()
    assert d["schema_version"] == SCHEMA_VERSION == 2
    assert not V1_ONLY & set(d) and {"parameters", "optimizer"} <= set(d)
    assert not {"status", "message", "nfev", "max_evals"} & set(d["convergence"] or {})
    validate_model_dict(d)
    again = FittedModel.load(fitted.save(tmp_path / "again.json"))
    X = np.array(EXPECTED[family]["X"])
    assert np.array_equal(quiet(again.predict, X), quiet(fitted.predict, X))
    assert again.report() == fitted.report() and again.to_dict() == d


def test_the_records_hold_what_the_ten_fields_held():
    d, fitted = v1_doc("stribeck"), load("stribeck")
    assert list(fitted.parameters) == list(d["params"])
    for name, p in fitted.parameters.items():
        assert p.value == d["params"][name] and p.unit == d["units"][name]
        assert p.fixed == (name in d["fixed"]) and p.at_bound == (name in d["at_bound"])
        if p.fixed:
            assert p.init is None and p.bounds is None and math.isnan(p.stderr)
            continue
        assert p.init == d["init"][name] and list(p.bounds) == d["bounds"][name]
        assert p.stderr == d["stderr"][name] and p.ci95_halfwidth == d["ci95"][name]
        assert p.ci95 == (d["ci95_low"][name], d["ci95_high"][name])
        assert [p.low_open, p.high_open] == d["ci_open"][name]
        assert p.note == d["uncertainty_note"][name]
    assert fitted.fixed == ("delta",) and fitted.at_bound == ("w_s",)
    assert [n for n, p in fitted.parameters.items() if p.not_determined] == ["tau_s", "w_s"]
    opt = fitted.optimizer
    assert (opt.method, opt.seed, opt.status, opt.message) == (
        d["method"],
        d["seed"],
        d["status"],
        d["message"],
    )
    assert opt.nfev == d["nfev"] and opt.max_evals == d["convergence"]["max_evals"]
    assert opt.history == d["history"]
    assert fitted.convergence == {
        k: v
        for k, v in d["convergence"].items()
        if k not in ("status", "message", "nfev", "max_evals")
    }


def test_a_correlation_in_another_order_is_reordered_to_the_free_parameters(tmp_path):
    d = v1_doc("stribeck")
    names = list(d["stderr"])
    order = [2, 0, 3, 1]  # stderr (the rows' order in version 1) written in another order
    d["stderr"] = {names[i]: d["stderr"][names[i]] for i in order}
    d["correlation"] = [[d["correlation"][i][j] for j in order] for i in order]
    path = tmp_path / "reordered.json"
    path.write_text(json.dumps(d))
    assert FittedModel.load(path).correlation == load("stribeck").correlation
    assert as_before(FittedModel.load(path)) == printed_now(EXPECTED["stribeck"]["report"])


def test_an_unconverged_block_without_a_reason_keeps_its_message():
    d = v1_doc("stribeck_bas")
    del d["convergence"]["reason"]
    fitted = FittedModel.from_dict(d, source="old.json")
    assert fitted.convergence["reason"] == d["convergence"]["message"]
    assert fitted.report().startswith(f"NOT CONVERGED: {d['convergence']['message']}; ")


def test_errors_in_a_version_1_file_name_its_own_fields():
    d = v1_doc("stribeck")
    d["bounds"]["tau_c"] = [1.0, 0.0]
    with pytest.raises(DataError, match=r"^old\.json: field 'bounds/tau_c': the minimum 1\.0"):
        FittedModel.from_dict(d, source="old.json")
    d = v1_doc("stribeck")
    d["stderr"]["tau_c"] = -1.0
    with pytest.raises(DataError, match=r"field 'stderr/tau_c' .* schema \(version 1\)"):
        FittedModel.from_dict(d, source="old.json")
    d = v1_doc("stribeck")
    del d["params"]
    with pytest.raises(DataError, match="'params' is a required property"):
        FittedModel.from_dict(d, source="old.json")
    d = v1_doc("stribeck")
    d["params"].pop("w_s")
    with pytest.raises(DataError, match="missing: w_s"):
        FittedModel.from_dict(d, source="old.json")


def test_the_upgrade_leaves_the_document_as_it_was():
    d = v1_doc("lugre")
    before = json.dumps(d, sort_keys=True)
    FittedModel.from_dict(d, source="old.json")
    assert json.dumps(d, sort_keys=True) == before


def test_an_unconverged_fit_does_not_call_its_parameters_not_determined():
    """A fit that did not converge has no standard errors at all, which says nothing about
    what the data determine: no "not determined" flag (version 1 files without notes printed
    one; the NOT CONVERGED line says why there are no intervals)."""
    d = v1_doc("stribeck_bas")
    del d["uncertainty_note"]
    fitted = FittedModel.from_dict(d, source="old.json")
    text = fitted.report()
    assert text.startswith("NOT CONVERGED: ") and "[not determined]" not in text
    assert not_determined(fitted) == [] and not any(
        p.not_determined for p in fitted.parameters.values()
    )
