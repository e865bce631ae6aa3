"""Pinocchio, imported on first use with a clear error when it is not installed."""

from __future__ import annotations

from functools import cache
from types import ModuleType

from ..errors import ConfigError


@cache
def pinocchio() -> ModuleType:
    """The ``pinocchio`` module (PyPI ``pin``), or a :class:`ConfigError` saying how to get it."""
    try:
        import pinocchio as pin
    except ImportError as exc:  # pragma: no cover - the dev install has it
        raise ConfigError(
            "whole-robot dynamics need Pinocchio: pip install 'fricid[robot]' "
            f"(PyPI package 'pin'); importing it failed: {exc}"
        ) from None
    return pin
