"""The facts cache: round trips, hits by content, and recovery from bad files."""

from __future__ import annotations

import dataclasses
import gc
import json
import sqlite3
import time
import zlib
from pathlib import Path
from typing import Any

import pytest

from archmetrics.facts import (
    Argument,
    Binding,
    CallSite,
    Class,
    ConfigTable,
    Decision,
    Deferred,
    Dependency,
    DependencyKind,
    FileFacts,
    Function,
    ParseWarning,
    Severity,
    Span,
    Statement,
)
from archmetrics.sources import cache as cache_module
from archmetrics.sources import cache_file, codec
from archmetrics.sources.cache import CacheError, FactsCache
from tests.harness import facts_of

SAMPLE = FileFacts(
    path="a/b.py",
    language="python",
    statements=(
        Statement("assign", Span(1, 2), "x = 1", None),
        Statement("def", Span(3, 3), "def f ( ) :", "f"),
    ),
    functions=(
        Function("f", "f", Span(3, 5), (Decision("if", 4), Decision("and", 4)), 3, ("a", "b")),
    ),
    classes=(Class("C", "C", Span(6, 9), "class"),),
    dependencies=(Dependency("", DependencyKind.IMPORT, Span(1, 1), 2, ("m", "n"), ("m", "o")),),
    call_sites=(
        CallSite(
            "bus.request",
            "request",
            "bus",
            Span(4, 4),
            (
                Argument("'wdb'", "wdb", True),
                Argument("x", None, False, "timeout"),
                Argument("2.5", 2.5, True),
                Argument("True", True, True),
            ),
            "f",
        ),
    ),
    bindings=(Binding("x", "1", 1), Binding("y", "( x , 2 )", 4, "f")),
    sloc=7,
    warnings=(ParseWarning("a/b.py", 3, "odd", Severity.ERROR),),
    parsed=True,
    generated=True,
)


def test_codec_round_trip() -> None:
    assert codec.decode(codec.encode(SAMPLE), "a/b.py") == SAMPLE


def test_codec_moves_facts_to_the_readers_path() -> None:
    moved = codec.decode(codec.encode(SAMPLE), "c/d.py")
    assert moved.path == "c/d.py" and moved.warnings[0].path == "c/d.py"


@pytest.mark.parametrize("language", ["python", "c", "cpp"])
def test_codec_round_trips_real_parser_output(language: str) -> None:
    source = {
        "python": "import os\n\ndef f(a):\n    if a and os.sep:\n        return g('x', 1)\n",
        "c": '#include <stdio.h>\nint f(int a) {\n    if (a && a > 1) return g("x", 1);\n'
        "    return 0;\n}\n",
        "cpp": '#include "a.h"\nnamespace n { struct S { int f(int a) { return a ? 1 : 2; } }; }\n',
    }[language]
    facts = facts_of(source, language)
    assert codec.decode(codec.encode(facts), facts.path) == facts


def test_codec_round_trips_a_string_value_that_is_a_lone_surrogate() -> None:
    # Python's "\ud800" is a str no UTF-8 can hold: the record is written with JSON escapes
    # (it made the file "not measured" and never cached)
    facts = facts_of('loads(text="\\ud800")\nf("\\udc80", "é")\n', "python")
    values = [a.value for c in facts.call_sites for a in c.arguments]
    assert values == ["\ud800", "\udc80", "é"]
    encoded = codec.encode(facts)
    encoded.decode("utf-8")  # valid UTF-8, so any cache or pipe can hold it
    assert codec.decode(encoded, facts.path) == facts


def test_decoded_facts_share_repeated_arguments_and_texts_but_keep_literal_types() -> None:
    source = "def f(self):\n    g(self, 0)\n    g(self, 0)\n    h(1)\n    h(1.0)\n    h(True)\n"
    facts = facts_of(source, "python")
    first = codec.decode(codec.encode(facts), facts.path)
    again = codec.decode(codec.encode(facts), facts.path)
    assert first == facts
    g1, g2, h1, h2, h3 = first.call_sites
    assert g1.arguments is g2.arguments  # one tuple for equal argument lists
    values = [h.arguments[0].value for h in (h1, h2, h3)]
    assert values == [1, 1.0, True] and [type(v) for v in values] == [int, float, bool]
    assert first.statements[1].text is again.statements[1].text  # texts are interned


