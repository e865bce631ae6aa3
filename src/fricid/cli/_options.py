"""Parsing helpers shared by sub-commands: NAME=VALUE pairs and LOW:HIGH ranges."""

from __future__ import annotations

import typer

__all__ = ["parse_assignments", "parse_ranges"]


def _split(item: str, flag: str) -> tuple[str, str]:
    name, sep, value = item.partition("=")
    if not sep or not name.strip() or not value.strip():
        raise typer.BadParameter(f"expected NAME=VALUE, got '{item}'", param_hint=flag)
    return name.strip(), value.strip()


def parse_assignments(items: list[str] | None, flag: str) -> dict[str, float]:
    """``["delta=1", "xi=2"]`` -> ``{"delta": 1.0, "xi": 2.0}``."""
    out: dict[str, float] = {}
    for item in items or []:
        name, value = _split(item, flag)
        try:
            out[name] = float(value)
        except ValueError:
            raise typer.BadParameter(
                f"'{value}' is not a number (in '{item}')", param_hint=flag
            ) from None
    return out


def parse_ranges(items: list[str] | None, flag: str) -> dict[str, tuple[float, float]]:
    """``["w_s=0.001:1"]`` -> ``{"w_s": (0.001, 1.0)}``."""
    out: dict[str, tuple[float, float]] = {}
    for item in items or []:
        name, value = _split(item, flag)
        lo, sep, hi = value.partition(":")
        try:
            out[name] = (float(lo), float(hi))
        except ValueError:
            raise typer.BadParameter(
                f"expected NAME=LOW:HIGH, got '{item}'", param_hint=flag
            ) from None
        if not sep:
            raise typer.BadParameter(f"expected NAME=LOW:HIGH, got '{item}'", param_hint=flag)
    return out
