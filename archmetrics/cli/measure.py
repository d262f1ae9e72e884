"""The measuring commands: scan, diff, series, compare, graph, rules, cache."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from archmetrics.app.diff import run_diff
from archmetrics.app.diff_options import DiffRequest
from archmetrics.app.progress import NoProgress
from archmetrics.app.scan import ScanRequest, run_scan
from archmetrics.app.series import SeriesRequest, parse_named_path, run_compare, run_series
from archmetrics.app.settings import repo_root
from archmetrics.cli.baseline import load_baseline
from archmetrics.cli.common import (
    EXIT_OK,
    UsageError,
    emit,
    facts_cache,
    gate_status,
    sample_path,
    settings_for,
    settings_from_file,
    settings_of,
    shown_progress,
    split,
    warn,
    write_output,
)
from archmetrics.config import Settings
from archmetrics.reports.charts import charts_missing
from archmetrics.reports.diff_rows import unmatched_glob
from archmetrics.reports.formats import (
    Grouping,
    OutputFormat,
    render_compare,
    render_diff,
    render_scan,
    render_series,
)
from archmetrics.reports.model import CompareReport, SeriesReport, Stage
from archmetrics.sources.checkout import Checkout, open_checkout
from archmetrics.sources.paths import quote_path
from archmetrics.sources.snapshot import EMPTY, WORKTREE, resolve_path


def check_chart(args: argparse.Namespace) -> str | None:
    """The format of the chart --chart asks for (its file ending), or None without one;
    checked before any work: a wrong ending or a folder that is not there is a usage error
    at once, not after the measurement."""
    if args.chart is None:
        return None
    fmt: str = args.chart.suffix.lower().lstrip(".")
    if fmt not in ("png", "svg"):
        raise UsageError(f"{args.chart}: --chart needs a .png or .svg file")
    missing = charts_missing()
    if missing is not None:
        raise UsageError(f"--chart: {missing}")
    folder = args.chart.parent
    if not folder.is_dir():
        raise UsageError(f"{args.chart}: --chart: no folder {folder}")
    return fmt


def write_chart(args: argparse.Namespace, report: CompareReport) -> None:
    """The chart --chart asks for, in the format its file ending names."""
    fmt = check_chart(args)
    if fmt is None:
        return
    from archmetrics.reports.charts import render_compare_chart

    write_output(args.chart, render_compare_chart(report, args.chart_kind, fmt))


def cache_command(args: argparse.Namespace) -> int:
    settings = settings_for(Path.cwd())
    with facts_cache(args, settings) as cache:
        assert cache is not None
        if args.action == "clear":
            print(f"removed {cache.clear()} entries from {cache.path}")
            return EXIT_OK
        info = cache.info()
        print(f"path:        {info.path}")
        print(f"entries:     {info.entries} ({info.current_entries} from this parser version)")
        print(f"size:        {info.bytes / 1e6:.1f} MB")
        print(f"fingerprint: {info.fingerprint}")
    return EXIT_OK


def scan_command(args: argparse.Namespace) -> int:
    paths: tuple[Path, ...] = tuple(args.paths)
    if args.sample:
        if paths or args.rev:
            raise UsageError("--sample takes no PATH and no --rev")
        paths = (sample_path(),)
    settings = settings_for(paths[0] if paths else Path.cwd(), args)
    fmt = OutputFormat(args.format)
    request = ScanRequest(
        paths=paths,
        rev=args.rev,
        settings=settings,
        jobs=args.jobs,
        plain_directory=args.sample,
        gates=tuple(args.fail_on),
        baseline=load_baseline(args.baseline),
    )
    with facts_cache(args, settings) as cache, shown_progress(fmt, args.quiet) as progress:
        report = run_scan(request, progress, cache)
        progress.phase("writing the report")
        text = render_scan(report, fmt, Grouping(args.by))
    emit(text, args.output)
    if args.output is not None or fmt not in (OutputFormat.TABLE, OutputFormat.MARKDOWN):
        for note in report.notes:  # (a table or Markdown on stdout shows them)
            print(f"archmetrics: note: {note}", file=sys.stderr)
    return gate_status(report.failures, args)


def rules_command(args: argparse.Namespace) -> int:
    from archmetrics.app.coupling import rule_set
    from archmetrics.coupling.ruletable import rule_rows, rules_markdown
    from archmetrics.reports.json_report import dumps
    from archmetrics.reports.table_report import rows_table, to_text

    settings = settings_for(args.repo, args)
    ruleset = rule_set(settings, repo_root(args.repo))
    if args.format == "markdown":
        sys.stdout.write(rules_markdown(ruleset))
        return EXIT_OK
    rows = rule_rows(ruleset)
    fields = ("pack", "rule", "language", "match", "kind", "role", "endpoint", "requires")
    if args.format == "json":
        document = {
            "schema": "archmetrics.rules/1",
            "rules": [{f: getattr(r, f) for f in fields} for r in rows],
        }
        sys.stdout.write(dumps(document))
        return EXIT_OK
    cells = [[getattr(r, f) for f in fields] for r in rows]
    sys.stdout.write(to_text(rows_table(f"{len(rows)} rules in force", fields, cells, 8)))
    return EXIT_OK


def graph_command(args: argparse.Namespace) -> int:
    from archmetrics.coupling.computation import computation_graph
    from archmetrics.reports.graph import render

    paths: tuple[Path, ...] = tuple(args.paths)
    settings = settings_for(paths[0] if paths else Path.cwd(), args)
    request = ScanRequest(paths=paths, rev=args.rev, settings=settings, jobs=args.jobs)
    with facts_cache(args, settings) as cache:
        report = run_scan(request, NoProgress(), cache)
    assert report.coupling is not None
    view = args.view
    if view is None:
        named = any(s.name for c in report.coupling.elements for s in c.link_sites)
        view = "computation" if named else "elements"
    graph = report.coupling.graph if view == "elements" else computation_graph(report.coupling)
    emit(render(graph, args.format), args.output)
    return EXIT_OK


def revisions_to_compare(args: argparse.Namespace, checkout: Checkout) -> tuple[str, str, str]:
    """The base and head to compare, and how to name the base: --base and --head; ``--base
    A...B`` (or --merge-base) compares B with the merge base of A and B, as ``git diff
    A...B`` does, and ``--base A..B`` is A against B. With --from-pre-commit, the range
    pre-commit was asked to check (``pre-commit run --from-ref A --to-ref B``, and pre-push,
    set both variables), compared as pre-commit selects its files: A...B. A commit sets
    neither: the hook's own --base HEAD --head INDEX measure the staged change."""
    head_given = args.head is not None
    base, head, merge = args.base, args.head or "WORKTREE", args.merge_base
    if args.from_pre_commit:
        start = os.environ.get("PRE_COMMIT_FROM_REF", "")
        end = os.environ.get("PRE_COMMIT_TO_REF", "")
        if start or end:
            if not (start and end):
                raise UsageError(
                    "pre-commit set only one of PRE_COMMIT_FROM_REF, PRE_COMMIT_TO_REF"
                )
            base, head, merge = start, end, True
        else:
            check_hook_files(args.files, checkout)
    elif args.files:
        raise UsageError(f"diff takes no PATH ({args.files[0]}); did you mean --base or --head?")
    if "..." in base or ".." in base:
        base, head, merge = _range(base, head, head_given)
    if not merge:
        return base, head, base
    label = f"{base}...{head}"
    return checkout.merge_base(base, head), head, label


