"""Hostile variants of valid model files, and what loading one may end in (issue 12, defect 4).

Shared by ``tests/fitted/test_fuzz_model.py`` (hypothesis draws the mutations) and
``benchmarks/fuzz_model.py`` (a seeded ``random.Random`` draws them, for longer runs). Every
mutation is drawn from a :class:`random.Random`, so both drive the same code.

Outcomes (:func:`classify`, :func:`classify_cli`):

- ``"error"``: a :class:`~fricid.errors.FricidError` on one line that names the file given
  (through the CLI: exit status 2 and one ``error: <file>: ...`` line; for a file that loads,
  one ``error:`` line of the command, such as an export that cannot represent the model);
- ``"valid"``: a model whose predictions are finite on a grid over its operating range (and
  off the probe points the loader uses), whose report renders, and which saves to a file
  that loads again (through the CLI: exit status 0 and finite numbers out);
- ``"traceback"``: any other exception, or an error message that is not one line naming the
  file;
- ``"wrong"``: a model that loaded but predicts a non-finite friction on its operating range,
  or an exit status 0 with non-finite output.
"""

from __future__ import annotations

import json
import random
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from typer.testing import CliRunner

from fricid.cli import app
from fricid.errors import FricidError
from fricid.fitted import FittedModel
from fricid.identify import fit
from fricid.identify.learned.rbf import fit_rbf
from fricid.samples import FrictionSamples

#: Model files of schema version 1, written by an earlier fricid (their reading upgrades them).
V1_FILES = Path(__file__).parent / "data" / "model_files_v1"

#: Families of schema version 1 fuzzed: ``<model>_v1`` is ``V1_FILES / "<model>.json"``.
V1_FAMILIES = ("stribeck_v1", "hybrid_v1", "lugre_v1")

#: Model families fuzzed: analytic, per-direction (_asym), the RBF network, and files of
#: schema version 1.
FAMILIES = ("coulomb_viscous", "stribeck", "vlt", "stribeck_asym", "msk_asym", "rbf", *V1_FAMILIES)

#: Byte-level and JSON-level mutations.
KINDS = (
    "flip",
    "truncate",
    "insert",
    "non_utf8",
    "value",
    "number",
    "delete",
    "add_key",
    "deep",
    "huge",
    "swap",
)


class Raw(str):
    """Text written into the JSON as it is (``NaN``, ``1e400``, 5000 digits)."""


NUMBERS: tuple[Any, ...] = (
    Raw("NaN"),
    Raw("Infinity"),
    Raw("-Infinity"),
    Raw("1e400"),
    Raw("-1e400"),
    Raw("1" + "0" * 400),
    Raw("9" * 5000),
    1e300,
    -1e300,
    1.7e308,
    5e-324,
    1e-300,
    0,
    -0.0,
    -1,
    2**63,
    1e30,
    -273.16,
)

TEXTS = (
    "",
    "rbf",
    "stribeck",
    "vlt_asym",
    "velocity",
    "tau_c",
    "a\nb",
    "*/ #define x",
    "\ud800",
    "\x00",
    "é" * 3,
    "x" * 2000,
    "gaussian_rbf",
)

KEYS = (
    "model",
    "parameters",
    "value",
    "bounds",
    "optimizer",
    "params",
    "state",
    "tau_c",
    "velocity",
    "centers",
    "widths",
    "x",
    "",
    "\ud800",
)


def samples() -> FrictionSamples:
    """Noisy samples over velocity, two loads and two temperatures, both directions."""
    rng = np.random.default_rng(0)
    v = np.tile(np.concatenate([np.geomspace(0.01, 2, 12), -np.geomspace(0.01, 2, 12)]), 2)
    load = np.repeat([0.0, 1.0], 24)
    temp = np.where(np.arange(48) % 3, 25.0, 40.0)
    f = (0.1 + 0.02 * load) * np.sign(v) + 0.05 * v + 0.001 * rng.standard_normal(48)
    return FrictionSamples(velocity=v, load=load, temperature=temp, friction=f, source="fuzz")


def v1_file(family: str) -> Path:
    """The schema-version-1 file of a family of :data:`V1_FAMILIES`."""
    return V1_FILES / f"{family.removesuffix('_v1')}.json"


def valid_models() -> dict[str, FittedModel]:
    """One model of every family in :data:`FAMILIES` (fitted, or read from version 1)."""
    s = samples()
    fitted = [name for name in FAMILIES if name != "rbf" and name not in V1_FAMILIES]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # a short budget: the files need the fields of a fit, not its best optimum
        out = {name: fit(s, name, max_evals=1500) for name in fitted}
        # one network (the forward direction: symmetry "pos"), so that the state's arrays
        # sit at its top level where the tests damage them; per-direction states hold two
        out["rbf"] = fit_rbf(s.subset(s.direction == 1), n_centers=8, trainer="lsq", random_state=0)
    out.update({name: FittedModel.load(v1_file(name)) for name in V1_FAMILIES})
    return out


