"""The ``[[Trust]]`` block that ``fricid fit`` prints, with or without ``--trajectory``."""

from __future__ import annotations

__all__ = ["trust_lines"]


def trust_lines(trust) -> str:
    """The ``[[Trust]]`` block of ``fricid fit``: the verdict line of the trust record stored
    in the model file (:func:`fricid.identify.trust.assess_trust`), and where its error
    ratio came from."""
    import math

    lines = ["[[Trust]]", f"    {trust.line()}"]
    if math.isfinite(trust.heldout_ratio):
        named = not trust.held_out or trust.heldout_scheme in trust.heldout_source
        scheme = "" if named else f" ({trust.heldout_scheme})"
        lines.append(
            f"    error / scatter    = {trust.heldout_ratio:.3g}: {trust.verdict} "
            f"[{trust.heldout_source}{scheme}]"
        )
    if trust.validation_note:
        lines.append(f"    note: {trust.validation_note}")
    return "\n".join(lines)
