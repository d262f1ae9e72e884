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
    estimated: bool = False  # read from tokens in part or whole: v_g estimated


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
    files_warned: int = 0  # files with at least one parse warning
    functions_estimated: int = 0  # functions whose v_g the token reading estimated

    def reading(self) -> Reading:
        return Reading(self.files, self.files_warned, self.functions, self.functions_estimated)


@dataclass(frozen=True, slots=True)
class Reading:
    """How much of the measured code the parsers read in full: the files with a warning,
    and the functions whose facts came from the token reading in part or whole
    (``Function.estimated``; docs/metrics.md, "Warnings")."""

    files: int
    files_warned: int
    functions: int
    functions_estimated: int

    @classmethod
    def of(cls, counts: Iterable[tuple[bool, int, int]]) -> Reading:
        """From (warned, functions, estimated) per file."""
        files = warned = functions = estimated = 0
        for has_warnings, count, guessed in counts:
            files += 1
            warned += has_warnings
            functions += count
            estimated += guessed
        return cls(files, warned, functions, estimated)

    def line(self) -> str:
        """The summary line a table or Markdown report shows."""
        return (
            f"read with warnings: {self.files_warned} of {self.files} files"
            f" ({_share(self.files_warned, self.files)}); v_g estimated from tokens:"
            f" {self.functions_estimated} of {self.functions} functions"
            f" ({_share(self.functions_estimated, self.functions)})"
        )


def _share(part: int, whole: int) -> str:
    return f"{100 * part / whole:.1f}%" if whole else "0%"


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
            estimated=f.estimated,
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
        files_warned=sum(bool(f.warnings) for f in items),
        functions_estimated=sum(g.estimated for f in items for g in f.functions),
    )