def write_valid(folder: Path) -> dict[str, Path]:
    """The model files of :func:`valid_models` in ``folder``, by family (the version-1 files
    copied as they are)."""
    out = {}
    for name, m in valid_models().items():
        path = folder / f"{name}.json"
        if name in V1_FAMILIES:
            path.write_bytes(v1_file(name).read_bytes())
        else:
            m.save(path)
        out[name] = path
    return out


# -- mutations -----------------------------------------------------------------------------


def dumps(doc: Any) -> bytes:
    """JSON of ``doc`` with every :class:`Raw` written as it is."""
    raws: list[str] = []

    def swap(value: Any) -> Any:
        if isinstance(value, Raw):
            raws.append(str(value))
            return f"@@RAW{len(raws) - 1}@@"
        if isinstance(value, dict):
            return {k: swap(v) for k, v in value.items()}
        if isinstance(value, list):
            return [swap(v) for v in value]
        return value

    text = json.dumps(swap(doc), allow_nan=True)
    for i, raw in enumerate(raws):
        text = text.replace(f'"@@RAW{i}@@"', raw, 1)
    return text.encode("utf-8", "surrogatepass")


def paths(doc: Any) -> list[tuple[Any, ...]]:
    """Every path (keys and indices) into ``doc``, the root included."""
    out: list[tuple[Any, ...]] = []
    stack: list[tuple[Any, tuple[Any, ...]]] = [(doc, ())]
    while stack:
        value, path = stack.pop()
        out.append(path)
        if isinstance(value, dict):
            stack.extend((v, (*path, k)) for k, v in value.items())
        elif isinstance(value, list):
            stack.extend((v, (*path, i)) for i, v in enumerate(value[:50]))
    return sorted(out, key=str)


def random_value(rng: random.Random, depth: int = 0) -> Any:
    """A random JSON value: hostile numbers and texts, wrong types, containers."""
    kind = rng.choice(("number", "number", "text", "bool", "null", "list", "dict", "float"))
    if depth > 3 and kind in ("list", "dict"):
        kind = "number"
    if kind == "number":
        return rng.choice(NUMBERS)
    if kind == "float":
        return rng.uniform(-1e3, 1e3) * 10 ** rng.randint(-5, 5)
    if kind == "text":
        return rng.choice(TEXTS)
    if kind == "bool":
        return rng.random() < 0.5
    if kind == "null":
        return None
    if kind == "list":
        return [random_value(rng, depth + 1) for _ in range(rng.randint(0, 4))]
    return {rng.choice(KEYS): random_value(rng, depth + 1) for _ in range(rng.randint(0, 3))}


def _set(doc: Any, path: tuple[Any, ...], value: Any) -> Any:
    if not path:
        return value
    parent = doc
    for key in path[:-1]:
        parent = parent[key]
    parent[path[-1]] = value
    return doc


def _delete(doc: Any, path: tuple[Any, ...]) -> Any:
    if not path:
        return {}
    parent = doc
    for key in path[:-1]:
        parent = parent[key]
    del parent[path[-1]]
    return doc


def _container(doc: Any, rng: random.Random) -> tuple[Any, ...]:
    choices = [p for p in paths(doc) if isinstance(_get(doc, p), dict | list)]
    return rng.choice(choices)


def _get(doc: Any, path: tuple[Any, ...]) -> Any:
    for key in path:
        doc = doc[key]
    return doc


def mutate(
    data: bytes,
    rng: random.Random,
    kind: str | None = None,
    huge: tuple[int, ...] = (1000, 100_001, 1_000_001),
) -> bytes:
    """A hostile variant of the model file ``data`` (``kind`` from :data:`KINDS`; a huge
    array has one of the lengths ``huge``)."""
    kind = kind or rng.choice(KINDS)
    if kind == "flip":
        out = bytearray(data)
        for _ in range(rng.randint(1, 8)):
            out[rng.randrange(len(out))] = rng.randrange(256)
        return bytes(out)
    if kind == "truncate":
        return data[: rng.randrange(len(data))]
    if kind == "insert":
        at = rng.randrange(len(data) + 1)
        junk = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
        return data[:at] + rng.choice((junk, b"[" * 200, b"{", b"]", b'"', b"\\", b",")) + data[at:]
    if kind == "non_utf8":
        at = data.find(b'"', rng.randrange(len(data)))
        at = at + 1 if at >= 0 else 0
        bad = rng.choice((b"\xff", b"\xc3(", b"\xe9", b"\xed\xa0\x80", b"\xf8\x88\x80\x80\x80"))
        return data[:at] + bad + data[at:]
    doc = json.loads(data)
    if kind in ("value", "number", "swap"):
        path = rng.choice(paths(doc))
        if kind == "value":
            value = random_value(rng)
        elif kind == "number":
            value = rng.choice(NUMBERS)
        else:  # another field's value, of the right look but the wrong place
            value = _get(doc, rng.choice(paths(doc)))
            value = json.loads(json.dumps(value))
        doc = _set(doc, path, value)
    elif kind == "delete":
        doc = _delete(doc, rng.choice(paths(doc)))
    elif kind == "add_key":
        path = _container(doc, rng)
        target = _get(doc, path)
        value = random_value(rng)
        if isinstance(target, dict):
            target[rng.choice(KEYS)] = value
        else:
            target.insert(rng.randint(0, len(target)), value)
    elif kind == "deep":  # written as text: building it would recurse here too
        n = rng.choice((30, 70, 500, 5000))
        opening, closing = rng.choice((("[", "]"), ('{"a": ', "}")))
        doc = _set(doc, rng.choice(paths(doc)), Raw(opening * n + "0" + closing * n))
    elif kind == "huge":
        n = rng.choice(huge)
        value = [rng.choice((0.5, 1, "x", None))] * n
        doc = _set(doc, rng.choice(paths(doc)), value)
    return dumps(doc)


