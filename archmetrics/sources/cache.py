"""The facts cache: facts stored under (blob hash, language, parser fingerprint) in SQLite.

Git names every file version by its blob hash, and files read from disk are hashed the same
way, so a file is parsed once per content however many revisions, paths or runs see it. The
parser fingerprint is a hash of the parser code itself, of the Python version and of the
parsing libraries' versions, so archmetrics never trusts facts that another version of it,
of Python (whose ``ast`` reads Python files), of libcst or of tree-sitter wrote. Rule packs
are applied to facts after the cache (coupling reads call sites, which do not depend on
rules), so they need no part in the key.

A corrupt file, or one that is not ours, is moved aside with a warning and a new cache is
built; a bad entry is dropped and parsed again. The cache is never trusted blindly.
"""

from __future__ import annotations

import hashlib
import os
import sqlite3
import sys
import time
from collections.abc import Iterable
from dataclasses import dataclass
from functools import cache
from importlib import metadata
from pathlib import Path

import archmetrics
from archmetrics.facts import FileFacts
from archmetrics.sources import codec

APPLICATION = "archmetrics-facts"
SCHEMA = "1"
DECODED_LIMIT = 50_000  # decoded facts kept in memory per run, at most


_PARSING_LIBRARIES = ("libcst", "tree-sitter", "tree-sitter-c", "tree-sitter-cpp")


@cache
def parser_fingerprint() -> str:
    """A hash of what makes facts: the parsers package, facts.py, the Python version (its
    ``ast`` reads Python files) and the versions of the parsing libraries."""
    root = Path(archmetrics.__file__).parent
    digest = hashlib.sha256(archmetrics.__version__.encode())
    for path in sorted([root / "facts.py", *(root / "parsers").glob("*.py")]):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    digest.update(str(codec.FORMAT).encode())
    digest.update(sys.version.encode())
    for library in _PARSING_LIBRARIES:
        try:
            digest.update(f"{library} {metadata.version(library)}".encode())
        except metadata.PackageNotFoundError:
            digest.update(f"{library} absent".encode())
    return digest.hexdigest()[:16]


def default_path() -> Path:
    """``$ARCHMETRICS_CACHE`` if set, else facts.sqlite3 in the user's cache directory."""
    from platformdirs import user_cache_dir

    override = os.environ.get("ARCHMETRICS_CACHE")
    return Path(override) if override else Path(user_cache_dir("archmetrics")) / "facts.sqlite3"


@dataclass(frozen=True, slots=True)
class CacheInfo:
    path: str
    entries: int
    bytes: int
    fingerprint: str
    current_entries: int  # entries written by this version of the parsers


class FactsCache:
    """A SQLite store of facts. Use as a context manager; writes are committed on close."""

    def __init__(self, path: Path):
        self.path = path
        self.fingerprint = parser_fingerprint()
        self.hits = 0
        self.misses = 0
        self.notices: list[str] = []  # problems recovered from, for the user to see
        # Facts this run already decoded or parsed, by (blob, language): a diff asks for most
        # blobs twice (the file is unchanged between base and head), and decoding is the
        # warm path's main cost. Frozen facts are safe to share (and sharing them halves a
        # diff's memory); bounded so a long series of revisions does not hold every version.
        self._decoded: dict[tuple[str, str], FileFacts] = {}
        self._db = self._open()

    def _open(self) -> sqlite3.Connection:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        try:
            db = sqlite3.connect(self.path, timeout=30)
            self._check(db)
            return db
        except sqlite3.DatabaseError as error:
            return self._rebuild(f"unreadable ({error})")
        except _Foreign as error:
            return self._rebuild(str(error))

    def _check(self, db: sqlite3.Connection) -> None:
        tables = {row[0] for row in db.execute("select name from sqlite_master where type='table'")}
        if not tables:
            db.executescript(
                "create table meta(key text primary key, value text);"
                "create table facts(blob text, language text, parser text, data blob,"
                " primary key(blob, language, parser));"
            )
            db.executemany(
                "insert into meta values (?, ?)", [("application", APPLICATION), ("schema", SCHEMA)]
            )
            db.commit()
            return
        meta = (
            dict(db.execute("select key, value from meta").fetchall()) if "meta" in tables else {}
        )
        if meta.get("application") != APPLICATION or meta.get("schema") != SCHEMA:
            db.close()
            raise _Foreign("not an archmetrics facts cache (or an older layout)")

    def _rebuild(self, why: str) -> sqlite3.Connection:
        aside = self.path.with_name(f"{self.path.name}.bad-{int(time.time())}")
        self.notices.append(
            f"facts cache {self.path} is {why}; moved it to {aside.name} and started a new one"
        )
        self.path.replace(aside)
        db = sqlite3.connect(self.path, timeout=30)
        self._check(db)
        return db

    def get(self, blob: str, language: str, path: str) -> FileFacts | None:
        known = self._decoded.get((blob, language))
        if known is not None and known.path == path:
            self.hits += 1
            return known
        row = self._db.execute(
            "select data from facts where blob=? and language=? and parser=?",
            (blob, language, self.fingerprint),
        ).fetchone()
        if row is None:
            self.misses += 1
            return None
        try:
            facts = codec.decode(row[0], path)
        except codec.CodecError:
            self._db.execute(
                "delete from facts where blob=? and language=? and parser=?",
                (blob, language, self.fingerprint),
            )
            self.misses += 1
            return None
        self.hits += 1
        self.remember(blob, facts)
        return facts

    def remember(self, blob: str, facts: FileFacts) -> None:
        """Keep ``facts`` (just parsed or decoded) for this run: a later ``get`` of the same
        blob, language and path returns them without reading or decoding."""
        if len(self._decoded) >= DECODED_LIMIT:
            self._decoded.clear()
        self._decoded[(blob, facts.language)] = facts

    def put_many(self, items: Iterable[tuple[str, FileFacts]]) -> None:
        self.put_encoded((blob, f.language, codec.encode(f)) for blob, f in items)

    def put_encoded(self, items: Iterable[tuple[str, str, bytes]]) -> None:
        """Store (blob, language, ``codec.encode(facts)``) rows already encoded elsewhere
        (the parser processes encode what they send back, so nothing is encoded twice)."""
        rows = [(blob, language, self.fingerprint, data) for blob, language, data in items]
        self._db.executemany("insert or replace into facts values (?, ?, ?, ?)", rows)

    def info(self) -> CacheInfo:
        total = self._db.execute("select count(*) from facts").fetchone()[0]
        current = self._db.execute(
            "select count(*) from facts where parser=?", (self.fingerprint,)
        ).fetchone()[0]
        size = self.path.stat().st_size if self.path.exists() else 0
        return CacheInfo(str(self.path), total, size, self.fingerprint, current)

    def clear(self) -> int:
        self._decoded.clear()
        removed: int = self._db.execute("delete from facts").rowcount
        self._db.commit()
        self._db.execute("vacuum")
        return removed

    def close(self) -> None:
        self._db.commit()
        self._db.close()

    def __enter__(self) -> FactsCache:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class _Foreign(Exception):
    pass
