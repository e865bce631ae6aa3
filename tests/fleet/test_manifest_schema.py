"""The fleet manifest's JSON Schema: a valid schema, shipped as package data, consistent with
the registries it mirrors, and the source of the manifest's columns and messages."""

from __future__ import annotations

import json
from importlib import resources

import pytest
from jsonschema import Draft202012Validator

from fricid.errors import DataError
from fricid.fleet import FIELDS, read_manifest
from fricid.fleet.manifest import SCHEMA
from fricid.io import READER_OPTIONS, READERS
from fricid.units import UNITS
from fricid.workflow import DIRECTIONS, SAMPLE_SETS

PROPERTIES = SCHEMA["$defs"]["fields"]["properties"]


def test_schema_is_valid_and_shipped_as_package_data():
    text = resources.files("fricid").joinpath("schemas", "manifest.schema.json").read_text("utf-8")
    schema = json.loads(text)
    Draft202012Validator.check_schema(schema)
    assert schema == SCHEMA


def test_fields_come_from_the_schema():
    assert list(FIELDS) == list(PROPERTIES)
    for name, spec in PROPERTIES.items():
        assert spec["x-group"] in ("core", "fit", "extract", "reader", "robot"), name
        assert spec["description"] and spec["x-message"], name
        if "x-quantity" in spec:
            assert spec["x-quantity"] in UNITS, name
        assert FIELDS[name].quantity == spec.get("x-quantity")


def test_schema_mirrors_the_registries():
    assert PROPERTIES["reader"]["enum"] == list(READERS)
    assert PROPERTIES["direction"]["enum"] == list(DIRECTIONS)
    assert PROPERTIES["samples"]["enum"] == list(SAMPLE_SETS)
    from fricid.identify.dynamic.arm._friction import FAMILIES
    from fricid.identify.dynamic.arm._lugre import LUGRE

    assert PROPERTIES["friction"]["enum"] == sorted((*FAMILIES, LUGRE))  # a robot row's
    options = {o for opts in READER_OPTIONS.values() for o in opts}
    reader_fields = {f.option for f in FIELDS.values() if f.group == "reader"}
    assert reader_fields <= options  # every reader column fills some reader's option


def test_a_document_validates_against_the_schema():
    validator = Draft202012Validator(SCHEMA, format_checker=Draft202012Validator.FORMAT_CHECKER)
    joint = {"robot": "r1", "joint": "j1", "log": "x.parquet", "seed": 2, "fix": {"delta": 1.0}}
    assert validator.is_valid({"joints": [joint], "defaults": {"method": "lm"}})
    assert not validator.is_valid({"joints": []})
    assert not validator.is_valid({"joints": [joint], "extra": 1})
    fields = Draft202012Validator(SCHEMA).evolve(schema=SCHEMA["$defs"]["joint"])
    assert fields.is_valid(joint)
    assert not fields.is_valid({**joint, "seed": -1})
    assert not fields.is_valid({**joint, "reader": "generic"})  # needs columns
    assert fields.is_valid({**joint, "reader": "generic", "columns": {"time": "t"}})


