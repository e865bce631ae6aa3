"""The manifest's text, read safely: a regular file within a size cap, CSV rows, and YAML
composed within a budget of values (no "billion laughs") and depth before it is built.
"""

from __future__ import annotations

import csv
import errno
import io
from pathlib import Path
from typing import Any

from ..errors import DataError
from ._fs import read_regular
from ._manifest_schema import resolve_key

__all__ = ["MAX_MANIFEST_BYTES", "MAX_YAML_DEPTH", "MAX_YAML_VALUES"]

#: The largest manifest read [bytes]: some 150 000 joints of CSV; larger is refused
#: before it is read (split the fleet into several manifests).
MAX_MANIFEST_BYTES = 16 * 2**20

#: A YAML manifest's aliases may stand for at most this many values in all (and at most
#: ten times the values written): a few hundred bytes of nested aliases ("billion laughs")
#: would otherwise stand for billions.
MAX_YAML_VALUES = 2_000_000
#: How deep a YAML manifest may nest (a manifest needs 4 levels).
MAX_YAML_DEPTH = 32


def _read_text(path: Path) -> str:
    """The manifest's text: a regular file of at most :data:`MAX_MANIFEST_BYTES`, UTF-8."""
    try:
        raw = read_regular(path, MAX_MANIFEST_BYTES)
    except OSError as exc:
        if exc.errno == errno.EINVAL:  # a FIFO, a device, a folder: never read
            why = f"it is {exc.strerror}, not a regular file"
        elif exc.errno == errno.EFBIG:
            why = (
                f"it is larger than {MAX_MANIFEST_BYTES // 2**20} MiB; split the fleet into "
                "several manifests"
            )
        else:
            why = exc.strerror or str(exc)
        raise DataError(f"cannot read the manifest: {why}", file=path) from None
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise DataError("the manifest is not UTF-8 text", file=path, row=line) from None


def _csv_entries(path: Path, text: str) -> list[tuple[int, dict[str, Any]]]:
    reader = csv.reader(io.StringIO(text, newline=""))
    header: list[str] | None = None
    header_line = 0
    entries: list[tuple[int, dict[str, Any]]] = []
    try:
        for cells in reader:
            line = reader.line_num
            if not cells or all(not c.strip() for c in cells) or cells[0].lstrip().startswith("#"):
                continue
            if header is None:
                header, header_line = [c.strip() for c in cells], line
                for label in header:
                    resolve_key(label, path, line)
                blank = [i for i, c in enumerate(header) if not c]
                if blank:
                    raise DataError(f"column {blank[0] + 1} has no name", file=path, row=line)
                continue
            if len(cells) > len(header):
                extra = [c for c in cells[len(header) :] if c.strip()]
                if extra:
                    raise DataError(
                        f"{len(cells)} cells but the header (line {header_line}) names "
                        f"{len(header)} columns",
                        file=path,
                        row=line,
                    )
            entries.append((line, dict(zip(header, cells, strict=False))))
    except csv.Error as exc:
        raise DataError(f"not valid CSV: {exc}", file=path, row=reader.line_num) from None
    if header is None:
        raise DataError("the manifest is empty (no header row)", file=path)
    return entries


def _yaml_lines(node: Any, key_path: list[Any]) -> list[int] | None:
    """1-based lines of the items of the YAML sequence at ``key_path`` (None if unknown)."""
    import yaml

    for key in key_path:
        if not isinstance(node, yaml.MappingNode):
            return None
        found = [v for k, v in node.value if getattr(k, "value", None) == key]
        if not found:
            return None
        node = found[0]
    if not isinstance(node, yaml.SequenceNode):
        return None
    return [item.start_mark.line + 1 for item in node.value]


def _yaml_budget(root: Any, path: Path) -> None:
    """Refuse a YAML document whose aliases stand for too many values, that refers to
    itself, or that nests too deeply (:data:`MAX_YAML_VALUES`, :data:`MAX_YAML_DEPTH`).

    Walks the composed nodes once each: an alias is the node it names, so the values a
    node stands for are counted without expanding anything.
    """
    import yaml

    values: dict[int, int] = {}  # node -> the values it stands for, expanded
    depth: dict[int, int] = {}
    on_path: set[int] = set()
    stack: list[tuple[Any, bool]] = [(root, False)]
    while stack:
        node, done = stack.pop()
        key = id(node)
        children: list[Any] = []
        if isinstance(node, yaml.SequenceNode):
            children = list(node.value)
        elif isinstance(node, yaml.MappingNode):
            children = [n for pair in node.value for n in pair]
        if done:
            on_path.discard(key)
            values[key] = 1 + sum(values[id(c)] for c in children)
            depth[key] = 1 + max((depth[id(c)] for c in children), default=0)
            if depth[key] > MAX_YAML_DEPTH:
                line = node.start_mark.line + 1
                raise DataError(
                    f"not a manifest: nested more than {MAX_YAML_DEPTH} levels deep",
                    file=path,
                    row=line,
                )
            continue
        if key in values:
            continue
        if key in on_path:
            raise DataError(
                "not a manifest: an alias refers to a value that contains it",
                file=path,
                row=node.start_mark.line + 1,
            )
        on_path.add(key)
        stack.append((node, True))
        stack.extend((c, False) for c in children if id(c) not in values)
    total, written = values[id(root)], len(values)
    if total > min(MAX_YAML_VALUES, max(10 * written, 10_000)):
        raise DataError(
            f"not a manifest: its aliases stand for {total} values ({written} written); "
            "write the values out, or use fewer aliases",
            file=path,
        )


def _yaml_load(path: Path, text: str) -> tuple[Any, Any]:
    """The YAML document and its composed node, within :func:`_yaml_budget`."""
    import yaml

    loader_class = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    loader = loader_class(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None, None
        _yaml_budget(node, path)
        return loader.construct_document(node), node
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        row = None if mark is None else mark.line + 1
        problem = " ".join(str(getattr(exc, "problem", None) or exc).split())  # one line
        raise DataError(f"not valid YAML: {problem}", file=path, row=row) from None
    except RecursionError:
        raise DataError(
            f"not a manifest: nested more than {MAX_YAML_DEPTH} levels deep", file=path
        ) from None
    finally:
        loader.dispose()
