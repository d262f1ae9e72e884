"""What one file may cost the parser layer before it is reported as not measured instead.

docs/metrics.md ("Limits") explains each limit and its default. A file over a limit is no
error of the run: it comes back as ``FileFacts(parsed=False)`` with one warning that names
the limit and how to raise it, like any file a parser cannot read.
"""

from __future__ import annotations

import sys
import threading
from dataclasses import dataclass, field

from archmetrics.facts import FileFacts, ParseWarning, Severity
from archmetrics.parsers.c_family_macro_rules import MacroNames

_MIB = 1 << 20
_REFERENCE_STACK = 8 * _MIB  # the main thread's stack on Linux and macOS by default


@dataclass(frozen=True, slots=True)
class ParseLimits:
    """Per-file limits (docs/metrics.md, "Limits").

    ``max_bytes``: a larger file is not read at all (the parsers' memory grows with the
    file: about 110 MB per MB of Python, 40 MB per MB of C). ``max_depth``: the deepest
    syntax tree a reader builds or walks (Python: each bracket, each operator of a chain
    such as ``a + b + c``, each ``elif`` is a level; C and C++: tree-sitter's tree, whose
    query goes no deeper than 65,000). ``parse_seconds``: tree-sitter's parse of one C or
    C++ file is cut off after this much wall-clock time. ``c_macros``: not a limit but the
    one other thing a parser is told, the C/C++ macros the configuration names
    (``[tool.archmetrics.macros]``, docs/metrics.md "Macros").
    """

    max_bytes: int = 16 * _MIB
    max_depth: int = 20_000
    parse_seconds: float = 20.0
    c_macros: MacroNames = field(default_factory=MacroNames)

    def __post_init__(self) -> None:
        for name in ("max_bytes", "max_depth", "parse_seconds"):
            if not getattr(self, name) > 0:
                raise ValueError(f"ParseLimits.{name} must be positive, got {getattr(self, name)}")


DEFAULT_LIMITS = ParseLimits()


def not_measured(path: str, language: str, line: int, message: str) -> FileFacts:
    """Facts of a file a limit kept from being measured: nothing but the reason."""
    warning = ParseWarning(path, line, message, Severity.ERROR)
    return FileFacts(path=path, language=language, parsed=False, warnings=(warning,))


def too_large(path: str, language: str, size: int, limits: ParseLimits) -> FileFacts:
    """A file over ``max_bytes``."""
    message = (
        f"file is {size:,} bytes; the limit is {limits.max_bytes:,}"
        " (raise limits.file-mb, ParseLimits.max_bytes, to measure it)"
    )
    return not_measured(path, language, 1, message)


def stack_bytes() -> int:
    """The stack the current thread may grow to, as far as it can be known.

    The main thread's is the ``RLIMIT_STACK`` soft limit (``ulimit -s``; unlimited is taken
    as 64 MiB); another thread's is what ``threading.stack_size`` was set to when it
    started, or, left at the platform's default, taken as 1 MiB (the smallest common one)."""
    if threading.current_thread() is not threading.main_thread():
        return threading.stack_size() or _MIB
    if sys.platform == "win32":
        return _MIB
    import resource

    soft, _ = resource.getrlimit(resource.RLIMIT_STACK)
    if soft == resource.RLIM_INFINITY or soft <= 0:
        return 64 * _MIB
    return int(soft)


def stack_share(limit: int) -> int:
    """``limit`` (chosen for an 8 MiB stack) scaled down to a smaller stack, never up."""
    stack = stack_bytes()
    if stack >= _REFERENCE_STACK:
        return limit
    return max(1, limit * stack // _REFERENCE_STACK)


__all__ = [
    "DEFAULT_LIMITS",
    "ParseLimits",
    "not_measured",
    "stack_bytes",
    "stack_share",
    "too_large",
]
