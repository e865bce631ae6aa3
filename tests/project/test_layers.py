"""DESIGN.md's layer table, enforced: who may import whom, and no import cycle between units.

The table ("Layout" in ``../shared/DESIGN.md``) is encoded below as data, bottom of the stack
first. A *unit* is a top-level module or package of fricid (``models``, ``fitted``, ...). A unit
may import the units its row's "may import" column names; a name there stands for itself and
for everything it may import in turn, and "X and below" adds every row lower in the stack than
X's row. Never a row higher in the stack, never a unit of the same row unless the table says so
(:data:`SIDEWAYS`); ``cli/`` may import anything. Every import counts: at the top of a module,
inside a function (lazy), under ``if TYPE_CHECKING:``, and static ``importlib.import_module``
calls; relative imports resolved (see ``_source.py``).

Both tests fail with one line per offending import (file, line, importing module, imported
module, rule), so the list says what is left to move.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from functools import cache

import pytest

from _source import ROOT, Import, Module, imports, modules, tree, unit

#: The table's rows, bottom of the stack (top of DESIGN.md's table) first.
ROWS: tuple[tuple[str, ...], ...] = (
    ("units", "errors", "metrics", "_jit"),
    ("samples",),
    ("io",),
    ("models",),
    ("optim",),
    ("robot",),
    ("extract",),
    ("sim",),
    ("fitted",),
    ("identify",),
    ("workflow",),
    ("experiments",),
    ("report", "export", "control"),
    ("fleet",),
    ("cli",),
)

#: Today's or older names of a unit (DESIGN.md: ``workflow.py``, today ``pipeline.py``).
ALIASES = {"pipeline": "workflow"}

#: The "may import" column: (names, "and below"). Units absent here may import nothing of fricid.
MAY_IMPORT: dict[str, tuple[tuple[str, ...], bool]] = {
    "units": (("errors",), False),
    "errors": ((), False),
    "metrics": ((), False),
    "_jit": ((), False),  # numba's compilers with the cache fallback
    "samples": (("units", "errors"), False),
    "io": (("samples",), True),
    "models": (("units", "errors", "_jit"), False),
    "optim": (("errors", "_jit"), False),
    # a whole arm's rigid-body dynamics from its (checked) URDF, by Pinocchio
    "robot": (("io", "units", "errors"), False),
    "extract": (("samples", "io", "units", "errors", "robot"), False),
    "sim": (("samples", "models", "robot"), False),
    "fitted": (("models", "samples", "metrics", "io"), False),
    "identify": (("fitted", "models", "optim", "samples", "metrics", "robot"), False),
    "workflow": (("identify", "extract", "io"), True),
    "experiments": (("workflow",), True),
    "report": (("experiments", "control"), True),  # "report may show control's results"
    "export": (("experiments",), True),
    "control": (("experiments",), True),
    "fleet": (("workflow", "report"), True),
}

#: Imports within a row that the table allows.
SIDEWAYS = {("units", "errors"), ("report", "control")}

#: ``cli/`` may import anything.
ANYTHING = {"cli"}

ROW_OF = {name: i for i, row in enumerate(ROWS) for name in row}


def canonical(name: str) -> str:
    """A unit's name in the table (``pipeline`` -> ``workflow``)."""
    return ALIASES.get(name, name)


@cache
def allowed(name: str) -> frozenset[str]:
    """The units ``name`` may import (its own unit and the package root always)."""
    names, and_below = MAY_IMPORT.get(name, ((), False))
    out = {name, ROOT, *names}
    for other in names:
        out |= allowed(other)
    if and_below and names:
        top = max(ROW_OF[n] for n in names)
        out |= {u for row in ROWS[:top] for u in row}
    return frozenset(out)


def rule(name: str) -> str:
    """The rule of one unit, as the failure message quotes it."""
    if name in ANYTHING:
        return f"{name}: anything"
    names, and_below = MAY_IMPORT.get(name, ((), False))
    said = ", ".join(names) or "nothing of fricid"
    return f"{name} may import {said}{' and below' if and_below else ''}"


