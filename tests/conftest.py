"""Fixtures shared by the whole suite: where the real recordings are.

The real recordings live in ``../shared/data/real/`` relative to the repository (a checkout
with ``shared/`` beside it, as CI clones it); they are never copied into the repository. A test
that needs them takes the :func:`real_data` or :func:`leadscrew_dir` fixture and is skipped,
with a reason naming the folder, where the folder is absent (a bare clone elsewhere).
"""

from __future__ import annotations

from pathlib import Path

import pytest

#: The repository's root (this file is ``<root>/tests/conftest.py``).
REPO = Path(__file__).resolve().parents[1]

#: The real recordings: ``../shared/data/real/`` relative to the repository.
REAL_DATA = REPO.parent / "shared" / "data" / "real"


def _folder_or_skip(folder: Path) -> Path:
    if not folder.is_dir():
        pytest.skip(
            f"real recordings not found at {folder} (expected ../shared/data/real/ beside the "
            "repository)"
        )
    return folder


@pytest.fixture(scope="session")
def real_data() -> Path:
    """The folder of real recordings, ``../shared/data/real/`` beside the repository."""
    return _folder_or_skip(REAL_DATA)


@pytest.fixture(scope="session")
def leadscrew_dir(real_data: Path) -> Path:
    """The Maxon EPOS lead-screw recordings, ``../shared/data/real/epos-leadscrew/``."""
    return _folder_or_skip(real_data / "epos-leadscrew")
