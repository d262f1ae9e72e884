"""The coupling index's dependency records of a tree state read from the cache
(sources/statecodec.py), kept as the columns they were read from."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from itertools import accumulate

from archmetrics.coupling.index import Dep
from archmetrics.sources.statecolumns import bad, ints, lists, texts

RESOLUTIONS = ("internal", "external", "unresolved")


class DepTable(Mapping[str, tuple[Dep, ...]]):
    """The coupling index's dependency records of a state read from the cache, kept as the
    columns they were read from; a file's records are made when asked for."""

    def __init__(self, files: list[str], where: list[int], starts: list[int],
                 targets: list[int], resolutions: list[int], names: list[str]) -> None:  # fmt: skip
        self.files, self.where, self.starts = files, where, starts
        self.targets, self.resolutions, self.names = targets, resolutions, names
        self._span: dict[str, tuple[int, int]] | None = None
        self._made: dict[str, tuple[Dep, ...]] = {}

    @classmethod
    def read(cls, value: object, files: list[str]) -> DepTable:
        where, sizes, targets, resolutions, names = lists(value, 5)
        located = ints(where, 0, len(files))
        lengths = ints(sizes, 1, 1 << 62, len(located))
        target = ints(targets, -1, len(files))
        if sum(lengths) != len(target) or len(set(located)) != len(located):
            raise bad("dependency columns that do not add up")
        codes = ints(resolutions, 0, len(RESOLUTIONS), len(target))
        return cls(files, located, [0, *accumulate(lengths)], target, codes,
                   texts(names, len(target)))  # fmt: skip

    @property
    def span(self) -> dict[str, tuple[int, int]]:
        """Each file's records' place in the columns (made when first asked for)."""
        if self._span is None:
            starts, files = self.starts, self.files
            self._span = {files[i]: (starts[k], starts[k + 1]) for k, i in enumerate(self.where)}
        return self._span

    def __getitem__(self, path: str) -> tuple[Dep, ...]:
        made = self._made.get(path)
        if made is None:
            start, end = self.span[path]
            files, targets, codes, names = self.files, self.targets, self.resolutions, self.names
            made = self._made[path] = tuple(
                Dep(None if targets[i] < 0 else files[targets[i]], RESOLUTIONS[codes[i]], names[i])
                for i in range(start, end)
            )
        return made

    def __iter__(self) -> Iterator[str]:
        return iter(self.span)

    def __len__(self) -> int:
        return len(self.where)

    def sources(self) -> dict[str, list[str]]:
        """For every file depended on, the files that include or import it."""
        found: dict[int, list[str]] = {}
        files, targets, starts = self.files, self.targets, self.starts
        for k, i in enumerate(self.where):
            for t in targets[starts[k] : starts[k + 1]]:
                if t >= 0:
                    found.setdefault(t, []).append(files[i])
        return {files[t]: sources for t, sources in found.items()}
