"""Where things are, for tests in any folder of ``tests/``: the repository, its sources and
its test data (the real recordings are ``conftest.py``'s fixtures)."""

from __future__ import annotations

from pathlib import Path

#: The repository's root (``tests/`` is right below it).
REPO = Path(__file__).resolve().parents[1]
#: The package sources, ``src/``.
SRC = REPO / "src"
#: The test suite's own data files, ``tests/data/``.
TEST_DATA = REPO / "tests" / "data"
