"""Where the facts cache lives, and the file rules that keep it from touching anything else.

The cache is an SQLite file that archmetrics creates, reads and, when it is damaged, moves
aside. Its path may come from a repository's own configuration, which in CI is written by
whoever opened the pull request, so three rules hold whatever the path (docs/security.md):

- A file is used only if it is an archmetrics cache: an SQLite file carrying our application
  id (or, written by an older archmetrics, our ``meta`` table). Anything else, a directory,
  a device, a source file, ``.git``, an empty file, is refused with :class:`CacheError`
  and left exactly as it was.
- A new cache is built beside its path and linked into place only if nothing is there yet,
  so archmetrics never writes into a file it did not create.
- Only a file that is ours is moved aside when damaged, and never over another file.

A path from the repository's configuration must also lie inside archmetrics's cache
directory (:func:`configured_path`); ``--cache-path`` and ``$ARCHMETRICS_CACHE`` come from
the person running archmetrics and may name any place.
"""

from __future__ import annotations

import contextlib
import os
import sqlite3
import stat
import time
from pathlib import Path

APPLICATION = "archmetrics-facts"
APPLICATION_ID = 0x41524D43  # "ARMC", in the SQLite header at offset 68
SCHEMA = "1"
_HEADER = b"SQLite format 3\x00"
_COLUMNS = ("blob", "language", "parser", "data")


class CacheError(Exception):
    """A cache archmetrics will not or cannot use; the message is one line for the user."""


class Damaged(Exception):
    """Our own cache file, but not readable as one: it is moved aside and rebuilt."""


_CORRUPT, _NOT_A_DATABASE, _ERROR = 11, 26, 1  # SQLite's result codes


def is_damage(error: sqlite3.DatabaseError) -> bool:
    """Whether SQLite's ``error`` says the file is damaged (not busy, full or unwritable)."""
    code = getattr(error, "sqlite_errorcode", None)
    return code in (_CORRUPT, _NOT_A_DATABASE) or (code == _ERROR and "no such" in str(error))


def cache_directory() -> Path:
    """archmetrics's directory in the user's cache directory (``$XDG_CACHE_HOME`` ...)."""
    from platformdirs import user_cache_dir

    return Path(user_cache_dir("archmetrics"))


def default_path() -> Path:
    """``$ARCHMETRICS_CACHE`` if set, else facts.sqlite3 in :func:`cache_directory`."""
    override = os.environ.get("ARCHMETRICS_CACHE")
    return Path(override).expanduser() if override else cache_directory() / "facts.sqlite3"


def choose_path(flag: Path | None, configured: str | None, source: str) -> Path:
    """The cache to use: ``--cache-path``, else ``$ARCHMETRICS_CACHE`` (both the word of the
    person running archmetrics), else the repository's ``cache-path`` (confined by
    :func:`configured_path`), else facts.sqlite3 in :func:`cache_directory`."""
    if flag is not None:
        return flag.expanduser()
    if configured is not None and not os.environ.get("ARCHMETRICS_CACHE"):
        return configured_path(configured, source)
    return default_path()


def configured_path(text: str, source: str) -> Path:
    """The cache path a repository's configuration names, confined to :func:`cache_directory`:
    ``~`` is expanded, a relative path is taken inside that directory, and a path that leads
    out of it (by ``..``, an absolute path or a symbolic link) is refused."""
    root = cache_directory()
    path = root / Path(text).expanduser()
    real_root, real = os.path.realpath(root), os.path.realpath(path)
    if os.path.commonpath([real_root, real]) != real_root or real == real_root:
        raise CacheError(
            f"{source}: cache-path {text!r} is outside archmetrics's cache directory {root}; "
            "a repository's configuration may only name a file inside it "
            "(use --cache-path or ARCHMETRICS_CACHE to put the cache elsewhere)"
        )
    return path


def identify(path: Path) -> bool:
    """Whether ``path`` (an existing regular file) is an archmetrics cache."""
    try:
        with open(path, "rb") as file:
            header = file.read(100)
    except OSError:
        return False
    if len(header) < 100 or not header.startswith(_HEADER):
        return False
    if int.from_bytes(header[68:72], "big") == APPLICATION_ID:
        return True
    try:  # written before the application id: its meta table says whose it is
        db = sqlite3.connect(f"{path.resolve().as_uri()}?mode=ro", uri=True)
        try:
            row = db.execute("select value from meta where key='application'").fetchone()
        finally:
            db.close()
    except sqlite3.Error:
        return False
    return row is not None and row[0] == APPLICATION


