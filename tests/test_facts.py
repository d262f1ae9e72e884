"""Facts records: a Deferred sequence behaves as the tuple it stands for."""

from __future__ import annotations

import pickle

import pytest

from archmetrics.facts import (
    Deferred,
    FileFacts,
    Span,
    Statement,
    kept_digest,
    statements_digest,
)

STATEMENTS = (Statement("assign", Span(1, 1), "x = 1"), Statement("pass", Span(2, 2), "pass"))


def deferred(calls: list[int] | None = None) -> Deferred[Statement]:
    def make() -> tuple[Statement, ...]:
        if calls is not None:
            calls.append(1)
        return STATEMENTS

    return Deferred(len(STATEMENTS), make)


def test_items_are_made_once_and_only_when_read() -> None:
    calls: list[int] = []
    lazy = deferred(calls)
    assert len(lazy) == 2 and calls == []
    assert lazy[0].text == "x = 1" and list(lazy) == list(STATEMENTS) and lazy[1:] == STATEMENTS[1:]
    assert calls == [1]


def test_it_equals_and_hashes_as_its_tuple_both_ways() -> None:
    assert deferred() == STATEMENTS and deferred() == STATEMENTS
    assert deferred() != STATEMENTS[:1] and deferred() != list(STATEMENTS)
    assert hash(deferred()) == hash(STATEMENTS)
    lazy = FileFacts("a.py", "python", statements=deferred())
    assert lazy == FileFacts("a.py", "python", statements=STATEMENTS)
    assert hash(lazy) == hash(FileFacts("a.py", "python", statements=STATEMENTS))


def test_it_pickles_as_a_plain_tuple() -> None:
    assert pickle.loads(pickle.dumps(deferred())) == STATEMENTS
    assert type(pickle.loads(pickle.dumps(deferred()))) is tuple


def test_a_wrong_count_is_an_error_not_a_silent_difference() -> None:
    with pytest.raises(ValueError, match="3 announced"):
        Deferred(3, lambda: STATEMENTS)[0]


def test_the_statements_digest_sees_kinds_and_texts_not_lines() -> None:
    moved = tuple(s._replace(span=Span(s.span.start + 5, s.span.end + 5)) for s in STATEMENTS)
    assert statements_digest(moved) == statements_digest(STATEMENTS)
    renamed = (STATEMENTS[0]._replace(text="x = 2"), STATEMENTS[1])
    rekinded = (STATEMENTS[0]._replace(kind="expr"), STATEMENTS[1])
    digests = {statements_digest(s) for s in (STATEMENTS, renamed, rekinded, STATEMENTS[:1])}
    assert len(digests) == 4
    assert kept_digest(STATEMENTS) is None
    assert kept_digest(Deferred(2, lambda: STATEMENTS, digest="abc")) == "abc"
