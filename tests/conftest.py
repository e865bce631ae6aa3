"""Fixtures shared by the whole suite: where the real recordings are.

The real recordings live in ``../shared/data/real/`` relative to the repository (a checkout
with ``shared/`` beside it, as CI clones it); they are never copied into the repository. A test
that needs them takes the :func:`real_data` or :func:`leadscrew_dir` fixture and is skipped,
with a reason naming the folder, where the folder is absent (a bare clone elsewhere).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

# A pytest-xdist worker (``make test`` runs two) starts with COLUMNS=80 and LINES=24 in its
# environment, which a terminal session does not have; rich would then fix its consoles at 80
# columns when fricid.cli is imported, and the tests of fricid's own width rule (tables keep whole
# names in a pipe) would test the worker instead. The suite runs as a user's pipe does.
if os.environ.get("PYTEST_XDIST_WORKER"):
    for _name in ("COLUMNS", "LINES"):
        os.environ.pop(_name, None)

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


@pytest.fixture(scope="module")
def pendulum():
    """The example double pendulum's rigid-body model, for the whole-arm tests (skipped
    without Pinocchio)."""
    pytest.importorskip("pinocchio")
    from fricid.robot import RigidBodyModel, example_urdf

    path, joints = example_urdf("double_pendulum")
    return RigidBodyModel.from_urdf(path, joints)


# -- every model the suite fits and saves, for tests/models/test_friction_sign.py -----------

#: ``(model dict, samples or None)`` of every model file a test wrote through
#: ``FittedModel.save``; the samples are those the model was fitted on, found by the content
#: hash its provenance records (None when the fit is not known).
SAVED_MODELS: list[tuple[dict, object]] = []

_SAMPLES_BY_HASH: dict[str, object] = {}


def pytest_configure(config):
    config.addinivalue_line(
        "markers", "after_all: run after every other test (checks what the suite produced)"
    )


def pytest_collection_modifyitems(session, config, items):
    """Tests marked ``after_all`` run last, so they see every model file the suite wrote."""
    items.sort(key=lambda item: item.get_closest_marker("after_all") is not None)


@pytest.fixture(autouse=True, scope="session")
def _record_saved_models():
    """Record every model file written and the samples it was fitted on (see SAVED_MODELS)."""
    import sys

    import fricid.identify
    import fricid.identify.learned.rbf
    import fricid.samples
    import fricid.workflow
    from fricid.fitted import FittedModel

    original_hash = fricid.samples.samples_hash

    def recording_hash(samples):
        digest = original_hash(samples)
        _SAMPLES_BY_HASH[digest] = samples
        return digest

    patched = [
        module
        for name, module in list(sys.modules.items())
        if name.startswith("fricid") and getattr(module, "samples_hash", None) is original_hash
    ]
    original_save = FittedModel.save

    def recording_save(self, path):
        out = original_save(self, path)
        digest = (self.provenance or {}).get("samples_sha256_16")
        SAVED_MODELS.append((self.to_dict(), _SAMPLES_BY_HASH.get(digest)))
        return out

    for module in patched:
        module.samples_hash = recording_hash
    FittedModel.save = recording_save
    try:
        yield
    finally:
        FittedModel.save = original_save
        for module in patched:
            module.samples_hash = original_hash
