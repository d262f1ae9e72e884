"""A file as a comparison reads it when it does not diff it: its row (pure).

A diff of two trees that share most of their files diffs only the files whose content
differs; every other file adds its size and complexity to both sides and nothing to Γ. For
those, a :class:`FileRow` (a few numbers kept with the tree's state, app/tree.py) stands in
for the file's facts, so that they are neither decoded nor read (docs/performance.md,
"Incremental diffs").
"""

from __future__ import annotations

from typing import NamedTuple

from archmetrics.changeset.model import MeasuredFile
from archmetrics.changeset.statement_diff import FileChange, diff_files
from archmetrics.facts import FileFacts, ParseWarning


class FileRow(NamedTuple):
    """One file of a tree: where it is, its content (``blob``, ``language``), λ, SLOC, v_g,
    whether a parser read it, whether it says it is generated, its parse warnings, and how
    many functions it has and how many of them are estimated (``Function.estimated``). A
    named tuple: a state read from the cache makes one per file of the tree."""

    path: str
    language: str
    blob: str
    loc: int
    sloc: int
    vg: int
    parsed: bool = True
    generated: bool = False
    warnings: tuple[ParseWarning, ...] = ()
    functions: int = 0
    estimated: int = 0

    @classmethod
    def of(cls, facts: FileFacts, blob: str) -> FileRow:
        return cls(
            facts.path, facts.language, blob, facts.loc, facts.sloc, facts.vg,
            facts.parsed, facts.generated, facts.warnings, len(facts.functions),
            sum(f.estimated for f in facts.functions),
        )  # fmt: skip


def diff_measured(pre: MeasuredFile | None, post: MeasuredFile | None) -> FileChange:
    """:func:`diff_files`, where a side may be a row: two rows of one content changed
    nothing; any other pair with a row cannot be diffed (the caller pairs rows only with
    rows of the same content)."""
    if isinstance(pre, FileRow) or isinstance(post, FileRow):
        if (
            isinstance(pre, FileRow)
            and isinstance(post, FileRow)
            and (pre.blob, pre.language) == (post.blob, post.language)
        ):
            return FileChange(pre.path, post.path, added=0, removed=0, modified=0)
        raise TypeError(f"{(post or pre).path}: a row has no statements to diff")  # type: ignore[union-attr]
    assert pre is None or isinstance(pre, FileFacts)
    assert post is None or isinstance(post, FileFacts)
    return diff_files(pre, post)