def edges() -> list[tuple[str, str, Import, str]]:
    """(importing unit, imported unit, the import, file) for every import between units."""
    out = []
    for module in modules():
        here = canonical(unit(module.name))
        for imp in imports(module):
            there = canonical(unit(imp.target))
            if there != here:
                out.append((here, there, imp, module.rel))
    return out


def describe(imp: Import, rel: str) -> str:
    return f"{rel}:{imp.line}: {imp.module} imports {imp.target}"


def test_the_encoded_table_is_consistent_with_its_own_rule():
    """Every unit the table lets a row import lies lower in the stack, or is a declared
    sideways import; every unit of the table has a rule."""
    assert set(MAY_IMPORT) | ANYTHING == set(ROW_OF)
    wrong = [
        (name, other)
        for name in MAY_IMPORT
        for other in allowed(name) - {name, ROOT}
        if ROW_OF[other] > ROW_OF[name]
        or (ROW_OF[other] == ROW_OF[name] and (name, other) not in SIDEWAYS)
    ]
    assert not wrong


def test_every_unit_is_in_the_table():
    """A new top-level module or package must be placed in DESIGN.md's table (and here)."""
    units = {canonical(unit(m.name)) for m in modules()} - {ROOT}
    assert not units - set(ROW_OF), f"units missing from the layer table: {units - set(ROW_OF)}"


def test_the_package_root_imports_nothing_of_fricid():
    """Every module may import ``fricid`` itself, so it must stay below everything."""
    root = [m for m in modules() if m.name == ROOT]
    bad = [describe(i, m.rel) for m in root for i in imports(m) if i.target != ROOT]
    assert not bad, "\n".join(bad)


