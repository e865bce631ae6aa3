"""Model files from strangers (issue 12, defect 4): loading is strict, and every outcome of a
hostile file is a clean error or a model that predicts finite friction on its range.

Valid files of every family (analytic, ``_asym``, ``rbf``, and files of schema version 1 that
an earlier fricid wrote) are mutated (byte flips,
truncation, inserted bytes, non-UTF-8, random JSON values in any field, NaN/Infinity/1e400
numbers, deleted and added keys, deep nesting, huge arrays, values of another field) and
loaded through the API and, for a sample, through ``fricid predict`` and ``fricid export``;
see ``_model_fuzz.py`` for the outcomes. Hypothesis keeps this module to about 20 s;
``benchmarks/fuzz_model.py`` runs the same mutations longer and prints the counts.
"""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

import _model_fuzz as mf
from fricid.cli import app
from fricid.errors import DataError
from fricid.export import model_schema
from fricid.fitted import FittedModel
from fricid.io import _jsonfile

runner = CliRunner()
FUZZ = dict(
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("models")


@pytest.fixture(scope="module")
def valid(folder) -> dict[str, Path]:
    return mf.write_valid(folder)


@pytest.fixture(scope="module")
def samples_csv(folder) -> Path:
    from fricid.io import write_samples

    path = folder / "samples.csv"
    write_samples(mf.samples(), path)
    return path


def doc(valid, family: str = "stribeck") -> dict:
    return json.loads(valid[family].read_text())


def write(folder: Path, name: str, content: bytes | str | dict) -> Path:
    path = folder / name
    if isinstance(content, dict):
        content = mf.dumps(content)
    path.write_bytes(
        content.encode("utf-8", "surrogatepass") if isinstance(content, str) else content
    )
    return path


def refused(path: Path, *words: str) -> str:
    with pytest.raises(DataError) as info:
        FittedModel.load(path)
    message = str(info.value)
    assert message.startswith((f"{path}: ", f"{path}, row ")), message
    assert "\n" not in message, message
    for word in words:
        assert word in message, message
    return message


# -- valid files, old and new -----------------------------------------------------------


@pytest.mark.slow  # 5 s measured under load (default run kept short)
def test_valid_files_of_every_family_load_and_predict_as_written(valid):
    models = mf.valid_models()
    for family, path in valid.items():
        loaded = FittedModel.load(path)
        X = mf.grid(loaded)
        assert np.allclose(loaded.predict(X), models[family].predict(X), rtol=1e-12, atol=0)
        assert mf.classify(path) == ("valid", family.removesuffix("_v1"))


def test_a_file_without_the_newer_fields_still_loads(folder, valid):
    for family in ("stribeck_asym", "rbf"):
        d = doc(valid, family)
        for key in ("statistics", "operating_range", "optimizer"):
            d.pop(key, None)
        for record in d["parameters"].values():
            for key in ("init", "ci95", "low_open", "high_open", "note", "not_determined"):
                record.pop(key)
        d["provenance"] = {"source": "an old file", "created": "2025-01-01T00:00:00+00:00"}
        assert FittedModel.load(write(folder, f"old_{family}.json", d)).model == family
    d = doc(valid, "stribeck_v1")  # version 1 without its newer fields
    for key in ("statistics", "status", "message", "init", "operating_range", "history"):
        d.pop(key, None)
    assert FittedModel.load(write(folder, "old_stribeck_v1.json", d)).model == "stribeck"


# -- the cases: one line naming the file, through the API -----------------------


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("NaN", ["parameters/tau_s/value", "NaN is not a finite number"]),
        ("Infinity", ["parameters/tau_s/value", "Infinity"]),
        ("-Infinity", ["parameters/tau_s/value", "-Infinity"]),
        ("1e400", ["parameters/tau_s/value", "1e400 exceeds 1e+300"]),
        ("-2e300", ["parameters/tau_s/value", "1e+300"]),
        ("1" + "0" * 400, ["parameters/tau_s/value", "exceeds"]),
        ("9" * 5000, ["parameters/tau_s/value", "exceeds"]),
        ('"0.6"', ["parameters/tau_s/value", "schema (version 2)"]),
        ("true", ["parameters/tau_s/value", "schema"]),
    ],
)
def test_numbers_that_are_not_finite_are_refused_by_field(folder, valid, text, words):
    d = doc(valid)
    d["parameters"]["tau_s"]["value"] = mf.Raw(text)
    refused(write(folder, "number.json", d), *words)
    # the same in a file of version 1, named by its own field
    d = doc(valid, "stribeck_v1")
    d["params"]["tau_s"] = mf.Raw(text)
    old = {"parameters/tau_s/value": "params/tau_s", "schema (version 2)": "schema (version 1)"}
    refused(write(folder, "number_v1.json", d), *[old.get(w, w) for w in words])


