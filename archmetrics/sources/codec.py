"""FileFacts to and from compact JSON, for the cache. Never pickle: a cache file is not trusted.

An entry is three JSON documents on three lines: everything but the call sites and the
statements, then the call sites, then the statements. ``decode`` reads the first and leaves
the others as bytes until first read (:class:`~archmetrics.facts.Deferred`): a diff reads
the statements of the files that changed, and coupling the call sites of files where a rule
names one of their callees, and building those records was most of a warm diff's decode
(docs/performance.md). The first document holds the count and CRC-32 of each of the other
two (so damage to them is found at once, like any other damage), the file's callees and the
digest of its statements' kinds and texts (a file that changed only in layout or comments
is then found unchanged without decoding its statements).

The path is left out, so one entry serves every path that holds the same blob; ``decode``
puts the reader's path back. Anything malformed raises :class:`CodecError`.
"""

from __future__ import annotations

import json
import zlib
from collections.abc import Callable
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
    statements_digest,
)

FORMAT = 5

_new = tuple.__new__


class CodecError(ValueError):
    """A cache entry that is not facts in our format."""


def _span(s: Span) -> list[int]:
    return [s.start, s.end]


def _json(document: Any) -> bytes:
    text = json.dumps(document, separators=(",", ":"), ensure_ascii=False)
    try:
        return text.encode("utf-8")
    except UnicodeEncodeError:  # a lone surrogate (the value of "\ud800" in Python): escaped
        return json.dumps(document, separators=(",", ":")).encode("ascii")


def encode(facts: FileFacts) -> bytes:
    # records are named tuples: json writes each as a list in its fields' order, in C
    statements = _json(tuple(facts.statements))  # [kind, [start, end], text, function]
    calls = _json(tuple(facts.call_sites))  # [callee, name, receiver, span, arguments, fn]
    document = [
        FORMAT,
        facts.language,
        [len(facts.statements), zlib.crc32(statements), statements_digest(facts.statements)],
        [len(facts.call_sites), zlib.crc32(calls), sorted(facts.callees())],
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
        facts.sloc,
        [[w.line, w.message, str(w.severity)] for w in facts.warnings],
        facts.parsed,
        facts.generated,
    ]
    # three lines: JSON escapes the newlines inside strings
    return b"\n".join((_json(document), calls, statements))


class _Spans(dict[tuple[int, int], Span]):
    """One Span object per line range: records on a line share it."""

    def __missing__(self, key: tuple[int, int]) -> Span:
        made = self[key] = Span(*key)  # checks the range: the bytes are not trusted
        return made


# Where a record can be read again (the facts cache's row), a function that reads it: then
# the records are not kept as bytes until first read but read again then (most never are)
Again = Callable[[], bytes | None]


def _deferred(
    data: bytes,
    count: Any,
    checksum: Any,
    what: str,
    path: str,
    make: Callable[[Any], list[Any]],
    keys: frozenset[str] | None = None,
    digest: str | None = None,
    again: tuple[Again, int] | None = None,
) -> Deferred[Any]:
    """Records left as bytes until first read; their count and checksum are checked now.
    ``again``: the record's reader and the line these records are on; the bytes are then
    dropped and read back on first use, checked against the same checksum."""
    if type(count) is not int or zlib.crc32(data) != checksum:
        raise CodecError(f"the {what} do not match their checksum")
    payload: Callable[[], bytes] = (
        (lambda: data) if again is None else _reread(again, checksum, what, path)
    )

    def made() -> tuple[Any, ...]:
        try:
            records = make(json.loads(payload()))
        except (ValueError, TypeError) as error:
            raise CodecError(f"bad {what} in the cached facts of {path}: {error}") from error
        if len(records) != count:
            raise CodecError(f"{len(records)} {what} in the cached facts of {path}, not {count}")
        return tuple(records)

    return Deferred(count, made, keys, digest)


