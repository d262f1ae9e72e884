"""The ``diff`` use case: two snapshots of a repository in, the chapter-6 metrics out."""

from __future__ import annotations

import functools
import hashlib
import json
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from importlib import metadata
from pathlib import Path
from typing import TypeVar

from archmetrics.app.collect import parse_all, select, worker_limits
from archmetrics.app.coupling import (
    configuration_files,
    coupling_options,
    packs_digest,
    rule_set,
)
from archmetrics.app.progress import NoProgress, Progress
from archmetrics.app.settings import gate_origins
from archmetrics.app.tree import Side, begin_delta, side_of
from archmetrics.app.unit_gates import for_gates, split_gates, touched_units
from archmetrics.app.workers import WorkerLimits
from archmetrics.changeset import ChangeReport, FilePair, LocationRules, compute_change
from archmetrics.changeset.elements import Differ
from archmetrics.changeset.files import exclusion, pair_files
from archmetrics.changeset.gates import Gate, check_gates
from archmetrics.changeset.model import MeasuredFile
from archmetrics.changeset.rows import FileRow, diff_measured
from archmetrics.changeset.statement_diff import (
    CHANGE_RECORD,
    FileChange,
    change_from_record,
    change_record,
    diff_files,
    same_statements,
)
from archmetrics.changeset.unchanged import Unchanged
from archmetrics.complexity.baseline import Baseline
from archmetrics.complexity.thresholds import Threshold, check_units
from archmetrics.config import Settings
from archmetrics.coupling import CouplingOptions, group_elements
from archmetrics.coupling.rules import RuleSet
from archmetrics.coupling.sitememo import RECORD, SiteMemo
from archmetrics.facts import FileFacts, ParseWarning
from archmetrics.parsers import LanguageTable
from archmetrics.reports.model import DiffReport
from archmetrics.sources import Snapshot
from archmetrics.sources.cache import FactsCache, code_fingerprint
from archmetrics.sources.checkout import Checkout, open_checkout


@functools.cache
def _rapidfuzz() -> str:
    return metadata.version("rapidfuzz")


@dataclass(frozen=True, slots=True)
class DiffRequest:
    """Compare ``base`` with ``head`` (revisions, EMPTY, WORKTREE or INDEX) in the repo at root."""

    root: Path
    base: str
    head: str
    settings: Settings
    new: tuple[str, ...] = ()  # --new globs, ahead of the configured ones
    framework: tuple[str, ...] = ()
    gates: tuple[str, ...] = ()  # --fail-on, after the configured ones
    jobs: int = 0
    dynamic_pre_zero: bool = False
    base_label: str = ""  # how reports name the base (``A...B``), when not ``base`` itself
    baseline: Baseline | None = None  # offenders already known (--baseline FILE)


@dataclass(frozen=True, slots=True)
class DiffOptions:
    """A request's command-line flags and its settings merged, once per command: every step
    of a diff (and each stage of a series) reads these, never the two sources again."""

    rules: LocationRules
    gates: tuple[Gate, ...]  # on the change's summaries (cost(new) > 20)
    unit_gates: tuple[Threshold, ...]  # on the functions and files it touches (app/unit_gates)
    languages: tuple[tuple[str, str], ...]  # file ending -> language
    limits: WorkerLimits
    jobs: int
    coupling: CouplingOptions
    packs: RuleSet
    dynamic_pre_zero: bool


def diff_options(request: DiffRequest, root: Path) -> DiffOptions:
    """The options of ``request`` for the repository at ``root`` (its rule packs are read
    from there). A bad gate or rule pack fails here, before any work."""
    settings = request.settings
    limits = worker_limits(settings.limits, settings.macros)
    gates, unit_gates = split_gates((*settings.gates, *request.gates))
    return DiffOptions(
        rules=location_rules(request),
        gates=gates,
        unit_gates=unit_gates,
        languages=settings.languages,
        # generated files count nowhere unless asked for: the first lines that say so suffice
        limits=replace(limits, skip_generated=not settings.include_generated),
        jobs=request.jobs or settings.jobs,
        coupling=coupling_options(settings),
        packs=rule_set(settings, root),
        dynamic_pre_zero=request.dynamic_pre_zero,
    )