@pytest.mark.parametrize(
    ("name", "content", "words"),
    [
        ("latin1.json", '{"model": "caf\xe9"}'.encode("latin-1"), ["not UTF-8", "0xe9", "row 1"]),
        ("binary.json", b"\x89PNG\r\n\x1a\n\x00\x00\xff", ["not UTF-8"]),
        ("zeros.json", b"\x00" * 100, ["not valid JSON"]),
        ("empty.json", b"", ["not valid JSON"]),
        ("deep.json", b"[" * 100_000 + b"]" * 100_000, ["nested 100000 deep", "at most 64"]),
        ("deepobj.json", b'{"a":' * 5000 + b"1" + b"}" * 5000, ["nested 5000 deep"]),
        ("unclosed.json", b"[" * 1_000_000, ["nested 1000000 deep"]),
        ("repeated.json", b'{"model": "rbf", "model": "stribeck"}', ["'model' appears twice"]),
        ("text.json", b'"just a string"', ["must hold a JSON object"]),
        ("array.json", b"[1, 2]", ["must hold a JSON object"]),
    ],
)
def test_files_that_are_not_model_json_are_refused(folder, name, content, words):
    refused(write(folder, name, content), *words)


def test_a_folder_or_a_missing_file_is_refused(folder):
    refused(folder, "cannot read the model file")
    refused(folder / "missing.json", "cannot read the model file", "No such file")


def test_brackets_inside_strings_do_not_count_as_nesting(folder, valid):
    d = doc(valid)
    d["optimizer"]["method"] = "[" * 500
    d["provenance"]["note"] = '{"' * 300 + "\\" * 7
    assert FittedModel.load(write(folder, "brackets.json", d)).optimizer.method == "[" * 500


