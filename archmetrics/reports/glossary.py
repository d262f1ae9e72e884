"""What each number of a report means, in plain words: the legend under tables and in Markdown,
the help text of SARIF rules, and the terms docs/glossary.md explains at length (a test keeps
the page and this table in step).

A term is a report's column or a gate's field: its thesis symbol, its JSON name, what it
counts, and which way is better (``lower``, ``higher``, or ``neither`` where its size alone
says nothing good or bad).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True, slots=True)
class Term:
    symbol: str  # as the table's column names it
    field: str  # the JSON field, and the gate or threshold field
    meaning: str
    better: str  # lower | higher | neither


TERMS: tuple[Term, ...] = (
    Term("λ", "loc", "logical lines of code: statements, not physical lines", "neither"),
    Term("SLOC", "sloc", "physical lines that are neither blank nor only comment", "neither"),
    Term("v_g", "vg", "McCabe complexity: 1 + decision points of a function, summed", "lower"),
    Term("Δs_a", "delta_s_a", "change in static afferent coupling (who imports this)", "lower"),
    Term("Δs_e", "delta_s_e", "change in static efferent coupling (what this imports)", "lower"),
    Term("Δd_a", "delta_d_a", "change in run-time afferent links (who talks to this)", "lower"),
    Term("Δd_e", "delta_d_e", "change in run-time efferent links (whom this talks to)", "lower"),
    Term("λ pre, λ post", "loc_pre", "logical lines before and after the change", "neither"),
    Term("λ̂", "loc_scale", "λ post / λ pre: how much the code grew (1 = same size)", "neither"),
    Term("Γ_A, Γ_R, Γ_M", "added", "statements added, removed, modified", "lower"),
    Term("Γ", "changes", "statements changed: added + removed + modified", "lower"),
    Term("Γ'", "scaled_changes", "λ̂ · Γ: the size of the change, scaled by growth", "lower"),
    Term("Vg pre, Vg post", "vg_pre", "McCabe complexity before and after", "neither"),
    Term("v̂g", "vg_scale", "Vg post / Vg pre: how much complexity grew (1 = same)", "neither"),
    Term("ΔVg", "delta_vg", "complexity added: Vg post − Vg pre", "lower"),
    Term("ΔVg'", "scaled_delta_vg", "v̂g · ΔVg: complexity added, scaled by growth", "lower"),
    Term(
        "E",
        "cost",
        "Γ' / ΔVg': statements changed per unit of complexity added; 0 when no complexity"
        " was added (a large change can have E = 0: read it with Γ')",
        "lower",
    ),
)

_BY_FIELD = {term.field: term for term in TERMS}
_ALIASES = {
    "loc_post": "loc_pre",
    "removed": "added",
    "modified": "added",
    "vg_post": "vg_pre",
}
_UNIT_FIELDS = {
    "functions": "functions in the file or tree",
    "files": "files measured",
    "warnings": "parse warnings (code read only in part)",
    "unparsed": "files that could not be parsed at all (a syntax error, a binary)",
    "s_a": "static afferent coupling: elements that import this one",
    "s_e": "static efferent coupling: elements this one imports",
    "d_a": "run-time afferent links: elements that connect to this one",
    "d_e": "run-time efferent links: elements this one connects to",
}


def meaning(field: str) -> str:
    """What ``field`` (a JSON, gate or threshold field) counts, in plain words."""
    term = _BY_FIELD.get(_ALIASES.get(field, field))
    if term is not None:
        return f"{term.symbol}: {term.meaning}"
    return _UNIT_FIELDS.get(field, field)


DIFF_LEGEND = (
    "Γ statements changed (added + removed + modified); λ logical lines; λ̂ growth λ post/λ pre;"
    " Γ' = λ̂·Γ; v_g McCabe complexity; ΔVg complexity added; ΔVg' = v̂g·ΔVg;"
    " E = Γ'/ΔVg' statements changed per unit of complexity added, lower is cheaper, 0 when"
    " no complexity was added (read E with Γ'); Δs_a, Δs_e, Δd_a, Δd_e changes in static"
    " and run-time coupling, lower is looser; eq. the thesis's equation."
    " `archmetrics docs glossary` explains each."
)
SCAN_LEGEND = (
    "λ logical lines (statements); SLOC non-blank, non-comment lines; v_g McCabe complexity"
    " (1 + decision points per function, summed), lower is simpler."
    " `archmetrics docs glossary` explains each."
)
ELEMENT_LEGEND = (
    "s_a, s_e static afferent and efferent coupling (imports into and out of the element);"
    " d_a, d_e the same for run-time links (sockets, topics, services)."
)


def docs_folder() -> Path | None:
    """The installed pages (inside the package), or a checkout's docs/ beside it."""
    package = Path(__file__).resolve().parent.parent
    for candidate in (package / "docs", package.parent / "docs"):
        if (candidate / "metrics.md").is_file():
            return candidate
    return None


def help_uri(page: str, anchor: str) -> str | None:
    """An absolute URI of ``page`` (e.g. ``ci.md``) at ``anchor`` in the docs: under
    ``$ARCHMETRICS_DOCS_URL`` when set (where a team publishes the pages), else the
    installed page's ``file:`` URI; None when the docs are not installed."""
    published = os.environ.get("ARCHMETRICS_DOCS_URL", "").strip()
    if published:
        return f"{published.rstrip('/')}/{page}#{anchor}"
    folder = docs_folder()
    if folder is None or not (folder / page).is_file():
        return None
    return f"{(folder / page).as_uri()}#{anchor}"
