"""Γ_A, Γ_R, Γ_M of one file (thesis eqs. 6.11-6.18), counted on statements, not raw lines.

Statements are the parser's logical lines of code (thesis p. 103) with normalized text, so
reformatting, comment edits and splitting a statement over several lines change nothing here.
The pairing rule (docs/metrics.md, "Pairing rule"):

1. Align the pre and post sequences with ``difflib.SequenceMatcher(autojunk=False)`` over the
   keys ``(kind, text)``. ``equal`` runs are unchanged, ``delete`` runs removed, ``insert``
   runs added.
2. Inside each ``replace`` run, a removed statement r and an added statement a *may pair* when
   they have the same kind or their token similarity is at least :data:`SIMILARITY_THRESHOLD`.
   Among order-preserving pairings we take the one with the most pairs, ties broken by the
   largest summed similarity (an LCS over "may pair"). Pairs count as modified; the rest of
   the run counts as removed and added.
3. Runs larger than :data:`EXACT_PAIRING_LIMIT` (removed x added) pair greedily in order and
   mark the file change ``approximate``.

A statement that moved counts as removed at its old place and added at its new one (what a line
diff shows); both sides are flagged ``moved`` so the number can be traced.
"""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from difflib import SequenceMatcher
from enum import StrEnum

from archmetrics.facts import FileFacts, Statement, kept_digest

SIMILARITY_THRESHOLD = 0.5
"""Token ratio 2·M/T at or above which two statements of different kinds still pair."""

EXACT_PAIRING_LIMIT = 2_500
"""Largest removed x added product of one replace run paired exactly (O(m·n) similarity)."""

GREEDY_WINDOW = 20
"""How far ahead the greedy fallback looks for a partner of each removed statement."""

_TOKEN = re.compile(r"\w+|\S")


class Action(StrEnum):
    ADDED = "added"
    REMOVED = "removed"
    MODIFIED = "modified"


@dataclass(frozen=True, slots=True)
class StatementChange:
    """One counted change: the statement(s) behind it, with spans on each side."""

    action: Action
    pre: Statement | None  # None for added
    post: Statement | None  # None for removed
    moved: bool = False  # removed/added text that reappears unchanged on the other side

    @property
    def similarity(self) -> float | None:
        """Token ratio of a modified pair (None otherwise), computed when asked: the pairing
        needs it only where it has a choice, and one statement can be thousands of tokens."""
        if self.action is not Action.MODIFIED or self.pre is None or self.post is None:
            return None
        return similarity(self.pre.text, self.post.text)


@dataclass(frozen=True, slots=True)
class FileChange:
    """Γ_A, Γ_R, Γ_M of one file pair and the statements that make them up."""

    pre_path: str | None
    post_path: str | None
    added: int
    removed: int
    modified: int
    changes: tuple[StatementChange, ...] = ()
    approximate: bool = False  # a replace run exceeded EXACT_PAIRING_LIMIT (greedy pairing)

    @property
    def total(self) -> int:
        """Γ of this file, eq. 6.11 / 6.15 restricted to one file."""
        return self.added + self.removed + self.modified


def tokens(text: str) -> tuple[str, ...]:
    """Word tokens and single punctuation characters: what similarity is measured on."""
    return tuple(_TOKEN.findall(text))


def similarity(a: str, b: str) -> float:
    """difflib ratio 2·M/T over the token sequences of two statement texts (1.0 if both empty)."""
    return SequenceMatcher(None, tokens(a), tokens(b), autojunk=False).ratio()


def _may_pair(removed: Statement, added: Statement, ratio: float) -> bool:
    return removed.kind == added.kind or ratio >= SIMILARITY_THRESHOLD


def _similarities(removed: Sequence[Statement], added: Sequence[Statement]) -> list[list[float]]:
    """Token ratio of every (removed, added) pair that may matter (0.0 where it cannot pair)."""
    removed_tokens = [tokens(r.text) for r in removed]
    table = [[0.0] * len(added) for _ in removed]
    matcher: SequenceMatcher[str] = SequenceMatcher(None, autojunk=False)
    for j, a in enumerate(added):
        matcher.set_seq2(tokens(a.text))
        for i, seq in enumerate(removed_tokens):
            matcher.set_seq1(seq)
            if removed[i].kind != a.kind and matcher.quick_ratio() < SIMILARITY_THRESHOLD:
                continue  # cannot pair: an upper bound of the ratio is already too low
            table[i][j] = matcher.ratio()
    return table


Pairs = list[tuple[int, int, float]]  # (removed index, added index, their token ratio)


def _pair_exact(removed: Sequence[Statement], added: Sequence[Statement]) -> Pairs:
    """Order-preserving pairing with the most pairs, then the most summed similarity."""
    m, n = len(removed), len(added)
    ratio = _similarities(removed, added)
    best = [[(0, 0.0)] * (n + 1) for _ in range(m + 1)]
    for i in range(1, m + 1):
        for j in range(1, n + 1):
            value = max(best[i - 1][j], best[i][j - 1])
            if _may_pair(removed[i - 1], added[j - 1], ratio[i - 1][j - 1]):
                count, score = best[i - 1][j - 1]
                value = max(value, (count + 1, score + ratio[i - 1][j - 1]))
            best[i][j] = value
    pairs: Pairs = []
    i, j = m, n
    while i > 0 and j > 0:
        if best[i][j] == best[i - 1][j]:
            i -= 1
        elif best[i][j] == best[i][j - 1]:
            j -= 1
        else:
            pairs.append((i - 1, j - 1, ratio[i - 1][j - 1]))
            i, j = i - 1, j - 1
    return pairs[::-1]


