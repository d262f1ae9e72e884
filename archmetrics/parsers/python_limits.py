"""How deep and how large a Python file each reader may be given (docs/metrics.md, "Limits").

The standard library's reader gets trees up to ``ParseLimits.max_depth`` deep, less on a
small stack: ``ast`` converts its tree to Python objects recursively in C. libcst's reader
gets less: its native parser overflows the stack on deep input (a segmentation fault, not
an exception) and takes time and memory that grow with the square of the depth, so the
source's nesting is counted on its tokens (python_depth.py) before libcst sees it.
"""

from __future__ import annotations

import ast
import sys
import warnings
from collections.abc import Iterator
from contextlib import contextmanager

from archmetrics.facts import FileFacts, Language
from archmetrics.parsers.limits import ParseLimits, not_measured, stack_share
from archmetrics.parsers.python_depth import nesting

# How deep a tree ``ast`` may build on an 8 MiB stack: its converter to Python objects
# recurses in C, about 80 bytes a level (a segmentation fault near 104,000 levels).
AST_STACK_DEPTH = 40_000
# What libcst's native parser may be given on an 8 MiB stack. It recurses 6-8 KB a bracket
# (a segmentation fault near 1,270 nested parentheses) and 1-2.5 KB a level of an operator
# chain, an elif chain or nested lambdas (near 7,000 `+`); its time and memory grow with the
# square of the depth (1,000 nested calls: 10 s, 2.2 GB). 200 brackets is CPython's own limit.
LIBCST_DEPTH = 1_000
LIBCST_BRACKETS = 200
LIBCST_ELIFS = 2_000  # about 1 KB of stack each (near 8,300 a segmentation fault), time linear
# Python frames libcst's code generation stacks per level of the tree it walks.
LIBCST_WALK_FRAMES = 3
# libcst needs about three times the memory of the standard-library reader per byte
# (300 against 110 MB per MB of source): it reads at most this share of ``max_bytes``.
LIBCST_BYTES_SHARE = 4


def ast_depth(limits: ParseLimits) -> int:
    """The deepest tree the ``ast`` reader builds: ``max_depth``, less on a small stack."""
    return min(limits.max_depth, stack_share(AST_STACK_DEPTH))


@contextmanager
def recursion_room(frames: int) -> Iterator[None]:
    """Room for ``frames`` more levels of recursion than the current depth (the limit is
    raised for the while, never lowered: it is the whole process's). ``ast``'s converter
    to Python objects (3.11) stops at three times the recursion limit, counted from the
    current depth, so a tree ``depth`` deep needs ``depth // 3 + 1``; later versions bound
    it by the C stack themselves, and this changes nothing there."""
    before = sys.getrecursionlimit()
    needed = python_depth() + frames + 2
    if needed > before:
        sys.setrecursionlimit(needed)
    try:
        yield
    finally:
        sys.setrecursionlimit(before)


def python_depth() -> int:
    """How many Python frames deep the caller runs."""
    frame = sys._getframe()
    depth = 0
    while frame is not None:
        depth += 1
        frame = frame.f_back  # type: ignore[assignment]
    return depth


def below_interpreter(path: str, source: str, depth: int, limits: ParseLimits) -> FileFacts | None:
    """A tree the interpreter built anyway (its own recursion limit lets ``ast`` build
    about 3,000 levels) checked against a lower ``depth``, on the tokens; None if within."""
    if depth >= 3 * (sys.getrecursionlimit() - python_depth()):
        return None
    found = nesting(source)
    if found.depth <= depth:
        return None
    message = f"Python source nested {found.depth:,} levels deep; {_limit(depth, limits)}"
    return not_measured(path, Language.PYTHON, found.line, message)


