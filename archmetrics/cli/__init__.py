"""The ``archmetrics`` command line: flags become a request, one use case runs, a report prints.

Exit status: 0 measured (and every gate holds), 1 a gate failed, 2 could not measure (bad usage,
unknown revision, bad configuration, or anything unforeseen) with a one-line error and no
traceback (``-v`` prints it). Exit 1 means a gate failed and nothing else.
"""

from __future__ import annotations

import gc
import os
import sys
import traceback
from collections.abc import Iterator, Sequence
from contextlib import contextmanager

from archmetrics.app.history_dask import ClusterError
from archmetrics.app.series import SeriesError
from archmetrics.changeset.gates import GateError
from archmetrics.changeset.plan import PlanError
from archmetrics.cli import baseline, docs, estimate, history, measure, study
from archmetrics.cli.common import EXIT_USAGE, UsageError, check_paths
from archmetrics.cli.options import settle_format
from archmetrics.cli.parser import build_parser
from archmetrics.complexity.thresholds import ThresholdError
from archmetrics.config import ConfigError
from archmetrics.coupling.rules import RulePackError
from archmetrics.globs import BadPattern
from archmetrics.parsers import UnknownLanguage
from archmetrics.reports.printable import one_line
from archmetrics.sources import SourceError
from archmetrics.sources.cache import CacheError
from archmetrics.sources.codec import CodecError
from archmetrics.study.manifest import ManifestError

COMMANDS = {
    "scan": measure.scan_command,
    "baseline": baseline.baseline_command,
    "diff": measure.diff_command,
    "series": measure.series_command,
    "compare": measure.compare_command,
    "history": history.history_command,
    "estimate": estimate.estimate_command,
    "replicate": study.replicate_command,
    "rules": measure.rules_command,
    "graph": measure.graph_command,
    "cache": measure.cache_command,
    "docs": docs.docs_command,
}
CANNOT_MEASURE = (
    SourceError,
    ConfigError,
    UnknownLanguage,
    UsageError,
    BadPattern,
    GateError,
    ThresholdError,
    RulePackError,
    SeriesError,
    ManifestError,
    CacheError,
    PlanError,
    baseline.BaselineError,
    ClusterError,
)


GC_THRESHOLD = (100_000, 50, 100)
"""Collector thresholds while a command runs (CPython's defaults are 700, 10, 10).

Facts are millions of small acyclic objects (statements, spans, call sites) that live for
the whole run; with the default thresholds the collector keeps walking them, which took 40 %
of decoding a numpy release from the cache and 29 % of a warm diff of two (docs/performance.md).
They hold no reference cycles, so collecting less often frees nothing later than it should.
"""


@contextmanager
def few_collections() -> Iterator[None]:
    """Run with :data:`GC_THRESHOLD`; the previous thresholds come back afterwards."""
    before = gc.get_threshold()
    gc.set_threshold(*GC_THRESHOLD)
    try:
        yield
    finally:
        gc.set_threshold(*before)


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        settle_format(args)
        if getattr(args, "jobs", 0) < 0:
            raise UsageError("--jobs must be 0 or more")
        if (getattr(args, "max_rows", None) or 0) < 0:
            raise UsageError("--max-rows must be 0 or more")
        check_paths(args)
        with few_collections():
            return COMMANDS[args.command](args)
    except CANNOT_MEASURE as error:
        return fail(str(error))
    except CodecError as error:  # statements are decoded when first read, after the checks
        return fail(f"{error}; `archmetrics cache clear` empties the cache")
    except KeyboardInterrupt:
        print("archmetrics: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader went away (`archmetrics scan | head`)
        silence_stdout()
        return EXIT_USAGE
    except Exception as error:  # an input nobody foresaw, or a bug: still one line, exit 2
        if getattr(args, "verbose", False):
            traceback.print_exc()
        hint = "" if getattr(args, "verbose", False) else "; rerun with -v for the traceback"
        return fail(f"unexpected {type(error).__name__}: {error} (please report it{hint})")


def fail(message: str) -> int:
    """Print ``message`` as the one-line error of a run that could not measure: exit 2."""
    print(f"archmetrics: error: {one_line(message)}", file=sys.stderr)
    return EXIT_USAGE


def silence_stdout() -> None:
    """Point stdout at /dev/null, so the interpreter's own flush at exit cannot fail again."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    os.close(devnull)
