"""FileFacts to and from compact JSON, for the cache. Never pickle: a cache file is not trusted.

An entry is four JSON documents on four lines: everything but the call sites, the statements
and the bindings (the head), then the call sites, the statements and the bindings (the
body). The facts cache keeps the head and the body apart (``split``): a look-up reads the
head alone, and the body only when a file's statements, call sites or bindings are first
used. ``decode`` reads the head and leaves the others as bytes until first read
(:class:`~archmetrics.facts.Deferred`): a diff reads the statements of the files that
changed, coupling the call sites of files where a rule names one of their callees and the
bindings of the files it traces endpoints through, and building those records was most of
a warm diff's decode (docs/performance.md). The head holds the count and CRC-32 of each of
the other three (so damage to them is found when they are read: then the cache forgets the
entry), the file's callees and the digest of its statements' kinds and texts (a file that
changed only in layout or comments is then found unchanged without decoding its
statements).

The path is left out, so one entry serves every path that holds the same blob; ``decode``
puts the reader's path back. Anything malformed raises :class:`CodecError`.
"""

from __future__ import annotations

import functools
import json
import zlib
from collections.abc import Callable
from sys import intern
from typing import Any, ParamSpec, TypeVar

from archmetrics.facts import (
    Argument,
    Binding,
    CallSite,
    Class,
    ConfigTable,
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

FORMAT = 10
BODY_LINES = 3  # call sites, statements, bindings

_new = tuple.__new__


class CodecError(ValueError):
    """A cache entry that is not facts in our format."""


def _span(s: Span) -> list[int]:
    return [s.start, s.end]


# the records are trees of tuples built here, never cyclic: no check for cycles, which costs
# a dictionary entry per list written (-12% of the encoding)
_ENCODER = json.JSONEncoder(separators=(",", ":"), ensure_ascii=False, check_circular=False)
_ASCII_ENCODER = json.JSONEncoder(separators=(",", ":"), check_circular=False)


def _json(document: Any) -> bytes:
    text = _ENCODER.encode(document)
    try:
        return text.encode("utf-8")
    except UnicodeEncodeError:  # a lone surrogate (the value of "\ud800" in Python): escaped
        return _ASCII_ENCODER.encode(document).encode("ascii")


def encode(facts: FileFacts) -> bytes:
    # records are named tuples: json writes each as a list in its fields' order, in C
    statements = _json(tuple(facts.statements))  # [kind, [start, end], text, function]
    calls = _json(tuple(facts.call_sites))  # [callee, name, receiver, span, args, fn, templates,
    # target]
    bindings = _json(tuple(facts.bindings))  # [name, value, line, function]
    document = [
        FORMAT,
        facts.language,
        [len(facts.statements), zlib.crc32(statements), statements_digest(facts.statements)],
        [len(facts.call_sites), zlib.crc32(calls), sorted(facts.callees())],
        [len(facts.bindings), zlib.crc32(bindings)],
        [
            [
                f.name,
                f.qualified_name,
                *_span(f.span),
                f.statements,
                [[d.kind, d.line] for d in f.decisions],
                list(f.parameters),
                list(f.suppressed),
                f.estimated,
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
        [
            [list(t.keys), t.line, [[k, list(vs)] for k, vs in t.values], t.parent]
            for t in facts.tables
        ],
    ]
    # four lines: JSON escapes the newlines inside strings
    return b"\n".join((_json(document), calls, statements, bindings))


class _Spans(dict[tuple[int, int], Span]):
    """One Span object per line range: records on a line share it."""

    def __missing__(self, key: tuple[int, int]) -> Span:
        made = self[key] = Span(*key)  # checks the range: the bytes are not trusted
        return made


# Where a record's body can be read again (the facts cache's row), a function that reads it:
# then the call sites and statements are not kept as bytes until first read but read again
# then (most never are); and one that forgets the record, called when the body read then is
# not the one its head describes (so that the next run measures the file again)
Again = Callable[[], bytes | None]
Forget = Callable[[], None]


def split(record: bytes) -> tuple[bytes, bytes]:
    """A record's head (its first line) and its body (the call sites, statements and
    bindings)."""
    head, _, body = record.partition(b"\n")
    return head, body


def _deferred(
    data: bytes | None,
    count: Any,
    checksum: Any,
    what: str,
    path: str,
    make: Callable[[Any], list[Any]],
    keys: frozenset[str] | None = None,
    digest: str | None = None,
    again: tuple[Again, int, Forget | None] | None = None,
) -> Deferred[Any]:
    """Records left as bytes until first read; their count and checksum are checked now if
    the bytes are given. ``again``: the body's reader, the line of the body these records
    are on, and what forgets the record; the bytes are then dropped (or never read) and read
    on first use, checked against the checksum."""
    if type(count) is not int or type(checksum) is not int:
        raise CodecError(f"the {what} have no count or checksum")
    if data is not None and zlib.crc32(data) != checksum:
        raise CodecError(f"the {what} do not match their checksum")
    if again is None:
        if data is None:
            raise CodecError(f"the {what} are missing")
        payload: Callable[[], bytes] = lambda: data  # noqa: E731
    else:
        payload = _reread(again, checksum, what, path)

    def made() -> tuple[Any, ...]:
        try:
            records = make(json.loads(payload()))
        except (ValueError, TypeError) as error:
            raise CodecError(f"bad {what} in the cached facts of {path}: {error}") from error
        if len(records) != count:
            raise CodecError(f"{len(records)} {what} in the cached facts of {path}, not {count}")
        return tuple(records)

    return Deferred(count, made, keys, digest)


def _reread(
    again: tuple[Again, int, Forget | None], checksum: int, what: str, path: str
) -> Callable[[], bytes]:
    """A reader of one line of a record's body, which must be the line its head describes."""
    read, line, forget = again

    def payload() -> bytes:
        body = read()
        lines = body.split(b"\n", 2) if body is not None else []
        if len(lines) != BODY_LINES or zlib.crc32(lines[line]) != checksum:
            if forget is not None:
                forget()
            raise CodecError(
                f"the {what} of {path} are no longer in the facts cache as its entry says"
                " (was it cleared or changed meanwhile?); the entry is dropped: run the"
                " command again"
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


def _bindings(rows: list[list[Any]]) -> list[Binding]:
    made = [
        _new(Binding, (intern(n), intern(v), line, fn and intern(fn))) for n, v, line, fn in rows
    ]
    if any(type(b.line) is not int for b in made):
        raise ValueError("a binding's line is not a number")
    return made


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

    made = [
        _new(
            CallSite,
            (
                intern(callee),
                intern(call),
                recv and intern(recv),
                spans[a, b],
                arguments(args),
                fn and intern(fn),
                tuple(templates) if templates else (),
                target,
            ),
        )
        for callee, call, recv, (a, b), args, fn, templates, target in rows
    ]
    if not all(
        all(type(t) is str for t in call.templates)
        and (call.target is None or type(call.target) is str)
        for call in made
    ):
        raise ValueError("a call's template arguments or target are not text")
    return made


_T = TypeVar("_T")
_P = ParamSpec("_P")


def _malformed_is_codec_error(read: Callable[_P, _T]) -> Callable[_P, _T]:
    """``read`` with what a malformed record raises (bad JSON, a wrong shape or type) turned
    into :class:`CodecError`."""

    @functools.wraps(read)
    def checked(*args: _P.args, **kwargs: _P.kwargs) -> _T:
        try:
            return read(*args, **kwargs)
        except CodecError:
            raise
        except (ValueError, TypeError, KeyError) as error:
            raise CodecError(f"not a facts record: {error}") from error

    return checked


@_malformed_is_codec_error
def _decode(
    head: bytes,
    body: tuple[bytes, bytes, bytes] | None,
    path: str,
    again: Again | None,
    forget: Forget | None,
) -> FileFacts:
    calls, statements, bindings = body if body is not None else (None, None, None)
    (
        fmt,
        language,
        (statement_count, statement_checksum, digest),
        (call_count, call_checksum, callees),
        (binding_count, binding_checksum),
        functions,
        classes,
        deps,
        sloc,
        warnings,
        parsed,
        generated,
        tables,
    ) = json.loads(head)
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
            again=None if again is None else (again, 1, forget),
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
                        tuple([intern(p) for p in ps]),
                        tuple(sp),
                        es is True,
                    ),
                )
                for n, q, a, b, st, ds, ps, sp, es in functions
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
            again=None if again is None else (again, 0, forget),
        ),
        bindings=_deferred(
            bindings,
            binding_count,
            binding_checksum,
            "bindings",
            path,
            _bindings,
            again=None if again is None else (again, 2, forget),
        ),
        sloc=sloc,
        warnings=tuple(ParseWarning(path, line, m, Severity(sev)) for line, m, sev in warnings),
        parsed=parsed,
        generated=generated,
        tables=tuple([_table(*table) for table in tables]),
    )


