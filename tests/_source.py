"""Reading fricid's own source for the structure tests (layers, isolated imports, size, copies).

Not a test module: ``test_layers.py`` and ``test_hygiene.py`` import it (pytest puts ``tests/``
on ``sys.path``). Everything here reads files as text and parses them with :mod:`ast`; nothing
of fricid is imported.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from functools import cache
from pathlib import Path

#: The repository's root and its ``src/fricid`` package.
REPO = Path(__file__).resolve().parents[1]
SRC = REPO / "src"
PACKAGE = SRC / "fricid"
ROOT = "fricid"


@dataclass(frozen=True)
class Module:
    """One module of fricid: its dotted name, its file and whether it is a package."""

    name: str
    path: Path
    is_package: bool

    @property
    def rel(self) -> str:
        """The file's path relative to the repository (for messages)."""
        return self.path.relative_to(REPO).as_posix()


@dataclass(frozen=True)
class Import:
    """One import statement (or ``importlib.import_module`` call) and what it resolves to."""

    module: str
    line: int
    target: str


@cache
def modules() -> tuple[Module, ...]:
    """Every module of fricid, found on disk (``__init__.py`` names its package)."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(SRC).with_suffix("").parts
        is_package = parts[-1] == "__init__"
        if is_package:
            parts = parts[:-1]
        found.append(Module(".".join(parts), path, is_package))
    return tuple(found)


@cache
def module_names() -> frozenset[str]:
    """The dotted names of every module and package of fricid."""
    return frozenset(m.name for m in modules())


@cache
def tree(path: Path) -> ast.Module:
    """The parsed source of one file."""
    return ast.parse(path.read_text(encoding="utf-8"), filename=str(path))


def _base(module: Module, level: int) -> str:
    """The package a relative import of ``level`` dots starts from."""
    package = module.name if module.is_package else module.name.rpartition(".")[0]
    parts = package.split(".")
    if level - 1 >= len(parts):
        raise ValueError(f"{module.rel}: relative import beyond the top-level package")
    return ".".join(parts[: len(parts) - (level - 1)])


def _join(base: str, name: str | None) -> str:
    return f"{base}.{name}" if name and base else (name or base)


def _dynamic_target(module: Module, call: ast.Call) -> str | None:
    """The module an ``importlib.import_module(...)`` call names, as far as it is static.

    A constant string resolves fully; an f-string resolves up to its first part that is not
    ``__package__``, ``__name__`` or a constant (so ``f"{__package__}.{name}"`` counts as an
    import of the package itself).
    """
    func = call.func
    name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)
    if name != "import_module" or not call.args:
        return None
    own = {
        "__name__": module.name,
        "__package__": module.name if module.is_package else module.name.rpartition(".")[0],
    }

    def static(node: ast.expr) -> str | None:
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            return node.value
        if isinstance(node, ast.Name) and node.id in own:
            return own[node.id]
        if isinstance(node, ast.FormattedValue):
            return static(node.value)
        return None

    arg = call.args[0]
    parts = arg.values if isinstance(arg, ast.JoinedStr) else [arg]
    text = ""
    for part in parts:
        value = static(part)
        if value is None:
            break
        text += value
    if text.startswith("."):
        anchor = static(call.args[1]) if len(call.args) > 1 else None
        if anchor is None:
            return None
        level = len(text) - len(text.lstrip("."))
        packages = anchor.split(".")
        text = _join(".".join(packages[: len(packages) - (level - 1)]), text[level:])
    return text.rstrip(".") or None


def imports(module: Module) -> list[Import]:
    """Every import of fricid in one module: top level, inside functions, under
    ``if TYPE_CHECKING:``, in ``try`` blocks, and static ``importlib.import_module`` calls;
    relative imports resolved. ``from pkg import name`` counts as an import of
    ``pkg.name`` where that is a module of fricid, else of ``pkg``.
    """
    names = module_names()
    found: list[Import] = []
    for node in ast.walk(tree(module.path)):
        targets: list[str] = []
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = _join(_base(module, node.level), node.module) if node.level else node.module
            base = base or ""
            for alias in node.names:
                sub = _join(base, alias.name)
                targets.append(sub if sub in names else base)
        elif isinstance(node, ast.Call):
            target = _dynamic_target(module, node)
            targets = [target] if target else []
        for target in targets:
            if target == ROOT or target.startswith(ROOT + "."):
                found.append(Import(module.name, node.lineno, target))
    return sorted(set(found), key=lambda i: (i.line, i.target))


def unit(name: str) -> str:
    """The top-level unit of a dotted name: ``fricid.models.rbf`` -> ``models``; the package
    root itself -> ``fricid``."""
    parts = name.split(".")
    return parts[1] if len(parts) > 1 else parts[0]


def docstring_lines(path: Path) -> set[int]:
    """The line numbers of every string statement (module, class and function docstrings, and
    bare string literals used as comments) in one file."""
    lines: set[int] = set()
    for node in ast.walk(tree(path)):
        if (
            isinstance(node, ast.Expr)
            and isinstance(node.value, ast.Constant)
            and isinstance(node.value.value, str)
        ):
            lines.update(range(node.lineno, (node.end_lineno or node.lineno) + 1))
    return lines


def import_lines(path: Path) -> set[int]:
    """The line numbers of every import statement in one file (all lines of a long one)."""
    lines: set[int] = set()
    for node in ast.walk(tree(path)):
        if isinstance(node, ast.Import | ast.ImportFrom):
            lines.update(range(node.lineno, (node.end_lineno or node.lineno) + 1))
    return lines
