"""The ``diff`` use case: two snapshots of a repository in, the chapter-6 metrics out."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from typing import NamedTuple

from archmetrics.app.collect import parse_all, select
from archmetrics.app.coupling import configuration_files
from archmetrics.app.diff_cache import cached_differ
from archmetrics.app.diff_options import DiffOptions, DiffRequest, diff_options
from archmetrics.app.progress import NoProgress, Progress
from archmetrics.app.settings import gate_origins
from archmetrics.app.tree import Side, begin_delta, side_of
from archmetrics.app.unit_gates import for_gates, touched_units
from archmetrics.changeset import ChangeReport, FilePair, compute_change
from archmetrics.changeset.files import exclusion, pair_files
from archmetrics.changeset.gates import (
    UNMEASURED_GATE,
    GateFailure,
    check_gates,
    unmeasured_failure,
)
from archmetrics.changeset.locations import LocationRules
from archmetrics.changeset.model import MeasuredFile
from archmetrics.changeset.rows import FileRow, diff_measured
from archmetrics.changeset.unchanged import Unchanged
from archmetrics.complexity import Reading
from archmetrics.complexity.thresholds import check_units
from archmetrics.coupling import group_elements
from archmetrics.facts import FileFacts, ParseWarning
from archmetrics.parsers import LanguageTable
from archmetrics.reports.model import DiffReport
from archmetrics.sources import Snapshot
from archmetrics.sources.cache import FactsCache
from archmetrics.sources.checkout import Checkout, open_checkout


class Measured(NamedTuple):
    """A diff's measure: the change, the parse warnings of both sides, and how much of the
    two sides' files was read in full."""

    change: ChangeReport
    warnings: tuple[ParseWarning, ...]
    reading: Reading


def reading_of(*sides: Sequence[FileRow], rules: LocationRules | None = None) -> Reading:
    """How much of the files of each side was read in full (files an exclude glob of
    ``rules`` leaves out are not counted); a file both sides hold alike counts once."""
    seen: dict[tuple[str, str], FileRow] = {}
    for side in sides:
        for row in side:
            if rules is None or not rules.is_excluded(row.path):
                seen.setdefault((row.path, row.blob), row)
    return Reading.of((bool(row.warnings), row.functions, row.estimated) for row in seen.values())


def parse_warnings(
    *sides: Sequence[FileFacts | FileRow], rules: LocationRules | None = None
) -> tuple[ParseWarning, ...]:
    """Every distinct parse warning of the files of each side, in order; none of a file an
    exclude glob of ``rules`` leaves out (it is listed as excluded, as a scan lists it)."""
    seen: dict[str, ParseWarning] = {}
    for side in sides:
        for facts in side:
            if rules is not None and rules.is_excluded(facts.path):
                continue
            for w in facts.warnings:
                seen.setdefault(str(w), w)
    return tuple(seen.values())


def parse_side(
    snapshot: Snapshot,
    options: DiffOptions,
    progress: Progress | None,
    cache: FactsCache | None,
    blobs: dict[str, str] | None = None,
) -> tuple[FileFacts, ...]:
    table = LanguageTable.default(dict(options.languages))
    selected = select(snapshot, table, configuration=configuration_files(options.packs))
    overrides = options.languages
    return parse_all(
        snapshot, selected, overrides, options.jobs, progress, cache, options.limits, blobs
    )


def measure_change(
    request: DiffRequest,
    progress: Progress | None = None,
    cache: FactsCache | None = None,
    checkout: Checkout | None = None,
    options: DiffOptions | None = None,
    sides: list[Side] | None = None,
) -> Measured:
    """The change report between the two snapshots, the parse warnings of both sides, and
    how much of them was read in full.
    ``checkout``: the repository, opened once by the caller (else opened here); ``options``:
    the request's options, merged once by the caller (else here); ``sides``, if given,
    receives the base's and the head's side. Every step is named on ``progress``: reading
    each side, parsing, coupling each tree, comparing the files."""
    progress = progress or NoProgress()
    progress.phase(f"reading {request.base} and {request.head}")
    checkout = checkout or open_checkout(request.root)
    options = options or diff_options(request, checkout.root, checkout)
    snapshots = (checkout.snapshot(request.base), checkout.snapshot(request.head))
    opened = checkout

    def renames() -> Mapping[str, str]:
        return opened.renames(request.base, request.head)

    return measure_snapshots(options, snapshots, renames, progress, cache, sides)