def _table(keys: list[Any], line: Any, values: list[Any], parent: Any) -> ConfigTable:
    """A configuration table read back, every part checked (the cache is not trusted)."""
    texts = [*keys, *(k for k, _ in values), *(v for _, vs in values for v in vs)]
    if not all(isinstance(t, str) for t in texts) or type(line) is not int or line < 1:
        raise CodecError("a configuration table of other than text and a line")
    if type(parent) is not int or parent < -1:
        raise CodecError("a configuration table's parent is not an index")
    return ConfigTable(tuple(keys), line, tuple((k, tuple(vs)) for k, vs in values), parent)


def decode(
    data: bytes, path: str, again: Again | None = None, forget: Forget | None = None
) -> FileFacts:
    """The facts ``encode`` wrote, now at ``path``; CodecError for anything else. ``again``:
    reads the record's body again (from the facts cache), so that the statements and call
    sites are not held as bytes until first read (their checksums are checked now and then)."""
    lines = data.split(b"\n", 3)
    if len(lines) != 1 + BODY_LINES:
        raise CodecError(f"not a facts record: not {1 + BODY_LINES} lines")
    return _decode(lines[0], (lines[1], lines[2], lines[3]), path, again, forget)


def decode_head(head: bytes, path: str, again: Again, forget: Forget | None = None) -> FileFacts:
    """The facts of a record's head (``split``), their call sites and statements read by
    ``again`` on first use and checked then; CodecError for anything else."""
    return _decode(head, None, path, again, forget)