def _reread(again: tuple[Again, int], checksum: int, what: str, path: str) -> Callable[[], bytes]:
    """A reader of one line of a record, which must be the line that was checked."""
    read, line = again

    def payload() -> bytes:
        record = read()
        lines = record.split(b"\n", 2) if record is not None else []
        if len(lines) != 3 or zlib.crc32(lines[line]) != checksum:
            raise CodecError(
                f"the {what} of {path} are no longer in the facts cache as they were when"
                " read (was it cleared or changed meanwhile?); run the command again"
            )
        return lines[line]

    return payload


# The records are named tuples, built by tuple's own constructor (their fields are unpacked
# first, so a record of the wrong length still fails); optional names are None or a string,
# and ``x and intern(x)`` keeps None as None.


def _statements(rows: list[list[Any]]) -> list[Statement]:
    spans = _Spans()
    return [
        _new(Statement, (intern(k), spans[a, b], intern(t), fn and intern(fn)))
        for k, (a, b), t, fn in rows
    ]


def _calls(rows: list[list[Any]]) -> list[CallSite]:
    spans = _Spans()
    lists: dict[tuple[Argument, ...], tuple[Argument, ...]] = {}

    def arguments(args: list[list[Any]]) -> tuple[Argument, ...]:
        """A call's arguments. Calls in a file repeat the same ones (``self``, ``NULL``, ``0``):
        equal lists share one tuple. (An argument's value follows from its text, so equal
        tuples never mix up ``1``, ``1.0`` and ``True``.)"""
        if not args:
            return ()
        made = tuple([_new(Argument, (intern(t), v, lit, kw)) for t, v, lit, kw in args])
        return lists.setdefault(made, made)

    return [
        _new(
            CallSite,
            (
                intern(callee),
                intern(call),
                recv and intern(recv),
                spans[a, b],
                arguments(args),
                fn and intern(fn),
            ),
        )
        for callee, call, recv, (a, b), args, fn in rows
    ]


def _decode(
    document: Any, calls: bytes, statements: bytes, path: str, again: Again | None
) -> FileFacts:
    (
        fmt,
        language,
        (statement_count, statement_checksum, digest),
        (call_count, call_checksum, callees),
        functions,
        classes,
        deps,
        sloc,
        warnings,
        parsed,
        generated,
    ) = document
    if fmt != FORMAT:
        raise CodecError(f"facts format {fmt!r}, expected {FORMAT}")
    spans = _Spans()
    return FileFacts(
        path=path,
        language=intern(language),
        statements=_deferred(
            statements,
            statement_count,
            statement_checksum,
            "statements",
            path,
            _statements,
            digest=digest if isinstance(digest, str) else None,
            again=None if again is None else (again, 2),
        ),
        functions=tuple(
            [
                _new(
                    Function,
                    (
                        n,
                        q,
                        spans[a, b],
                        tuple([_new(Decision, (intern(k), line)) for k, line in ds]),
                        st,
                    ),
                )
                for n, q, a, b, st, ds in functions
            ]
        ),
        classes=tuple([Class(n, q, spans[a, b], k) for n, q, a, b, k in classes]),
        dependencies=tuple(
            [
                Dependency(t, DependencyKind(k), spans[a, b], lv, tuple(ns), tuple(bn))
                for t, k, a, b, lv, ns, bn in deps
            ]
        ),
        call_sites=_deferred(
            calls,
            call_count,
            call_checksum,
            "call sites",
            path,
            _calls,
            frozenset(intern(callee) for callee in callees),
            again=None if again is None else (again, 1),
        ),
        sloc=sloc,
        warnings=tuple(ParseWarning(path, line, m, Severity(sev)) for line, m, sev in warnings),
        parsed=parsed,
        generated=generated,
    )


def decode(data: bytes, path: str, again: Again | None = None) -> FileFacts:
    """The facts ``encode`` wrote, now at ``path``; CodecError for anything else. ``again``:
    reads ``data`` again (from the facts cache), so that the statements and call sites are
    not held as bytes until first read (their checksums are checked now and then)."""
    lines = data.split(b"\n", 2)
    if len(lines) != 3:
        raise CodecError("not a facts record: not three lines")
    try:
        return _decode(json.loads(lines[0]), lines[1], lines[2], path, again)
    except CodecError:
        raise
    except (ValueError, TypeError, KeyError) as error:
        raise CodecError(f"not a facts record: {error}") from error
