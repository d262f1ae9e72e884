"""Logical LOC (λ), SLOC and McCabe's v_g, summarised from facts. Pure."""

from archmetrics.complexity.summary import (
    FileMetrics,
    FunctionMetrics,
    Reading,
    Totals,
    file_metrics,
    totals,
)

__all__ = ["FileMetrics", "FunctionMetrics", "Reading", "Totals", "file_metrics", "totals"]
