"""C/C++ facts against lizard on real code nobody here wrote: functions found, equal v_g.

    python benchmarks/oracle_c.py [--corpus DIR] [--only NAME ...] [--show N] [--jobs N]

Sdists from PyPI (pinned below) are fetched into ``DIR`` (default ``.cache/corpus13``) from
PyPI's simple index and unpacked. For every C/C++ file both tools read, functions are
matched by (file, last line), as tests/parsers/test_c_oracle.py does. Per corpus it prints:
the files, lizard's functions, how many of them we found, how many of the found ones have
the same v_g (the others by the class of docs/metrics.md that explains them: "equal or a
named class" counts the found ones whose difference is a named lizard miscount), and the
files whose v_g sum falls below 0.9x lizard's while our parser reports
a lost region (lizard's v_g corrected by the named classes' miscounts, which are no parse
failure of ours). ``--show`` prints that many examples of each kind of difference.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import sys
import tarfile
import urllib.request
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from archmetrics.facts import Language  # noqa: E402
from archmetrics.parsers import c_family  # noqa: E402
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
}  # fmt: skip
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
    lizard: int = 0
    found: int = 0
    equal: int = 0
    low_files: int = 0
    missing: list[str] = field(default_factory=list)
    unequal: list[str] = field(default_factory=list)
    explained: dict[str, int] = field(default_factory=dict)
    low: list[str] = field(default_factory=list)
    extra: int = 0


def compare_file(item: tuple[str, str]) -> Tally:
    import lizard

    path, shown = item
    source = Path(path).read_text(encoding="utf-8", errors="replace")
    language = SUFFIXES[Path(path).suffix]
    facts = c_family.parse(shown, source, language)
    theirs = lizard.analyze_file.analyze_source_code(path, source).function_list
    ours = {f.span.end: f for f in facts.functions}
    tally = Tally(files=1, lizard=len(theirs))
    lines = source.splitlines()
    miscounted = 0
    for other in theirs:
        mine = ours.get(other.end_line)
        where = f"{shown}:{other.start_line}-{other.end_line} {other.long_name[:80]}"
        if mine is None or not mine.span.contains(other.start_line):
            tally.missing.append(where)
            continue
        tally.found += 1
        if mine.complexity == other.cyclomatic_complexity:
            tally.equal += 1
            continue
        kind = _disagreement_class(lines, mine, other.cyclomatic_complexity)
        tally.explained[kind] = tally.explained.get(kind, 0) + 1
        if kind != "unexplained":  # lizard's miscount, not ours: not a loss to a parse failure
            miscounted += mine.complexity - other.cyclomatic_complexity
        tally.unequal.append(
            f"{where}: ours {mine.complexity}, lizard {other.cyclomatic_complexity} [{kind[:2]}]"
        )
    tally.extra = len(ours) - tally.found
    lizard_vg = sum(f.cyclomatic_complexity for f in theirs) + miscounted
    our_vg = sum(f.complexity for f in facts.functions)
    lost = [
        w
        for w in facts.warnings
        if "not measured" in w.message or "could not be parsed" in w.message
    ]
    if lizard_vg >= 10 and our_vg < 0.9 * lizard_vg and lost:
        tally.low_files = 1
        tally.low.append(
            f"{shown}: v_g {our_vg} vs lizard {lizard_vg} (corrected); {lost[0].message[:100]}"
        )
    return tally


def merge(tallies: list[Tally]) -> Tally:
    total = Tally()
    for t in tallies:
        for name in ("files", "lizard", "found", "equal", "low_files", "extra"):
            setattr(total, name, getattr(total, name) + getattr(t, name))
        total.missing += t.missing
        total.unequal += t.unequal
        for kind, count in t.explained.items():
            total.explained[kind] = total.explained.get(kind, 0) + count
        total.low += t.low
    return total


def corpus_files(root: Path, parts: tuple[str, ...]) -> list[tuple[str, str]]:
    found = []
    for part in parts:
        for path in sorted((root / part).rglob("*")):
            if path.suffix in SUFFIXES and path.is_file():
                found.append((str(path), str(path.relative_to(root))))
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--corpus", type=Path, default=ROOT / ".cache" / "corpus13")
    parser.add_argument("--only", nargs="*", default=list(CORPORA))
    parser.add_argument("--show", type=int, default=0)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    rows = []
    with multiprocessing.Pool(args.jobs) as pool:
        for name in args.only:
            requirement, parts = CORPORA[name]
            root = fetch(args.corpus, requirement)
            total = merge(pool.map(compare_file, corpus_files(root, parts), chunksize=8))
            rows.append((name, total))
            print(f"{name}: {total.files} files, lizard {total.lizard} functions, found "
                  f"{total.found} ({total.found / max(1, total.lizard):.2%}), equal v_g "
                  f"{total.equal} ({total.equal / max(1, total.found):.2%}), files below "
                  f"0.9x v_g {total.low_files}, ours only {total.extra}", flush=True)  # fmt: skip
            for kind, count in sorted(total.explained.items(), key=lambda item: -item[1]):
                print(f"  v_g differs, class {kind}: {count}")
            for title, examples in (("missing", total.missing), ("unequal", total.unequal),
                                    ("low", total.low)):  # fmt: skip
                for example in examples[: args.show]:
                    print(f"  {title}: {example}")
    print("\n| corpus | files | lizard functions | found | equal v_g | equal or a named class "
          "| unexplained | files < 0.9x v_g |")  # fmt: skip
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for name, t in rows:
        unexplained = t.explained.get("unexplained", 0)
        named = t.found - unexplained
        print(f"| {name} | {t.files} | {t.lizard} | {t.found} ({t.found / max(1, t.lizard):.1%}) "
              f"| {t.equal} ({t.equal / max(1, t.found):.1%}) "
              f"| {named} ({named / max(1, t.found):.2%}) | {unexplained} "
              f"| {t.low_files} |")  # fmt: skip


if __name__ == "__main__":
    main()
