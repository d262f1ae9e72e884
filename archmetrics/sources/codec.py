"""FileFacts to and from compact JSON, for the cache. Never pickle: a cache file is not trusted.

An entry is two JSON documents on two lines: everything but the statements, then the
statements. ``decode`` reads the first and leaves the second as bytes until the statements
are first read (:class:`~archmetrics.facts.Deferred`): a diff reads the statements of the
files that changed and of few others, and decoding them was half of a warm diff's decode
(docs/performance.md). The first document holds the statements' count and CRC-32, so a
damaged second line is found at once, like any other damage.

The path is left out, so one entry serves every path that holds the same blob; ``decode``
puts the reader's path back. Anything malformed raises :class:`CodecError`.
"""

from __future__ import annotations

import json
import zlib
from sys import intern
from typing import Any

from archmetrics.facts import (
    Argument,
    CallSite,
    Class,
    Decision,
    Deferred,
    Dependency,
    DependencyKind,
    FileFacts,
    Function,
    ParseWarning,
    Severity,
    Span,
    Statement,
)

FORMAT = 2

_new = tuple.__new__


class CodecError(ValueError):
    """A cache entry that is not facts in our format."""


def _span(s: Span) -> list[int]:
    return [s.start, s.end]


def _json(document: Any) -> bytes:
    return json.dumps(document, separators=(",", ":"), ensure_ascii=False).encode("utf-8")


def encode(facts: FileFacts) -> bytes:
    statements = _json([[s.kind, *_span(s.span), s.text, s.function] for s in facts.statements])
    document = [
        FORMAT,
        facts.language,
        [len(facts.statements), zlib.crc32(statements)],
        [
            [
                f.name,
                f.qualified_name,
                *_span(f.span),
                f.statements,
                [[d.kind, d.line] for d in f.decisions],
            ]
            for f in facts.functions
        ],
        [[c.name, c.qualified_name, *_span(c.span), c.kind] for c in facts.classes],
        [
            [d.target, str(d.kind), *_span(d.span), d.level, list(d.names), list(d.bound)]
            for d in facts.dependencies
        ],
        [
            [
                c.callee,
                c.name,
                c.receiver,
                *_span(c.span),
                c.function,
                [[a.text, a.value, a.is_literal, a.keyword] for a in c.arguments],
            ]
            for c in facts.call_sites
        ],
        facts.sloc,
        [[w.line, w.message, str(w.severity)] for w in facts.warnings],
        facts.parsed,
        facts.generated,
    ]
    return _json(document) + b"\n" + statements  # JSON escapes newlines inside strings


def _statements(data: bytes, count: int, path: str) -> tuple[Statement, ...]:
    """The statements of an entry, decoded when first read."""
    spans: dict[tuple[int, int], Span] = {}
    known = spans.get
    try:
        made = tuple(
            [
                _new(
                    Statement,
                    (
                        intern(k),
                        known((a, b)) or spans.setdefault((a, b), Span(a, b)),
                        intern(t),
                        fn and intern(fn),
                    ),
                )
                for k, a, b, t, fn in json.loads(data)
            ]
        )
    except (ValueError, TypeError) as error:
        raise CodecError(f"bad statements in the cached facts of {path}: {error}") from error
    if len(made) != count:
        raise CodecError(f"{len(made)} statements in the cached facts of {path}, not {count}")
    return made


def _decode(document: Any, statements: bytes, path: str) -> FileFacts:
    (
        fmt,
        language,
        (count, checksum),
        functions,
        classes,
        deps,
        calls,
        sloc,
        warnings,
        parsed,
        generated,
    ) = document
    if fmt != FORMAT:
        raise CodecError(f"facts format {fmt!r}, expected {FORMAT}")
    if zlib.crc32(statements) != checksum or type(count) is not int:
        raise CodecError("the statements do not match their checksum")
    spans: dict[tuple[int, int], Span] = {}
    known = spans.get  # `known((a, b)) or span(a, b)`: only a C call for a range seen before

    def span(a: int, b: int) -> Span:
        """One Span object per line range: statements and calls on a line share it."""
        made = spans[(a, b)] = Span(a, b)  # checks the range: the bytes are not trusted
        return made

    lists: dict[tuple[Argument, ...], tuple[Argument, ...]] = {}

    def arguments(args: list[list[Any]]) -> tuple[Argument, ...]:
        """A call's arguments. Calls in a file repeat the same ones (``self``, ``NULL``, ``0``):
        equal lists share one tuple. (An argument's value follows from its text, so equal
        tuples never mix up ``1``, ``1.0`` and ``True``.)"""
        if not args:
            return ()
        made = tuple([_new(Argument, (intern(t), v, lit, kw)) for t, v, lit, kw in args])
        return lists.setdefault(made, made)

    # The records are named tuples, built here by tuple's own constructor (their fields are
    # unpacked above it, so a record of the wrong length still fails); optional names are
    # None or a string, and ``x and intern(x)`` keeps None as None.
    return FileFacts(
        path=path,
        language=intern(language),
        statements=Deferred(count, lambda: _statements(statements, count, path)),
        functions=tuple(
            [
                _new(
                    Function,
                    (
                        n,
                        q,
                        known((a, b)) or span(a, b),
                        tuple([_new(Decision, (intern(k), line)) for k, line in ds]),
                        st,
                    ),
                )
                for n, q, a, b, st, ds in functions
            ]
        ),
        classes=tuple([Class(n, q, known((a, b)) or span(a, b), k) for n, q, a, b, k in classes]),
        dependencies=tuple(
            [
                Dependency(
                    t, DependencyKind(k), known((a, b)) or span(a, b), lv, tuple(ns), tuple(bn)
                )
                for t, k, a, b, lv, ns, bn in deps
            ]
        ),
        call_sites=tuple(
            [
                _new(
                    CallSite,
                    (
                        intern(callee),
                        intern(call),
                        recv and intern(recv),
                        known((a, b)) or span(a, b),
                        arguments(args),
                        fn and intern(fn),
                    ),
                )
                for callee, call, recv, a, b, fn, args in calls
            ]
        ),
        sloc=sloc,
        warnings=tuple(ParseWarning(path, line, m, Severity(sev)) for line, m, sev in warnings),
        parsed=parsed,
        generated=generated,
    )


def decode(data: bytes, path: str) -> FileFacts:
    """The facts ``encode`` wrote, now at ``path``; CodecError for anything else."""
    head, newline, statements = data.partition(b"\n")
    if not newline:
        raise CodecError("not a facts record: no statements line")
    try:
        return _decode(json.loads(head), statements, path)
    except CodecError:
        raise
    except (ValueError, TypeError, KeyError) as error:
        raise CodecError(f"not a facts record: {error}") from error
