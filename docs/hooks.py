"""MkDocs hook of fricid's site: the API reference pages and the paper-equation index, both
generated at build time from the sources' docstrings (nothing typed by hand).

- ``reference/<package>.md``: one page per public package (and top-level module) of
  ``src/fricid``; each renders, through mkdocstrings, the package's docstring and every name in
  its ``__all__`` where it is defined.
- ``equations.md``: every equation reference in a docstring (``eq. 7``, ``eqs. 14-15``,
  ``equation 3``), grouped by the paper it names (``BAS-RBFNN paper eq. 7``), else the paper
  its module's docstring names, listing the objects that cite it.

Run as a script (``python docs/hooks.py``) it prints the equation index's Markdown.
"""

from __future__ import annotations

import importlib
import re
import sys
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

import griffe

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
#: The packages and top-level modules with a reference page, in the order of the stack
#: (bottom first, as the layer table of the design).
PACKAGES = (
    "units",
    "errors",
    "metrics",
    "samples",
    "io",
    "models",
    "optim",
    "robot",
    "extract",
    "sim",
    "fitted",
    "identify",
    "workflow",
    "report",
    "export",
    "control",
    "fleet",
)
#: The papers an equation reference may name: key, how the docstrings spell it (name or
#: citation key), and the title the index gives it (in this order).
PAPERS = {
    "BAS-RBFNN": (
        r"BAS-RBFNN|\[B\]",
        "BAS-RBFNN paper (static friction: analytic models and an RBF network trained by BAS)",
    ),
    "RWSAVSBAS": (r"RWSAVSBAS|\[R\]", "RWSAVSBAS paper (Stribeck parameters by RWSAVSBAS)"),
    "CW95": (r"Canudas de Wit|\[CW95\]", "Canudas de Wit et al. 1995 (the LuGre model)"),
    "D76": (r"\[D76\]|Dahl \(?1976", "Dahl 1976 (the Dahl model)"),
    "GZ": (r"\[GZ\]|Gaz et al", "Gaz et al. 2019 (the Franka Emika Panda's friction)"),
    "RW06": (
        r"R&W|Rasmussen (?:&|and) (?:C\. K\. I\. )?Williams",
        "Rasmussen and Williams 2006 (Gaussian Processes for Machine Learning)",
    ),
    "QR05": (
        r"Quinonero-Candela",
        "Quinonero-Candela and Rasmussen 2005 (sparse Gaussian processes)",
    ),
    "SW97": (
        r"Swevers",
        "Swevers et al. 1997 (optimal robot excitation and identification, IEEE T-RA 13(5))",
    ),
    "ESL": (
        r"\bESL\b",
        "ESL (Hastie, Tibshirani and Friedman, The Elements of Statistical Learning)",
    ),
}
UNNAMED = "paper not named in the docstring"
_PAPER = re.compile("|".join(f"(?P<{k.replace('-', '_')}>{rx})" for k, (rx, _) in PAPERS.items()))
#: ``eq. 7``, ``Eq. 7``, ``eqs. 14-15``, ``eq. (3)``, ``equation 13``, ``eq. 3.50``.
_EQ = re.compile(
    r"\b(?:[Ee]qs?\.|[Ee]quations?)\s*\(?(\d+(?:\.\d+)?)\)?(?:\s*(?:-|–|to)\s*\(?(\d+)\)?)?"
)


def _paper_key(m: re.Match) -> str:
    """The :data:`PAPERS` key of a match of :data:`_PAPER`."""
    return m.lastgroup.replace("_", "-")


def load() -> griffe.Module:
    """fricid's sources, read statically by griffe (as mkdocstrings reads them)."""
    return griffe.load("fricid", search_paths=[str(SRC)])


# ------------------------------------------------------------------------------- API pages


def _target(obj: griffe.Object | griffe.Alias) -> str:
    """The path where ``obj`` is defined (an alias followed to its target)."""
    return obj.target_path if obj.is_alias else obj.path


