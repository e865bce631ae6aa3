"""Checks anyone can run (issue 10, "Done when"): every module imports on its own, no module is
over 500 lines without a reason in its docstring, and ``src/`` holds no copied block over 10
lines.
"""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from collections import defaultdict
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from _source import ROOT, SRC, docstring_lines, import_lines, modules, tree

# --------------------------------------------------------------------------- isolated imports

#: Run in a fresh interpreter: load the third-party packages fricid uses (so each child does not
#: pay for them again), then fork one child per fricid module, two at a time; the child imports
#: that module into an interpreter where nothing of fricid is loaded yet, and reports its
#: traceback (its last 32 kB, which fit in the pipe).
_FORK_IMPORTS = r"""
import gc, importlib, json, os, sys, traceback
preload, names = json.loads(sys.argv[1]), json.loads(sys.argv[2])
for name in preload:
    try:
        importlib.import_module(name)
    except Exception:  # the child that needs it reports the error
        pass
gc.collect()
gc.freeze()  # the children's collector leaves the parent's objects (and pages) alone
assert not [m for m in sys.modules if m == "fricid" or m.startswith("fricid.")]
failures, running, queue = {}, {}, list(reversed(names))
while queue or running:
    while queue and len(running) < 2:
        name = queue.pop()
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:
            os.close(r)
            code = 0
            try:
                importlib.import_module(name)
            except BaseException:
                os.write(w, traceback.format_exc()[-32000:].encode())
                code = 1
            os._exit(code)
        os.close(w)
        running[pid] = (name, r)
    pid, status = os.wait()
    name, r = running.pop(pid)
    with os.fdopen(r, "rb") as pipe:
        error = pipe.read().decode(errors="replace")
    if status:
        failures[name] = error or f"exit status {status}"
print(json.dumps(failures))
"""


def _environment() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(SRC), *filter(None, [env.get("PYTHONPATH")])])
    env["MPLBACKEND"] = "Agg"
    return env


def third_party_imports() -> list[str]:
    """Every absolute import of another package in fricid's source (``numpy``, ``scipy.optimize``,
    ...), for the parent to load once."""
    names: set[str] = set()
    for module in modules():
        for node in ast.walk(tree(module.path)):
            if isinstance(node, ast.Import):
                names.update(alias.name for alias in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                names.add(node.module)
    return sorted(n for n in names if n.split(".")[0] != ROOT and n != "__future__")


def import_alone(
    names: list[str], *, fork: bool = hasattr(os, "fork"), preload: list[str] | None = None
) -> dict[str, str]:
    """Import each module in an interpreter where nothing of fricid is loaded yet.

    Where ``os.fork`` exists, one fresh interpreter loads the third-party packages and forks a
    child per module, two at a time (the whole package in about 10 s of CPU); elsewhere
    (``fork=False``) one ``python -c "import ..."`` per module, two at a time. ``preload``: the
    packages the parent loads (default: every third-party import of fricid). Returns module ->
    error text for those that fail.
    """
    env = _environment()
    if fork:
        preload = third_party_imports() if preload is None else preload
        cmd = [sys.executable, "-c", _FORK_IMPORTS, json.dumps(preload), json.dumps(names)]
        done = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)
        assert done.returncode == 0, done.stderr
        return json.loads(done.stdout.strip().splitlines()[-1])

    def run_one(name: str) -> tuple[str, str]:
        cmd = [sys.executable, "-c", f"import {name}"]
        done = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)
        return name, (done.stderr if done.returncode else "")

    with ThreadPoolExecutor(2) as pool:
        return {name: err for name, err in pool.map(run_one, names) if err}


@pytest.mark.parametrize("fork", [False, *([True] if hasattr(os, "fork") else [])])
def test_import_alone_reports_the_error(tmp_path, monkeypatch, fork):
    """The checker itself: a module that fails to import is reported with its error."""
    (tmp_path / "fricid_bad_probe.py").write_text("import fricid\nraise ImportError('boom')\n")
    (tmp_path / "fricid_good_probe.py").write_text("import fricid.errors\n")
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))
    failures = import_alone(["fricid_good_probe", "fricid_bad_probe"], fork=fork, preload=[])
    assert list(failures) == ["fricid_bad_probe"]
    assert "ImportError: boom" in failures["fricid_bad_probe"]


