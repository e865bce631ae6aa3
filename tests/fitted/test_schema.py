"""The model file's JSON Schema: shipped in the package, matched by every file fricid writes,
and enforced on load with an error naming the file and the failing field."""

from __future__ import annotations

import json

import numpy as np
import pytest
from jsonschema import Draft202012Validator

from fricid.errors import DataError
from fricid.export import model_schema, schema_path, validate_model_dict
from fricid.fitted import SCHEMA_VERSION, FittedModel
from fricid.identify import fit
from fricid.samples import FrictionSamples


@pytest.fixture(scope="module")
def fitted() -> FittedModel:
    v = np.concatenate([np.geomspace(0.01, 2, 12), -np.geomspace(0.01, 2, 12)])
    f = 0.1 * np.sign(v) + 0.05 * v + np.where(v > 0, 0.01, 0.0)
    s = FrictionSamples(velocity=v, load=0.0, temperature=25.0, friction=f, source="synthetic")
    return fit(s, "coulomb_viscous_asym")


def test_schema_is_valid_draft_2020_12_and_shipped():
    schema = model_schema()
    Draft202012Validator.check_schema(schema)
    assert schema_path().name == "model.schema.json" and schema_path().is_file()
    # every field of FittedModel is documented
    for name in FittedModel.__dataclass_fields__:
        assert "description" in schema["properties"][name], name


def test_written_files_match_the_schema(tmp_path, fitted):
    path = fitted.save(tmp_path / "m.json")
    d = json.loads(path.read_text())
    validate_model_dict(d)  # no error
    assert d["schema_version"] == SCHEMA_VERSION == 2
    assert d["parameters"]["beta_pos"]["unit"] == "N m s/rad"
    assert {"source", "fricid_version", "created"} <= d["provenance"].keys()
    assert d["optimizer"]["method"] == "lm" and d["optimizer"]["seed"] == 0
    assert FittedModel.load(path).params == fitted.params


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (
            lambda d: d["parameters"]["f_c_pos"].update(value="0.1"),
            "parameters/f_c_pos/value",
        ),
        (lambda d: d.update(model=""), "model"),
        (lambda d: d["parameters"]["f_c_pos"].update(fixed="f_c"), "parameters/f_c_pos/fixed"),
        (lambda d: d["operating_range"].update(velocity=[0.1]), "operating_range/velocity"),
        (lambda d: d["optimizer"].update(seed=1.5), "optimizer/seed"),
        (lambda d: d.update(model="rbf", state=None), "state"),
        (lambda d: d["provenance"].update(directions=[2]), "provenance/directions/0"),
    ],
)
def test_bad_field_is_named(tmp_path, fitted, edit, field):
    d = fitted.to_dict()
    edit(d)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(d))
    with pytest.raises(DataError) as info:
        FittedModel.load(path)
    message = str(info.value)
    assert message.startswith(f"{path}: field '{field}'"), message


def test_missing_required_field(tmp_path, fitted):
    d = fitted.to_dict()
    del d["parameters"]
    path = tmp_path / "noparams.json"
    path.write_text(json.dumps(d))
    with pytest.raises(DataError, match="'parameters' is a required property"):
        FittedModel.load(path)


def test_newer_schema_version_asks_for_an_upgrade(tmp_path, fitted):
    d = fitted.to_dict()
    d["schema_version"] = SCHEMA_VERSION + 1
    d["parameters"] = "a format we do not know"  # a newer file may change anything
    path = tmp_path / "new.json"
    path.write_text(json.dumps(d))
    with pytest.raises(DataError, match=r"newer than this fricid .* upgrade fricid"):
        FittedModel.load(path)


def test_unknown_top_level_keys_are_ignored(tmp_path, fitted):
    d = fitted.to_dict()
    d["comment"] = "written by hand"
    path = tmp_path / "extra.json"
    path.write_text(json.dumps(d))
    assert FittedModel.load(path).model == "coulomb_viscous_asym"
