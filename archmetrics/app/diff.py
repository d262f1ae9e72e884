"""The ``diff`` use case: two snapshots of a repository in, the chapter-6 metrics out."""

from __future__ import annotations

import functools
import hashlib
import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from importlib import metadata
from pathlib import Path
from typing import TypeVar

from archmetrics.app.collect import parse_all, select, worker_limits
from archmetrics.app.coupling import configuration_files, coupling_options, rule_set
from archmetrics.app.progress import NoProgress, Progress
from archmetrics.app.workers import WorkerLimits
from archmetrics.changeset import ChangeReport, Coupling, LocationRules, compute_change
from archmetrics.changeset.elements import Differ
from archmetrics.changeset.files import measured_files, pair_files
from archmetrics.changeset.gates import Gate, check_gates, parse_gate
from archmetrics.changeset.statement_diff import (
    CHANGE_RECORD,
    FileChange,
    change_from_record,
    change_record,
    diff_files,
    same_statements,
)
from archmetrics.config import Settings
from archmetrics.coupling import CouplingOptions, group_elements, measure_coupling
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


@dataclass(frozen=True, slots=True)
class DiffOptions:
    """A request's command-line flags and its settings merged, once per command: every step
    of a diff (and each stage of a series) reads these, never the two sources again."""

    rules: LocationRules
    gates: tuple[Gate, ...]
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
    return DiffOptions(
        rules=location_rules(request),
        gates=tuple(parse_gate(g) for g in (*settings.gates, *request.gates)),
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


def coupling_values(
    files: Sequence[FileFacts],
    rules: LocationRules,
    options: CouplingOptions,
    packs: RuleSet,
    cache: FactsCache | None = None,
    blobs: Mapping[str, str] | None = None,
) -> dict[str, Coupling]:
    """Element name -> (s_a, s_e, d_a, d_e) over the measured (not excluded) files of a tree.

    With a ``cache`` and the files' ``blobs``, the result is kept under a digest of all that
    decides it (:func:`coupling_key`) and read back when the same tree is measured again."""
    measured = measured_files(files, rules)
    key = (
        None
        if cache is None or blobs is None
        else coupling_key(measured, blobs, options, packs, cache.fingerprint)
    )

    def compute() -> dict[str, Coupling]:
        memo = None
        if cache is not None and blobs is not None:
            memo = site_memo(cache, measured, blobs, options, packs)
        report = measure_coupling(measured, options, packs, memo)
        return {c.element.name: Coupling(c.s_a, c.s_e, c.d_a, c.d_e) for c in report.elements}

    return _kept(cache, key, _read_coupling, compute, _compact)


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
    measured: Sequence[FileFacts],
    blobs: Mapping[str, str],
    options: CouplingOptions,
    packs: RuleSet,
) -> SiteMemo:
    """Each file's link sites kept in ``cache`` by content: a tree coupled after another that
    shares most of its files (the worktree after an edit, the next revision of a series)
    matches rules and traces endpoints only for the files whose reach changed."""
    context = _digest([RECORD, code_fingerprint(), cache.fingerprint, repr(options), repr(packs)])
    identity = {f.path: f"{blobs[f.path]}:{f.language}" for f in measured if blobs.get(f.path)}
    return SiteMemo(_CachedSites(cache), context, identity)


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


def coupling_key(
    measured: Sequence[FileFacts],
    blobs: Mapping[str, str],
    options: CouplingOptions,
    packs: RuleSet,
    parser: str,
) -> str | None:
    """A digest of what decides a tree's coupling: this archmetrics's code, the facts (each
    file's path, blob and language, in order, under the ``parser`` fingerprint of the facts
    cache, which holds the parser settings), the coupling options and the rule packs as
    loaded. None if a file's blob is unknown."""
    files = []
    for facts in measured:
        blob = blobs.get(facts.path)
        if not blob:
            return None
        files.append((facts.path, blob, facts.language))
    return _digest(["coupling/1", code_fingerprint(), parser, repr(options), repr(packs), files])


def _read_coupling(data: bytes) -> dict[str, Coupling] | None:
    """Coupling values as ``coupling_values`` stored them, or None if ``data`` is anything
    else (the cache file is not trusted: a bad entry is recomputed, never believed)."""
    try:
        document = json.loads(data)
    except ValueError:
        return None
    if not isinstance(document, dict):
        return None
    values: dict[str, Coupling] = {}
    for name, numbers in document.items():
        if not (
            isinstance(numbers, list)
            and len(numbers) == 4
            and all(type(n) is int and n >= 0 for n in numbers)
        ):
            return None
        values[name] = Coupling(*numbers)
    return values


