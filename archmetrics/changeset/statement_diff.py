"""Γ_A, Γ_R, Γ_M of one file (thesis eqs. 6.11-6.18), counted on statements, not raw lines.

Statements are the parser's logical lines of code (thesis p. 103) with normalized text, so
reformatting, comment edits and splitting a statement over several lines change nothing here.
The pairing rule (docs/metrics.md, "Pairing rule"):

1. Align the pre and post sequences with ``difflib.SequenceMatcher(autojunk=False)`` over the
   keys ``(kind, text)``. ``equal`` runs are unchanged, ``delete`` runs removed, ``insert``
   runs added.
2. Inside each ``replace`` run, a removed statement r and an added statement a *may pair* when
   they have the same kind or their token similarity (an LCS ratio) is at least one half.
   Among order-preserving pairings we take the one with the most pairs, ties broken by the
   largest summed similarity (an LCS over "may pair", :mod:`~archmetrics.changeset.pairing`).
   Pairs count as modified; the rest of the run counts as removed and added.
3. Runs larger than ``pairing.EXACT_PAIRING_CELLS`` (removed x added) pair greedily in order
   and mark the file change ``approximate``.

A statement that moved counts as removed at its old place and added at its new one (what a line
diff shows); both sides are flagged ``moved`` so the number can be traced.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from difflib import SequenceMatcher
from enum import StrEnum

from archmetrics.changeset.pairing import pair, similarity, tokens
from archmetrics.facts import FileFacts, Span, Statement, kept_digest

__all__ = ["Action", "FileChange", "StatementChange", "change_from_record", "change_record",
           "diff_files", "diff_statements", "same_statements", "similarity", "tokens"]  # fmt: skip


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
    approximate: bool = False  # a replace run exceeded EXACT_PAIRING_CELLS (greedy pairing)

    @property
    def total(self) -> int:
        """Γ of this file, eq. 6.11 / 6.15 restricted to one file."""
        return self.added + self.removed + self.modified


def _replace_run(
    removed: Sequence[Statement], added: Sequence[Statement]
) -> tuple[list[StatementChange], bool]:
    pairs, exact = pair(removed, added)
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


def same_statements(pre: Sequence[Statement], post: Sequence[Statement]) -> bool:
    """Whether two sequences are known equal without reading them: one object (the cache
    hands both revisions one for an unchanged blob) or equal digests kept by the cache."""
    if pre is post:
        return True
    digest = kept_digest(pre)
    return digest is not None and digest == kept_digest(post)


def diff_statements(
    pre: Sequence[Statement],
    post: Sequence[Statement],
    pre_path: str | None = None,
    post_path: str | None = None,
) -> FileChange:
    """Γ_A, Γ_R, Γ_M between two statement sequences of one file, with per-statement detail."""
    if same_statements(pre, post):
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


# A file pair's change as a record of JSON types, kept in the cache by the two files' blobs
# (app/diff_cache.py) so that a diff seen before reads neither file's statements again:
# [added, removed, modified, approximate, [[action, pre, post, moved], ...]], a statement
# [kind, start, end, text, function].
CHANGE_RECORD = "file-change/1"


def _statement_record(statement: Statement | None) -> list[object] | None:
    if statement is None:
        return None
    kind, (start, end), text, function = statement
    return [kind, start, end, text, function]


def change_record(change: FileChange) -> list[object]:
    """``change`` without its paths, as JSON types (:func:`change_from_record` reads it)."""
    return [
        change.added,
        change.removed,
        change.modified,
        change.approximate,
        [
            [c.action.value, _statement_record(c.pre), _statement_record(c.post), c.moved]
            for c in change.changes
        ],
    ]


def _statement_from(record: object) -> Statement | None:
    if record is None:
        return None
    if not (isinstance(record, list) and len(record) == 5):
        raise ValueError("a statement record has five fields")
    kind, start, end, text, function = record
    if not (
        isinstance(kind, str)
        and isinstance(text, str)
        and (function is None or isinstance(function, str))
        and type(start) is int
        and type(end) is int
    ):
        raise ValueError("a statement record's fields have the wrong types")
    return Statement(kind, Span(start, end), text, function)  # Span checks the range


def change_from_record(
    record: object, pre_path: str | None, post_path: str | None
) -> FileChange | None:
    """The change ``change_record`` made, with these paths; None if ``record`` is anything
    else (it comes from the cache file, which is not trusted: a bad record is recomputed,
    never believed), including counts that do not match its changes."""
    if not (isinstance(record, list) and len(record) == 5):
        return None
    added, removed, modified, approximate, rows = record
    try:
        changes = []
        for action, pre, post, moved in rows:
            change = StatementChange(
                Action(action), _statement_from(pre), _statement_from(post), moved is True
            )
            action = change.action
            has_pre, has_post = action is not Action.ADDED, action is not Action.REMOVED
            if (change.pre is not None) != has_pre or (change.post is not None) != has_post:
                return None
            changes.append(change)
    except (TypeError, ValueError):
        return None
    count = Counter(c.action for c in changes)
    counts = (count[Action.ADDED], count[Action.REMOVED], count[Action.MODIFIED])
    numbers = (added, removed, modified)
    if any(type(n) is not int for n in numbers) or numbers != counts:
        return None
    if type(approximate) is not bool:
        return None
    return FileChange(pre_path, post_path, added, removed, modified, tuple(changes), approximate)