def _range(text: str, head: str, head_given: bool) -> tuple[str, str, bool]:
    """``A...B`` or ``A..B`` given as --base: its two ends (an empty end is HEAD, as in
    git) and whether to compare from their merge base."""
    merge = "..." in text
    first, _, second = text.partition("..." if merge else "..")
    first, second = first or "HEAD", second or "HEAD"
    if head_given and head != second:
        raise UsageError(f"--base {text} names the head ({second}); --head {head} disagrees")
    return first, second, merge


def check_hook_files(files: list[str], checkout: Checkout) -> None:
    """Refuse to pass silently when pre-commit hands the hook files that are not the staged
    change (``pre-commit run --all-files`` or ``--files``): archmetrics measures a change,
    and without --from-ref/--to-ref nothing says which."""
    if not files:
        return
    staged = checkout.staged_paths()  # as reports name them: escaped as git escapes them
    others = [path for path in files if quote_path(path) not in staged]
    if others:
        raise UsageError(
            f"pre-commit ran the hook on files, not on a change ({others[0]} is not staged:"
            " --all-files or --files); archmetrics measures a change: give pre-commit the"
            " range, e.g. pre-commit run archmetrics --from-ref origin/main --to-ref HEAD,"
            " or leave the hook out of this run with SKIP=archmetrics"
        )


