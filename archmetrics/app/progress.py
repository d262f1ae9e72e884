"""The progress port: use cases report progress through it; the CLI decides how it looks.

A long run has counted steps (``start``, ``advance``: parsing N files) and steps without a
count (``phase``: listing a revision's files, coupling a tree, comparing statements, writing
the report). Every long step is named, so the terminal never sits silent after a bar ends."""

from __future__ import annotations

from typing import Protocol


class Progress(Protocol):
    def phase(self, description: str) -> None:
        """A step without a count begins (it ends when the next step begins, or ``stop``)."""

    def start(self, description: str, total: int) -> None: ...

    def advance(self, count: int = 1) -> None: ...

    def stop(self) -> None: ...


class NoProgress:
    """Shows nothing (JSON output, tests, small runs)."""

    def phase(self, description: str) -> None:
        pass

    def start(self, description: str, total: int) -> None:
        pass

    def advance(self, count: int = 1) -> None:
        pass

    def stop(self) -> None:
        pass