def open_database(path: Path, notices: list[str]) -> sqlite3.Connection:
    """The cache at ``path``: created if nothing is there, used if it is ours (rebuilt, with a
    notice, if it is damaged), refused otherwise."""
    path = Path(os.path.realpath(path))
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return _create(path)
    except OSError as error:
        raise CacheError(f"facts cache {path}: cannot read: {error.strerror}") from error
    if not stat.S_ISREG(mode):
        raise CacheError(f"facts cache {path}: is not a regular file; choose another cache path")
    if not identify(path):
        raise CacheError(
            f"facts cache {path}: exists and is not an archmetrics facts cache (or is damaged "
            "past recognition); archmetrics leaves it alone: remove it or choose another path"
        )
    try:
        db = sqlite3.connect(path, timeout=30)
    except sqlite3.Error as error:
        raise CacheError(f"facts cache {path}: cannot open: {error}") from error
    try:
        check(db)
        with contextlib.suppress(sqlite3.OperationalError):  # read-only: no totals kept
            db.execute(_TOTALS)  # a cache made before the totals table gains it, facts kept
            db.execute(_BODIES)  # and the bodies table (its older facts are never read)
    except (Damaged, sqlite3.DatabaseError) as error:
        db.close()
        if isinstance(error, sqlite3.DatabaseError) and not is_damage(error):
            raise CacheError(f"facts cache {path}: {error}") from error
        return rebuild(path, f"damaged ({error})", notices)
    return db


# What a revision's facts add up to (a diff's coupling of one tree), by a digest of
# everything that decides it (cache.py, ``FactsCache.get_total``).
_TOTALS = "create table if not exists totals(key text primary key, data blob)"
# The bodies of facts records (their call sites and statements), read on first use: a look-up
# reads the head alone (codec.py, ``split``).
_BODIES = (
    "create table if not exists bodies(blob text, language text, parser text, data blob,"
    " primary key(blob, language, parser))"
)


def check(db: sqlite3.Connection) -> None:
    """Raise :class:`Damaged` unless ``db`` holds our tables in the current layout."""
    tables = {row[0] for row in db.execute("select name from sqlite_master where type='table'")}
    if not {"meta", "facts"} <= tables:
        raise Damaged("its tables are missing")
    meta = dict(db.execute("select key, value from meta").fetchall())
    if meta.get("application") != APPLICATION or meta.get("schema") != SCHEMA:
        raise Damaged("an older layout")
    columns = tuple(row[1] for row in db.execute("pragma table_info(facts)"))
    if columns != _COLUMNS:
        raise Damaged("its facts table has other columns")
    db.execute("select blob from facts limit 1").fetchone()  # reads the table's root page


def rebuild(path: Path, why: str, notices: list[str]) -> sqlite3.Connection:
    """Move our damaged cache aside (under a name nothing else has) and create a new one."""
    aside = _move_aside(path)
    notices.append(f"facts cache {path} is {why}; moved it to {aside.name} and started a new one")
    return _create(path)


def _move_aside(path: Path) -> Path:
    stamp = int(time.time())
    for attempt in range(1000):
        aside = path.with_name(f"{path.name}.bad-{stamp}" + (f"-{attempt}" if attempt else ""))
        try:
            os.link(path, aside)  # fails if the name is taken: nothing is overwritten
        except FileExistsError:
            continue
        except OSError as error:
            raise CacheError(f"facts cache {path}: cannot move it aside: {error}") from error
        os.unlink(path)
        return aside
    raise CacheError(f"facts cache {path}: too many damaged copies beside it; remove them")


def _create(path: Path) -> sqlite3.Connection:
    """A new, empty cache at ``path``, built under a temporary name and linked into place only
    if ``path`` is still free."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        temporary = path.with_name(f".{path.name}.{os.getpid()}.{time.monotonic_ns()}.new")
        _initialise(temporary)
        try:
            os.link(temporary, path)
        finally:
            os.unlink(temporary)
    except FileExistsError:  # another archmetrics created it meanwhile: use theirs
        return _reopen(path)
    except (OSError, sqlite3.Error) as error:
        reason = getattr(error, "strerror", None) or str(error)
        raise CacheError(f"facts cache {path}: cannot create: {reason}") from error
    return sqlite3.connect(path, timeout=30)


def _reopen(path: Path) -> sqlite3.Connection:
    if not identify(path):
        raise CacheError(f"facts cache {path}: appeared meanwhile and is not ours")
    return sqlite3.connect(path, timeout=30)


def _initialise(path: Path) -> None:
    db = sqlite3.connect(path)
    try:
        db.execute(f"pragma application_id = {APPLICATION_ID}")
        db.executescript(
            "create table meta(key text primary key, value text);"
            "create table facts(blob text, language text, parser text, data blob,"
            " primary key(blob, language, parser));"
            f"{_TOTALS};{_BODIES};"
        )
        db.executemany(
            "insert into meta values (?, ?)", [("application", APPLICATION), ("schema", SCHEMA)]
        )
        db.commit()
    finally:
        db.close()
