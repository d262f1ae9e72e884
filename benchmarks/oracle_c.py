"""C/C++ facts against lizard on real code nobody here wrote: functions found, equal v_g,
made-up functions, losses under no warning, warnings confirmed.

    python benchmarks/oracle_c.py [--corpus DIR] [--only NAME ...] [--folder NAME=PATH ...]
                                  [--show N] [--jobs N]

Sdists from PyPI (pinned below) are fetched into ``DIR`` (default ``.cache/corpus13``) from
PyPI's simple index and unpacked; ``--folder`` adds every C/C++ file under a folder (a
checkout, a fetched repository). Functions are matched by (file, last line) and lizard's
first line lying in our span, as tests/parsers/test_c_oracle.py does. lizard's own
inventions (c_inventions.py: a keyword as a name, a span over other functions, a function
inside a #define, a method of a class inside one of our functions) are left out of its
functions and counted by class. Per corpus it prints: lizard's real functions, how many we
found (read by the tree or estimated from tokens), how many of those have the same v_g
(the others by the class of docs/metrics.md that explains them), our functions that are
made up (c_inventions.made_up), lizard's functions we lose or miscount under no warning,
the files with a warning, the functions estimated, and the warnings confirmed: a file with
warnings is parsed again without the second reading (``second_reading=False``) and a
warning counts as confirmed when lizard shows the tree alone lost, misnamed, made up or
miscounted a function there, or, for a warning that claims only statements or call sites,
when lizard's tokens counted again hold more of them on its lines than the tree's facts.
``--show`` prints that many examples of each kind.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import re
import sys
import tarfile
import urllib.request
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import c_inventions  # noqa: E402

from archmetrics.facts import FileFacts, Language  # noqa: E402
from archmetrics.parsers import ParseLimits, c_family  # noqa: E402
from tests.parsers.test_c_oracle import _disagreement_class  # noqa: E402

# name -> (pip requirement, folders inside the unpacked sdist that hold the C/C++ we read)
CORPORA: dict[str, tuple[str, tuple[str, ...]]] = {
    "grpcio": ("grpcio==1.68.0", ("src/core", "third_party/abseil-cpp", "third_party/upb",
                                  "third_party/re2", "third_party/address_sorting")),
    "sentencepiece": ("sentencepiece==0.2.0", ("sentencepiece/src",)),
    "rapidjson": ("python-rapidjson==1.20", ("rapidjson/include",)),
    "psutil": ("psutil==6.1.0", ("psutil",)),
    "gevent": ("gevent==24.11.1", ("deps/libev", "deps/libuv", "deps/c-ares", "src")),
    "ujson": ("ujson==5.10.0", ("src", "deps")),
    "pycryptodome": ("pycryptodome==3.21.0", ("src",)),
    "uvloop": ("uvloop==0.21.0", ("vendor/libuv/src", "vendor/libuv/include")),
    "numpy": ("numpy==2.2.0", ("numpy/_core/src", "numpy/_core/include", "numpy/fft",
                               "numpy/linalg", "numpy/random/src")),
    # a database: SQLite's 260k-line amalgamation and the sqlean extensions
    "sqlite": ("sqlean-py==3.50.4.5", ("sqlite", "src")),
    # a scripting language: Lua 5.4 and LuaJIT 2.1 as lupa vendors them
    "lua": ("lupa==2.5", ("third-party/lua54", "third-party/luajit21/src")),
}  # fmt: skip
# a loaded host must not cut a big file's parse (sqlite3.c, 9 MB) short: that is no loss of
# the reading this measures
LIMITS = ParseLimits(parse_seconds=600)
SUFFIXES = {".c": Language.C, ".h": Language.CPP, ".cc": Language.CPP, ".cpp": Language.CPP,
            ".hpp": Language.CPP, ".cxx": Language.CPP, ".hh": Language.CPP}  # fmt: skip


def fetch(folder: Path, requirement: str) -> Path:
    """The unpacked sdist of ``requirement`` (name==version) in ``folder``."""
    name, version = requirement.split("==")
    for candidate in folder.iterdir() if folder.is_dir() else ():
        stem = candidate.name.lower().replace("_", "-")
        if candidate.is_dir() and stem == f"{name.lower()}-{version}":
            return candidate
    folder.mkdir(parents=True, exist_ok=True)
    request = urllib.request.Request(
        f"https://pypi.org/simple/{name}/",
        headers={"Accept": "application/vnd.pypi.simple.v1+json"},
    )
    with urllib.request.urlopen(request, timeout=120) as answer:
        files = json.load(answer)["files"]
    wanted = {
        f"{name.lower()}-{version}.tar.gz",
        f"{name.lower().replace('-', '_')}-{version}.tar.gz",
    }
    [entry] = [f for f in files if f["filename"].lower() in wanted]
    archive = folder / entry["filename"]
    urllib.request.urlretrieve(entry["url"], archive)
    with tarfile.open(archive) as tar:
        tar.extractall(folder, filter="data")
    return fetch(folder, requirement)


@dataclass
class Tally:
    files: int = 0
    lizard: int = 0  # lizard's real functions (its inventions left out)
    found: int = 0
    equal: int = 0
    low_files: int = 0
    estimated: int = 0  # of ours, read from tokens in part or whole
    functions: int = 0  # ours
    warned_files: int = 0
    warnings: int = 0
    true_warnings: int = 0  # a loss of the syntax tree there, confirmed by lizard
    counts_only: int = 0  # claiming only statements or call sites, not checkable by lizard
    missing: list[str] = field(default_factory=list)
    unequal: list[str] = field(default_factory=list)
    explained: dict[str, int] = field(default_factory=dict)
    inventions: dict[str, int] = field(default_factory=dict)
    low: list[str] = field(default_factory=list)
    made_up: list[str] = field(default_factory=list)
    silent: list[str] = field(default_factory=list)  # lost or miscounted, under no warning
    false_warnings: list[str] = field(default_factory=list)
    counts: list[str] = field(default_factory=list)  # the counts-only warnings
    extra: int = 0


_REGION = re.compile(r"lines? (\d+)(?:-(\d+))?:")


def _regions(facts: FileFacts) -> list[tuple[int, int, str]]:
    """(first line, last line, message) of each warning about a region; a file not
    measured at all is one region."""
    found = []
    if not facts.parsed:
        return [(1, 1 << 30, w.message) for w in facts.warnings[:1]]
    for warning in facts.warnings:
        matched = _REGION.match(warning.message)
        if matched:
            first = int(matched.group(1))
            found.append((first, int(matched.group(2) or first), warning.message))
    return found


def _ours(facts: FileFacts) -> list[c_inventions.Ours]:
    return [
        c_inventions.Ours(f.qualified_name, f.span.start, f.span.end, f.complexity, f.estimated)
        for f in facts.functions
    ]


def _local_classes(facts: FileFacts) -> list[tuple[int, int]]:
    spans = [(f.span.start, f.span.end) for f in facts.functions]
    return [
        (c.span.start, c.span.end)
        for c in facts.classes
        if any(s < c.span.start and c.span.end <= e for s, e in spans)
    ]


def _match(ours: list[c_inventions.Ours], other: c_inventions.Theirs) -> c_inventions.Ours | None:
    return next((f for f in ours if f.end == other.end and f.start <= other.start), None)


def compare_file(item: tuple[str, str]) -> Tally:
    import lizard

    path, shown = item
    source = Path(path).read_text(encoding="utf-8", errors="replace")
    language = SUFFIXES[Path(path).suffix]
    facts = c_family.parse(shown, source, language, LIMITS)
    result = lizard.analyze_file.analyze_source_code(path, source).function_list
    all_theirs = [
        c_inventions.Theirs(f.name, f.start_line, f.end_line, f.cyclomatic_complexity)
        for f in result
    ]
    ours = _ours(facts)
    local = _local_classes(facts)
    defines = c_inventions.define_lines(source)
    tally = Tally(files=1, functions=len(ours), estimated=sum(f.estimated for f in ours))
    theirs = []
    lines = source.splitlines()
    for other in all_theirs:
        kind = c_inventions.invention(other, all_theirs, ours, defines, local, lines)
        if kind is None:
            theirs.append(other)
        else:
            tally.inventions[kind] = tally.inventions.get(kind, 0) + 1
    for function, why in c_inventions.made_up(
        ours, theirs, c_inventions.macro_names(source), local, lines
    ):
        tally.made_up.append(f"{shown}:{function.start}-{function.end} {function.name}: {why}")
    tally.lizard = len(theirs)
    regions = _regions(facts)
    miscounted, matched = 0, set()
    for other in theirs:
        mine = _match(ours, other)
        where = f"{shown}:{other.start}-{other.end} {other.name[:80]}"
        covered = any(a <= other.end and other.start <= b for a, b, _ in regions)
        if mine is None:
            tally.missing.append(where)
            if not covered:
                tally.silent.append(where + " (not found)")
            continue
        matched.add(id(mine))
        tally.found += 1
        if mine.vg == other.vg:
            tally.equal += 1
            continue
        function = next(f for f in facts.functions if f.span.start == mine.start)
        kind = _disagreement_class(lines, function, other.vg)
        tally.explained[kind] = tally.explained.get(kind, 0) + 1
        if kind != "unexplained":  # lizard's miscount, not ours: not a loss to a parse failure
            miscounted += mine.vg - other.vg
        elif not covered:
            tally.silent.append(f"{where}: ours {mine.vg}, lizard {other.vg}")
        tally.unequal.append(f"{where}: ours {mine.vg}, lizard {other.vg} [{kind[:2]}]")
    tally.extra = len(ours) - len(matched)
    _warnings_checked(tally, facts, regions, shown, source, language, theirs, lines)
    lizard_vg = sum(f.vg for f in theirs) + miscounted
    our_vg = sum(f.vg for f in ours)
    if lizard_vg >= 10 and our_vg < 0.9 * lizard_vg and facts.warnings:
        tally.low_files = 1
        tally.low.append(f"{shown}: v_g {our_vg} vs lizard {lizard_vg} (corrected)")
    return tally


def _warnings_checked(
    tally: Tally,
    facts: FileFacts,
    regions: list[tuple[int, int, str]],
    shown: str,
    source: str,
    language: Language,
    theirs: list[c_inventions.Theirs],
    lines: list[str],
) -> None:
    """Count the warnings, and those that report a loss of the syntax tree's reading that
    lizard confirms: a function of lizard's there that the tree alone does not find, or
    finds with another v_g (no named class explains), or a function the tree alone made
    up there. Warnings that claim only statements or call sites are counted apart."""
    tally.warnings = len(regions)
    tally.warned_files = int(bool(facts.warnings))
    if not regions:
        return
    syntax = c_family.parse(shown, source, language, LIMITS, second_reading=False)
    tree = _ours(syntax)
    local = _local_classes(syntax)
    invented = c_inventions.made_up(tree, theirs, c_inventions.macro_names(source), local, lines)
    for first, last, message in regions:
        lost = any(f.start <= last and first <= f.end for f, _ in invented)
        for other in theirs:
            if lost or not (other.start <= last and first <= other.end):
                continue
            mine = _match(tree, other)
            if mine is None:
                lost = True
            elif mine.vg != other.vg:
                function = next(f for f in syntax.functions if f.span.start == mine.start)
                lost = _disagreement_class(lines, function, other.vg) == "unexplained"
        claims = message.split(" (")[0]
        if not lost and "function" in claims:  # lizard may lose them too: the source's own
            lost = _swallowed(tree, lines, first, last)  # heads, at the start of a line
        if not lost and ("statement" in claims or "call site" in claims):
            lost = _recounted(syntax, source, first, last, claims)
        renamed = _RENAMED.search(claims)
        if not lost and renamed:  # lizard names the function as the token reading did
            lost = any(
                other.name.rsplit("::", 1)[-1] == renamed.group(1).rsplit("::", 1)[-1]
                for other in theirs
                if first <= other.start <= last + 1
            )
        if lost:
            tally.true_warnings += 1
        elif not any(word in claims for word in ("function", "v_g", "read as")):
            tally.counts_only += 1
            tally.counts.append(f"{shown}:{first}: {message[:160]}")
        else:
            tally.false_warnings.append(f"{shown}:{first}: {message[:160]}")


_RENAMED = re.compile(r"the head of (\S+) read as")
# a function's head as C code writes it at file scope: at a line's start, a name and a `(`,
# not a statement or a declaration (no `;` at its end), and its body's `{` on that line or
# the next line's start
_HEAD = re.compile(
    r"(?:[A-Za-z_][\w\s*&:<>,]*[\s*&])?(?!(?:if|for|while|switch|return)\b)[A-Za-z_]\w*\s*\([^;]*$"
)


def _swallowed(tree: list[c_inventions.Ours], lines: list[str], first: int, last: int) -> bool:
    """Whether a function of the tree alone that overlaps lines ``first``..``last`` holds,
    after its own first lines, another function's head at the start of a line: a head at
    column 0 whose body's `{` ends it or starts the next line (checked on the text, not by
    either reading; lizard loses such functions too, where its reading derails)."""
    for function in tree:
        if not (function.start <= last and first <= function.end):
            continue
        for number in range(function.start + 2, function.end - 1):
            line = lines[number - 1]
            following = lines[number] if number < len(lines) else ""
            if _HEAD.match(line) and (line.rstrip().endswith("{") or following.startswith("{")):
                return True
    return False


def _recounted(syntax: FileFacts, source: str, first: int, last: int, claims: str) -> bool:
    """Whether lizard's tokens, counted again (c_inventions.recount), hold more statements
    or calls on the lines than the syntax tree's facts, as the warning claims."""
    statements, calls = c_inventions.recount(source, first, last)
    counted = sum(
        1
        for s in syntax.statements
        if first <= s.span.end <= last and s.kind != "function"
    )
    called = sum(1 for c in syntax.call_sites if first <= c.span.start <= last)
    return ("statement" in claims and statements > counted) or (
        "call site" in claims and calls > called
    )


