"""fricid: identify the friction of robot joints and hand it to a controller.

The flow (DESIGN.md): raw log --extract--> FrictionSamples --identify--> FittedModel -->
report / export / predict. SI units throughout.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("fricid")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