def cached_differ(
    cache: FactsCache, pre_blobs: Mapping[str, str], post_blobs: Mapping[str, str]
) -> Differ:
    """``diff_files`` with each file pair's change kept in ``cache`` under a digest of what
    decides it (:func:`change_key`): a diff that meets the same two blobs again (the next
    diff of a branch, a warm rerun, each stage of a series) reads neither file's statements."""

    def diff(pre: FileFacts | None, post: FileFacts | None) -> FileChange:
        if pre and post and same_statements(pre.statements, post.statements):
            return diff_files(pre, post)  # known equal without reading them: nothing to keep
        pre_path, post_path = pre.path if pre else None, post.path if post else None

        def read(data: bytes) -> FileChange | None:
            try:
                return change_from_record(json.loads(data), pre_path, post_path)
            except ValueError:
                return None

        key = change_key(pre, post, pre_blobs, post_blobs, cache.fingerprint)
        return _kept(
            cache,
            key,
            read,
            lambda: diff_files(pre, post),
            lambda change: _compact(change_record(change)),
        )

    return diff


def change_key(
    pre: FileFacts | None,
    post: FileFacts | None,
    pre_blobs: Mapping[str, str],
    post_blobs: Mapping[str, str],
    parser: str,
) -> str | None:
    """A digest of what decides a file pair's change: this archmetrics's code (the pairing
    rule), rapidfuzz's version (its similarity), and each side's blob and language under the
    ``parser`` fingerprint of the facts cache, named by the record's kind (the cache's
    ``totals`` table holds trees' coupling too). None if a side's blob is unknown."""
    sides: list[object] = []
    for facts, blobs in ((pre, pre_blobs), (post, post_blobs)):
        if facts is None:
            sides.append(None)
            continue
        blob = blobs.get(facts.path)
        if not blob:
            return None
        sides.append([blob, facts.language])
    document = [CHANGE_RECORD, code_fingerprint(), _rapidfuzz(), parser, sides]
    return f"{CHANGE_RECORD}:{_digest(document)}"


def parse_warnings(
    *sides: Sequence[FileFacts], rules: LocationRules | None = None
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
    renames = checkout.renames(request.base, request.head)
    return measure_snapshots(options, snapshots, renames, progress, cache)


def measure_snapshots(
    options: DiffOptions,
    snapshots: tuple[Snapshot, Snapshot],
    renames: Mapping[str, str],
    progress: Progress | None = None,
    cache: FactsCache | None = None,
) -> tuple[ChangeReport, tuple[ParseWarning, ...]]:
    """:func:`measure_change` of two snapshots already opened (``renames``: old path -> new
    path), under ``options``."""
    progress = progress or NoProgress()
    base, head = snapshots
    rules = options.rules
    pre_blobs: dict[str, str] = {}
    post_blobs: dict[str, str] = {}
    pre = parse_side(base, options, progress, cache, pre_blobs)
    progress.phase(f"reading {head.label}")
    post = parse_side(head, options, progress, cache, post_blobs)
    coupling, packs = options.coupling, options.packs
    progress.phase(f"coupling {base.label}")
    pre_coupling = coupling_values(pre, rules, coupling, packs, cache, pre_blobs)
    progress.phase(f"coupling {head.label}")
    post_coupling = coupling_values(post, rules, coupling, packs, cache, post_blobs)
    progress.phase("comparing the changed files")
    paths = {f.path for f in (*pre, *post)}
    change = compute_change(
        pair_files(pre, post, renames),
        group_elements(paths, coupling.per_file),
        rules,
        pre_coupling,
        post_coupling,
        dynamic_pre_zero=options.dynamic_pre_zero,
        diff=diff_files if cache is None else cached_differ(cache, pre_blobs, post_blobs),
    )
    progress.stop()
    return change, parse_warnings(pre, post, rules=rules)


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
    report = DiffReport(request.base, request.head, change, warnings, tuple(g.text for g in gates))
    failures = check_gates(gates, report.summaries())
    return DiffReport(report.base, report.head, change, warnings, report.gates, failures)
