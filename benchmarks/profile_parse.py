"""Profile archmetrics's parsers in one process (no pool) over a folder of source files.

Run:  .venv/bin/python benchmarks/profile_parse.py FOLDER [--limit N] [--top 30] [--no-profile]
Prints the per-language parse time and cProfile's top frames by own time and by cumulative
time, for docs/performance.md; with ``--no-profile``, the parsers' own CPU seconds instead,
unprofiled (what a scan's process-tree CPU is compared with). Not part of the tests.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from archmetrics.parsers import LanguageTable, parse_source  # noqa: E402


def files_of(folder: Path, table: LanguageTable, limit: int) -> list[tuple[str, bytes, str]]:
    """(path, bytes, language) for the measured files under ``folder``, sorted, up to limit."""
    chosen = []
    for path in sorted(folder.rglob("*")):
        language = table.language_of(path.name)
        if path.is_file() and ".git" not in path.parts and language is not None:
            chosen.append((str(path.relative_to(folder)), path.read_bytes(), language))
    return chosen[:limit] if limit else chosen


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folder", type=Path)
    parser.add_argument("--limit", type=int, default=0, help="at most N files (0: all)")
    parser.add_argument("--top", type=int, default=30, help="how many frames to print")
    parser.add_argument("--no-profile", action="store_true", help="only the parsers' CPU")
    args = parser.parse_args()
    table = LanguageTable.default()
    files = files_of(args.folder, table, args.limit)
    if args.no_profile:
        cpu: dict[str, float] = {}
        for path, data, language in files:
            start = time.process_time()
            parse_source(path, data, language, table)
            cpu[language] = cpu.get(language, 0.0) + time.process_time() - start
        shown = ", ".join(f"{language} {value:.2f}" for language, value in sorted(cpu.items()))
        print(f"{len(files)} files, parse CPU seconds: {shown}; total {sum(cpu.values()):.2f}")
        return 0
    seconds: dict[str, float] = {}
    profile = cProfile.Profile()
    for path, data, language in files:
        start = time.perf_counter()
        profile.enable()
        parse_source(path, data, language, table)
        profile.disable()
        seconds[language] = seconds.get(language, 0.0) + time.perf_counter() - start
    size = sum(len(data) for _, data, _ in files)
    print(f"{len(files)} files, {size / 1e6:.1f} MB, parse seconds by language: {seconds}")
    stats = pstats.Stats(profile)
    stats.sort_stats("tottime").print_stats(args.top)
    stats.sort_stats("cumulative").print_stats(args.top)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