def measure_snapshots(
    options: DiffOptions,
    snapshots: tuple[Snapshot, Snapshot],
    renames: Mapping[str, str] | Callable[[], Mapping[str, str]],
    progress: Progress | None = None,
    cache: FactsCache | None = None,
    sides: list[Side] | None = None,
) -> Measured:
    """:func:`measure_change` of two snapshots already opened (``renames``: old path -> new
    path, or how to ask for them when the head's state was not patched from the base's),
    under ``options``. Each side's state comes from app/tree.py: kept, patched or built."""
    progress = progress or NoProgress()
    base, head = snapshots
    delta = begin_delta(base, head, cache)  # git walks the head tree while the base is read
    try:
        pre = side_of(base, options, cache, progress)
        progress.phase(f"reading {head.label}")
        post = side_of(head, options, cache, progress, origin=pre, delta=delta)
    finally:
        if delta is not None:
            delta.cancel()  # its git processes, if the head's state did not need them
    if sides is not None:
        sides[:] = [pre, post]
    if post.renames is not None:
        moved: Mapping[str, str] = post.renames
    else:
        moved = renames() if callable(renames) else renames
    progress.phase("comparing the changed files")
    change = compare_sides(pre, post, moved, options, progress, cache)
    progress.stop()
    change = for_gates(change, pre, post, options.rules, bool(options.unit_gates))
    return Measured(
        change,
        parse_warnings(pre.state.rows, post.state.rows, rules=options.rules),
        reading_of(pre.state.rows, post.state.rows, rules=options.rules),
    )


def compare_sides(
    pre: Side,
    post: Side,
    renames: Mapping[str, str],
    options: DiffOptions,
    progress: Progress,
    cache: FactsCache | None,
) -> ChangeReport:
    """The change between the two sides. Where both group their files alike (the same
    paths), only the elements holding a file that differs are paired and diffed; the
    others are reported from the base side's element rows (changeset/unchanged.py)."""
    differ = diff_measured if cache is None else cached_differ(cache, pre.by_path, post.by_path)
    values = (pre.state.index.values, post.state.index.values)
    links = (pre.state.index.sites, post.state.index.sites)
    same = pre.state.groups is post.state.groups or pre.state.groups == post.state.groups
    if not same:
        pairs = pair_files(pre.state.rows, post.state.rows, renames)
        paths = {row.path for row in (*pre.state.rows, *post.state.rows)}
        elements = group_elements(paths, options.coupling.grouping)
        return compute_change(
            _with_facts(pairs, pre, post, options, progress), elements, options.rules,
            values[0], values[1], dynamic_pre_zero=options.dynamic_pre_zero, diff=differ,
            links=links,
        )  # fmt: skip
    changed = post.changed if post.changed is not None else _differing(pre, post)
    owner = pre.owner
    touched = {owner[path] for path in changed if path in owner}
    touched_elements = [e for e in pre.state.groups if e.name in touched]
    pairs = [FilePair(pre.by_path[p], post.by_path[p]) for e in touched_elements for p in e.files]
    unchanged = Unchanged(
        {name: row for name, row in pre.state.table.items() if name not in touched},
        tuple(x for x in pre.state.excluded if owner.get(x.path) not in touched),
    )
    return compute_change(
        _with_facts(pairs, pre, post, options, progress), touched_elements, options.rules,
        values[0], values[1], dynamic_pre_zero=options.dynamic_pre_zero, diff=differ,
        unchanged=unchanged, links=links,
    )  # fmt: skip


