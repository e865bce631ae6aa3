"""A URDF read safely, as text and as a graph: a regular file within :data:`MAX_BYTES`, its
encoding from the byte-order mark or the XML declaration, no DOCTYPE or entity in the decoded
text, and joints that form one tree (:mod:`fricid.io.urdf`'s notes).
"""

from __future__ import annotations

import codecs
import os
import re
import stat
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..errors import DataError

__all__ = ["MAX_BYTES", "check_graph", "parse_xml"]

#: Largest URDF read [bytes] (meshes live in separate files, so real URDFs are far smaller).
MAX_BYTES = 8 * 1024 * 1024

#: Byte-order marks and the encodings they announce (UTF-32 before UTF-16: a prefix).
_BOMS = (
    (codecs.BOM_UTF32_LE, "utf-32-le"),
    (codecs.BOM_UTF32_BE, "utf-32-be"),
    (codecs.BOM_UTF8, "utf-8"),
    (codecs.BOM_UTF16_LE, "utf-16-le"),
    (codecs.BOM_UTF16_BE, "utf-16-be"),
)

#: The first bytes of ``<?`` or ``<r`` without a byte-order mark (XML 1.0, appendix F).
_SNIFF = (
    (b"\x00\x00\x00<", "utf-32-be"),
    (b"<\x00\x00\x00", "utf-32-le"),
    (b"\x00<\x00", "utf-16-be"),
    (b"<\x00", "utf-16-le"),
)

#: Declared encodings read (normalised names) and the codec of each.
_DECLARED = {
    "utf8": "utf-8",
    "usascii": "ascii",
    "ascii": "ascii",
    "iso88591": "latin-1",
    "latin1": "latin-1",
    "utf16": "utf-16",
    "utf32": "utf-32",
}

_DECLARATION = re.compile(r"\A\s*<\?xml\b[^>]*?\?>")
_ENCODING = re.compile(r"""encoding\s*=\s*(?:"([^"]*)"|'([^']*)')""")


def _read_bytes(path: Path) -> bytes:
    """The file's bytes: a regular file only, at most :data:`MAX_BYTES`."""
    src = str(path)
    try:
        # non-blocking: opening a FIFO must not wait for a writer before it is refused
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise DataError(f"cannot read the URDF: {exc.strerror or exc}", file=src) from None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise DataError("the URDF is not a regular file", file=src)
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read(MAX_BYTES + 1)
    except OSError as exc:
        raise DataError(f"cannot read the URDF: {exc.strerror or exc}", file=src) from None
    finally:
        os.close(fd)
    if len(data) > MAX_BYTES:
        raise DataError(f"the URDF is over the {MAX_BYTES} bytes read", file=src)
    return data


def _declared_encoding(text: str, src: str) -> str | None:
    """The codec of the encoding the XML declaration at the start of ``text`` names (None
    without one); an encoding not read is a DataError."""
    declaration = _DECLARATION.match(text)
    match = _ENCODING.search(declaration.group()) if declaration else None
    if match is None:
        return None
    declared = (match.group(1) or match.group(2) or "").strip()
    codec = _DECLARED.get(re.sub(r"[^a-z0-9]", "", declared.lower()))
    if codec is None:
        raise DataError(
            f"the XML declaration names encoding '{declared[:40]}'; a URDF is read in UTF-8, "
            "UTF-16, UTF-32, US-ASCII or ISO-8859-1 (save it as UTF-8)",
            file=src,
        )
    return codec


def _decode(data: bytes, src: str) -> str:
    """The file's text: the encoding from the byte-order mark or the first bytes, and the
    XML declaration (module notes); a declaration that contradicts them is refused."""
    found = next(((bom, name) for bom, name in _BOMS if data.startswith(bom)), None)
    if found is not None:
        data, codec = data[len(found[0]) :], found[1]
    else:
        codec = next((name for head, name in _SNIFF if data.startswith(head)), None)
    if codec is None:  # ASCII-compatible: the declaration decides, UTF-8 by default
        codec = _declared_encoding(data[:512].decode("latin-1"), src) or "utf-8"
        if codec.startswith(("utf-16", "utf-32")):
            raise DataError(
                f"the XML declaration names {codec.upper()}, which the bytes are not", file=src
            )
    try:
        text = data.decode(codec)
    except UnicodeDecodeError as exc:
        raise DataError(f"not valid {codec.upper()} text (byte {exc.start})", file=src) from None
    declared = _declared_encoding(text, src)
    if declared is not None and not (codec.startswith(declared) or declared == codec):
        raise DataError(
            f"the XML declaration names {declared.upper()} but the file is {codec.upper()}",
            file=src,
        )
    return text


def parse_xml(path: Path) -> ET.Element:
    """The root element of the file, decoded and checked (module notes)."""
    src = str(path)
    text = _decode(_read_bytes(path), src)
    upper = text.upper()
    if "<!DOCTYPE" in upper or "<!ENTITY" in upper:
        raise DataError("a URDF with a DOCTYPE or entity declaration is refused", file=src)
    # the text without its declaration, as UTF-8: the parser sees the encoding checked here
    body = _DECLARATION.sub("", text, count=1)
    try:
        return ET.fromstring(body.encode("utf-8"))
    except ET.ParseError as exc:
        raise DataError(f"not XML: {exc}", file=src) from None


def check_graph(links: Mapping[str, Any], joints: Mapping[str, Any], src: str) -> str:
    """The root link of a tree of ``links`` (names) and ``joints`` (each with ``name``,
    ``parent``, ``child``); a cycle or anything but one root is a DataError."""
    parent_of = {j.child: j for j in joints.values()}
    done: set[str] = set()
    for start in links:
        path: list[str] = []
        link = start
        while link in parent_of and link not in done:
            if link in path:
                cycle = path[path.index(link) :]
                names = " -> ".join(f"'{parent_of[name].name[:60]}'" for name in reversed(cycle))
                raise DataError(
                    f"<joint name='{parent_of[link].name[:60]}'>: the joints {names} form a "
                    "cycle; a URDF must be a tree",
                    file=src,
                )
            path.append(link)
            link = parent_of[link].parent
        done.update(path)
    roots = [name for name in links if name not in parent_of]
    if len(roots) != 1:
        raise DataError(
            f"the URDF must form one tree; links without a parent joint: "
            f"{', '.join(r[:60] for r in roots[:5]) or 'none'}",
            file=src,
        )
    return roots[0]
