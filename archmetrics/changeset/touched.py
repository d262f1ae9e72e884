"""What a change touched, after it: the files with a statement added, removed or modified,
and in each the functions those statements are in (``Statement.function``, the parser's
fact), so that a diff can gate on them: "no function this change touches may exceed v_g 15".

A function is touched when a statement of it was added or modified (its post side names it)
or removed (its pre side names it, and the function is still there after); a new function
is touched by its every statement. A file the change only renamed is not touched.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from archmetrics.changeset.model import ChangeReport, Status, Touched
from archmetrics.changeset.statement_diff import FileChange
from archmetrics.complexity import file_metrics
from archmetrics.facts import FileFacts


def _names(change: FileChange) -> set[str]:
    """The qualified names of the functions whose statements ``change`` counts."""
    names = set()
    for counted in change.changes:
        for statement in (counted.post, counted.pre):
            if statement is not None and statement.function is not None:
                names.add(statement.function)
    return names


def touched(report: ChangeReport, after: Mapping[str, FileFacts]) -> tuple[Touched, ...]:
    """The files of ``report`` a change touched, with their touched functions, measured on
    the facts ``after`` the change (by path; a file without facts there is left out)."""
    found = []
    changes: Iterable[FileChange] = (
        change
        for element in report.computed
        if element.status is not Status.UNCHANGED
        for change in element.file_changes
    )
    for change in changes:
        facts = after.get(change.post_path) if change.post_path else None
        if facts is None or not change.total:
            continue
        names = _names(change)
        metrics = file_metrics(facts)
        functions = tuple(f for f in metrics.functions if f.qualified_name in names)
        found.append(Touched(metrics, functions))
    return tuple(sorted(found, key=lambda t: t.file.path))
