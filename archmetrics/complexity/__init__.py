"""Logical LOC (λ), SLOC and McCabe's v_g, summarised from facts. Pure."""

from archmetrics.complexity.summary import (
    FileMetrics,
    FunctionMetrics,
    Totals,
    file_metrics,
    totals,
)

__all__ = ["FileMetrics", "FunctionMetrics", "Totals", "file_metrics", "totals"]