CONFIG = FileFacts(
    path="pragmatics/rules.toml",
    language="toml",
    tables=(
        ConfigTable(("rules",), 2, (("name", ("drive",)),)),
        ConfigTable(("rules", "to"), 4, (("kind", ("send",)), ("service", ("muri.backend",)))),
    ),
)


def test_codec_round_trips_a_configuration_files_tables() -> None:
    assert codec.decode(codec.encode(CONFIG), CONFIG.path) == CONFIG


@pytest.mark.parametrize(
    "edit",
    [
        lambda t: t[0].__setitem__(1, 0),  # a table on line 0
        lambda t: t[0].__setitem__(1, "2"),  # a line that is text
        lambda t: t[1][2][1][1].__setitem__(0, 7),  # a value that is a number
        lambda t: t[1].__setitem__(0, ["rules", None]),  # a key that is no text
        lambda t: t[1].pop(),  # a table of two parts
    ],
)
def test_codec_rejects_tampered_configuration_tables(edit: Any) -> None:
    head, *body = codec.encode(CONFIG).split(b"\n")
    document = json.loads(head)
    edit(document[-1])
    with pytest.raises(codec.CodecError):
        codec.decode(b"\n".join((json.dumps(document).encode(), *body)), CONFIG.path)


def _parts() -> tuple[list[Any], bytes, bytes, bytes]:
    head, calls, statements, bindings = codec.encode(SAMPLE).split(b"\n")
    return json.loads(head), calls, statements, bindings


def _joined(document: list[Any], calls: bytes, statements: bytes, bindings: bytes) -> bytes:
    return b"\n".join((json.dumps(document).encode(), calls, statements, bindings))


def _tampered(edit: str) -> bytes:
    document, calls, statements, bindings = _parts()
    if edit == "statement":  # a statement starting on line 0, the checksum left as it was
        statements = statements.replace(b'"assign",[1,2]', b'"assign",[0,2]')
    elif edit == "call":  # an argument with two fields of four
        calls = calls.replace(b'["x",null,false,"timeout"]', b'["x",null]')
    elif edit == "binding":  # a binding whose line is text, the checksum left as it was
        bindings = bindings.replace(b'"1",1,', b'"1","1",')
    else:
        document[5][0][2] = 0  # a function starting on line 0
    return _joined(document, calls, statements, bindings)


@pytest.mark.parametrize("edit", ["statement", "call", "binding", "function"])
@pytest.mark.security
def test_codec_rejects_tampered_records(edit: str) -> None:
    assert _tampered(edit) != codec.encode(SAMPLE)
    with pytest.raises(codec.CodecError):
        codec.decode(_tampered(edit), "x.py")


def test_statements_and_calls_are_decoded_when_first_read() -> None:
    facts = codec.decode(codec.encode(SAMPLE), "a/b.py")
    assert isinstance(facts.statements, Deferred) and isinstance(facts.call_sites, Deferred)
    assert facts.loc == 2  # counted without decoding them
    assert facts.callees() == {"bus.request"}  # kept readable without decoding the calls
    assert facts.statements[1].text == "def f ( ) :"
    assert facts.call_sites[0].arguments[1].keyword == "timeout"
    assert facts.statements == SAMPLE.statements and facts == SAMPLE


@pytest.mark.parametrize("part", ["statements", "call sites", "bindings"])
def test_records_damaged_behind_a_good_checksum_fail_when_read(part: str) -> None:
    document, calls, statements, bindings = _parts()
    if part == "statements":
        statements = statements.replace(b'"assign",[1,2]', b'"assign",[0,2]')
        document[2][1] = zlib.crc32(statements)
    elif part == "call sites":
        calls = calls.replace(b'"bus.request","request"', b'"bus.request",7')
        document[3][1] = zlib.crc32(calls)
    else:
        bindings = bindings.replace(b'"1",1,', b'"1","1",')
        document[4][1] = zlib.crc32(bindings)
    facts = codec.decode(_joined(document, calls, statements, bindings), "x.py")
    assert facts.loc == 2 and len(facts.call_sites) == 1 and len(facts.bindings) == 2
    read = {"statements": facts.statements, "call sites": facts.call_sites}.get(part)
    with pytest.raises(codec.CodecError, match=rf"bad {part} in the cached facts of x\.py"):
        list(facts.bindings if read is None else read)