def location_rules(request: DiffRequest) -> LocationRules:
    """``--new`` and ``--framework`` globs first, then the configured new, framework and base
    globs, in that order: the first that matches a path decides its location."""
    configured = request.settings.locations
    cli = LocationRules.from_mapping({"new": request.new, "framework": request.framework})
    rest = LocationRules.from_mapping(
        {"new": configured.new, "framework": configured.framework, "base": configured.base}
    )
    return LocationRules(
        cli.rules + rest.rules, request.settings.exclude, not request.settings.include_generated
    )


class _CachedSites:
    """The facts cache as a store of link-site records (coupling/sitememo.py)."""

    def __init__(self, cache: FactsCache) -> None:
        self.cache = cache

    def get_many(self, keys: Sequence[str]) -> Mapping[str, bytes]:
        return self.cache.get_totals(keys)

    def put_many(self, items: Mapping[str, bytes]) -> None:
        self.cache.put_totals(items.items())


def site_memo(
    cache: FactsCache,
    measured: Sequence[MeasuredFile] | Mapping[str, FileRow],
    blobs: Mapping[str, str],
    options: CouplingOptions,
    packs: RuleSet,
) -> SiteMemo:
    """Each file's link sites kept in ``cache`` by content: a tree coupled after another that
    shares most of its files (the worktree after an edit, the next revision of a series)
    matches rules and traces endpoints only for the files whose reach changed. ``measured``:
    the measured files, or rows by path (each file's content then named when asked for:
    a patch asks for the few files it redoes)."""
    context = _digest(
        [RECORD, code_fingerprint(), cache.fingerprint, repr(options), packs_digest(packs)]
    )
    identity: Mapping[str, str]
    if isinstance(measured, Mapping):
        identity = _Contents(measured)
    else:
        identity = {f.path: f"{blobs[f.path]}:{f.language}" for f in measured if blobs.get(f.path)}
    return SiteMemo(_CachedSites(cache), context, identity)


class _Contents(Mapping[str, str]):
    """Each file's content id (blob and language), made from its row when asked for."""

    def __init__(self, rows: Mapping[str, FileRow]) -> None:
        self.rows = rows

    def __getitem__(self, path: str) -> str:
        row = self.rows[path]
        if not row.blob:
            raise KeyError(path)
        return f"{row.blob}:{row.language}"

    def __iter__(self) -> Iterator[str]:
        return iter(self.rows)

    def __len__(self) -> int:
        return len(self.rows)


_T = TypeVar("_T")


def _kept(
    cache: FactsCache | None,
    key: str | None,
    read: Callable[[bytes], _T | None],
    compute: Callable[[], _T],
    write: Callable[[_T], bytes],
) -> _T:
    """What ``cache`` keeps under ``key`` if ``read`` believes it (the cache file is not
    trusted: ``read`` gives None for anything it did not write), else ``compute``'s result,
    kept as ``write`` gives it. Without a cache or a key, computed."""
    if cache is None or key is None:
        return compute()
    data = cache.get_total(key)
    known = read(data) if data is not None else None
    if known is not None:
        return known
    value = compute()
    cache.put_total(key, write(value))
    return value


def _compact(value: object) -> bytes:
    """JSON without blanks, ASCII escapes (a text may hold a lone surrogate, which no UTF-8
    can)."""
    return json.dumps(value, separators=(",", ":")).encode()


def _digest(document: Sequence[object]) -> str:
    return hashlib.sha256(json.dumps(document).encode()).hexdigest()


