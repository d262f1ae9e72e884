"""``archmetrics baseline``: write the offenders a code base already has, so that ``scan``
and ``diff --baseline FILE`` fail only on new offenders and on offenders that got worse
(complexity/baseline.py says how they are matched)."""

from __future__ import annotations

import argparse
from pathlib import Path

from archmetrics import __version__
from archmetrics.app.progress import NoProgress
from archmetrics.app.scan import ScanRequest, run_scan
from archmetrics.changeset.gates import is_unit_gate
from archmetrics.cli.common import EXIT_OK, UsageError, emit, facts_cache, settings_for
from archmetrics.complexity.baseline import (
    Baseline,
    BaselineError,
    baseline_document,
    baseline_of,
    read_baseline,
)

DEFAULT_FILE = Path("archmetrics-baseline.json")


def load_baseline(path: Path | None) -> Baseline | None:
    """The baseline ``--baseline`` names (None without the flag); exit 2 if it is unreadable."""
    if path is None:
        return None
    try:
        data = path.read_bytes()
    except OSError as error:
        raise UsageError(f"{path}: --baseline: cannot read: {error.strerror}") from None
    return read_baseline(data, str(path))


def baseline_command(args: argparse.Namespace) -> int:
    paths: tuple[Path, ...] = tuple(args.paths)
    settings = settings_for(paths[0] if paths else Path.cwd(), args)
    thresholds = (*args.fail_on, *(g for g in settings.gates if is_unit_gate(g)))
    if not thresholds:
        raise UsageError(
            "a baseline records the offenders of thresholds: give --fail-on 'vg(function) > 15'"
            " (or a function or file gate in the configuration's gates)"
        )
    request = ScanRequest(paths=paths, rev=args.rev, settings=settings, jobs=args.jobs,
                          gates=thresholds)  # fmt: skip
    with facts_cache(args, settings) as cache:
        report = run_scan(request, NoProgress(), cache)
    baseline = baseline_of(report.failures)
    output: Path = args.output or DEFAULT_FILE
    emit(baseline_document(baseline, thresholds, __version__), output)
    count = len(baseline.offenders)
    print(f"archmetrics: {count} offenders of {', '.join(thresholds)} written to {output}")
    return EXIT_OK


__all__ = ["BaselineError", "baseline_command", "load_baseline"]
