"""Shared pieces of the BAS-RBFNN reproduction's network sections (Tables 3-4, Fig. 8-10).

[B] the BAS-RBFNN paper. Labels of the study's rows and the paper's keys, and small formatters.
"""

from __future__ import annotations

import numpy as np

from ...experiments.rbfnn_study import StudyResult

__all__ = ["T3_PAPER", "T4_PAPER", "VLT_LABEL", "epochs", "mnm", "quick_setting", "row_label"]

#: Table 3's rows of the paper's three models: the study's label -> key of the paper's numbers.
T3_PAPER = {"RBFNN": "rbfnn", "BAS-RBFNN": "bas_rbfnn", "VLT model": "vlt"}
#: How the report names the study's ``VLT model`` row.
VLT_LABEL = "Velocity-load-temperature model (eq. 4)"
#: The study's labels of Table 4's two methods -> key of the paper's numbers.
T4_PAPER = {"GA-RBFNN": "ga_rbfnn", "BAS-RBFNN": "bas_rbfnn"}


def row_label(study_label: str) -> str:
    """The report's name of a study row (eq. 4 spelled out)."""
    return VLT_LABEL if study_label == "VLT model" else study_label


def mnm(value: float) -> str:
    """``value`` [mN m] as text."""
    return f"{value:.3g} mN m"


def epochs(value: float) -> str:
    """An epoch count as text; infinite: "not reached"."""
    return f"{value:g} epochs" if np.isfinite(value) else "not reached"


def quick_setting(res: StudyResult) -> str:
    """The quick run's size, for captions."""
    cfg = res.config
    n = int(res.tables["data"]["samples"].iloc[0])
    return f"{n} samples, {cfg.n_centers} centres, at most {cfg.max_epochs} epochs"
