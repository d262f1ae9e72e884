"""A digest of the facts of every C/C++ file under some folders, to show a change kept them.

    python benchmarks/facts_digest.py OUT.json FOLDER ...          # record
    python benchmarks/facts_digest.py OUT.json FOLDER ... --against BEFORE.json [--subset]

Parses every file the default language table reads as C or C++ (the scan's choice of
parser; hidden folders skipped) with ``parse_source`` and keeps, per file, a SHA-256 of
the ``repr`` of its :class:`FileFacts` (every field: statements and their texts, functions,
decisions, call sites and arguments, bindings, warnings). With ``--against``, prints every
file whose digest differs or that one side lacks (``--subset``: only the files both
sides hold), and exits 1 if there is one. Not part of
the tests; the parser steps of docs/metrics.md ("Cost") were checked this way. A function
whose ``estimated`` is false and ``suppressed`` empty is digested as it was before those
fields existed.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import multiprocessing
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from archmetrics.facts import Language  # noqa: E402
from archmetrics.parsers import LanguageTable, parse_source  # noqa: E402

TABLE = LanguageTable.default()
C_FAMILY = {str(Language.C), str(Language.CPP)}


def files_under(folder: Path) -> list[tuple[str, str]]:
    """(shown name, path) of the C/C++ files under ``folder``, sorted."""
    found = []
    for path in sorted(folder.rglob("*")):
        relative = path.relative_to(folder)
        if any(part.startswith(".") for part in relative.parts) or not path.is_file():
            continue
        if TABLE.language_of(path.name) in C_FAMILY:
            found.append((f"{folder.name}/{relative.as_posix()}", str(path)))
    return found


def digest(item: tuple[str, str]) -> tuple[str, str]:
    shown, path = item
    language = TABLE.language_of(Path(path).name)
    assert language is not None
    facts = parse_source(shown, Path(path).read_bytes(), language, TABLE)
    # a function not estimated and not suppressed is written as before Function.suppressed
    # and Function.estimated existed, so that a record made by an older checkout compares
    # equal where nothing else changed
    text = repr(facts).replace(", suppressed=(), estimated=False)", ")")
    text = text.replace(", estimated=False)", ")")
    return shown, hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("folders", type=Path, nargs="+")
    parser.add_argument("--against", type=Path)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument(
        "--subset", action="store_true", help="compare only the files both records hold"
    )
    args = parser.parse_args()
    items = [item for folder in args.folders for item in files_under(folder.resolve())]
    with multiprocessing.Pool(args.jobs) as pool:
        digests = dict(pool.imap(digest, items, chunksize=8))
    args.out.write_text(json.dumps(digests, indent=0, sort_keys=True))
    print(f"{len(digests)} files digested into {args.out}")
    if args.against is None:
        return 0
    before: dict[str, str] = json.loads(args.against.read_text())
    compared = before.keys() & digests.keys() if args.subset else before.keys() | digests.keys()
    differ = sorted(k for k in compared if before.get(k) != digests.get(k))
    for name in differ:
        print(f"differs: {name}")
    print(f"{len(differ)} of {len(compared)} files differ")
    return 1 if differ else 0


if __name__ == "__main__":
    raise SystemExit(main())
