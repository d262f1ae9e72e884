"""The ``scan`` use case: measure one snapshot, per file and per function."""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from archmetrics.app.collect import parse_all, select, worker_limits
from archmetrics.app.coupling import configuration_files, measure, rule_set
from archmetrics.app.progress import NoProgress, Progress
from archmetrics.changeset.locations import LocationRules
from archmetrics.changeset.model import ExcludedFile
from archmetrics.complexity import file_metrics, totals
from archmetrics.complexity.baseline import Baseline
from archmetrics.complexity.thresholds import (
    FIELDS,
    Threshold,
    Unit,
    check_units,
    parse_threshold,
)
from archmetrics.config import Settings
from archmetrics.parsers import LanguageTable
from archmetrics.reports.frames import scan_table
from archmetrics.reports.json_report import totals_dict
from archmetrics.reports.model import ScanReport
from archmetrics.sources import SourceError
from archmetrics.sources.cache import FactsCache
from archmetrics.sources.checkout import open_checkout
from archmetrics.sources.paths import quote_path
from archmetrics.sources.snapshot import DirectorySnapshot, Snapshot, resolve_path


@dataclass(frozen=True, slots=True)
class ScanRequest:
    """What to measure: ``paths`` on disk (files or folders), optionally at git revision ``rev``."""

    paths: tuple[Path, ...]
    rev: str | None
    settings: Settings
    jobs: int = 0
    plain_directory: bool = False  # read the one path given as a folder, even inside git
    gates: tuple[str, ...] = ()  # thresholds to check (--fail-on 'vg(function) > 15')
    baseline: Baseline | None = None  # offenders already known (--baseline FILE)


def _locate(request: ScanRequest) -> tuple[Path, Snapshot, tuple[str, ...]]:
    """The root, the snapshot and the path prefixes (relative to root) to keep."""
    targets = [resolve_path(p) for p in request.paths] or [Path.cwd().resolve()]
    for target in targets:
        if not target.exists() and request.rev is None:
            raise SourceError(f"{target}: no such file or directory")
    anchor = targets[0] if targets[0].is_dir() else targets[0].parent
    if request.plain_directory:
        return anchor, DirectorySnapshot(anchor), ()
    checkout = open_checkout(anchor)
    if request.rev is None and checkout.repo is None:
        if len(targets) == 1 and targets[0].is_dir():
            return targets[0], DirectorySnapshot(targets[0]), ()
        root = Path(os.path.commonpath([str(t) for t in targets]))
        root = root if root.is_dir() else root.parent
        on_disk = [t.relative_to(root).as_posix() if t != root else "" for t in targets]
        folder = DirectorySnapshot(root, within=on_disk)
        return root, folder, tuple(_relative(t, root) for t in targets)
    root = checkout.root.resolve()
    snapshot = checkout.snapshot(request.rev)
    prefixes = tuple(_relative(t, root) for t in targets)
    return root, snapshot, tuple(p for p in prefixes if p)


def _relative(target: Path, root: Path) -> str:
    try:
        return quote_path(target.relative_to(root).as_posix()) if target != root else ""
    except ValueError as error:
        raise SourceError(f"{target}: not under {root}") from error


def _under(path: str, prefixes: tuple[str, ...]) -> bool:
    if not prefixes:
        return True
    pure = PurePosixPath(path)
    return any(path == p or pure.is_relative_to(p) for p in prefixes)


def _nothing_to_measure(request: ScanRequest, snapshot: Snapshot, prefixes: tuple[str, ...]) -> str:
    """Why nothing is measured: a note (a tree of docs only is measured as empty, exit 0, so
    that a job over the changed files passes a change with no source in it); a path missing
    at the revision asked for is an error (SourceError, exit 2)."""
    if request.rev is not None and prefixes:
        known = [f.path for f in snapshot.files()]
        missing = [p for p in prefixes if not any(_under(k, (p,)) for k in known)]
        if missing:
            raise SourceError(f"{missing[0]}: no such path at revision {request.rev}")
    where = ", ".join(prefixes) or "the tree"
    return (
        f"no source files to measure in {where} ({snapshot.label}): nothing measured; file"
        " endings are read as docs/metrics.md says ('languages' in the configuration adds some)"
    )