def exported(pkg: griffe.Module, name: str) -> list[str]:
    """The defining paths of ``fricid.<name>``'s public names (its ``__all__``)."""
    module = pkg[name]
    names = list(module.exports or [])
    if not names:  # a package that imports lazily (``__getattr__`` over ``_WHERE``)
        sys.path.insert(0, str(SRC))
        try:
            runtime = importlib.import_module(f"fricid.{name}")
        finally:
            sys.path.remove(str(SRC))
        names = list(getattr(runtime, "__all__", []))
        where = getattr(runtime, "_WHERE", {})
        return [
            _target(pkg[f"{name}.{where[n]}.{n}"]) if n in where else _target(module[n])
            for n in names
        ]
    return [_target(module[n]) for n in names]


def reference_page(pkg: griffe.Module, name: str) -> str:
    """The Markdown of ``reference/<name>.md``."""
    lines = [
        f"# fricid.{name}",
        "",
        f"::: fricid.{name}",
        "    options:",
        "      members: false",
        "      show_root_heading: false",
        "",
    ]
    for path in exported(pkg, name):
        lines += [f"::: {path}", ""]
    return "\n".join(lines)


def rendered_paths(pkg: griffe.Module) -> set[str]:
    """Every path the reference pages give an anchor: the exported objects, their public
    members, and the packages themselves."""
    out: set[str] = set()

    def walk(obj: griffe.Object) -> None:
        out.add(obj.path)
        if obj.is_class:
            for m in obj.members.values():
                if not m.is_alias and not m.name.startswith("_") and m.docstring:
                    walk(m)

    for name in PACKAGES:
        out.add(f"fricid.{name}")
        for path in exported(pkg, name):
            walk(pkg[path.removeprefix("fricid.")])
    return out


# ------------------------------------------------------------------------- equation index


@dataclass(frozen=True)
class Citation:
    """One equation cited by one object's docstring."""

    paper: str
    equation: str
    path: str


def _objects(obj: griffe.Object):
    """``obj`` and everything defined inside it (aliases left out: they are cited where they
    are defined)."""
    yield obj
    for member in obj.members.values():
        if not member.is_alias:
            yield from _objects(member)


def _first_paper(obj: griffe.Object) -> str | None:
    """The first paper named by the docstring of ``obj``, else of its module, its package..."""
    while obj is not None:
        m = _PAPER.search(obj.docstring.value if obj.docstring else "")
        if m:
            return _paper_key(m)
        obj = obj.parent
    return None


#: A paper named right after the reference: ``eq. 18 of [B]``, ``eq. 7 in the RWSAVSBAS paper``.
_AFTER = re.compile(r"\s*(?:of|in|from)\s+(?:the\s+)?")


def _paper_of(text: str, start: int, obj: griffe.Object, end: int | None = None) -> str:
    """The paper of the equation reference ``text[start:end]``: one named right after it
    (``eq. 18 of [B]``), else the one named last before it in its paragraph, else the first
    its docstring names, else its module's."""
    if end is not None:
        after = _AFTER.match(text, end)
        named = after and _PAPER.match(text, after.end())
        if named:
            return _paper_key(named)
    paragraph_start = text.rfind("\n\n", 0, start) + 1
    before = list(_PAPER.finditer(text, paragraph_start, start))
    if before:
        return _paper_key(before[-1])
    return _first_paper(obj) or UNNAMED


def _labels(first: str, last: str | None) -> list[str]:
    """The equations of ``eq. first-last`` (``eq. 3.50`` alone; ranges of up to 20)."""
    if last is None or "." in first or not 0 < int(last) - int(first) <= 20:
        return [first]
    return [str(e) for e in range(int(first), int(last) + 1)]


def citations(pkg: griffe.Module) -> list[Citation]:
    """Every equation reference in fricid's docstrings, with the paper it belongs to."""
    out = []
    for obj in _objects(pkg):
        text = obj.docstring.value if obj.docstring else ""
        for m in _EQ.finditer(text):
            paper = _paper_of(text, m.start(), obj, m.end())
            out += [Citation(paper, eq, obj.path) for eq in _labels(m.group(1), m.group(2))]
    return out


def _eq_key(label: str) -> tuple[int, ...]:
    return tuple(int(part) for part in label.split("."))