def _pair_greedy(removed: Sequence[Statement], added: Sequence[Statement]) -> Pairs:
    """Fallback for huge runs: each removed statement takes the first partner ahead of the last."""
    pairs: Pairs = []
    start = 0
    for i, r in enumerate(removed):
        for j in range(start, min(start + GREEDY_WINDOW, len(added))):
            ratio = similarity(r.text, added[j].text)
            if _may_pair(r, added[j], ratio):
                pairs.append((i, j, ratio))
                start = j + 1
                break
    return pairs


def _forced(removed: Sequence[Statement], added: Sequence[Statement]) -> Pairs | None:
    """The pairing when there is nothing to choose: as many removed as added statements, each
    of the same kind as its counterpart. Pairing position by position then pairs them all,
    and no other order-preserving pairing does, so rule 2 picks it whatever the token ratios
    are; they are not computed (in the numpy diff such runs held 2.2 s of 4 s of ratios)."""
    if len(removed) != len(added):
        return None
    if any(r.kind != a.kind for r, a in zip(removed, added, strict=True)):
        return None
    return [(i, i, 1.0) for i in range(len(removed))]  # 1.0: unused, see StatementChange


def _replace_run(
    removed: Sequence[Statement], added: Sequence[Statement]
) -> tuple[list[StatementChange], bool]:
    exact = True
    pairs = _forced(removed, added)
    if pairs is None:
        exact = len(removed) * len(added) <= EXACT_PAIRING_LIMIT
        pairs = (_pair_exact if exact else _pair_greedy)(removed, added)
    paired_r = {i for i, _, _ in pairs}
    paired_a = {j for _, j, _ in pairs}
    changes = [StatementChange(Action.MODIFIED, removed[i], added[j]) for i, j, _ in pairs]
    changes += [
        StatementChange(Action.REMOVED, r, None) for i, r in enumerate(removed) if i not in paired_r
    ]
    changes += [
        StatementChange(Action.ADDED, None, a) for j, a in enumerate(added) if j not in paired_a
    ]
    return changes, not exact


def _key(statement: Statement) -> tuple[str, str]:
    return statement.kind, statement.text


def _flag_moves(changes: list[StatementChange]) -> list[StatementChange]:
    """Mark removed/added statements whose key appears unchanged on the other side."""
    removed = Counter(_key(c.pre) for c in changes if c.action is Action.REMOVED and c.pre)
    added = Counter(_key(c.post) for c in changes if c.action is Action.ADDED and c.post)
    budget = {Action.REMOVED: removed & added, Action.ADDED: added & removed}
    flagged: list[StatementChange] = []
    for change in changes:
        statement = change.pre if change.action is Action.REMOVED else change.post
        left = budget.get(change.action)
        if statement is not None and left is not None and left[_key(statement)] > 0:
            left[_key(statement)] -= 1
            change = StatementChange(change.action, change.pre, change.post, moved=True)
        flagged.append(change)
    return flagged


def diff_statements(
    pre: Sequence[Statement],
    post: Sequence[Statement],
    pre_path: str | None = None,
    post_path: str | None = None,
) -> FileChange:
    """Γ_A, Γ_R, Γ_M between two statement sequences of one file, with per-statement detail."""
    if pre is post:  # the cache hands both revisions one object for an unchanged blob
        return FileChange(pre_path, post_path, added=0, removed=0, modified=0)
    digest = kept_digest(pre)
    if digest is not None and digest == kept_digest(post):  # as below, without decoding them
        return FileChange(pre_path, post_path, added=0, removed=0, modified=0)
    pre_keys, post_keys = [_key(s) for s in pre], [_key(s) for s in post]
    if pre_keys == post_keys:  # nothing changed but layout or comments
        return FileChange(pre_path, post_path, added=0, removed=0, modified=0)
    matcher = SequenceMatcher(None, pre_keys, post_keys, autojunk=False)
    changes: list[StatementChange] = []
    approximate = False
    for tag, i1, i2, j1, j2 in matcher.get_opcodes():
        if tag == "delete":
            changes += [StatementChange(Action.REMOVED, s, None) for s in pre[i1:i2]]
        elif tag == "insert":
            changes += [StatementChange(Action.ADDED, None, s) for s in post[j1:j2]]
        elif tag == "replace":
            run, rough = _replace_run(pre[i1:i2], post[j1:j2])
            changes += run
            approximate = approximate or rough
    changes = _flag_moves(changes)
    count = Counter(c.action for c in changes)
    return FileChange(
        pre_path,
        post_path,
        added=count[Action.ADDED],
        removed=count[Action.REMOVED],
        modified=count[Action.MODIFIED],
        changes=tuple(changes),
        approximate=approximate,
    )


def diff_files(pre: FileFacts | None, post: FileFacts | None) -> FileChange:
    """The change of one file pair; a missing side means the file was added or removed."""
    return diff_statements(
        pre.statements if pre else (),
        post.statements if post else (),
        pre.path if pre else None,
        post.path if post else None,
    )
