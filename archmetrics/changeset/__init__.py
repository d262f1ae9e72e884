"""Change sets between two revisions: statement diff, Γ, scale factors, ΔVg and cost E (pure).

Thesis chapter 6 (Hestand 2011, pp. 98-107). Entry point: :func:`compute_change`.
"""

from __future__ import annotations

from archmetrics.changeset.compute import compute_change, coupling_by_element, report_of
from archmetrics.changeset.cost import Sums, location_summary, total_summary
from archmetrics.changeset.locations import Location, LocationRule, LocationRules
from archmetrics.changeset.model import (
    SUMMARY_FIELDS,
    ChangeReport,
    Coupling,
    ElementChange,
    ExcludedFile,
    FilePair,
    Metrics,
    Status,
    Summary,
)
from archmetrics.changeset.statement_diff import (
    Action,
    FileChange,
    StatementChange,
    diff_files,
    diff_statements,
)

__all__ = [
    "SUMMARY_FIELDS",
    "Action",
    "ChangeReport",
    "Coupling",
    "ElementChange",
    "ExcludedFile",
    "FileChange",
    "FilePair",
    "Location",
    "LocationRule",
    "LocationRules",
    "Metrics",
    "StatementChange",
    "Status",
    "Summary",
    "Sums",
    "compute_change",
    "coupling_by_element",
    "diff_files",
    "diff_statements",
    "location_summary",
    "report_of",
    "total_summary",
]
