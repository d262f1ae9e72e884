"""How long a call site's texts may grow: the rule both language families share.

A call site's callee, receiver and argument texts are the call's own tokens. Where calls
chain or nest (``a.m().m().m()``, ``f(f(f(x)))``), each call's text holds the calls inside
it again, so n calls hold n²/2 calls' worth of text: 8,000 chained calls on one line made
640 million characters of it. A text that holds a call longer than :data:`LIMIT` characters
(Python: its tokens joined by spaces; C and C++: its bytes) is therefore cut to its first
:data:`LIMIT` characters and :data:`CUT` (docs/metrics.md, "Limits"), and the texts of a
chain, which all start alike, share one string. Other texts are whole: a long text whose
calls are short (a table of ``dict(...)`` entries, a 17 KB literal) is written once; only
calls nested in long calls repeat it.
"""

from __future__ import annotations

LIMIT = 2000
CUT = "…"


def cut(text: str) -> str:
    """``text`` cut to :data:`LIMIT` characters (the caller knows it holds a call)."""
    return text if len(text) <= LIMIT else text[:LIMIT] + CUT
