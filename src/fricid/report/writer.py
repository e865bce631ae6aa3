"""Write a :class:`~fricid.report.document.Document` to a folder, all or nothing.

The folder receives ``report.html`` (self-contained), ``report.md``, one ``<name>.csv`` per
table, one ``<name>.png`` per figure and ``manifest.json`` (the list of files). Everything is
first built in a temporary folder beside the target; only when every file is written is it
moved into place (DESIGN.md, "Files"): a failure leaves the target as it was.

* A target that does not exist (or is empty) becomes the built folder by one rename.
* An existing folder keeps any file that is not ours: each new file replaces its namesake by
  an atomic rename, and files listed in the previous ``manifest.json`` that the new report no
  longer produces are removed.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import shutil
import tempfile
from os import PathLike
from pathlib import Path

from ..errors import ConfigError
from ..io.atomic import atomic_write, remove_stale, temp_prefix
from .document import Document
from .render import render_html, render_markdown

__all__ = ["MANIFEST", "write_document"]

logger = logging.getLogger(__name__)

#: Name of the file listing what a report folder holds.
MANIFEST = "manifest.json"


def _build(doc: Document, folder: Path) -> list[str]:
    """Write every file of ``doc`` into ``folder``; return their names."""
    doc.check_unique()
    names: list[str] = []
    for table in doc.tables():
        name = f"{table.name}.csv"
        with atomic_write(folder / name, "w") as fh:
            table.frame.to_csv(fh, index=table.index, float_format="%.10g")
        names.append(name)
    for fig in doc.figures():
        name = f"{fig.name}.png"
        with atomic_write(folder / name, "wb") as fh:
            fh.write(fig.png)
        names.append(name)
    with atomic_write(folder / "report.md", "w") as fh:
        fh.write(render_markdown(doc))
    with atomic_write(folder / "report.html", "w") as fh:
        fh.write(render_html(doc))
    names += ["report.md", "report.html", MANIFEST]
    with atomic_write(folder / MANIFEST, "w") as fh:
        json.dump({"title": doc.title, "files": names}, fh, indent=1)
        fh.write("\n")
    return names


def _previous_files(out: Path) -> set[str]:
    try:
        data = json.loads((out / MANIFEST).read_text(encoding="utf-8"))
        return {str(f) for f in data.get("files", []) if "/" not in str(f)}
    except (OSError, ValueError, AttributeError):
        return set()


def write_document(doc: Document, out: str | PathLike[str]) -> Path:
    """Write ``doc`` into the folder ``out`` (created if missing), all or nothing.

    Returns
    -------
    Path of ``report.html``.

    Raises
    ------
    ConfigError
        If ``out`` exists and is not a folder.
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out must be a folder; {out} is a file")
    out.parent.mkdir(parents=True, exist_ok=True)
    remove_stale(out.parent, name=out.name)  # what a killed run of fricid left
    tmp = Path(tempfile.mkdtemp(prefix=temp_prefix(out.name), suffix=".tmp", dir=out.parent))
    try:
        names = _build(doc, tmp)
        if not out.exists() or not any(out.iterdir()):
            with contextlib.suppress(FileNotFoundError, OSError):
                out.rmdir()
            os.replace(tmp, out)
            os.chmod(out, 0o755)  # mkdtemp makes it 0o700
        else:
            stale = _previous_files(out) - set(names)
            for name in names:
                os.replace(tmp / name, out / name)
            for name in stale:
                with contextlib.suppress(FileNotFoundError):
                    (out / name).unlink()
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    logger.info("wrote report %s (%d files)", out, len(names))
    return out / "report.html"