def too_deep_for_ast(
    path: str, source: str, kind: str, depth: int, limits: ParseLimits
) -> FileFacts:
    """The facts of a file the interpreter's parser gave up on for its nesting (``kind``:
    "brackets", "depth", "memory"), saying how deep it goes and which limit it passed."""
    found = nesting(source)
    if kind == "brackets":
        message = (
            f"Python source nested {found.brackets:,} brackets deep; the limit is 200"
            " (CPython's own: no Python version runs it)"
        )
    elif kind == "depth" and found.depth > depth:
        message = f"Python source nested {found.depth:,} levels deep; {_limit(depth, limits)}"
    elif kind == "memory" and found.depth < _PARSER_STACK_DEPTH:  # memory itself ran out
        lines = source.count("\n") + (not source.endswith("\n"))
        message = (
            f"Python source of {lines:,} lines and {len(source):,} characters: the interpreter's"
            " parser ran out of memory (MemoryError) within the worker's memory limit (raise"
            " limits.worker-memory-mb, or lower limits.file-mb, to measure or skip it sooner)"
        )
    else:  # the interpreter's own parser stopped short of our limit
        cause = "MemoryError" if kind == "memory" else "RecursionError"
        message = (
            f"Python source nested {found.depth:,} levels deep: more than the interpreter's"
            f" parser takes ({cause}; it stops near 6,000 nested conditional expressions)"
        )
    return not_measured(path, Language.PYTHON, found.line, message)


_PARSER_STACK_DEPTH = 1_000
"""Nesting below which a MemoryError of the interpreter's parser is memory running out, not
its own stack (that gives out near 6,000 nested conditional expressions)."""


def _limit(depth: int, limits: ParseLimits) -> str:
    if depth < limits.max_depth:
        return f"the limit is {depth:,} on this thread's stack (ulimit -s)"
    return f"the limit is {depth:,} (raise limits.nesting, ParseLimits.max_depth, to measure it)"


def beyond_libcst(path: str, source: str, limits: ParseLimits) -> FileFacts | None:
    """Why libcst must not read ``source``, as the file's facts; None when it may."""
    most = limits.max_bytes // LIBCST_BYTES_SHARE
    if len(source) > most:
        line, why = _why_libcst(source)
        message = (
            f"{why}; libcst, which reads the rest, reads at most {most:,} characters"
            f" (a quarter of ParseLimits.max_bytes) and this file has {len(source):,}"
        )
        return not_measured(path, Language.PYTHON, line, message)
    found = nesting(source)
    brackets = stack_share(LIBCST_BRACKETS)
    if found.brackets > brackets:
        message = f"Python source nested {found.brackets:,} brackets deep; " + (
            "the limit is 200 (CPython's own: no Python version runs it)"
            if brackets == LIBCST_BRACKETS
            else f"libcst's reader takes {brackets:,} on this thread's stack (ulimit -s)"
        )
        return not_measured(path, Language.PYTHON, found.line, message)
    if found.depth > limits.max_depth:
        message = (
            f"Python source nested {found.depth:,} levels deep; {_limit(limits.max_depth, limits)}"
        )
        return not_measured(path, Language.PYTHON, found.line, message)
    for levels, most, what in (
        (found.expression, stack_share(LIBCST_DEPTH), "levels deep in one statement"),
        (found.elifs, stack_share(LIBCST_ELIFS), "elif branches deep"),
    ):
        if levels > most:
            return not_measured(
                path, Language.PYTHON, found.line, _libcst_message(source, levels, most, what)
            )
    return None


def _libcst_message(source: str, levels: int, most: int, what: str) -> str:
    """Why libcst does not read source nested ``levels`` deep (at most ``most``)."""
    return (
        f"Python source nested {levels:,} {what}; the interpreter does not read it"
        f" ({_why_libcst(source)[1]}), and libcst, which reads the rest, takes at most"
        f" {most:,} (deeper, its native parser overflows the stack or runs for minutes)"
    )


def _why_libcst(source: str) -> tuple[int, str]:
    """Where and why the interpreter's reader did not read ``source``, in a few words."""
    line, message = _interpreter_error(source)
    if not message:
        return line, "its tokens do not line up with the interpreter's tree"
    return line, f"Python syntax error at line {line}: {message}"


def _interpreter_error(source: str) -> tuple[int, str]:
    """Where and why the interpreter rejects ``source``: (1, "") when it does not."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ast.parse(source)
    except SyntaxError as error:
        return error.lineno or 1, error.msg
    except (ValueError, RecursionError, MemoryError, OverflowError) as error:
        return 1, f"{type(error).__name__}: {error}"
    return 1, ""
