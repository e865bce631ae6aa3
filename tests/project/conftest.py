"""The workspace of small files every documented command runs in, built once per session
(:func:`_docs_workspace.build_workspace`): the README's, ``--help``'s and the site's."""

from __future__ import annotations

import pytest

from _docs_workspace import LEADSCREW, build_workspace


@pytest.fixture(scope="session")
def docs_workspace(tmp_path_factory):
    ws = tmp_path_factory.mktemp("docs-workspace")
    build_workspace(ws, LEADSCREW)
    return ws
