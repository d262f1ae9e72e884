"""Descriptor problems: each names the file, the line and the field it is about."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Problem:
    """One thing wrong with a descriptor, printed as ``file:line: field: message``."""

    source: str
    line: int
    field: str
    message: str

    def __str__(self) -> str:
        """One line, whatever the descriptor (or its file name) contains."""
        where = f"{self.field}: " if self.field else ""
        return one_line(f"{self.source}:{self.line}: {where}{self.message}")


def one_line(text: str) -> str:
    """``text`` with every unprintable character (line breaks included) escaped as in repr."""
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


class DescriptorError(ValueError):
    """A descriptor failed to parse, to match the schema, or a semantic check."""

    def __init__(self, problems: Iterable[Problem]) -> None:
        self.problems: tuple[Problem, ...] = tuple(problems)
        super().__init__("\n".join(str(p) for p in self.problems))
