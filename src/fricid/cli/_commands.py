"""Imports every sub-command module so that each registers itself on the app."""

from __future__ import annotations

import importlib

#: Sub-command modules; a module missing here is simply not offered.
MODULES = (
    "simulate",
    "extract",
    "fit",
    "evaluate",
    "demo",
    "bench",
    "bench_rbfnn",
    "predict",
    "export",
    "compensate",
    "report",
    "reproduce",
    "fleet",
    "robot_simulate",
    "robot_extract",
    "robot_export",
    "robot_fit",
    "robot_design",
)

for _name in MODULES:
    try:
        importlib.import_module(f"{__package__}.{_name}")
    except ModuleNotFoundError as exc:  # a command still being written
        if exc.name != f"{__package__}.{_name}":
            raise