@pytest.mark.slow  # 37 s measured under load (default run kept short)
def test_every_module_imports_in_isolation():
    """``python -c "import fricid.x.y"`` for every module: no module relies on another having
    been imported first (cycles, registration order, missing imports)."""
    failures = import_alone([m.name for m in modules()])
    assert not failures, "\n\n".join(f"import {k} fails:\n{v}" for k, v in sorted(failures.items()))


# --------------------------------------------------------------------------- module size

MAX_LINES = 500
#: The phrase a module's docstring uses to say why it is longer.
REASON = "longer than 500 lines because"


def oversized() -> list[str]:
    """Modules over :data:`MAX_LINES` lines whose docstring gives no reason."""
    out = []
    for module in modules():
        n = len(module.path.read_text(encoding="utf-8").splitlines())
        doc = ast.get_docstring(tree(module.path)) or ""
        if n > MAX_LINES and REASON not in " ".join(doc.split()):
            out.append(f"{module.rel}: {n} lines")
    return out


def test_no_module_over_500_lines_without_a_reason():
    """A module over 500 lines says why in its docstring ("... longer than 500 lines because
    ..."); otherwise it is split."""
    bad = oversized()
    assert not bad, (
        f"{len(bad)} modules over {MAX_LINES} lines with no '{REASON}' in the docstring:\n"
        + "\n".join(bad)
    )


# --------------------------------------------------------------------------- copied blocks

#: A copied block is this many significant lines or more ("no copied block over 10 lines").
WINDOW = 11


def significant_lines(path: Path) -> list[tuple[int, str]]:
    """(line number, normalised text) of the lines that count: no blank lines, comments,
    imports or docstrings; whitespace and trailing comments removed."""
    skip = docstring_lines(path) | import_lines(path)
    out = []
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        text = line.split("  #", 1)[0].strip()
        if number in skip or not text or text.startswith("#"):
            continue
        out.append((number, " ".join(text.split())))
    return out


def copied_blocks(paths: list[Path], window: int = WINDOW) -> list[tuple[str, str, int]]:
    """Places where ``window`` or more significant lines stand again, as (first place, second
    place, number of significant lines); a place is ``file:first-last``.

    Every run of ``window`` consecutive significant lines is hashed; two runs with the same
    text are a copy (in different files, or in one file where they do not overlap), and
    consecutive matching runs merge into one block.
    """
    lines = {p: significant_lines(p) for p in paths}
    seen: dict[tuple[str, ...], list[tuple[Path, int]]] = defaultdict(list)
    for path, rows in lines.items():
        for i in range(len(rows) - window + 1):
            seen[tuple(text for _, text in rows[i : i + window])].append((path, i))
    pairs: set[tuple[Path, int, Path, int]] = set()
    for places in seen.values():
        for a in range(len(places)):
            for b in range(a + 1, len(places)):
                (pa, ia), (pb, ib) = places[a], places[b]
                if pa != pb or abs(ia - ib) >= window:
                    pairs.add((pa, ia, pb, ib))
    blocks = []
    for pa, ia, pb, ib in sorted(pairs, key=lambda t: (str(t[0]), t[1], str(t[2]), t[3])):
        if (pa, ia - 1, pb, ib - 1) in pairs:
            continue  # inside a block that started earlier
        n = window
        while (pa, ia + n - window + 1, pb, ib + n - window + 1) in pairs:
            n += 1
        blocks.append((_place(pa, lines[pa], ia, n), _place(pb, lines[pb], ib, n), n))
    return blocks


def _place(path: Path, rows: list[tuple[int, str]], first: int, n: int) -> str:
    """``file:first-last`` of ``n`` significant lines from row ``first``."""
    name = path.relative_to(SRC.parent).as_posix() if path.is_relative_to(SRC.parent) else path
    return f"{name}:{rows[first][0]}-{rows[first + n - 1][0]}"


