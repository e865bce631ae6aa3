"""The README's measured numbers and example output, rendered from the benchmarks' JSON output
in ``benchmarks/results/`` (nothing typed by hand).

The README marks each generated number ``<!-- n:NAME -->12 s<!-- /n -->`` and each generated
block ``<!-- block:NAME -->`` ... ``<!-- /block -->``; :data:`NUMBERS` and :data:`BLOCKS` say
where each comes from. ``tests/project/test_readme_numbers.py`` fails when the README differs
from what this renders, or holds a number outside the marks.

To plug in a number another benchmark measures (for instance a fresh clone's ``make demo``):
write it into a JSON file of ``benchmarks/results/`` and point the :data:`NUMBERS` entry at
it (file, key path, format); a ``null`` or missing value renders as :data:`NOT_MEASURED`.
``make_demo_fresh*`` come from ``python benchmarks/bench_readme.py fresh``.

Run from the repository root: ``python benchmarks/readme_numbers.py --write`` updates the
README in place; ``--check`` exits 1 when it is stale.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
README = ROOT / "README.md"
#: What a number not measured yet reads as.
NOT_MEASURED = "not measured yet"

#: name -> (file in benchmarks/results/, dotted key path, format of the value).
NUMBERS: dict[str, tuple[str, str, str]] = {
    "demo_wall": ("demo.json", "fricid_demo.wall_s", "{:.0f} s"),
    "demo_cpu": ("demo.json", "fricid_demo.cpu_s", "{:.0f} s"),
    "demo_load": ("demo.json", "machine.load_average.0", "{:.1f}"),
    "demo_cpus": ("demo.json", "machine.cpus", "{:d}"),
    # a fresh clone's `make demo` (venv, install, demo): `bench_readme.py fresh`
    "make_demo_fresh": ("demo.json", "fresh_make_demo.wall_s", "{:.0f} s"),
    "make_demo_fresh_cpu": ("demo.json", "fresh_make_demo.cpu_s", "{:.0f} s"),
    "make_demo_fresh_load": ("demo.json", "fresh_make_demo.load_before.0", "{:.1f}"),
    "quickstart_extract_wall": ("quickstart.json", "commands.0.wall_s", "{:.0f} s"),
    "quickstart_fit_wall": ("quickstart.json", "commands.1.wall_s", "{:.0f} s"),
    "quickstart_load": ("quickstart.json", "machine.load_average.0", "{:.1f}"),
}

#: The sections of ``fricid fit``'s printout the README shows (the others: "...").
FIT_SECTIONS = ("[[Variables]]", "[[Goodness of fit]]", "[[Trust]]")


def load(name: str) -> dict:
    """``benchmarks/results/<name>``."""
    return json.loads((RESULTS / name).read_text(encoding="utf-8"))


def lookup(record, path: str):
    """``record``'s value at the dotted ``path`` (list items by index); None where absent."""
    for key in path.split("."):
        if record is None:
            return None
        if isinstance(record, list):
            record = record[int(key)] if int(key) < len(record) else None
        else:
            record = record.get(key)
    return record


def number(name: str) -> str:
    """The README's text for the number ``name``."""
    file, path, fmt = NUMBERS[name]
    value = lookup(load(file), path) if (RESULTS / file).is_file() else None
    return NOT_MEASURED if value is None else fmt.format(value)


def fit_excerpt(stdout: str) -> list[str]:
    """The :data:`FIT_SECTIONS` of ``fricid fit``'s printout, "..." for the sections left out."""
    out, keep = [], False
    for line in stdout.rstrip("\n").splitlines():
        if line.startswith("[["):
            keep = line[: line.index("]]") + 2] in FIT_SECTIONS
            if not keep and (not out or out[-1] != "..."):
                out.append("...")
        if keep:
            out.append(line)
    return out


def quickstart_block() -> str:
    """The Quick start's real-data commands as a terminal shows them, with their output."""
    lines = []
    for run in load("quickstart.json")["commands"]:
        lines.append(f"$ {run['command']}")
        shown = fit_excerpt(run["stdout"]) if " fit " in run["command"] else []
        shown = shown or run["stdout"].rstrip("\n").splitlines()
        lines += shown + run["stderr"].rstrip("\n").splitlines()
    return "```text\n" + "\n".join(lines) + "\n```"


#: name -> the Markdown of the block.
BLOCKS: dict[str, Callable[[], str]] = {"quickstart": quickstart_block}

_NUMBER = re.compile(r"<!-- n:([\w-]+) -->(.*?)<!-- /n -->", re.S)
_BLOCK = re.compile(r"<!-- block:([\w-]+) -->\n(.*?)<!-- /block -->", re.S)


def render(text: str) -> str:
    """``text`` with every marked number and block as the results give them."""
    text = _NUMBER.sub(lambda m: f"<!-- n:{m[1]} -->{number(m[1])}<!-- /n -->", text)
    return _BLOCK.sub(lambda m: f"<!-- block:{m[1]} -->\n{BLOCKS[m[1]]()}\n<!-- /block -->", text)


def marked(text: str) -> tuple[list[str], list[str]]:
    """The names of the numbers and the blocks ``text`` marks."""
    return [m[0] for m in _NUMBER.findall(text)], [m[0] for m in _BLOCK.findall(text)]


def unmarked(text: str) -> str:
    """``text`` without its generated parts (marked numbers and blocks), code and links: the
    prose a test scans for numbers typed by hand."""
    text = _BLOCK.sub("", _NUMBER.sub("", text))
    text = re.sub(r"```.*?```", "", text, flags=re.S)  # code blocks: commands, paths
    text = re.sub(r"`[^`]*`", "", text)  # inline code: names, commands, options
    text = re.sub(r"\]\([^)]*\)", "]", text)  # link targets
    return re.sub(r"<!--.*?-->", "", text, flags=re.S)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true", help="update README.md in place")
    ap.add_argument("--check", action="store_true", help="exit 1 when README.md is stale")
    args = ap.parse_args()
    text = README.read_text(encoding="utf-8")
    new = render(text)
    if args.write and new != text:
        README.write_text(new, encoding="utf-8")
        print("README.md updated")
    elif args.check and new != text:
        print("README.md is stale: python benchmarks/readme_numbers.py --write", file=sys.stderr)
        sys.exit(1)
    elif not (args.write or args.check):
        for name in NUMBERS:
            print(f"{name}: {number(name)}")


if __name__ == "__main__":
    main()