def test_the_size_cap(folder, valid, monkeypatch):
    assert _jsonfile.MAX_BYTES == 64 * 2**20
    monkeypatch.setattr(_jsonfile, "MAX_BYTES", 1000)
    refused(valid["stribeck"], "larger than 1000 bytes")
    res = runner.invoke(app, ["predict", str(valid["stribeck"]), "--velocity", "1"])
    assert res.exit_code == 2 and "larger than" in res.output


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda d: d["provenance"].update(x=[0] * (_jsonfile.MAX_ITEMS + 1)), ["provenance/x"]),
        (lambda d: d["optimizer"].update(history=[[1, 1, 1]]), ["optimizer/history/0"]),
        (lambda d: d["provenance"].update(x={f"k{i}": 0 for i in range(10_001)}), ["10000"]),
        (
            lambda d: d["optimizer"].update(method="x" * 100_001),
            ["optimizer/method", "longer than 1000 characters"],
        ),
        (lambda d: d["provenance"].update(source="\ud800"), ["provenance/source", "surrogate"]),
        (lambda d: d["parameters"].update({"a\nb": {"value": 1.0}}), ["parameters", "not match"]),
        (lambda d: d.update(model="stribeck\n#define"), ["field 'model'"]),
        (lambda d: d.update(model="nonesuch"), ["unknown model 'nonesuch'"]),
        (lambda d: d["parameters"].pop("w_s"), ["missing: w_s"]),
        (lambda d: d["parameters"]["w_s"].pop("value"), ["parameters/w_s", "'value'"]),
        (lambda d: d["operating_range"].update(velocity=[2.0, -2.0]), ["minimum 2.0 exceeds"]),
        (
            lambda d: d["parameters"]["tau_c"].update(bounds=[1.0, 0.0]),
            ["parameters/tau_c/bounds", "minimum 1.0 exceeds"],
        ),
        (lambda d: d["parameters"]["tau_c"].update(ci95=[0.1]), ["parameters/tau_c/ci95"]),
        (lambda d: d["parameters"]["tau_c"].update(low_open=1), ["parameters/tau_c/low_open"]),
        (lambda d: d["operating_range"].update(temperature=[-300.0, 25.0]), ["temperature"]),
        (lambda d: d["parameters"]["tau_c"].update(stderr=-1.0), ["parameters/tau_c/stderr"]),
        (lambda d: d.update(correlation=[[1.0, 0.5], [0.5]]), ["correlation"]),
        (lambda d: d.update(correlation=[[1.0, 2.0], [2.0, 1.0]]), ["correlation/0/1"]),
        (lambda d: d["optimizer"].update(seed=-1), ["optimizer/seed"]),
        (lambda d: d["optimizer"].update(nfev=None), ["optimizer/nfev"]),
        (lambda d: d["metrics"].update(n=1.5), ["metrics/n"]),
        (lambda d: d["optimizer"].update(history=[[1.0], [2.0, 3.0]]), ["optimizer/history/0"]),
    ],
)
def test_absurd_sizes_names_and_values_are_refused(folder, valid, edit, words):
    d = doc(valid)
    edit(d)
    refused(write(folder, "absurd.json", d), *words)


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda s: s.update(widths=s["widths"][:-1]), ["state/widths", "shape"]),
        (lambda s: s.update(weights=[*s["weights"], 1.0]), ["state/weights"]),
        (lambda s: s.update(centers=[c[:2] for c in s["centers"]]), ["state/centers"]),
        (lambda s: s["centers"][0].pop(), ["state/centers"]),  # ragged rows
        (lambda s: s.update(input_scale=s["input_scale"][:2]), ["state/input_scale"]),
        (lambda s: s.update(widths=[0.0] * len(s["widths"])), ["state/widths/0"]),
        (lambda s: s.update(velocity_scale="abc"), ["state/velocity_scale"]),
        (lambda s: s.update(inputs=["velocity", "velocity"]), ["state/inputs"]),
        (lambda s: s.pop("bias"), ["state lacks 'bias'"]),
        (lambda s: s.update(kind="other"), ["unknown RBF state kind"]),
        (lambda s: s.update(widths=[1e-300] * len(s["widths"])), ["non-finite friction"]),
    ],
)
def test_rbf_networks_with_inconsistent_arrays_are_refused(folder, valid, edit, words):
    d = doc(valid, "rbf")
    edit(d["state"])
    refused(write(folder, "rbf_bad.json", d), *words)


def test_a_model_that_overflows_on_its_range_is_refused(folder, valid):
    d = doc(valid)
    d["parameters"]["tau_v"]["value"] = 1e300
    d["operating_range"]["velocity"] = [-1e300, 1e300]
    refused(write(folder, "overflow.json", d), "non-finite friction", "velocity -1e+300")
    d = doc(valid, "vlt")  # vlt's viscous level times (1 - exp(...)): inf * 0 at v = 0
    d["parameters"]["f_v0"]["value"] = d["parameters"]["f_vT"]["value"] = 1e300
    d["operating_range"].update(velocity=[-1.0, 1.0], temperature=[25.0, 1e300])
    refused(write(folder, "overflow_vlt.json", d), "non-finite friction")


def test_from_dict_checks_python_values_as_strictly(valid):
    d = doc(valid)
    d["parameters"]["tau_s"]["value"] = math.nan
    with pytest.raises(
        DataError, match=r"^given\.json: field 'parameters/tau_s/value'.*not finite"
    ):
        FittedModel.from_dict(d, source="given.json")
    d["parameters"]["tau_s"]["value"] = 1e301
    with pytest.raises(DataError, match="parameters/tau_s/value"):
        FittedModel.from_dict(d, source="given.json")


def test_the_schema_states_the_readers_limits():
    schema = model_schema()
    anything = schema["$defs"]["any"]
    assert anything["maxItems"] == _jsonfile.MAX_ITEMS
    assert anything["maxLength"] == _jsonfile.MAX_STRING
    assert anything["maxProperties"] == _jsonfile.MAX_PROPERTIES == schema["maxProperties"]
    assert anything["maximum"] == _jsonfile.MAX_MAGNITUDE == -anything["minimum"]
    assert str(_jsonfile.MAX_DEPTH) in anything["description"]
    assert "64 MiB" in schema["description"]


# -- every command that loads a model: exit 2 and one line ------------------------------