@pytest.mark.parametrize(
    ("name", "text", "row", "column", "words"),
    [
        ("m.csv", "robot,joint,log,date\nr,j,x,2024-02-30\n", 2, "date", "not a date"),
        ("m.csv", "robot,joint,log,flip_sign,reader\nr,j,x,maybe,epos\n", 2, "flip_sign", "true"),
        (
            "m.csv",
            "robot,joint,log,velocity_tolerance\nr,j,x,-1\n",
            2,
            "velocity_tolerance",
            "> 0, got '-1'",
        ),
        ("m.csv", "robot,joint,log,reader\nr,j,x,generic\n", 2, "columns", "needs 'columns'"),
        ("m.csv", "robot,joint,log,max_evals\nr,j,x,0\n", 2, "max_evals", "integer >= 1"),
        ("m.csv", "robot,joint,log,fix\nr,j,x,a=1;a=2\n", 2, "fix", "given twice"),
        (
            "m.yaml",
            "defaults: {robot: r}\njoints: [{joint: j, log: x}]\n",
            None,
            "robot",
            "cannot have a default",
        ),
        ("m.yaml", "joints:\n  - {robot: r, joint: j, log: x}\n  - 5\n", 3, None, "a mapping"),
        ("m.yaml", "foo: 1\njoints: [{robot: r, joint: j, log: x}]\n", None, None, "'foo'"),
        ("m.yaml", "joints: []\n", None, None, "lists no joints"),
        ("m.yaml", "defaults: 3\njoints: [{robot: r, joint: j, log: x}]\n", None, None, "defaults"),
    ],
)
def test_schema_errors_are_one_line_with_file_row_and_column(
    tmp_path, name, text, row, column, words
):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    with pytest.raises(DataError) as info:
        read_manifest(path)
    err = info.value
    assert (err.file, err.row, err.column) == (str(path), row, column)
    assert words in str(err) and "\n" not in str(err)


def test_yaml_values_are_read_like_csv_cells(tmp_path):
    (tmp_path / "a.yaml").write_text(
        "joints:\n  - robot: r\n    joint: j\n    log: x\n    date: 2024-01-05\n"
        "    reader: EPOS\n    flip_sign: yes\n    nominal_torque [mN m]: 9.84\n    seed: 3.0\n",
        encoding="utf-8",
    )
    (tmp_path / "b.csv").write_text(
        "robot,joint,log,date,reader,flip_sign,nominal_torque [mN m],seed\n"
        "r,j,x,2024-01-05,epos,true,9.84,3\n",
        encoding="utf-8",
    )
    a, b = (read_manifest(tmp_path / n).joints[0] for n in ("a.yaml", "b.csv"))
    assert a.settings() == b.settings() and a.date == b.date == "2024-01-05"
    assert a.reader_options == {"flip_sign": True, "nominal_torque": pytest.approx(9.84e-3)}
    assert a.seed == 3 and isinstance(a.seed, int)


def test_fit_options_of_fricid_fit_reach_run_joint(tmp_path):
    """validate, loss, f_scale, weights and intervals: fricid fit's options, as columns."""
    (tmp_path / "m.csv").write_text(
        "robot,joint,log,validate,loss,f_scale [mN m],weights,intervals\n"
        "r,j,x,KFOLD:4,soft_l1,0.5,std,jacobian\n"
        "r,k,x,,,,,\n",
        encoding="utf-8",
    )
    given, default = read_manifest(tmp_path / "m.csv").joints
    kwargs = given.run_kwargs()
    assert (kwargs["validate"], kwargs["loss"], kwargs["weights"]) == ("kfold:4", "soft_l1", "std")
    assert kwargs["f_scale"] == pytest.approx(5e-4) and kwargs["intervals"] == "jacobian"
    assert given.settings()["validate"] == "kfold:4"
    want = {"validate": None, "loss": "l2", "f_scale": None, "weights": "none", "intervals": "auto"}
    assert {k: default.run_kwargs()[k] for k in want} == want
    for column, cell, words in (
        ("validate", "lovo:3", "must be lovo, kfold or kfold:K"),
        ("validate", "kfold:1", "must be lovo, kfold or kfold:K"),
        ("loss", "cauchy", "must be one of: l2, soft_l1, huber"),
        ("weights", "given", "must be one of: none, std"),
        ("intervals", "bootstrap", "must be one of: auto, profile, jacobian, none"),
    ):
        (tmp_path / "bad.csv").write_text(f"robot,joint,log,{column}\nr,j,x,{cell}\n")
        with pytest.raises(DataError, match=words) as info:
            read_manifest(tmp_path / "bad.csv")
        assert info.value.row == 2 and info.value.column == column