def run_scan(
    request: ScanRequest, progress: Progress | None = None, cache: FactsCache | None = None
) -> ScanReport:
    """Facts and metrics for every source file under the requested paths, and every unit
    that fails one of the request's thresholds."""
    thresholds = tuple(parse_threshold(g) for g in request.gates)  # bad ones before any work
    progress = progress or NoProgress()
    progress.phase("listing the files")
    root, snapshot, prefixes = _locate(request)
    overrides = request.settings.languages
    table = LanguageTable.default(dict(overrides))
    packs = rule_set(request.settings, root)  # they say which files are configuration
    configuration = configuration_files(packs)
    selected = select(snapshot, table, lambda path: _under(path, prefixes), configuration)
    if not selected and request.rev is None and prefixes and len(request.paths) == 1:
        # a folder git ignores (a virtualenv, a build tree) is read as the plain folder it is
        folder = resolve_path(request.paths[0])
        if folder.is_dir():
            root, snapshot, prefixes = folder, DirectorySnapshot(folder), ()
            packs = rule_set(request.settings, root)
            configuration = configuration_files(packs)
            selected = select(snapshot, table, configuration=configuration)
    # the configuration's `exclude` leaves files out; they are listed, with the folders a
    # plain folder's walk left out
    rules = LocationRules((), request.settings.exclude)
    judged = [(item, rules.is_excluded(item.file.path)) for item in selected]
    excluded = [ExcludedFile(item.file.path, why) for item, why in judged if why]
    selected = tuple(item for item, why in judged if why is None)
    notes = () if selected else (_nothing_to_measure(request, snapshot, prefixes),)
    if isinstance(snapshot, DirectorySnapshot):
        excluded += [ExcludedFile(path, reason) for path, reason in snapshot.skipped.items()]
    jobs = request.jobs or request.settings.jobs
    limits = worker_limits(request.settings.limits, request.settings.macros)
    facts = parse_all(snapshot, selected, overrides, jobs, progress, cache, limits)
    progress.phase("coupling")
    metrics = tuple(file_metrics(f) for f in facts)
    coupling = measure(facts, request.settings, packs)
    progress.stop()
    report = ScanReport(
        root=str(root),
        revision=snapshot.label,
        facts=facts,
        files=metrics,
        totals=totals(metrics),
        coupling=coupling,
        excluded=tuple(excluded),
        gates=tuple(t.text for t in thresholds),
        notes=notes,
    )
    if not thresholds:
        return report
    checked = check_units(thresholds, units_of(report, thresholds), request.baseline)
    return dataclasses.replace(
        report,
        failures=checked.failures,
        suppressed=checked.suppressed,
        baselined=checked.baselined,
    )


def units_of(report: ScanReport, thresholds: Iterable[Threshold]) -> dict[str, list[Unit]]:
    """The functions, files, elements and the total of ``report`` as threshold units (only
    the kinds some threshold names), their numbers read from the rows the CSV and the API
    show (reports/frames.py); a function's with its suppression comment's fields."""
    units: dict[str, list[Unit]] = {}
    for kind in {t.unit for t in thresholds}:
        if kind == "function":
            units[kind] = [
                Unit(fn.qualified_name, f.path, fn.line, {"vg": fn.vg, "loc": fn.loc},
                     suppressed=fn.suppressed)
                for f in report.files
                for fn in f.functions
            ]
            continue
        if kind == "total":
            numbers = totals_dict(report.totals)
            units[kind] = [Unit("total", None, None, {f: numbers[f] for f in FIELDS[kind]})]
            continue
        table = scan_table(report, kind)
        rows = [dict(zip(table.columns, row, strict=True)) for row in table.rows]
        name, path = _WHERE[kind]
        units[kind] = [
            Unit(
                str(row[name]),
                str(row[path]) if path else None,
                None,
                {f: int(row[f]) for f in FIELDS[kind]},  # type: ignore[arg-type]
            )
            for row in rows
        ]
    return units


# a unit kind's columns (reports/frames.py) naming it and its file
_WHERE = {"file": ("path", "path"), "element": ("element", None)}