def merge(tallies: list[Tally]) -> Tally:
    total = Tally()
    for t in tallies:
        for name, value in vars(t).items():
            if isinstance(value, int):
                setattr(total, name, getattr(total, name) + value)
            elif isinstance(value, list):
                getattr(total, name).extend(value)
            else:
                for kind, count in value.items():
                    getattr(total, name)[kind] = getattr(total, name).get(kind, 0) + count
    return total


def corpus_files(root: Path, parts: tuple[str, ...]) -> list[tuple[str, str]]:
    found = []
    for part in parts:
        for path in sorted((root / part).rglob("*")):
            if path.suffix in SUFFIXES and path.is_file():
                found.append((str(path), str(path.relative_to(root))))
    return found


def corpora(args: argparse.Namespace) -> list[tuple[str, list[tuple[str, str]]]]:
    """(name, files) of the named PyPI corpora and of each ``--folder NAME=PATH``."""
    found = []
    for name in args.only:
        requirement, parts = CORPORA[name]
        found.append((name, corpus_files(fetch(args.corpus, requirement), parts)))
    for folder in args.folder:
        name, _, path = folder.partition("=")
        found.append((name, corpus_files(Path(path), (".",))))
    return found


def arguments(description: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--corpus", type=Path, default=ROOT / ".cache" / "corpus13")
    parser.add_argument("--only", nargs="*", default=list(CORPORA))
    parser.add_argument(
        "--folder",
        action="append",
        default=[],
        help="NAME=PATH: every C/C++ file under PATH too (a checkout, a fetched repository)",
    )
    parser.add_argument("--show", type=int, default=0)
    parser.add_argument("--jobs", type=int, default=2)
    return parser.parse_args()


def _share(part: int, whole: int, digits: int = 1) -> str:
    return f"{part} ({part / max(1, whole):.{digits}%})"


def main() -> None:
    args = arguments(__doc__.splitlines()[0])
    rows = []
    with multiprocessing.Pool(args.jobs) as pool:
        for name, files in corpora(args):
            total = merge(pool.map(compare_file, files, chunksize=8))
            rows.append((name, total))
            print(f"{name}: {total.files} files, lizard {total.lizard} functions, found "
                  f"{_share(total.found, total.lizard, 2)}, equal v_g "
                  f"{_share(total.equal, total.found, 2)}, ours only {total.extra}, made up "
                  f"{len(total.made_up)}, under no warning {len(total.silent)}, warnings "
                  f"{total.warnings} (true {total.true_warnings}, counts only "
                  f"{total.counts_only})", flush=True)  # fmt: skip
            for kind, count in sorted(total.explained.items(), key=lambda item: -item[1]):
                print(f"  v_g differs, class {kind}: {count}")
            for kind, count in sorted(total.inventions.items(), key=lambda item: -item[1]):
                print(f"  lizard's invention, {kind}: {count}")
            for title, examples in (("missing", total.missing), ("unequal", total.unequal),
                                    ("low", total.low), ("made up", total.made_up),
                                    ("under no warning", total.silent),
                                    ("false warning", total.false_warnings),
                                    ("counts only", total.counts)):  # fmt: skip
                for example in examples[: args.show]:
                    print(f"  {title}: {example}")
    print("\n| corpus | files | lizard functions | found | equal v_g | equal or a named class "
          "| unexplained | made up | lost under no warning | files warned | functions "
          "estimated | warnings confirmed |")  # fmt: skip
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, t in rows:
        unexplained = t.explained.get("unexplained", 0)
        named = t.found - unexplained
        print(f"| {name} | {t.files} | {t.lizard} | {_share(t.found, t.lizard)} "
              f"| {_share(t.equal, t.found)} | {_share(named, t.found, 2)} | {unexplained} "
              f"| {len(t.made_up)} | {len(t.silent)} | {_share(t.warned_files, t.files)} "
              f"| {_share(t.estimated, t.functions, 2)} "
              f"| {_share(t.true_warnings, t.warnings)} of {t.warnings} |")  # fmt: skip


if __name__ == "__main__":
    main()