def cached_differ(
    cache: FactsCache, pre: Mapping[str, FileRow], post: Mapping[str, FileRow]
) -> Differ:
    """``diff_measured`` with each file pair's change kept in ``cache`` under a digest of
    what decides it (:func:`change_key`): a diff that meets the same two blobs again (the
    next diff of a branch, a warm rerun, each stage of a series) reads neither file's
    statements. ``pre``, ``post``: each side's rows by path (their blobs)."""

    def diff(before: MeasuredFile | None, after: MeasuredFile | None) -> FileChange:
        if not isinstance(before, FileFacts | None) or not isinstance(after, FileFacts | None):
            return diff_measured(before, after)  # rows of one content: nothing to keep
        if before and after and same_statements(before.statements, after.statements):
            return diff_files(before, after)  # known equal without reading them
        pre_path, post_path = before.path if before else None, after.path if after else None

        def read(data: bytes) -> FileChange | None:
            try:
                return change_from_record(json.loads(data), pre_path, post_path)
            except ValueError:
                return None

        key = change_key(before, after, pre, post, cache.fingerprint)
        return _kept(
            cache,
            key,
            read,
            lambda: diff_files(before, after),
            lambda change: _compact(change_record(change)),
        )

    return diff


def change_key(
    pre: FileFacts | None,
    post: FileFacts | None,
    pre_rows: Mapping[str, FileRow],
    post_rows: Mapping[str, FileRow],
    parser: str,
) -> str | None:
    """A digest of what decides a file pair's change: this archmetrics's code (the pairing
    rule), rapidfuzz's version (its similarity), and each side's blob and language under the
    ``parser`` fingerprint of the facts cache, named by the record's kind (the cache's
    ``totals`` table holds trees' coupling too). None if a side's blob is unknown."""
    sides: list[object] = []
    for facts, rows in ((pre, pre_rows), (post, post_rows)):
        if facts is None:
            sides.append(None)
            continue
        row = rows.get(facts.path)
        if row is None or not row.blob:
            return None
        sides.append([row.blob, facts.language])
    document = [CHANGE_RECORD, code_fingerprint(), _rapidfuzz(), parser, sides]
    return f"{CHANGE_RECORD}:{_digest(document)}"


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
) -> tuple[ChangeReport, tuple[ParseWarning, ...]]:
    """The change report between the two snapshots, and the parse warnings of both sides.
    ``checkout``: the repository, opened once by the caller (else opened here); ``options``:
    the request's options, merged once by the caller (else here). Every step is named on
    ``progress``: reading each side, parsing, coupling each tree, comparing the files."""
    progress = progress or NoProgress()
    progress.phase(f"reading {request.base} and {request.head}")
    checkout = checkout or open_checkout(request.root)
    options = options or diff_options(request, checkout.root)
    snapshots = (checkout.snapshot(request.base), checkout.snapshot(request.head))
    opened = checkout

    def renames() -> Mapping[str, str]:
        return opened.renames(request.base, request.head)

    return measure_snapshots(options, snapshots, renames, progress, cache)


def measure_snapshots(
    options: DiffOptions,
    snapshots: tuple[Snapshot, Snapshot],
    renames: Mapping[str, str] | Callable[[], Mapping[str, str]],
    progress: Progress | None = None,
    cache: FactsCache | None = None,
) -> tuple[ChangeReport, tuple[ParseWarning, ...]]:
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
    if post.renames is not None:
        moved: Mapping[str, str] = post.renames
    else:
        moved = renames() if callable(renames) else renames
    progress.phase("comparing the changed files")
    change = compare_sides(pre, post, moved, options, progress, cache)
    progress.stop()
    change = for_gates(change, pre, post, options.rules, bool(options.unit_gates))
    return change, parse_warnings(pre.state.rows, post.state.rows, rules=options.rules)


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
    options = options or diff_options(request, checkout.root)  # a bad gate fails before work
    change, warnings = measure_change(request, progress, cache, checkout, options)
    gates = options.gates
    label = request.base_label or request.base
    texts = (*(g.text for g in gates), *(t.text for t in options.unit_gates))
    report = DiffReport(label, request.head, change, warnings, texts)
    failures = check_gates(gates, report.summaries())
    checked = check_units(options.unit_gates, touched_units(change), request.baseline)
    origins = gate_origins(request.settings, checkout.root)
    commits = (checkout.commit_id(request.base), checkout.commit_id(request.head))
    return replace(
        report, failures=failures, offenders=checked.failures, suppressed=checked.suppressed,
        baselined=checked.baselined, origins=origins, commits=commits,
    )  # fmt: skip