def equation_index(pkg: griffe.Module | None = None) -> str:
    """The Markdown of ``equations.md``."""
    pkg = pkg or load()
    cites = citations(pkg)
    linked = rendered_paths(pkg)
    by_paper: dict[str, dict[str, set[str]]] = defaultdict(lambda: defaultdict(set))
    for c in cites:
        by_paper[c.paper][c.equation].add(c.path)
    lines = [
        "# Paper-equation index",
        "",
        "Where each equation of the papers fricid implements is cited in its docstrings, "
        "generated from the sources by `docs/hooks.py` at every build "
        f"({len(cites)} citations in {len({c.path for c in cites})} docstrings). "
        "An equation is attributed to the paper named right after it (eq. 18 of [B]), else "
        "to the one its docstring names last before it in the same paragraph, else to the "
        "first paper the docstring names, else to its module's. "
        "Objects of the API reference are links; the "
        "others are private helpers, named by their path.",
        "",
    ]
    for paper in [*PAPERS, UNNAMED]:
        if paper not in by_paper:
            continue
        title = PAPERS[paper][1] if paper in PAPERS else paper.capitalize()
        lines += [f"## {title}", ""]
        lines += ["| equation | cited by |", "|---|---|"]
        for eq in sorted(by_paper[paper], key=_eq_key):
            refs = [
                f"[`{p.removeprefix('fricid.')}`][{p}]"
                if p in linked
                else f"`{p.removeprefix('fricid.')}`"
                for p in sorted(by_paper[paper][eq])
            ]
            lines.append(f"| eq. {eq} | {', '.join(refs)} |")
        lines.append("")
    return "\n".join(lines)


# ------------------------------------------------------------------- docstring examples

_SECTION = re.compile(r"^\s*[A-Z][A-Za-z ]+\n\s*-{3,}\s*$", re.M)
_FLAG = re.compile(r"\s*#\s*doctest:.*$")


def fence_doctests(text: str) -> str:
    """``text`` with each run of ``>>>`` example lines (before its first numpydoc section,
    whose Examples the parser reads itself) in a ``pycon`` code fence, doctest flags left
    out: Markdown would read ``>>>`` as nested quotes."""
    section = _SECTION.search(text)
    head, tail = (text[: section.start()], text[section.start() :]) if section else (text, "")
    out: list[str] = []
    block: list[str] = []
    for line in [*head.split("\n"), None]:
        if block and (line is None or not line.strip()):
            indent = block[0][: len(block[0]) - len(block[0].lstrip())]
            out += [f"{indent}```pycon", *block, f"{indent}```"]
            block = []
        if line is None:
            break
        if block or line.lstrip().startswith(">>>"):
            block.append(_FLAG.sub("", line))
        else:
            out.append(line)
    return "\n".join(out) + tail


class DoctestFences(griffe.Extension):
    """A griffe extension (mkdocs.yml) applying :func:`fence_doctests` to every docstring."""

    def on_instance(self, *, obj, **kwargs) -> None:
        if obj.docstring and ">>>" in obj.docstring.value:
            obj.docstring.value = fence_doctests(obj.docstring.value)


# ---------------------------------------------------------------------------- MkDocs hooks

_ROLE = re.compile(r":(?:py:)?(?:func|class|meth|attr|data|mod|obj|exc|const):(<code>)~?")


def on_config(config, **kwargs):
    """The API reference's nav: one page per package, generated by :func:`on_files`."""
    for item in config.nav:
        if isinstance(item, dict) and item.get("API reference") == "reference/":
            item["API reference"] = [f"reference/{name}.md" for name in PACKAGES]
    return config


def on_files(files, config, **kwargs):
    """Add the generated pages (reference pages and the equation index)."""
    from mkdocs.structure.files import File

    pkg = load()
    for name in PACKAGES:
        files.append(
            File.generated(config, f"reference/{name}.md", content=reference_page(pkg, name))
        )
    files.append(File.generated(config, "equations.md", content=equation_index(pkg)))
    return files


def on_page_content(html, **kwargs):
    """Docstrings' Sphinx roles (``:func:`x```) rendered as their code alone."""
    return _ROLE.sub(r"\1", html)


if __name__ == "__main__":
    sys.stdout.write(equation_index() + "\n")