def _differing(pre: Side, post: Side) -> frozenset[str]:
    """The paths (the same on both sides) whose files differ in content or language."""
    return frozenset(
        a.path
        for a, b in zip(pre.state.rows, post.state.rows, strict=True)
        if (a.blob, a.language) != (b.blob, b.language)
    )


def _with_facts(
    pairs: list[FilePair], pre: Side, post: Side, options: DiffOptions, progress: Progress
) -> list[FilePair]:
    """``pairs`` of rows, those of files that differ given the facts of each side that can
    be measured (so that they are diffed); pairs of one content stay rows."""
    wanted: tuple[set[str], set[str]] = (set(), set())
    for pair in pairs:
        sides = (pair.pre, pair.post)
        if _same(*sides) or not all(row.parsed for row in sides if row):
            continue  # rows of one content, or a pair dropped whole (not_parsed)
        for row, paths in zip(sides, wanted, strict=True):
            if isinstance(row, FileRow) and exclusion(row, options.rules) is None:
                paths.add(row.path)
    found = (
        pre.facts_of(wanted[0], options, progress),
        post.facts_of(wanted[1], options, progress),
    )
    return [
        pair if _same(pair.pre, pair.post) else FilePair(
            found[0].get(pair.pre.path, pair.pre) if pair.pre else None,
            found[1].get(pair.post.path, pair.post) if pair.post else None,
        )
        for pair in pairs
    ]  # fmt: skip


def _same(pre: MeasuredFile | None, post: MeasuredFile | None) -> bool:
    return (
        isinstance(pre, FileRow)
        and isinstance(post, FileRow)
        and (pre.blob, pre.language) == (post.blob, post.language)
    )


def run_diff(
    request: DiffRequest,
    progress: Progress | None = None,
    cache: FactsCache | None = None,
    checkout: Checkout | None = None,
    options: DiffOptions | None = None,
) -> DiffReport:
    """Measure, then check the gates. ``checkout`` and ``options`` as for
    :func:`measure_change` (a series opens and merges once for all its stages)."""
    checkout = checkout or open_checkout(request.root)
    options = options or diff_options(request, checkout.root, checkout)  # a bad gate fails
    # before any work
    sides: list[Side] = []
    change, warnings, reading = measure_change(request, progress, cache, checkout, options, sides)
    gates = options.gates
    label = request.base_label or request.base
    texts = (*(g.text for g in gates), *(t.text for t in options.unit_gates))
    report = DiffReport(label, request.head, change, warnings, texts)
    failures = check_gates(gates, report.summaries())
    if gates or options.unit_gates:  # a gated diff: what the base's configuration
        # measures, the head must measure too
        failures += _unmeasured(request, checkout, options, sides)
        texts += (UNMEASURED_GATE,)
    checked = check_units(options.unit_gates, touched_units(change), request.baseline)
    origins = gate_origins(request.settings, checkout.root)
    commits = (checkout.commit_id(request.base), checkout.commit_id(request.head))
    return replace(
        report, gates=texts, failures=failures, offenders=checked.failures,
        suppressed=checked.suppressed, baselined=checked.baselined, origins=origins,
        commits=commits, reading=reading,
    )  # fmt: skip


def _unmeasured(
    request: DiffRequest, checkout: Checkout, options: DiffOptions, sides: list[Side]
) -> tuple[GateFailure, ...]:
    """The failure of the implicit gate unmeasured(head), if the head leaves unmeasured files
    the base's configuration measures (judged by the base's settings when the run's came
    from the head or a file)."""
    from archmetrics.app.unmeasured import unmeasured_in_head

    base = request.base_settings
    judge = None if base is None else diff_options(replace(request, settings=base),
                                                   checkout.root, checkout)  # fmt: skip
    left = unmeasured_in_head(sides[0], sides[1], options, judge)
    return (unmeasured_failure(left),) if left else ()
