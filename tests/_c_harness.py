"""The C compiler harness every C-export test shares: compile an exported ``fricid_friction.c``
with a ``main`` that reads ``v l T`` lines and prints the friction, run it, read the numbers.

One set of flags for every test (C99, pedantic, every warning an error); tests that need a C
compiler take the ``needs_cc`` mark and are skipped, saying why, where there is none.
"""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest

CC = shutil.which("cc") or shutil.which("gcc")
needs_cc = pytest.mark.skipif(
    CC is None, reason="no C compiler (cc or gcc) on PATH: optional, not a Python dependency"
)
CFLAGS = [
    "-std=c99",
    "-O2",
    "-Wall",
    "-Wextra",
    "-Wpedantic",
    "-Werror",
    "-Wshadow",
    "-Wconversion",
]

HARNESS = r"""
#include <stdio.h>
#include "fricid_friction.h"
int main(void)
{
    double v, l, t;
    while (scanf("%lf %lf %lf", &v, &l, &t) == 3)
        printf("%.17g\n", fricid_friction(v, l, t));
    return 0;
}
"""


def compile_c(directory: Path, sources: Sequence[str], exe: str = "friction") -> Path:
    """``sources`` (in ``directory``) compiled with :data:`CFLAGS` and libm; the compiler's
    messages are the assertion's when it fails."""
    path = directory / exe
    res = subprocess.run(
        [CC, *CFLAGS, "-o", str(path), *(str(directory / s) for s in sources), "-lm"],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stderr
    return path


def compile_and_run(directory: Path, X: np.ndarray) -> np.ndarray:
    """The friction the exported C in ``directory`` computes at the rows ``(v, load, T)`` of
    ``X``, run in ``directory`` (so anything it writes lands there)."""
    (directory / "main.c").write_text(HARNESS)
    exe = compile_c(directory, ("main.c", "fricid_friction.c"))
    text = "\n".join(" ".join(repr(float(x)) for x in row) for row in X)
    run = subprocess.run(
        [str(exe)], input=text, check=True, capture_output=True, text=True, cwd=directory
    )
    return np.array([float(line) for line in run.stdout.split()])
