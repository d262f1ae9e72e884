"""Python parser: source text in, :class:`FileFacts` out.

Two readers apply the same rules (docs/metrics.md, "How a file is read"): the standard
library's (``ast`` and the token stream, python_ast.py) reads every file the running
interpreter parses; libcst's (python_walk.py) reads the rest, and is imported only then.
Bad input never raises: a file neither can parse is reported with a warning naming the line,
and nothing is guessed from it. Nor may input crash the process or run away: how deep a tree
either reader builds is bounded (docs/metrics.md, "Limits"), and libcst, whose native parser
overflows its stack on deep input instead of raising, never sees source nested deeper than
it can take.
"""

from __future__ import annotations

import ast
import re
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING

from archmetrics.facts import FileFacts, Language, ParseWarning, Severity
from archmetrics.parsers import python_ast
from archmetrics.parsers.limits import DEFAULT_LIMITS, ParseLimits
from archmetrics.parsers.python_limits import (
    LIBCST_DEPTH,
    LIBCST_ELIFS,
    LIBCST_WALK_FRAMES,
    ast_depth,
    below_interpreter,
    beyond_libcst,
    recursion_room,
    too_deep_for_ast,
)
from archmetrics.parsers.python_shown import PendingCall

if TYPE_CHECKING:
    import libcst as cst

_ERROR_AT = re.compile(r"error at (\d+):(\d+)")
_ERROR_PREFIX = re.compile(r"^(?:parser|tokenizer) error: (?:error at \d+:\d+: )?")

_BRACKETS_MESSAGE = "too many nested parentheses"  # CPython's tokenizer, at 200 levels


class _TooDeep(Exception):
    """The interpreter gave up on the nesting (``kind``): libcst would fare worse."""

    def __init__(self, kind: str):
        super().__init__(kind)
        self.kind = kind


def parse(path: str, source: str, limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    """Facts of one Python file (``generated`` is left to the registry)."""
    if "\r" in source:  # Python reads \r\n and lone \r as newlines; so do we
        source = source.replace("\r\n", "\n").replace("\r", "\n")
    depth = ast_depth(limits)
    try:
        tree = _standard_tree(source, depth)
    except _TooDeep as refusal:
        return too_deep_for_ast(path, source, refusal.kind, depth, limits)
    if tree is not None:
        refused = below_interpreter(path, source, depth, limits)
        if refused is not None:
            return refused
        try:
            return python_ast.read(path, source, tree)
        except Exception:  # libcst below reads it, the same rules
            pass
    return parse_with_libcst(path, source, limits)


def _standard_tree(source: str, depth: int = DEFAULT_LIMITS.max_depth) -> ast.Module | None:
    """The running interpreter's syntax tree of ``source``, at most ``depth`` levels deep,
    or None when it rejects the source. Raises :class:`_TooDeep` when the interpreter gives
    up on the nesting, not the syntax."""
    try:
        with warnings.catch_warnings(), recursion_room(depth // 3 + 1):
            warnings.simplefilter("ignore")  # "invalid escape sequence" is the author's business
            return ast.parse(source)
    except RecursionError:  # deeper than ``depth``
        raise _TooDeep("depth") from None
    except MemoryError:  # the parser's own stack (6,000 rules deep), or memory itself
        raise _TooDeep("memory") from None
    except SyntaxError as error:
        if error.msg == _BRACKETS_MESSAGE:
            raise _TooDeep("brackets") from None
        return None
    except (ValueError, OverflowError):
        return None


def parse_with_libcst(path: str, source: str, limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    """Facts of one Python file through libcst (newlines already normalized)."""
    refusal = beyond_libcst(path, source, limits)
    if refusal is not None:
        return refusal
    import libcst as cst

    from archmetrics.parsers.python_walk import FactsWalker

    try:
        with _unvalidated_nodes():
            module = cst.parse_module(source)
    except cst.ParserSyntaxError as error:
        message = _ERROR_PREFIX.sub("", error.message)
        return _unparsed(path, _error_line(error, source), f"Python syntax error: {message}")
    except RecursionError:
        return _unparsed(path, 1, "Python source nested too deeply to parse")
    except Exception as error:  # the native parser's own failures on odd input
        return _unparsed(path, 1, f"Python parser failed: {type(error).__name__}: {error}")
    walker = FactsWalker()
    try:
        with recursion_room(LIBCST_WALK_FRAMES * (LIBCST_DEPTH + LIBCST_ELIFS)):
            module._codegen(walker)
    except RecursionError:
        return _unparsed(path, 1, "Python source nested too deeply to measure")
    walker.give_targets()
    return FileFacts(
        path=path,
        language=Language.PYTHON,
        statements=tuple(walker.statements),
        functions=tuple(f for f in walker.functions if f is not None),
        classes=tuple(c for c in walker.classes if c is not None),
        dependencies=tuple(walker.dependencies),
        call_sites=tuple(
            c.site() if isinstance(c, PendingCall) else c for c in walker.calls if c is not None
        ),
        bindings=tuple(walker.bindings),
        sloc=walker.sloc(source),
    )


def _no_validation(node: cst.CSTNode) -> None:
    """Stands in for ``CSTNode.__post_init__`` while the parser builds a tree."""


@contextmanager
def _unvalidated_nodes() -> Iterator[None]:
    """libcst checks every node as it is built (``CSTNode.__post_init__`` calls
    ``_validate``), which is there for trees built by hand: nodes the parser builds from
    accepted source satisfy those checks by construction, as libcst's own comment on that
    method says. Skipping them takes a quarter off ``parse_module``, the dominant cost of
    measuring Python (docs/performance.md). The hook is put back when the parse ends, even
    on error, so nodes built anywhere else are still checked."""
    from libcst import CSTNode

    original = CSTNode.__dict__.get("__post_init__")
    if original is None:  # a libcst without the hook: nothing to skip
        yield
        return
    CSTNode.__post_init__ = _no_validation  # type: ignore[method-assign,assignment]
    try:
        yield
    finally:
        CSTNode.__post_init__ = original  # type: ignore[method-assign]


def _unparsed(path: str, line: int, message: str) -> FileFacts:
    warning = ParseWarning(path, line, message, Severity.ERROR)
    return FileFacts(path=path, language=Language.PYTHON, parsed=False, warnings=(warning,))


def _error_line(error: cst.ParserSyntaxError, source: str) -> int:
    """The line of a syntax error as CPython reports it (libcst's own lines can be off by one).

    Only paid for on failure: CPython's parser is asked where the error is; if it accepts the
    source, libcst's position stands.
    """
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ast.parse(source)
    except SyntaxError as python_error:
        line = python_error.lineno or 1
    except (ValueError, RecursionError, MemoryError):
        line = error.raw_line
    else:
        found = _ERROR_AT.search(error.message)
        line = int(found.group(1)) if found else error.raw_line
    last = source.count("\n") + (0 if source.endswith("\n") else 1)
    return max(1, min(line, last))