# -- outcomes ------------------------------------------------------------------------------


def grid(fitted: FittedModel, n: int = 7) -> np.ndarray:
    """Inputs (k, 3) on an ``n``-point grid over the operating range (defaults without)."""
    axes = []
    defaults = {"velocity": (-1.0, 1.0), "load": (0.0, 0.0), "temperature": (25.0, 25.0)}
    for name in ("velocity", "load", "temperature"):
        low, high = fitted.operating_range.get(name, defaults[name])
        axes.append(np.unique(np.concatenate([np.linspace(low, high, n), [low / 3 + high / 7]])))
    mesh = np.meshgrid(*axes, indexing="ij")
    return np.column_stack([m.ravel() for m in mesh])


def _one_line_naming(message: str, path: Path) -> bool:
    return "\n" not in message.strip() and str(path) in message


def classify(path: Path) -> tuple[str, str]:
    """Load ``path`` through the API and classify the outcome (see the module notes)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            fitted = FittedModel.load(path)
    except FricidError as exc:
        if not str(exc).startswith(str(path)) or not _one_line_naming(str(exc), path):
            return "traceback", f"message not one line naming the file: {exc!r}"
        return "error", str(exc)
    except Exception as exc:
        return "traceback", f"{type(exc).__name__}: {exc}"[:300]
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            y = fitted.predict(grid(fitted))
            fitted.report()
            again = FittedModel.from_dict(json.loads(json.dumps(fitted.to_dict())), "again")
    except Exception as exc:
        return "traceback", f"after loading: {type(exc).__name__}: {exc}"[:300]
    if not np.isfinite(y).all():
        return "wrong", "non-finite prediction on the operating range"
    if again.model != fitted.model:
        return "wrong", "the model does not survive saving"
    return "valid", fitted.model


runner = CliRunner()


def classify_cli(path: Path, command: str, out: Path) -> tuple[str, str]:
    """Run ``fricid predict`` or ``fricid export`` on ``path`` and classify the outcome."""
    loads = True
    try:
        span = FittedModel.load(path).operating_range
    except FricidError:
        loads, span = False, {}
    rng = {k: span.get(k, [d, d]) for k, d in (("load", 0), ("temperature", 25))}
    v = span.get("velocity", [-1.0, 1.0])
    if command == "predict":
        args = ["predict", str(path), "--load", repr(rng["load"][1]), "--temperature"]
        args += [repr(rng["temperature"][0])]
        for x in (v[0], v[1], v[0] / 2 + v[1] / 2):
            args += ["--velocity", repr(float(x))]
    else:
        args = ["export", str(path), "--to", command, "--out", str(out)]
    res = runner.invoke(app, args)
    if res.exception is not None and not isinstance(res.exception, SystemExit):
        return "traceback", f"{type(res.exception).__name__}: {res.exception}"[:300]
    if res.exit_code == 2:
        lines = [line for line in res.output.splitlines() if line.startswith("error:")]
        # a file that does not load: the line names it; a model that loads may still be
        # refused by the command (an export that cannot represent it), in one line
        if len(lines) != 1 or (not loads and str(path) not in lines[0]):
            return "traceback", f"exit 2 without one error line naming the file: {res.output!r}"
        return "error", lines[0]
    if res.exit_code != 0:
        return "traceback", f"exit {res.exit_code}: {res.output[:300]!r}"
    if command == "predict":
        rows = [r.split(",") for r in res.stdout.splitlines() if r and not r.startswith("#")]
        try:
            values = np.array([[float(x) for x in r] for r in rows[1:]], dtype=float)
        except ValueError:
            return "wrong", f"predict printed something else: {res.stdout[:200]!r}"
        if values.size == 0 or not np.isfinite(values).all():
            return "wrong", f"predict printed non-finite numbers: {res.stdout[:200]!r}"
    return "valid", command
