"""The head files a gated diff leaves unmeasured although the base's configuration measures
them: what a pull request would do to slip its code past the workflow's gates (excluding
it, dropping or changing its language in its own configuration, pushing it over a limit,
breaking its syntax, marking it generated). Any such file fails the diff's implicit gate
``unmeasured(head) > 0`` (docs/ci.md, "Whose configuration")."""

from __future__ import annotations

from collections.abc import Callable

from archmetrics.app.coupling import configuration_files
from archmetrics.app.diff_options import DiffOptions
from archmetrics.app.tree import Side
from archmetrics.changeset.rows import FileRow
from archmetrics.parsers import LanguageTable


def unmeasured_in_head(
    pre: Side, post: Side, in_force: DiffOptions, base: DiffOptions | None = None
) -> list[tuple[str, str]]:
    """(path, why) of each head file the base's configuration measures and the head does
    not. ``base``: the base's options when those ``in_force`` are not the base's
    (``--config-from head`` or a file); the head's whole tree is then judged by them."""
    judge = base or in_force
    rows = post.by_path
    language_of: Callable[[str], str | None]
    if base is None:
        candidates = list(rows)
        language_of = lambda path: rows[path].language  # noqa: E731
    else:
        table = LanguageTable.default(dict(base.languages))
        configuration = configuration_files(base.packs)
        candidates = [file.path for file in post.snapshot.files()]
        language_of = lambda path: table.language_of(path) or configuration(path)  # noqa: E731
    found = []
    for path in candidates:
        language = language_of(path)
        if language is None or judge.rules.is_excluded(path):
            continue  # the base does not measure it either
        why = _why(rows.get(path), language, in_force, pre.by_path.get(path))
        if why is not None:
            found.append((path, why))
    return found


def _why(row: FileRow | None, language: str, in_force: DiffOptions, before: FileRow | None
         ) -> str | None:  # fmt: skip
    """Why the head's ``row`` of a file the base measures as ``language`` is unmeasured."""
    if row is None:
        return "no language in the configuration in force"
    if reason := in_force.rules.is_excluded(row.path):
        return f"excluded by the configuration in force: {reason}"
    if row.language != language:
        return f"read as {row.language}; the base's configuration reads {language}"
    if not row.parsed and (before is None or before.parsed):  # broken before: not this change
        message = row.warnings[0].message if row.warnings else "not parsed"
        return message if message.startswith("not measured") else f"not measured: {message}"
    if row.generated and in_force.rules.exclude_generated and not (before and before.generated):
        return "says it is generated, which the base's file did not"
    return None
