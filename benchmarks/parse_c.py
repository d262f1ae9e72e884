"""CPU time of the C/C++ parser alone over the oracle corpora, for a before/after comparison.

    python benchmarks/parse_c.py [--checkout DIR] [--repeat N] [--every N] NAME ...

Parses every C/C++ file of the named corpora of benchmarks/oracle_c.py (fetched as it
fetches them) in one process, ``--repeat`` times, and prints the best CPU time. ``--checkout``
measures another checkout of archmetrics (``git worktree add /tmp/old REV``), so the two
figures come from the same files and the same interpreter. Time it with nothing else running.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="+")
    parser.add_argument("--checkout", type=Path, default=ROOT)
    parser.add_argument("--corpus", type=Path, default=ROOT / ".cache" / "corpus13")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument(
        "--every", type=int, default=1, help="only every Nth file (a sample for callgrind)"
    )
    args = parser.parse_args()
    sys.path.insert(0, str(args.checkout))
    from archmetrics.parsers import c_family  # before oracle_c, which puts ROOT on the path

    sys.path.insert(1, str(ROOT / "benchmarks"))
    import oracle_c

    files = []
    for name in args.names:
        requirement, parts = oracle_c.CORPORA[name]
        root = oracle_c.fetch(args.corpus, requirement)
        for path, shown in oracle_c.corpus_files(root, parts)[:: args.every]:
            source = Path(path).read_text(encoding="utf-8", errors="replace")
            files.append((shown, source, oracle_c.SUFFIXES[Path(path).suffix]))
    best = float("inf")
    for _ in range(args.repeat):
        start = time.process_time()
        for shown, source, language in files:
            c_family.parse(shown, source, language)
        best = min(best, time.process_time() - start)
    measured = Path(c_family.__file__).parents[2]
    print(f"{measured}: {len(files)} files, best of {args.repeat}: {best:.2f} s CPU")


if __name__ == "__main__":
    main()
