"""Per-file and per-function λ, SLOC and v_g, and their totals.

λ is the number of logical statements the parser found (thesis page 103); v_g of a function is
1 + its decision points, and of a file or element the sum over its functions (thesis eq. 6.31
builds location values the same way, by summing element parts).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from archmetrics.facts import FileFacts, ParseWarning


@dataclass(frozen=True, slots=True)
class FunctionMetrics:
    name: str
    qualified_name: str
    line: int
    end_line: int
    loc: int
    vg: int
    suppressed: tuple[str, ...] = ()  # fields a reviewer's comment exempts it from


@dataclass(frozen=True, slots=True)
class FileMetrics:
    path: str
    language: str
    loc: int
    sloc: int
    vg: int
    functions: tuple[FunctionMetrics, ...]
    warnings: tuple[ParseWarning, ...]
    parsed: bool
    generated: bool


@dataclass(frozen=True, slots=True)
class Totals:
    files: int
    functions: int
    loc: int
    sloc: int
    vg: int
    warnings: int
    unparsed: int


def file_metrics(facts: FileFacts) -> FileMetrics:
    """The numbers a report shows for one file, traced to its functions."""
    functions = tuple(
        FunctionMetrics(
            name=f.name,
            qualified_name=f.qualified_name,
            line=f.span.start,
            end_line=f.span.end,
            loc=f.statements,
            vg=f.complexity,
            suppressed=f.suppressed,
        )
        for f in facts.functions
    )
    return FileMetrics(
        path=facts.path,
        language=facts.language,
        loc=facts.loc,
        sloc=facts.sloc,
        vg=facts.vg,
        functions=functions,
        warnings=facts.warnings,
        parsed=facts.parsed,
        generated=facts.generated,
    )


def totals(files: Iterable[FileMetrics]) -> Totals:
    """Sums over files (v_g of a set of files is the sum of their functions' v_g)."""
    items = list(files)
    return Totals(
        files=len(items),
        functions=sum(len(f.functions) for f in items),
        loc=sum(f.loc for f in items),
        sloc=sum(f.sloc for f in items),
        vg=sum(f.vg for f in items),
        warnings=sum(len(f.warnings) for f in items),
        unparsed=sum(not f.parsed for f in items),
    )
