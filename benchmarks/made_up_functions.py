"""Every reported C/C++ function no reader of the source would name; exit 1 if there is one.

    python benchmarks/made_up_functions.py [--only NAME ...] [--folder NAME=PATH ...] [--jobs N]

Reads the corpora of benchmarks/oracle_c.py (the pinned PyPI sdists, fetched as it fetches
them, and any ``--folder``: a checkout, a repository brought by ``git clone``) with the
parser, and lists each reported function whose name is a C or C++ keyword, a macro the
file defines whose body is no function head, or whose span covers the start of a function
lizard reports that is no method of a class defined inside it (c_inventions.py). Prints a
table per corpus and every such function.
"""

from __future__ import annotations

import multiprocessing
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import c_inventions  # noqa: E402
import oracle_c  # noqa: E402

from archmetrics.parsers import c_family  # noqa: E402


def check_file(item: tuple[str, str]) -> tuple[int, list[str]]:
    """(functions reported, the made-up ones with why) of one file."""
    import lizard

    path, shown = item
    source = Path(path).read_text(encoding="utf-8", errors="replace")
    facts = c_family.parse(shown, source, oracle_c.SUFFIXES[Path(path).suffix])
    theirs = [
        c_inventions.Theirs(f.name, f.start_line, f.end_line, f.cyclomatic_complexity)
        for f in lizard.analyze_file.analyze_source_code(path, source).function_list
    ]
    ours = oracle_c._ours(facts)
    found = c_inventions.made_up(
        ours,
        theirs,
        c_inventions.macro_names(source),
        oracle_c._local_classes(facts),
        source.splitlines(),
    )
    return len(ours), [f"{shown}:{f.start}-{f.end} {f.name!r}: {why}" for f, why in found]


def main() -> int:
    args = oracle_c.arguments(__doc__.splitlines()[0])
    rows = []
    with multiprocessing.Pool(args.jobs) as pool:
        for name, files in oracle_c.corpora(args):
            results = pool.map(check_file, files, chunksize=8)
            made_up = [entry for _, found in results for entry in found]
            rows.append((name, len(files), sum(count for count, _ in results), made_up))
            for entry in made_up:
                print(f"made up: {entry}", flush=True)
    print("\n| corpus | files | functions reported | made up |")
    print("|---|---:|---:|---:|")
    for name, files, functions, made_up in rows:
        print(f"| {name} | {files} | {functions} | {len(made_up)} |")
    return 1 if any(made_up for *_, made_up in rows) else 0


if __name__ == "__main__":
    raise SystemExit(main())
