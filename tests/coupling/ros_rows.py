"""Rows of hand-checked ROS link sites, and the rule that matches reported sites to them.

The full oracle (benchmarks/ros_oracle/``<owner>__<name>.sites``, read by
benchmarks/ros_oracle.py) and the pinned slice (tests/coupling/ros_cases/cases.sites, read by
test_ros_oracle_slice.py) share this format: ``|``-separated cells under the header
``file|line|end|kind|name|type|from|written|launch|note``, ``#`` comment lines
(benchmarks/ros_oracle/README.md says what every column means). A reported site matches a row
of the same file when its line lies in ``[line - LINE_SLACK, end]`` (a tool may report the
statement's first line rather than the callee's); each row and each site is matched at most
once, nearest line first, and among equally near ones a site whose kind (then name) agrees
with the row's.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

from tests.coupling.ros_adapter import KIND_CATEGORY, kind_family

COLUMNS = ("file", "line", "end", "kind", "name", "type", "from", "written", "launch", "note")
LINE_SLACK = 2
#: How a name counts as given statically: the issue's sense (a literal, a constant or a
#: parameter default in the same package), and the wider sense a reader can still resolve.
NAMED_ISSUE = frozenset({"literal", "constant", "parameter-default"})
NAMED_STATIC = NAMED_ISSUE | {"variable", "member", "argument", "implicit"}
GIVEN = NAMED_STATIC | {"parameter", "computed", "none"}


@dataclass(frozen=True, slots=True)
class Row:
    """One hand-checked site: where, what, and the names a correct endpoint may carry."""

    file: str
    line: int
    end: int
    kind: str
    names: tuple[str, ...]
    launch_names: tuple[str, ...]
    types: tuple[str, ...]
    given: str
    written: str
    test: bool

    def accepts(self, name: str | None) -> bool:
        """Does a reported name agree with this row (its own names or a launch file's)?"""
        return name is not None and name in {*self.names, *self.launch_names}


@dataclass
class Match:
    """Rows and reported sites of one repository, paired."""

    pairs: list[tuple[Row, Mapping[str, object]]] = field(default_factory=list)
    missed: list[Row] = field(default_factory=list)
    extra: list[Mapping[str, object]] = field(default_factory=list)


def is_test_path(path: str) -> bool:
    """A file of a test: under a ``test``/``tests`` folder, or named ``test_*``/``*_test``."""
    *folders, name = path.split("/")
    stem = name.split(".", 1)[0]
    return (
        any(f in ("test", "tests") for f in folders)
        or stem.startswith(("test_", "test-"))
        or stem.endswith("_test")
    )


def judged(path: str, kind: str) -> bool:
    """Does the oracle judge a reported site of this kind family in this file?

    Parameter values written in parameter and launch files (YAML ``ros__parameters``, ``<param>``,
    ``<rosparam>``, launch_ros ``parameters=[...]``) are configuration the oracle does not label:
    a site in a YAML file that is not a launch file, or of a parameter kind in a launch or XML
    file, is neither found nor extra (the benchmark counts such sites apart).
    """
    name = path.rsplit("/", 1)[-1]
    suffix = "." + name.rsplit(".", 1)[-1] if "." in name else ""
    if suffix in (".yaml", ".yml") and "launch" not in name:
        return False
    configuration = suffix in (".xml", ".launch", ".test", ".yaml", ".yml") or (
        suffix == ".py" and "launch" in name
    )
    return not (configuration and KIND_CATEGORY.get(kind) == "parameter")


def _split(text: str) -> tuple[str, ...]:
    return tuple(part for part in text.split(";") if part)


def parse_rows(text: str, source: str) -> list[Row]:
    """The rows of one ``.sites`` file; a malformed line is an error naming the line."""
    rows: list[Row] = []
    header_seen = False
    for number, line in enumerate(text.splitlines(), 1):
        if not line.strip() or line.startswith("#"):
            continue
        cells = line.split("|")
        if len(cells) != len(COLUMNS):
            raise ValueError(f"{source}:{number}: {len(cells)} columns, expected {len(COLUMNS)}")
        if not header_seen:
            if tuple(cells) != COLUMNS:
                raise ValueError(f"{source}:{number}: the header must be {'|'.join(COLUMNS)}")
            header_seen = True
            continue
        cell = dict(zip(COLUMNS, cells, strict=True))
        if cell["kind"] not in KIND_CATEGORY or cell["from"] not in GIVEN:
            unknown = f"{cell['kind']}, {cell['from']}"
            raise ValueError(f"{source}:{number}: unknown kind or from: {unknown}")
        launch = tuple(n.split("@", 1)[0] for n in _split(cell["launch"]))
        rows.append(Row(cell["file"], int(cell["line"]), int(cell["end"]), cell["kind"],
                        _split(cell["name"]), launch, _split(cell["type"]), cell["from"],
                        cell["written"], is_test_path(cell["file"])))  # fmt: skip
    return rows


Endpoint = Callable[[Mapping[str, object]], tuple[str, str | None, str | None]]


def _disagree(row: Row, site: Mapping[str, object], endpoint_of: Endpoint | None) -> int:
    if endpoint_of is None:
        return 0
    kind, name, _ = endpoint_of(site)
    return 2 * (kind != kind_family(row.kind)) + (bool(row.names) and not row.accepts(name))


def match_sites(
    rows: Iterable[Row],
    sites: Iterable[Mapping[str, object]],
    endpoint_of: Endpoint | None = None,
) -> Match:
    """Pair rows and reported sites of one tree by file and line (LINE_SLACK, nearest first).

    ``endpoint_of`` (``ros_endpoint``) only decides between equally near pairs: first those whose
    kinds agree, then those whose names do -- a subscription and the publish call in its
    callback on one line, two parameters read on one line.
    """
    by_file: dict[str, list[Mapping[str, object]]] = {}
    for site in sites:
        by_file.setdefault(str(site["path"]), []).append(site)
    result = Match()
    for file in sorted({row.file for row in rows} | set(by_file)):
        candidates = by_file.get(file, [])
        file_rows = [row for row in rows if row.file == file]
        options = sorted(
            (abs(int(str(site["line"])) - row.line), _disagree(row, site, endpoint_of), i, j)
            for i, row in enumerate(file_rows)
            for j, site in enumerate(candidates)
            if row.line - LINE_SLACK <= int(str(site["line"])) <= row.end
        )
        used_rows: set[int] = set()
        used_sites: set[int] = set()
        for _, _, i, j in options:
            if i not in used_rows and j not in used_sites:
                used_rows.add(i)
                used_sites.add(j)
                result.pairs.append((file_rows[i], candidates[j]))
        result.missed += [row for i, row in enumerate(file_rows) if i not in used_rows]
        result.extra += [site for j, site in enumerate(candidates) if j not in used_sites]
    return result