@pytest.mark.parametrize(
    "bad",
    [b"", b"[]", b"{}", b"[7]\n[]\n[]\n[]", b"not json", b'[7, "python"]\n[]\n[]\n[]', b"\n\n\n"],
)
def test_codec_rejects_what_it_did_not_write(bad: bytes) -> None:
    with pytest.raises(codec.CodecError):
        codec.decode(bad, "x.py")


def test_cache_hits_by_blob_and_survives_reopen(tmp_path: Path) -> None:
    path = tmp_path / "cache.sqlite3"
    with FactsCache(path) as cache:
        assert cache.get("abc", "python", "a/b.py") is None
        cache.put_many([("abc", SAMPLE)])
    with FactsCache(path) as cache:
        assert cache.get("abc", "python", "x/y.py") == codec.decode(codec.encode(SAMPLE), "x/y.py")
        assert cache.get("abc", "c", "a/b.py") is None
        assert (cache.hits, cache.misses) == (1, 1)
        assert cache.info().entries == 1
        assert cache.clear() == 1
        assert cache.get("abc", "python", "a/b.py") is None


def _tree(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` and its bytes: to show nothing was touched."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


@pytest.mark.parametrize(
    "content",
    [
        b"this is not a database" * 100,
        b"",
        b"print('hello')\n",
        b"SQLite format 3\x00" + b"\0" * 84,
    ],
    ids=["text", "empty", "source", "bare-header"],
)
@pytest.mark.security
def test_a_file_that_is_not_a_cache_is_refused_and_left_alone(
    tmp_path: Path, content: bytes
) -> None:
    path = tmp_path / "cache.sqlite3"
    path.write_bytes(content)
    with pytest.raises(CacheError, match="not an archmetrics facts cache"):
        FactsCache(path)
    assert _tree(tmp_path) == {"cache.sqlite3": content}


def test_a_foreign_database_is_refused_and_left_alone(tmp_path: Path) -> None:
    path = tmp_path / "cache.sqlite3"
    db = sqlite3.connect(path)
    db.execute("create table facts(blob, language, parser, data)")
    db.commit()
    db.close()
    before = _tree(tmp_path)
    with pytest.raises(CacheError, match="not an archmetrics facts cache"):
        FactsCache(path)
    assert _tree(tmp_path) == before


def test_a_directory_is_refused_and_left_alone(tmp_path: Path) -> None:
    git = tmp_path / ".git"
    (git / "objects").mkdir(parents=True)
    (git / "HEAD").write_text("ref: refs/heads/main\n")
    before = _tree(tmp_path)
    with pytest.raises(CacheError, match="not a regular file"):
        FactsCache(git)
    assert _tree(tmp_path) == before


def test_a_new_cache_carries_the_application_id(tmp_path: Path) -> None:
    path = tmp_path / "deep" / "cache.sqlite3"
    with FactsCache(path) as cache:
        assert cache.notices == []
    header = path.read_bytes()[:100]
    assert int.from_bytes(header[68:72], "big") == cache_file.APPLICATION_ID
    assert sorted(p.name for p in path.parent.iterdir()) == ["cache.sqlite3"]


def test_a_cache_written_before_the_application_id_is_still_ours(tmp_path: Path) -> None:
    path = tmp_path / "cache.sqlite3"
    with FactsCache(path) as cache:
        cache.put_many([("abc", SAMPLE)])
    db = sqlite3.connect(path)
    db.execute("pragma application_id = 0")
    db.commit()
    db.close()
    with FactsCache(path) as cache:
        assert cache.notices == []
        assert cache.get("abc", "python", "a/b.py") is not None


def _damage(path: Path, table_change: str) -> None:
    db = sqlite3.connect(path)
    db.executescript(table_change)
    db.commit()
    db.close()


@pytest.mark.parametrize(
    "change",
    [
        "drop table facts",
        "drop table facts; create table facts(x, y)",
        "update meta set value = '0' where key = 'schema'",
    ],
    ids=["facts-missing", "facts-wrong", "older-layout"],
)
@pytest.mark.security
def test_our_cache_with_bad_tables_is_moved_aside_and_rebuilt(tmp_path: Path, change: str) -> None:
    path = tmp_path / "cache.sqlite3"
    with FactsCache(path) as cache:
        cache.put_many([("abc", SAMPLE)])
    _damage(path, change)
    with FactsCache(path) as cache:
        assert cache.notices and "moved it to" in cache.notices[0]
        cache.put_many([("abc", SAMPLE)])
        assert cache.get("abc", "python", "a/b.py") is not None
    assert len(list(tmp_path.glob("cache.sqlite3.bad-*"))) == 1


def test_a_damaged_page_found_mid_run_rebuilds_the_cache(tmp_path: Path) -> None:
    path = tmp_path / "cache.sqlite3"
    blobs = [f"{n:040x}" for n in range(400)]
    with FactsCache(path) as cache:
        cache.put_many([(blob, SAMPLE) for blob in blobs])
    data = bytearray(path.read_bytes())
    data[-4096:] = b"\xff" * 4096  # the last page: the header and the first pages stay good
    path.write_bytes(bytes(data))
    with FactsCache(path) as cache:
        assert cache.notices == []  # found only when the page is read
        found = [cache.get(blob, "python", "a/b.py") for blob in blobs]
        lost = found.count(None)
        for facts in found:  # the page may hold bodies, read when the statements are used
            if facts is not None:
                try:
                    list(facts.statements)
                except codec.CodecError as error:
                    assert "run the command again" in str(error)
                    lost += 1
        assert any("damaged" in notice for notice in cache.notices)
        assert lost >= 1
        cache.put_many([("abc", SAMPLE)])
        assert cache.get("abc", "python", "a/b.py") is not None
    [aside] = tmp_path.glob("cache.sqlite3.bad-*")
    assert aside.read_bytes() == bytes(data)


def test_moving_aside_never_overwrites_a_file(tmp_path: Path) -> None:
    path = tmp_path / "cache.sqlite3"
    with FactsCache(path):
        pass
    _damage(path, "drop table facts")
    for stamp in range(-2, 3):  # whatever second it is, the plain name is taken
        path.with_name(f"cache.sqlite3.bad-{int(time.time()) + stamp}").write_text("keep me")
    with FactsCache(path) as cache:
        assert "moved it to" in cache.notices[0]
    kept = [p for p in tmp_path.glob("cache.sqlite3.bad-*") if p.read_bytes() == b"keep me"]
    assert len(kept) == 5


@pytest.mark.security
def test_a_configured_path_stays_inside_the_cache_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "home-cache"))
    root = cache_file.cache_directory()
    assert cache_module.configured_path("mine.sqlite3", "pyproject.toml") == root / "mine.sqlite3"
    inside = str(root / "x" / "y.sqlite3")
    assert cache_module.configured_path(inside, "pyproject.toml") == Path(inside)
    monkeypatch.setenv("HOME", str(root))
    assert cache_module.configured_path("~/z.db", "p") == root / "z.db"
    assert cache_module.configured_path(".git", "p") == root / ".git"  # a name, not the repo's
    for text in ("/", "/dev/null", "../x.sqlite3", "~", str(tmp_path / "a.db"), "."):
        with pytest.raises(CacheError, match="outside archmetrics's cache directory"):
            cache_module.configured_path(text, "pyproject.toml")
    root.mkdir(parents=True)
    (root / "link").symlink_to(tmp_path)
    with pytest.raises(CacheError, match="outside"):
        cache_module.configured_path("link/cache.sqlite3", "pyproject.toml")


def test_bad_entry_is_dropped_and_reparsed(tmp_path: Path) -> None:
    path = tmp_path / "cache.sqlite3"
    with FactsCache(path) as cache:
        cache.put_many([("abc", SAMPLE)])
        cache._db.execute("update facts set data = ?", (b"garbage",))
        assert cache.get("abc", "python", "a/b.py") is None
        assert cache.info().entries == 0


def test_facts_other_parsers_wrote_are_not_served(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "cache.sqlite3"
    with FactsCache(path) as cache:
        cache.put_many([("abc", SAMPLE)])
    monkeypatch.setattr(cache_module, "parser_fingerprint", lambda: "another-archmetrics")
    with FactsCache(path) as cache:
        assert cache.get("abc", "python", "a/b.py") is None
        assert (cache.info().entries, cache.info().current_entries) == (1, 0)


def test_the_fingerprint_names_the_python_that_parsed(monkeypatch: pytest.MonkeyPatch) -> None:
    ours = cache_module.parser_fingerprint.__wrapped__()
    assert cache_module.parser_fingerprint.__wrapped__() == ours
    monkeypatch.setattr(cache_module.sys, "version", "3.99.0 (another)")
    assert cache_module.parser_fingerprint.__wrapped__() != ours


def test_facts_from_the_cache_read_their_statements_back_from_it(tmp_path: Path) -> None:
    # the statements and call sites are not held as bytes until first read: they are read
    # again from the cache (also after it was closed), checked against the checksum seen
    path = tmp_path / "cache.sqlite3"
    with FactsCache(path) as cache:
        cache.put_many([("abc", SAMPLE), ("def", SAMPLE)])
    with FactsCache(path) as cache:
        first = cache.get("abc", "python", "a/b.py")
        later = cache.get("def", "python", "a/b.py")
        assert first is not None and later is not None
        assert first.statements == SAMPLE.statements  # read while open
    assert later.statements == SAMPLE.statements  # read after the cache was closed
    assert later.call_sites == SAMPLE.call_sites
    with FactsCache(path) as cache:
        changed = cache.get("abc", "python", "a/b.py")
        assert changed is not None
        other = dataclasses.replace(SAMPLE, statements=SAMPLE.statements[:1])
        head, body = codec.split(codec.encode(other))
        with sqlite3.connect(path) as db:  # another process rewrites the entry meanwhile
            db.execute("update facts set data = ? where blob = 'abc'", (head,))
            db.execute("update bodies set data = ? where blob = 'abc'", (body,))
        with pytest.raises(codec.CodecError, match="no longer in the facts cache"):
            changed.statements.items()
        assert changed.functions == SAMPLE.functions  # what was decoded stays
        assert cache.get("abc", "python", "a/b.py") is None  # the entry was dropped


def test_a_head_without_its_body_is_not_believed(tmp_path: Path) -> None:
    # the facts table keeps records' heads, the bodies table their call sites and
    # statements, written together; a head whose body is gone is dropped and measured again
    path = tmp_path / "cache.sqlite3"
    with FactsCache(path) as cache:
        cache.put_many([("abc", SAMPLE)])
    with sqlite3.connect(path) as db:
        [(head,)] = db.execute("select data from facts").fetchall()
        assert b"\n" not in head
        db.execute("delete from bodies")
    with FactsCache(path) as cache:
        assert cache.get("abc", "python", "a/b.py") is None
    with sqlite3.connect(path) as db:
        assert db.execute("select count(*) from facts").fetchone()[0] == 0


def _kept_and_read_back(path: Path) -> FileFacts:
    """SAMPLE stored in a new cache at ``path``, then decoded from it by another cache
    object, which is closed and dropped before the facts are returned."""
    with FactsCache(path) as cache:
        cache.put_many([("abc", SAMPLE)])
    with FactsCache(path) as cache:
        facts = cache.get("abc", "python", "a/b.py")
    del cache
    gc.collect()
    assert facts is not None
    return facts


def test_facts_that_outlive_their_cache_object_still_read_back(tmp_path: Path) -> None:
    # facts hold their cache weakly (no cycle through every decoded fact): once it is gone,
    # the record is read through a connection of its own, read-only
    facts = _kept_and_read_back(tmp_path / "cache.sqlite3")
    assert facts.statements == SAMPLE.statements


def test_facts_whose_cache_file_is_gone_fail_with_a_codec_error(tmp_path: Path) -> None:
    path = tmp_path / "cache.sqlite3"
    facts = _kept_and_read_back(path)
    path.unlink()
    with pytest.raises(codec.CodecError, match="no longer in the facts cache"):
        facts.call_sites.items()
