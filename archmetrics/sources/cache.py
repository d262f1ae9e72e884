"""The facts cache: facts stored under (blob hash, language, parser fingerprint) in SQLite.

Git names every file version by its blob hash, and files read from disk are hashed the same
way, so a file is parsed once per content however many revisions, paths or runs see it. The
parser fingerprint is a hash of the parser code itself, of the Python version and of the
parsing libraries' versions, so archmetrics never trusts facts that another version of it,
of Python (whose ``ast`` reads Python files), of libcst or of tree-sitter wrote. Rule packs
are applied to facts after the cache (coupling reads call sites, which do not depend on
rules), so they need no part in the key.

The file itself is handled by :mod:`archmetrics.sources.cache_file`: a path that is not an
archmetrics cache is refused and left alone; our own cache, when damaged (at open or when a
page turns out bad mid-run), is moved aside with a notice and rebuilt; a bad entry is dropped
and parsed again. The cache is never trusted blindly, and never writes where it should not.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import sqlite3
import sys
import weakref
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from functools import cache
from importlib import metadata
from pathlib import Path
from typing import Any, TypeVar

import archmetrics
from archmetrics.facts import FileFacts
from archmetrics.sources import codec
from archmetrics.sources.cache_file import (
    CacheError,
    choose_path,
    configured_path,
    default_path,
    is_damage,
    open_database,
    rebuild,
)

__all__ = [
    "CacheError",
    "FactsCache",
    "choose_path",
    "configured_path",
    "default_path",
    "parser_fingerprint",
]

DECODED_LIMIT = 50_000  # decoded facts kept in memory per run, at most


_T = TypeVar("_T")
_PARSING_LIBRARIES = ("libcst", "tree-sitter", "tree-sitter-c", "tree-sitter-cpp")


def _source_digest(paths: Iterable[Path]) -> hashlib._Hash:
    """A running hash of archmetrics's version and of ``paths``' names and bytes, in order."""
    root = Path(archmetrics.__file__).parent
    digest = hashlib.sha256(archmetrics.__version__.encode())
    for path in sorted(paths):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(path.read_bytes())
    return digest


@cache
def code_fingerprint() -> str:
    """A hash of archmetrics's whole source: what a total kept in the cache (a tree's
    coupling) may depend on."""
    return _source_digest(Path(archmetrics.__file__).parent.rglob("*.py")).hexdigest()


@cache
def parser_fingerprint() -> str:
    """A hash of what makes facts: the parsers package, facts.py, the Python version (its
    ``ast`` reads Python files) and the versions of the parsing libraries."""
    root = Path(archmetrics.__file__).parent
    digest = _source_digest([root / "facts.py", *(root / "parsers").glob("*.py")])
    digest.update(str(codec.FORMAT).encode())
    digest.update(sys.version.encode())
    for library in _PARSING_LIBRARIES:
        try:
            digest.update(f"{library} {metadata.version(library)}".encode())
        except metadata.PackageNotFoundError:
            digest.update(f"{library} absent".encode())
    return digest.hexdigest()[:16]


@dataclass(frozen=True, slots=True)
class CacheInfo:
    path: str
    entries: int
    bytes: int
    fingerprint: str
    current_entries: int  # entries written by this version of the parsers


# a record's head, and whether its body is there (a record is written in one transaction,
# so both are or neither; a cache that lost one is not believed)
_HEAD = (
    "select f.data, b.blob is not null from facts f left join bodies b"
    " on b.blob=f.blob and b.language=f.language and b.parser=f.parser"
    " where f.blob=? and f.language=? and f.parser=?"
)
_BODY = "select data from bodies where blob=? and language=? and parser=?"
_KEY = "blob=? and language=? and parser=?"
_HAS = f"select 1 from facts where {_KEY}"


def _read_only(path: Path) -> sqlite3.Connection:
    """A connection that can only read the cache at ``path``."""
    return sqlite3.connect(f"{path.as_uri()}?mode=ro", uri=True, check_same_thread=False)


class FactsCache:
    """A SQLite store of facts. Use as a context manager; writes are committed on close."""

    def __init__(self, path: Path, salt: str = ""):
        """``salt``: what else decides the facts (the parser limits in force when they are
        not the defaults), so facts made under other limits are never served."""
        self.path = Path(os.path.realpath(path.expanduser()))
        fingerprint = parser_fingerprint()
        if salt:
            fingerprint = hashlib.sha256(f"{fingerprint} {salt}".encode()).hexdigest()[:16]
        self.fingerprint = fingerprint
        self.hits = 0
        self.misses = 0
        self.notices: list[str] = []  # problems recovered from, for the user to see
        # Facts this run already decoded or parsed, by (blob, language, path): a diff asks for
        # most files twice (unchanged between base and head), and decoding is the warm
        # path's main cost; facts name their file, so copies of one blob at several paths
        # (vendored trees) are each kept. Frozen facts are safe to share (and sharing them
        # halves a diff's memory); bounded so a long series does not hold every version.
        self._decoded: dict[tuple[str, str, str], FileFacts] = {}
        self.decoded_limit = DECODED_LIMIT  # a history, which meets every version, keeps fewer
        self._db = open_database(self.path, self.notices)
        # a read-only cache made before the bodies table holds no facts of this version
        self._bodies = self._run(
            lambda db: (
                db.execute(
                    "select count(*) from sqlite_master where type='table' and name='bodies'"
                ).fetchone()[0]
                == 1
            )
        )
        self._closed = False
        self._reader: sqlite3.Connection | None = None

    def _run(self, query: Callable[[sqlite3.Connection], _T]) -> _T:
        """``query`` on the database; if SQLite finds the file damaged (a bad page deep in
        it shows only when read), the file is moved aside, a new cache started and the query
        run once more on it."""
        try:
            return query(self._db)
        except sqlite3.DatabaseError as error:
            if not is_damage(error):
                raise CacheError(f"facts cache {self.path}: {error}") from error
            self._db.close()
            self._db = rebuild(self.path, f"damaged ({error})", self.notices)
            return query(self._db)

    def get(self, blob: str, language: str, path: str) -> FileFacts | None:
        known = self._decoded.get((blob, language, path))
        if known is not None:
            self.hits += 1
            return known
        key = (blob, language, self.fingerprint)
        row = self._run(lambda db: db.execute(_HEAD, key).fetchone()) if self._bodies else None
        if row is None:
            self.misses += 1
            return None
        try:
            if not (isinstance(row[0], bytes) and row[1]):
                raise codec.CodecError("a record without its body")
            facts = codec.decode_head(
                row[0], path, self.reader(blob, language), self.forgetter(blob, language)
            )
        except codec.CodecError:
            self._forget(key)
            self.misses += 1
            return None
        self.hits += 1
        self.remember(blob, facts)
        return facts

    def has(self, blob: str, language: str) -> bool:
        """Whether facts of ``blob`` in ``language`` are kept (without reading them)."""
        key = (blob, language, self.fingerprint)
        if not self._bodies:
            return False
        return self._run(lambda db: db.execute(_HAS, key).fetchone()) is not None

    def get_encoded(self, keys: Sequence[tuple[str, str]]) -> dict[tuple[str, str], bytes]:
        """The records kept for these (blob, language) pairs, as ``put_encoded`` takes them
        (a history sends them to a worker that has no cache of its own); a record without
        its body is left out."""
        found: dict[tuple[str, str], bytes] = {}
        if not self._bodies:
            return found
        for blob, language in keys:
            key = (blob, language, self.fingerprint)

            def row(db: sqlite3.Connection, query: str, key: tuple[str, ...] = key) -> Any:
                return db.execute(query, key).fetchone()

            head = self._run(lambda db: row(db, _HEAD))
            body = self._run(lambda db: row(db, _BODY))
            if head is None or body is None:
                continue
            if isinstance(head[0], bytes) and head[1] and isinstance(body[0], bytes):
                found[(blob, language)] = bytes(head[0]) + b"\n" + bytes(body[0])
        return found

    def _forget(self, key: tuple[str, str, str]) -> None:
        self._run(lambda db: db.execute(f"delete from facts where {_KEY}", key))
        self._run(lambda db: db.execute(f"delete from bodies where {_KEY}", key))

    def forgetter(self, blob: str, language: str) -> codec.Forget:
        """A function that drops the record kept for ``blob`` and ``language`` (when its body
        is not what its head says), if the cache is still open."""
        key = (blob, language, self.fingerprint)
        cache = weakref.ref(self)

        def forget() -> None:
            live = cache()
            if live is not None and not live._closed:
                with contextlib.suppress(CacheError, sqlite3.Error):
                    for kept in [k for k in live._decoded if k[:2] == (blob, language)]:
                        del live._decoded[kept]
                    live._forget(key)

        return forget

    def reader(self, blob: str, language: str) -> codec.Again:
        """A function that reads the body of the record kept for ``blob`` and ``language``
        (None if there is none now), also after the cache was closed: facts decoded from the
        cache read their statements and call sites back from it on first use instead of
        holding them (docs/performance.md, "Warm diffs")."""
        key = (blob, language, self.fingerprint)
        # a weak reference: facts the cache remembers must not hold the cache (a cycle
        # through every decoded fact would be left to the garbage collector)
        cache, path = weakref.ref(self), self.path

        def read() -> bytes | None:
            live = cache()
            try:
                if live is not None and not live._closed:
                    row = live._run(lambda db: db.execute(_BODY, key).fetchone())
                else:
                    db = live._read_only() if live is not None else _read_only(path)
                    row = db.execute(_BODY, key).fetchone()
            except (sqlite3.Error, CacheError):  # gone or unreadable: the caller says so
                return None
            return bytes(row[0]) if row is not None and isinstance(row[0], bytes) else None

        return read

    def _read_only(self) -> sqlite3.Connection:
        """A read-only connection to the closed cache, opened once, for ``reader``."""
        if self._reader is None:
            self._reader = _read_only(self.path)
        return self._reader

    def remember(self, blob: str, facts: FileFacts) -> None:
        """Keep ``facts`` (just parsed or decoded) for this run: a later ``get`` of the same
        blob, language and path returns them without reading or decoding."""
        if len(self._decoded) >= self.decoded_limit:
            self._decoded.clear()
        self._decoded[(blob, facts.language, facts.path)] = facts

    def put_many(self, items: Iterable[tuple[str, FileFacts]]) -> None:
        self.put_encoded((blob, f.language, codec.encode(f)) for blob, f in items)

    def put_encoded(self, items: Iterable[tuple[str, str, bytes]]) -> None:
        """Store (blob, language, ``codec.encode(facts)``) rows already encoded elsewhere
        (the parser processes encode what they send back, so nothing is encoded twice)."""
        heads, bodies = [], []
        for blob, language, data in items:
            head, body = codec.split(data)
            heads.append((blob, language, self.fingerprint, head))
            bodies.append((blob, language, self.fingerprint, body))

        def write(db: sqlite3.Connection) -> None:
            db.executemany("insert or replace into facts values (?, ?, ?, ?)", heads)
            db.executemany("insert or replace into bodies values (?, ?, ?, ?)", bodies)

        self._run(write)

    def get_total(self, key: str) -> bytes | None:
        """What was stored under ``key`` (a digest of all that decides it), if anything.
        The bytes are as untrusted as the file: the caller checks them."""
        return self.get_totals([key]).get(key)

    def get_totals(self, keys: Sequence[str]) -> dict[str, bytes]:
        """What was stored under each of ``keys`` that has a row (as untrusted as
        ``get_total``'s bytes), asked 500 keys a query."""
        found: dict[str, bytes] = {}
        for start in range(0, len(keys), 500):
            chunk = list(keys[start : start + 500])

            def rows(db: sqlite3.Connection, chunk: list[str] = chunk) -> list[tuple[object, ...]]:
                marks = ",".join("?" * len(chunk))
                query = f"select key, data from totals where key in ({marks})"
                return db.execute(query, chunk).fetchall()

            try:
                for key, data in self._run(rows):
                    if isinstance(key, str) and isinstance(data, bytes):
                        found[key] = data
            except CacheError:  # no totals table (a read-only cache made before it)
                return {}
        return found

    def put_totals(self, items: Iterable[tuple[str, bytes]]) -> None:
        rows = list(items)
        with contextlib.suppress(CacheError):  # read-only: nothing kept
            self._run(
                lambda db: db.executemany("insert or replace into totals values (?, ?)", rows)
            )

    def put_total(self, key: str, data: bytes) -> None:
        self.put_totals([(key, data)])

    def unread(self, blob: str, language: str) -> bool:
        """Whether a diff found this blob generated by its first lines and read no further
        (``mark_unread``): it need not be sent to a worker again to learn that. Asked after
        ``get`` missed; a mark found counts as served."""
        if not self.marked_unread(blob, language):
            return False
        self.misses, self.hits = self.misses - 1, self.hits + 1  # the facts' miss, answered
        return True

    def marked_unread(self, blob: str, language: str) -> bool:
        """Whether the blob carries the mark of :meth:`mark_unread` (no count changes)."""
        return self.get_total(self._unread_key(blob, language)) == b"generated"

    def mark_unread(self, blob: str, language: str) -> None:
        self.put_total(self._unread_key(blob, language), b"generated")

    def _unread_key(self, blob: str, language: str) -> str:
        # the facts' fingerprint: what decides "generated" is the parsers' text helpers
        return f"generated-head/1:{self.fingerprint}:{language}:{blob}"

    def info(self) -> CacheInfo:
        total, current = self._run(
            lambda db: db.execute(
                "select count(*), count(case when parser=? then 1 end) from facts",
                (self.fingerprint,),
            ).fetchone()
        )
        size = self.path.stat().st_size if self.path.exists() else 0
        return CacheInfo(str(self.path), total, size, self.fingerprint, current)

    def clear(self) -> int:
        self._decoded.clear()
        removed: int = self._run(lambda db: db.execute("delete from facts").rowcount)
        self._run(lambda db: db.execute("delete from bodies"))
        self._run(lambda db: db.execute("delete from totals"))
        self._run(lambda db: db.commit())
        self._run(lambda db: db.execute("vacuum"))
        return removed

    def close(self) -> None:
        try:
            self._run(lambda db: db.commit())
        finally:
            self._db.close()
            self._closed = True

    def __enter__(self) -> FactsCache:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
