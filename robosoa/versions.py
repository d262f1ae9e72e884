"""Service versions and version ranges (``1.2.0``, ``>=1.0,<2``, ``~=1.4``, ``*``)."""

from __future__ import annotations

import operator
import re
from collections.abc import Callable

Version = tuple[int, ...]

_VERSION = re.compile(r"^\d+(\.\d+)*$")
_CLAUSE = re.compile(r"^(>=|<=|==|!=|~=|>|<|\^)?\s*(\d+(?:\.\d+)*)(\.\*)?$")
_OPS: dict[str, Callable[[Version, Version], bool]] = {
    ">=": operator.ge, "<=": operator.le, ">": operator.gt, "<": operator.lt,
    "==": operator.eq, "!=": operator.ne,
}


def parse_version(text: str) -> Version:
    """``"1.2"`` -> ``(1, 2, 0)``; raises ValueError on anything but dotted integers."""
    text = text.strip()
    if not _VERSION.match(text):
        raise ValueError(f"bad version {text!r}: expected dotted integers like 1.2.0")
    parts = tuple(int(p) for p in text.split("."))
    return parts + (0,) * (3 - len(parts)) if len(parts) < 3 else parts


def _clause(text: str) -> Callable[[Version], bool]:
    match = _CLAUSE.match(text.strip())
    if not match:
        raise ValueError(f"bad version range clause {text!r}")
    op, number, star = match.group(1) or "", match.group(2), match.group(3)
    bound = parse_version(number)
    width = len(number.split("."))
    if star or op == "":
        if star or width < 3:  # "1.2" or "1.2.*" means any 1.2.x
            return lambda v: v[:width] == bound[:width]
        return lambda v: v == bound
    if op in ("~=", "^"):
        keep = max(width - 1, 1) if op == "~=" else 1
        upper = (*bound[:keep - 1], bound[keep - 1] + 1)
        return lambda v: v >= bound and v[:keep] < upper
    compare = _OPS[op]
    return lambda v: compare(v, bound)


def version_matcher(spec: str | None) -> Callable[[str], bool]:
    """A predicate for a range like ``>=1.0,<2``; None, "" and "*" accept every version."""
    if spec is None or spec.strip() in ("", "*"):
        return lambda _version: True
    clauses = [_clause(part) for part in spec.split(",") if part.strip()]

    def matches(version: str) -> bool:
        try:
            parsed = parse_version(version)
        except ValueError:
            return False
        return all(clause(parsed) for clause in clauses)

    return matches


def version_key(version: str) -> Version:
    """Sort key; unparseable versions sort first."""
    try:
        return parse_version(version)
    except ValueError:
        return (-1,)
