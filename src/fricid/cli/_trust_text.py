"""The ``[[Validation]]``, ``[[Model selection]]`` and ``[[Trust]]`` blocks that ``fricid fit``
prints, with or without ``--trajectory``: each held-out figure says which folds it pools, so
that the pooled leave-one-velocity-out error of the first two is not read against the trust
verdict's interior one."""

from __future__ import annotations

__all__ = ["heldout_lines", "trust_lines"]


def heldout_lines(fitted) -> list[str]:
    """The ``[[Validation]]`` and ``[[Model selection]]`` blocks of ``fricid fit`` when the
    model file holds them (``[]`` otherwise): the held-out RMSE, named by the folds it pools
    (:func:`fricid.identify.validate.scheme_label`), beside the scatter its ratio is over."""
    from ..identify.validate import scheme_label

    lines: list[str] = []
    v = fitted.validation
    sc = f"{v['scatter']:.3g} N m" if v and v.get("scatter") is not None else "unknown"
    if v:
        rm = f"{v['rmse']:.4g} N m" if v.get("rmse") is not None else "n/a"
        lines += [
            "[[Validation]]",
            f"    held-out RMSE ({scheme_label(v['scheme'])}) = {rm}, scatter {sc}: {v['verdict']}",
        ]
        if v.get("failed"):
            lines.append(f"    {v['failed']} of {len(v['folds'])} folds could not be fitted")
        if v.get("not_converged"):
            lines.append(f"    {v['not_converged']} fold fits did not converge")
        if v.get("note"):
            lines.append(f"    note: {v['note']}")
    sel = fitted.selection
    if sel:
        lines += ["[[Model selection]]", f"    chosen: {sel['reason']}"]
        label = scheme_label(str(sel.get("scheme") or (v or {}).get("scheme") or ""))
        lines.append(
            f"    {'candidate':<22} {'':>3} par  {'held-out RMSE':>14}  ({label}; the verdict "
            f"is it over the scatter {sc})"
        )
        for r in sel["table"]:
            err = r.get("heldout_rmse")
            cell = f"{err:.4g} N m" if err is not None else "-"
            lines.append(f"    {r['model']:<22} {r['n_params']:>3} par  {cell:>14}  {r['note']}")
        if sel.get("advice"):
            lines.append(f"    advice: {sel['advice']}")
    return lines


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