def configuration(
    args: argparse.Namespace, checkout: Checkout, base: str, head: str
) -> tuple[Settings, Settings | None]:
    """The settings a comparison runs under, as ``--config-from`` says: the ``base``
    revision's (the default), the ``head``'s or the runner's file; and, when they are not
    the base's, the base's too (the implicit gate unmeasured(head) judges by them)."""
    choice = getattr(args, "config_from", "base")
    if choice == "base":
        return settings_of(checkout, base, args), None
    chosen = settings_of(checkout, head, args) if choice == "head" else (
        settings_from_file(Path(choice), args)
    )  # fmt: skip
    return chosen, settings_of(checkout, base, args)


def diff_request(
    args: argparse.Namespace,
    checkout: Checkout,
    base: str = "",
    head: str = "",
    label: str = "",
    config_base: str | None = None,
    config_head: str | None = None,
) -> DiffRequest:
    """The command line's diff, in the repository the command opened: flags and settings
    are merged from here on once (``app.diff_options.diff_options``). The configuration is that of
    ``config_base`` and ``config_head`` (default: ``base``, ``head``) as ``--config-from``
    chooses."""
    settings, base_settings = configuration(
        args, checkout, config_base or base, config_head or head or WORKTREE
    )
    return DiffRequest(
        root=checkout.root,
        base=base,
        head=head,
        base_label=label,
        settings=settings,
        base_settings=base_settings,
        new=tuple(args.new),
        framework=tuple(args.framework),
        gates=tuple(args.fail_on),
        jobs=args.jobs,
        dynamic_pre_zero=args.dynamic_pre_zero,
        baseline=load_baseline(getattr(args, "baseline", None)),
    )


def series_command(args: argparse.Namespace) -> int:
    check_chart(args)
    fmt = OutputFormat(args.format)
    checkout = open_checkout(args.repo)
    revisions = tuple(args.revisions)
    request = SeriesRequest(
        diff_request(args, checkout, **_series_configuration(args.root, revisions)),
        revisions,
        split(args.labels),
        args.root,
    )
    with facts_cache(args, request.diff.settings) as cache, shown_progress(fmt, args.quiet) as p:
        report = run_series(request, p, cache, checkout)
        p.phase("writing the report")
        text = render_series(report, fmt, args.max_rows)
    emit(text, args.output)
    write_chart(args, CompareReport(((resolve_path(Path(args.repo)).name, report),)))
    return gate_status(report.failures, args)


def compare_command(args: argparse.Namespace) -> int:
    check_chart(args)
    fmt = OutputFormat(args.format)
    named = []
    checkouts: dict[str, Checkout] = {}
    for text in args.repos:
        name, path = parse_named_path(text)
        checkout = open_checkout(path)
        revisions = split(args.revisions) or checkout.tags()
        request = SeriesRequest(
            diff_request(args, checkout, **_series_configuration(args.root, revisions)),
            revisions,
            split(args.labels),
            args.root,
        )
        named.append((name, request))
        checkouts[name] = checkout
    settings = named[0][1].diff.settings
    with facts_cache(args, settings) as cache, shown_progress(fmt, args.quiet) as p:
        report = run_compare(named, p, cache, checkouts)
        p.phase("writing the report")
        text = render_compare(report, fmt)
    emit(text, args.output)
    write_chart(args, report)
    return gate_status(report.failures, args)


def _series_configuration(root: str, revisions: tuple[str, ...]) -> dict[str, str]:
    """Where a series takes its configuration from: its first stage's base (``--root``,
    or the first revision when that is EMPTY), or its last revision."""
    first = revisions[0] if root == EMPTY and revisions else root
    return {"config_base": first, "config_head": revisions[-1] if revisions else WORKTREE}


def diff_command(args: argparse.Namespace) -> int:
    check_chart(args)
    fmt = OutputFormat(args.format)
    checkout = open_checkout(args.repo)
    base, head, label = revisions_to_compare(args, checkout)
    request = diff_request(args, checkout, base, head, label)
    settings = request.settings
    with facts_cache(args, settings) as cache, shown_progress(fmt, args.quiet) as progress:
        report = run_diff(request, progress, cache, checkout)
        progress.phase("writing the report")
        text = render_diff(report, fmt, args.max_rows)
    emit(text, args.output)
    for glob in report.change.unmatched:
        warn(unmatched_glob(glob))
    stage = Stage(f"{label}..{head}", report)
    name = resolve_path(Path(args.repo)).name
    write_chart(args, CompareReport(((name, SeriesReport(str(args.repo), (stage,))),)))
    return gate_status(report.failed, args)
