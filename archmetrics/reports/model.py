"""What reports render: plain frozen values built by the use cases."""

from __future__ import annotations

from dataclasses import dataclass

from archmetrics.complexity import FileMetrics, Totals
from archmetrics.facts import FileFacts

SCAN_SCHEMA = "archmetrics.scan/1"


@dataclass(frozen=True, slots=True)
class ScanReport:
    """One snapshot measured: facts (for tracing) and the metrics shown."""

    root: str
    revision: str
    facts: tuple[FileFacts, ...]
    files: tuple[FileMetrics, ...]
    totals: Totals
