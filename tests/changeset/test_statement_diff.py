"""The pairing rule on hand-built statement sequences, and its invariants (hypothesis)."""

from __future__ import annotations

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from archmetrics.changeset import pairing, statement_diff
from archmetrics.changeset.statement_diff import Action, diff_statements, similarity
from archmetrics.facts import Deferred, Span, Statement
from archmetrics.sources import codec
from tests.harness import facts_of


def stmts(*items: tuple[str, str]) -> tuple[Statement, ...]:
    """Statements on consecutive lines from (kind, text) pairs."""
    return tuple(Statement(kind, Span(n, n), text) for n, (kind, text) in enumerate(items, 1))


A = ("assign", "x = 1")
B = ("call", "f(x)")
C = ("return", "return x")


def counts(pre: tuple[Statement, ...], post: tuple[Statement, ...]) -> tuple[int, int, int]:
    change = diff_statements(pre, post)
    return change.added, change.removed, change.modified


def test_identical_is_zero() -> None:
    assert counts(stmts(A, B, C), stmts(A, B, C)) == (0, 0, 0)


def test_insert_and_delete() -> None:
    assert counts(stmts(A, C), stmts(A, B, C)) == (1, 0, 0)
    assert counts(stmts(A, B, C), stmts(A, C)) == (0, 1, 0)


def test_same_kind_in_place_is_modified_with_spans_on_both_sides() -> None:
    change = diff_statements(stmts(A, ("if", "if x > 0:"), C), stmts(A, ("if", "if x >= 0:"), C))
    assert (change.added, change.removed, change.modified) == (0, 0, 1)
    (only,) = change.changes
    assert only.action is Action.MODIFIED
    assert only.pre is not None and only.pre.text == "if x > 0:" and only.pre.span == Span(2, 2)
    assert only.post is not None and only.post.text == "if x >= 0:"
    assert only.similarity is not None and 0.5 < only.similarity < 1


def test_different_kind_pairs_only_when_similar() -> None:
    # assignment dropped, call kept: similar tokens -> modified
    assert counts(stmts(("assign", "y = f(a, b)")), stmts(("call", "f(a, b)"))) == (0, 0, 1)
    # unrelated kinds and texts -> removed + added
    assert counts(stmts(("assign", "y = 1")), stmts(("call", "go()"))) == (1, 1, 0)


def test_pairing_prefers_the_most_similar_partner() -> None:
    pre = stmts(A, ("call", "send(a, b)"), C)
    post = stmts(A, ("call", "send(a, b, c)"), ("call", "log()"), C)
    change = diff_statements(pre, post)
    assert (change.added, change.removed, change.modified) == (1, 0, 1)
    modified = next(c for c in change.changes if c.action is Action.MODIFIED)
    assert modified.post is not None and modified.post.text == "send(a, b, c)"


def test_moved_statement_is_removed_and_added_and_flagged() -> None:
    change = diff_statements(stmts(A, B, C), stmts(B, C, A))
    assert (change.added, change.removed, change.modified) == (1, 1, 0)
    assert all(c.moved for c in change.changes)


def test_similarity_is_over_tokens() -> None:
    assert similarity("count = 0", "n = 0") == pytest.approx(2 * 2 / 6)
    assert similarity("", "") == 1.0


def test_similarity_is_the_lcs_ratio_not_difflibs() -> None:
    """2·LCS/T: the tokens of 'a = b ( c )' and 'c ( a , b )' have a longest common
    subsequence of 3 ('a b )'), so 6/12; difflib's Ratcliff-Obershelp ratio, used before,
    takes the first longest block ('a' with 'a') and finds only 2 (4/12), so they did not pair.
    """
    assert similarity("a = b ( c )", "c ( a , b )") == pytest.approx(0.5)
    pre, post = stmts(("assign", "a = b ( c )")), stmts(("call", "c ( a , b )"))
    assert counts(pre, post) == (0, 0, 1)