COMMANDS = {
    "predict": lambda m, s, out: ["predict", m, "--velocity", "0.5"],
    "export": lambda m, s, out: ["export", m, "--to", "c", "--out", out],
    "evaluate": lambda m, s, out: ["evaluate", m, s],
    "report": lambda m, s, out: ["report", m, s, "--out", out],
    "compensate": lambda m, s, out: ["compensate", m],
}


@pytest.mark.parametrize("command", sorted(COMMANDS))
@pytest.mark.parametrize(
    ("name", "content"),
    [
        ("nan.json", "NaN"),
        ("huge.json", "1e400"),
        ("latin1.json", b'{"schema_version": 1, "model": "\xe9"}'),
        ("deep.json", b"[" * 50_000 + b"]" * 50_000),
    ],
)
def test_every_command_that_loads_a_model_exits_2_with_one_line(
    folder, valid, samples_csv, command, name, content
):
    if isinstance(content, str):
        d = doc(valid)
        d["parameters"]["tau_c"]["value"] = mf.Raw(content)
        content = mf.dumps(d)
    path = write(folder, f"{command}_{name}", content)
    out = folder / f"out_{command}_{name}"
    res = runner.invoke(app, COMMANDS[command](str(path), str(samples_csv), str(out)))
    assert res.exit_code == 2, res.output
    assert isinstance(res.exception, SystemExit), res.exception
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {path}"), res.output
    assert not out.exists()


# -- fuzzing ----------------------------------------------------------------------------


@pytest.mark.slow  # 26 s measured under load (default run kept short)
@settings(max_examples=200, **FUZZ)
@given(
    family=st.sampled_from(mf.FAMILIES),
    kind=st.sampled_from(mf.KINDS),
    rng=st.randoms(use_true_random=False),
)
def test_fuzzed_model_files_load_cleanly_or_predict_finite_friction(
    folder, valid, family, kind, rng
):
    data = mf.mutate(valid[family].read_bytes(), rng, kind, huge=(1000, 100_001))
    path = write(folder, f"fuzz_{family}.json", data)
    outcome, detail = mf.classify(path)
    assert outcome in ("error", "valid"), f"{family}/{kind}: {outcome}: {detail}"


@pytest.mark.slow  # 6 s measured under load (default run kept short)
@settings(max_examples=40, **FUZZ)
@given(
    family=st.sampled_from(mf.FAMILIES),
    kind=st.sampled_from(mf.KINDS),
    command=st.sampled_from(("predict", "c", "urdf", "yaml")),
    rng=st.randoms(use_true_random=False),
)
def test_fuzzed_model_files_through_the_cli(folder, valid, family, kind, command, rng):
    data = mf.mutate(valid[family].read_bytes(), rng, kind, huge=(1000,))
    path = write(folder, f"cli_{family}.json", data)
    out = Path(tempfile.mkdtemp(dir=folder)) / "out"
    outcome, detail = mf.classify_cli(path, command, out)
    assert outcome in ("error", "valid"), f"{family}/{kind}/{command}: {outcome}: {detail}"


def _subschemas(node, path=()):
    """Every subschema of the model schema, with its path."""
    if isinstance(node, dict):
        yield path, node
        for key, value in node.items():
            if key in ("properties", "$defs"):
                for name, sub in value.items():
                    yield from _subschemas(sub, (*path, key, name))
            elif key in ("items", "additionalProperties", "propertyNames", "then", "else", "if"):
                yield from _subschemas(value, (*path, key))
            elif key in ("allOf", "oneOf", "anyOf"):
                for i, sub in enumerate(value):
                    yield from _subschemas(sub, (*path, key, i))


def test_every_number_array_string_and_object_of_the_schema_is_bounded():
    bounds = {
        "number": ("maximum",),
        "integer": ("maximum",),
        "array": ("maxItems",),
        "string": ("maxLength", "enum", "const"),
        "object": ("maxProperties",),
    }
    low = ("minimum", "exclusiveMinimum")
    loose = []
    for path, node in _subschemas(model_schema()):
        if "if" in path or "$ref" in node or "enum" in node or "const" in node:
            continue
        types = node.get("type", [])
        for kind in [types] if isinstance(types, str) else types:
            unbounded = kind in bounds and not any(b in node for b in bounds[kind])
            if kind in ("number", "integer") and not any(b in node for b in low):
                unbounded = True
            if unbounded:
                loose.append(f"{'/'.join(map(str, path))}: {kind}")
    assert not loose, loose