def test_imports_follow_the_layer_table():
    """No import reaches a row higher in the stack or sideways (DESIGN.md, "Layout")."""
    bad = [
        f"{describe(imp, rel)}  [{rule(here)}]"
        for here, there, imp, rel in sorted(edges(), key=lambda e: (e[3], e[2].line))
        if here in ROW_OF and here not in ANYTHING and there not in allowed(here)
    ]
    assert not bad, f"{len(bad)} imports break DESIGN.md's layer table:\n" + "\n".join(bad)


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one unit (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_imports_are_found_lazy_type_checking_relative_and_dynamic(tmp_path):
    path = tmp_path / "fake.py"
    path.write_text(
        "from typing import TYPE_CHECKING\n"
        "import numpy\n"
        "from . import get_model\n"
        "from ..errors import ConfigError\n"
        "if TYPE_CHECKING:\n"
        "    from ..fitted import FittedModel\n"
        "def f():\n"
        "    import importlib\n"
        "    from fricid.optim import minimize\n"
        "    return importlib.import_module(f'{__package__}.elsewhere')\n",
        encoding="utf-8",
    )
    got = [(i.line, i.target) for i in imports(Module("fricid.models.fake", path, False))]
    assert got == [
        (3, "fricid.models"),
        (4, "fricid.errors"),
        (6, "fricid.fitted"),
        (9, "fricid.optim"),
        (10, "fricid.models.elsewhere"),
    ]


def test_cycles_finds_a_cycle_and_passes_a_dag():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": {"c"}, "d": {"a", "c"}}) == []


def _assert_acyclic(graph: dict[str, set[str]], where: dict[tuple[str, str], list[str]]) -> None:
    """Fail with every import of every cycle in ``graph`` (``where`` says where each edge is)."""
    found = cycles(graph)
    lines = []
    for component in found:
        lines.append(f"cycle between {', '.join(component)}:")
        for a in component:
            for b in component:
                lines += [f"  {line}" for line in where.get((a, b), ())]
    assert not found, "\n".join(lines)


def test_no_import_cycle_between_units():
    """No cycle between fricid's top-level units, lazy imports included."""
    graph: dict[str, set[str]] = defaultdict(set)
    where: dict[tuple[str, str], list[str]] = defaultdict(list)
    for here, there, imp, rel in edges():
        if there != ROOT:
            graph[here].add(there)
            where[here, there].append(describe(imp, rel))
    _assert_acyclic(graph, where)


def test_no_import_cycle_between_modules():
    """No cycle between any two modules either (a package counts as its ``__init__``), lazy
    imports included: a cycle inside a unit hides a module in the wrong place. An
    ``importlib.import_module(f"{__package__}.{name}")`` (the CLI's command registry) imports
    a submodule, not the package: :func:`imports` reads it as the package, so it is left out."""
    graph: dict[str, set[str]] = defaultdict(set)
    where: dict[tuple[str, str], list[str]] = defaultdict(list)
    for module in modules():
        lines = module.path.read_text(encoding="utf-8").splitlines()
        for imp in imports(module):
            submodule = (
                module.name.startswith(imp.target + ".")
                and "import_module(" in (lines[imp.line - 1])
            )
            if imp.target not in (module.name, ROOT) and not submodule:
                graph[module.name].add(imp.target)
                where[module.name, imp.target].append(describe(imp, module.rel))
    _assert_acyclic(graph, where)


@pytest.mark.parametrize(
    ("name", "other", "ok"),
    [
        ("units", "errors", True),
        ("errors", "units", False),
        ("models", "samples", False),
        ("models", "optim", False),
        ("fitted", "io", True),
        ("identify", "io", True),  # through fitted
        ("workflow", "sim", True),  # "and below"
        ("experiments", "report", False),
        ("report", "control", True),
        ("export", "control", False),
        ("control", "export", False),
        ("fleet", "report", True),
        ("fleet", "export", False),
        ("optim", "models", False),
    ],
)
def test_rules_read_as_design_md_says(name, other, ok):
    assert (other in allowed(name)) is ok


#: The modules that compute validation, the measurement scatter and the trust verdict: the
#: identification layer's (DESIGN.md: "validation, scatter and the trust verdict, computed
#: here once"), which report/ renders and never runs.
VALIDATION_MODULES = frozenset(
    f"{ROOT}.identify.{name}"
    for name in (
        "validate",
        "_scatter",
        "_heldout",
        "_advice",
        "static.select",
        "learned._trust",
    )
)

#: Functions whose call computes a validation, a scatter or a verdict.
VALIDATION_CALLS = frozenset(
    {
        "validate",
        "measurement_scatter",
        "assess_trust",
        "run_validation",
        "misfit_advice",
        "interior_rmse",
        "cv_validation",
    }
)


def _called_names(module: Module) -> list[tuple[int, str]]:
    """(line, name) of every call by a plain or attribute name in one module."""
    found = []
    for node in ast.walk(tree(module.path)):
        if isinstance(node, ast.Call):
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)
            if name:
                found.append((node.lineno, name))
    return found


def report_modules() -> list[Module]:
    return [
        m for m in modules() if m.name == f"{ROOT}.report" or m.name.startswith(f"{ROOT}.report.")
    ]


def test_report_imports_no_validation():
    """report/ renders the trust record (fricid.identify.trust) and never computes a
    validation, a scatter or a verdict: it imports none of the modules that do, and calls
    none of their functions."""
    assert report_modules()
    bad = [
        describe(imp, m.rel)
        for m in report_modules()
        for imp in imports(m)
        if imp.target in VALIDATION_MODULES
    ]
    bad += [
        f"{m.rel}:{line}: calls {name}()"
        for m in report_modules()
        for line, name in _called_names(m)
        if name in VALIDATION_CALLS
    ]
    assert not bad, "report/ computes validation:\n" + "\n".join(bad)


def test_report_validation_check_finds_an_offender(tmp_path):
    path = tmp_path / "bad.py"
    path.write_text(
        "from ..identify.validate import measurement_scatter\n"
        "def f(s):\n"
        "    return measurement_scatter(s)\n",
        encoding="utf-8",
    )
    module = Module("fricid.report.bad", path, False)
    assert [i.target for i in imports(module)] == ["fricid.identify.validate"]
    assert (3, "measurement_scatter") in _called_names(module)