def test_huge_replace_runs_pair_greedily_and_say_so(monkeypatch: pytest.MonkeyPatch) -> None:
    pre = stmts(*[("call", f"old_{i}(a)") for i in range(30)])
    post = stmts(*[("call", f"new_{i}(a)") for i in range(31)])
    exact = diff_statements(pre, post)
    assert not exact.approximate and (exact.modified, exact.added) == (30, 1)
    monkeypatch.setattr(pairing, "EXACT_PAIRING_CELLS", 100)
    rough = diff_statements(pre, post)
    assert rough.approximate and (rough.modified, rough.added) == (30, 1)


def test_a_square_run_of_matching_kinds_pairs_in_place_at_any_size(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    pre = stmts(*[("call" if i % 3 else "if", f"old_{i}(a)") for i in range(30)])
    post = stmts(*[("call" if i % 3 else "if", f"new({i})") for i in range(30)])
    monkeypatch.setattr(pairing, "EXACT_PAIRING_CELLS", 100)
    change = diff_statements(pre, post)
    assert not change.approximate and change.modified == 30
    assert [(c.pre, c.post) for c in change.changes] == list(zip(pre, post, strict=True))
    assert change.changes[0].similarity == similarity("old_0(a)", "new(0)")  # when asked


_PAIR_TEXTS = st.text("ab(=) ", max_size=8)
_SAME_KINDS = st.lists(
    st.tuples(st.sampled_from(["assign", "call", "if"]), _PAIR_TEXTS), min_size=1, max_size=8
)


@settings(max_examples=200, deadline=None)
@given(_SAME_KINDS, st.data())
def test_the_in_place_pairing_is_what_the_exact_rule_chooses(
    pre_items: list[tuple[str, str]], data: st.DataObject
) -> None:
    size = len(pre_items)
    texts = data.draw(st.lists(_PAIR_TEXTS, min_size=size, max_size=size))
    removed = stmts(*pre_items)
    added = stmts(*[(kind, text) for (kind, _), text in zip(pre_items, texts, strict=True)])
    forced = pairing.forced(removed, added)
    assert forced is not None
    assert [(i, j) for i, j, _ in pairing.pair_exact(removed, added)] == [
        (i, j) for i, j, _ in forced
    ]


_KINDS = st.sampled_from(["assign", "call", "if", "return"])
_TEXTS = st.sampled_from(["x = 1", "x = 2", "f(x)", "g(y, z)", "if a:", "return b", ""])
_SEQ = st.lists(st.tuples(_KINDS, _TEXTS), max_size=25)


@settings(max_examples=200, deadline=None)
@given(_SEQ, _SEQ)
def test_counts_balance_and_are_never_negative(
    pre_items: list[tuple[str, str]], post_items: list[tuple[str, str]]
) -> None:
    pre, post = stmts(*pre_items), stmts(*post_items)
    change = diff_statements(pre, post)
    assert change.added - change.removed == len(post) - len(pre)
    assert min(change.added, change.removed, change.modified) >= 0
    assert change.removed + change.modified <= len(pre)
    assert change.added + change.modified <= len(post)
    assert len(change.changes) == change.total
    pairs = [c for c in change.changes if c.action is Action.MODIFIED]
    for c in pairs:
        assert c.pre is not None and c.post is not None
        assert c.pre.kind == c.post.kind or similarity(c.pre.text, c.post.text) >= 0.5
    pre_lines = [c.pre.span.start for c in pairs if c.pre]
    post_lines = [c.post.span.start for c in pairs if c.post]
    assert pre_lines == sorted(pre_lines) and post_lines == sorted(post_lines)  # no crossing


@settings(max_examples=100, deadline=None)
@given(_SEQ)
def test_identical_sequences_count_zero(items: list[tuple[str, str]]) -> None:
    change = diff_statements(stmts(*items), stmts(*items))
    assert change.total == 0 and change.changes == ()


def test_cached_files_that_changed_only_in_layout_are_not_decoded() -> None:
    before = facts_of("def f(a):\n    return a+1\n", "python")
    after = facts_of("# note\ndef f(a):\n\n    return a + 1  # same\n", "python")
    changed = facts_of("def f(a):\n    return a + 2\n", "python")
    pre, post, other = (codec.decode(codec.encode(f), "m.py") for f in (before, after, changed))
    assert isinstance(pre.statements, Deferred) and isinstance(post.statements, Deferred)
    change = statement_diff.diff_files(pre, post)
    assert (change.added, change.removed, change.modified) == (0, 0, 0)
    assert (pre.statements._items, post.statements._items) == (None, None)
    assert statement_diff.diff_files(pre, other).modified == 1  # decoded when they differ


def _reference_pairs(
    removed: tuple[Statement, ...], added: tuple[Statement, ...]
) -> list[tuple[int, int]]:
    """The rule, written the plain way: a table of (pairs, summed similarity in quanta)."""
    m, n = len(removed), len(added)
    best = [[(0, 0)] * (n + 1) for _ in range(m + 1)]
    for i in range(1, m + 1):
        for j in range(1, n + 1):
            value = max(best[i - 1][j], best[i][j - 1])
            ratio = similarity(removed[i - 1].text, added[j - 1].text)
            if pairing.may_pair(removed[i - 1], added[j - 1], ratio):
                count, score = best[i - 1][j - 1]
                value = max(value, (count + 1, score + round(ratio * pairing.SCORE_QUANTUM)))
            best[i][j] = value
    pairs, i, j = [], m, n
    while i > 0 and j > 0:
        if best[i][j] == best[i - 1][j]:
            i -= 1
        elif best[i][j] == best[i][j - 1]:
            j -= 1
        else:
            pairs.append((i - 1, j - 1))
            i, j = i - 1, j - 1
    return pairs[::-1]


_RUN = st.lists(st.tuples(_KINDS, st.text("ab(=) ,", max_size=10)), max_size=12)


@settings(max_examples=300, deadline=None)
@given(_RUN, _RUN)
def test_the_table_in_numpy_and_in_python_is_the_rule(
    removed_items: list[tuple[str, str]], added_items: list[tuple[str, str]]
) -> None:
    """Both ways to run the table (numpy when installed, Python's built-ins when not) give
    the pairs of the rule, and the same ratios."""
    removed, added = stmts(*removed_items), stmts(*added_items)
    reference = _reference_pairs(removed, added)
    in_numpy = pairing.pair_exact_numpy(removed, added)
    in_python = pairing.pair_exact_python(removed, added)
    assert [(i, j) for i, j, _ in in_numpy] == reference
    assert in_python == in_numpy


@given(_SEQ, _SEQ, st.booleans())
def test_a_change_record_gives_back_the_change(
    pre_items: list[tuple[str, str]], post_items: list[tuple[str, str]], in_function: bool
) -> None:
    # the record the cache keeps (through JSON, as it is stored) makes the same change
    function = "pkg.f" if in_function else None
    pre = tuple(s._replace(function=function) for s in stmts(*pre_items))
    post = stmts(*post_items)
    change = diff_statements(pre, post, "a.py", "b.py")
    record = json.loads(json.dumps(statement_diff.change_record(change)))
    assert statement_diff.change_from_record(record, "a.py", "b.py") == change


def test_a_change_record_that_does_not_add_up_is_refused() -> None:
    change = diff_statements(stmts(A, B), stmts(A, C, B))
    record = statement_diff.change_record(change)
    assert statement_diff.change_from_record(record, None, None) is not None
    assert statement_diff.change_from_record([0, *record[1:]], None, None) is None
    assert statement_diff.change_from_record([*record[:4], []], None, None) is None
    assert statement_diff.change_from_record(record[:4], None, None) is None


def test_a_change_record_keeps_a_lone_surrogate_through_ascii_json() -> None:
    change = diff_statements(stmts(A), stmts(("assign", 'x = "\ud800"')))
    stored = json.dumps(statement_diff.change_record(change)).encode()  # as the cache keeps it
    assert statement_diff.change_from_record(json.loads(stored), None, None) == change
