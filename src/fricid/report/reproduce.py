"""``fricid reproduce PAPER``: regenerate every table and figure of a seed paper into a folder.

Papers (:data:`PAPERS`): ``bas-rbfnn`` (computed by :mod:`fricid.experiments.bas_rbfnn_paper`,
composed by :mod:`fricid.report.studies.bas_rbfnn`) and ``rwsavsbas``
(:mod:`fricid.experiments.rwsavsbas_paper`, :mod:`fricid.report.studies.rwsavsbas`). Each
builds a :class:`~fricid.report.Document` with the paper's numbers beside ours
(:mod:`fricid.experiments.paper_numbers`), written by :func:`fricid.report.write_document` as
``report.html`` (self-contained), ``report.md``, one CSV per table and one PNG per figure, all
or nothing.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass
from os import PathLike
from pathlib import Path

from ..errors import ConfigError
from .document import Document
from .writer import write_document

__all__ = ["PAPERS", "ReproduceResult", "default_out", "paper_steps", "reproduce"]

logger = logging.getLogger(__name__)

#: The reproducible papers: name -> (module of :mod:`fricid.report.studies`, builder function).
PAPERS: dict[str, tuple[str, str]] = {
    "bas-rbfnn": ("bas_rbfnn", "build_bas_rbfnn"),
    "rwsavsbas": ("rwsavsbas", "build_rwsavsbas"),
}


@dataclass
class ReproduceResult:
    """What :func:`reproduce` produced."""

    paper: str
    out: Path
    document: Document
    seconds: float

    @property
    def html(self) -> Path:
        return self.out / "report.html"


def _module(paper: str):
    import importlib

    key = str(paper).strip().lower()
    if key not in PAPERS:
        raise ConfigError(f"unknown paper '{paper}'; choose one of: {', '.join(PAPERS)}")
    module, builder = PAPERS[key]
    mod = importlib.import_module(f"{__package__}.studies.{module}")
    return key, mod, getattr(mod, builder)


def paper_steps(paper: str) -> tuple[str, ...]:
    """The progress step labels of ``paper``, in order."""
    _, mod, _ = _module(paper)
    return tuple(mod.STEPS)


def default_out(paper: str) -> Path:
    """``./fricid-reproduce/<paper>/``."""
    return Path("fricid-reproduce") / str(paper).strip().lower()


def reproduce(
    paper: str,
    out: str | PathLike[str] | None = None,
    *,
    quick: bool = False,
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
) -> ReproduceResult:
    """Reproduce ``paper`` ("bas-rbfnn" or "rwsavsbas") into the folder ``out``.

    Parameters
    ----------
    paper : str
        Which paper (:data:`PAPERS`).
    out : path-like, optional
        Output folder (default :func:`default_out`); written all or nothing.
    quick : bool
        Reduced designs and budgets (used by the tests).
    seed : int
        Seeds every stochastic step; same seed, same report.
    progress : callable, optional
        Called with each step's label as it starts (see :func:`paper_steps`).

    Returns
    -------
    ReproduceResult

    Raises
    ------
    ConfigError
        If ``paper`` is unknown.
    """
    key, _, build = _module(paper)
    out = Path(out) if out is not None else default_out(key)
    t0 = time.perf_counter()
    doc = build(quick=quick, seed=seed, progress=progress)
    seconds = time.perf_counter() - t0
    doc.meta["run time"] = f"{seconds:.1f} s"
    write_document(doc, out)
    logger.info("reproduced %s in %.1f s into %s", key, seconds, out)
    return ReproduceResult(key, out, doc, seconds)