def test_copied_blocks_are_found_across_and_within_files(tmp_path):
    body = "\n".join(f"x{i} = compute({i}, 'a')  # note" for i in range(12))
    (tmp_path / "a.py").write_text(f'"""Doc."""\nimport os\n\n{body}\n', encoding="utf-8")
    (tmp_path / "b.py").write_text(f"import sys\n# another\ny = 1\n{body}\n", encoding="utf-8")
    (tmp_path / "c.py").write_text("\n".join(body.splitlines()[:10]) + "\n", encoding="utf-8")
    found = copied_blocks(sorted(tmp_path.glob("*.py")))
    assert [(a.split("/")[-1], b.split("/")[-1], n) for a, b, n in found] == [
        ("a.py:4-15", "b.py:4-15", 12)
    ]  # c.py shares only 10 lines: allowed


@pytest.mark.slow  # 3 s measured under load (default run kept short)
def test_no_copied_block_over_10_lines():
    """No run of more than 10 significant lines (ignoring blank lines, comments, imports and
    docstrings) stands twice in ``src/``: such code is shared, not copied."""
    found = copied_blocks([m.path for m in modules()])
    assert not found, f"{len(found)} copied blocks of {WINDOW}+ lines in src/:\n" + "\n".join(
        f"{a} ~ {b} ({n} lines)" for a, b, n in found
    )


@pytest.mark.parametrize("path", ["src", "tests", "benchmarks"])
def test_no_absolute_machine_paths(path):
    """Code finds data relative to the repository (``../shared/data/real``), never by a path
    that exists only on one machine."""
    root = SRC.parent / path
    here = Path(__file__).resolve()
    needles = ("/" + "work/", "/" + "tmp/", "/" + "home/")
    bad = [
        f"{p.relative_to(SRC.parent)}:{n}: {line.strip()}"
        for p in sorted(root.rglob("*.py"))
        if p.resolve() != here
        for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), start=1)
        if any(needle in line for needle in needles)
    ]
    assert not bad, "\n".join(bad)


# ------------------------------------------------------------------ public scikit-learn API only


def private_sklearn_imports(source: str) -> list[str]:
    """The private scikit-learn modules or names a source imports: an ``import`` or
    ``from ... import`` (at any depth: in functions, ``try`` blocks) or an
    ``importlib.import_module`` / ``__import__`` call with a constant name, any of whose parts
    after ``sklearn`` begins with ``_`` (dunders such as ``__version__`` excepted)."""

    def private(dotted: str) -> bool:
        head, *rest = dotted.split(".")
        return head == "sklearn" and any(
            p.startswith("_") and not (p.startswith("__") and p.endswith("__")) for p in rest
        )

    found = []
    for node in ast.walk(ast.parse(source)):
        names: list[str] = []
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
            names = [f"{node.module}.{alias.name}" for alias in node.names]
        elif isinstance(node, ast.Call) and node.args:
            func = node.func
            called = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            arg = node.args[0]
            if called in ("import_module", "__import__") and isinstance(arg, ast.Constant):
                names = [str(arg.value)]
        found += [f"line {node.lineno}: {n}" for n in names if private(n)]
    return found


def test_the_private_sklearn_import_check_finds_each_form():
    source = (
        "from sklearn.utils._param_validation import Interval\n"
        "def f():\n"
        "    from sklearn.cluster._kmeans import _kmeans_single_lloyd\n"
        "    from sklearn.utils import _openmp_helpers\n"
        "    import sklearn._config\n"
        "    importlib.import_module('sklearn.cluster._kmeans')\n"
        "from sklearn.cluster import KMeans\n"
        "from sklearn import __version__\n"
        "import sklearn.utils.validation\n"
    )
    assert [f.split(": ")[1] for f in private_sklearn_imports(source)] == [
        "sklearn.utils._param_validation.Interval",
        "sklearn.cluster._kmeans._kmeans_single_lloyd",
        "sklearn.utils._openmp_helpers",
        "sklearn._config",
        "sklearn.cluster._kmeans",
    ]


def test_src_uses_public_sklearn_api_only():
    """fricid allows a range of scikit-learn releases (pyproject.toml); a private module can
    change or vanish in any of them, so ``src/`` imports none."""
    bad = [
        f"{m.rel}: {hit}"
        for m in modules()
        for hit in private_sklearn_imports(m.path.read_text(encoding="utf-8"))
    ]
    assert not bad, "\n".join(bad)
