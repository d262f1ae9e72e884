"""Location globs: gitignore-like matching, first match wins, unmatched is base, exclusions."""

from __future__ import annotations

import re

import pytest

from archmetrics.changeset.locations import Location, LocationRule, LocationRules
from archmetrics.globs import BadPattern, glob_matches


@pytest.mark.parametrize(
    ("pattern", "path", "expected"),
    [
        # no slash: any depth, file or directory component
        ("*.py", "a.py", True),
        ("*.py", "pkg/sub/a.py", True),
        ("*.py", "pkg/a.pyc", False),
        ("generated", "x/generated/y.c", True),
        ("generated", "x/generated.c", False),
        ("a?.c", "src/ab.c", True),
        ("a?.c", "src/a/.c", False),
        # a slash anchors at the root
        ("src/*.c", "src/a.c", True),
        ("src/*.c", "lib/src/a.c", False),
        ("src/*.c", "src/x/a.c", False),
        ("/main.c", "main.c", True),
        ("/main.c", "src/main.c", False),
        # ** forms
        ("src/**/*.c", "src/a.c", True),
        ("src/**/*.c", "src/x/y/a.c", True),
        ("src/**/*.c", "other/src/a.c", False),
        ("wdb/**", "wdb/a.py", True),
        ("wdb/**", "wdb/deep/er/a.py", True),
        ("wdb/**", "wdb", False),
        ("wdb/**", "wdbx/a.py", False),
        ("**/proxy/*.h", "proxy/p.h", True),
        ("**/proxy/*.h", "a/b/proxy/p.h", True),
        ("a**b.c", "axxb.c", True),
        ("a**b.c", "ax/xb.c", False),
        # a directory match covers everything below it
        ("wdb", "wdb/a.py", True),
        ("client/", "client/a.c", True),
        ("client/", "client", False),
        ("client/", "src/client/a.c", True),
        ("src/lib", "src/lib/x/y.c", True),
        # classes and escapes
        ("[ab].c", "b.c", True),
        ("[!ab].c", "b.c", False),
        ("[!ab].c", "c.c", True),
        ("\\*.c", "*.c", True),
        ("\\*.c", "x.c", False),
        ("[^ab].c", "c.c", True),
        ("\\#notes", "#notes", True),
        ("trail\\ ", "trail ", True),
        ("trail ", "trail", True),  # unescaped trailing spaces are dropped, as git does
        # case-sensitive, and paths are normalized
        ("*.C", "a.c", False),
        ("src/*.c", "./src/a.c", True),
    ],
)
def test_glob(pattern: str, path: str, expected: bool) -> None:
    assert glob_matches(pattern, path) is expected


@pytest.mark.parametrize(
    "pattern", ["", "/", "  ", "!wdb/**", "#notes", "[unclosed.c", "a[]", "x\\", "x" * 1025]
)
def test_unusable_globs_are_refused(pattern: str) -> None:
    with pytest.raises(BadPattern):
        LocationRules((LocationRule(Location.NEW, pattern),))


def test_manifest_order_first_match_wins_unmatched_is_base() -> None:
    rules = LocationRules.from_mapping(
        {"new": ["wdb/**"], "framework": ["proxy/**", "wdb/shared/**"], "base": ["client/**"]},
        exclude=["generated/**"],
    )
    assert rules.location_of("wdb/store.py") is Location.NEW
    assert rules.location_of("wdb/shared/x.py") is Location.NEW  # earlier rule wins
    assert rules.location_of("proxy/p.cpp") is Location.FRAMEWORK
    assert rules.location_of("client/c.c") is Location.BASE
    assert rules.location_of("tools/other.py") is Location.BASE
    assert rules.is_excluded("generated/stub.py") == "exclude:generated/**"
    assert rules.is_excluded("wdb/store.py") is None


def test_rule_order_is_the_mapping_order() -> None:
    first = LocationRules.from_mapping({"framework": ["*.h"], "new": ["new/**"]})
    second = LocationRules.from_mapping({"new": ["new/**"], "framework": ["*.h"]})
    assert first.location_of("new/api.h") is Location.FRAMEWORK
    assert second.location_of("new/api.h") is Location.NEW


def test_unknown_location_name_is_named() -> None:
    with pytest.raises(BadPattern, match="'vendor'"):
        LocationRules.from_mapping({"vendor": ["third_party/**"]})


@pytest.mark.parametrize(
    "pattern", ["[z-a]", "src/[b-a]*.c", "**/x[9-0]", "[[:alpha:]].c", "[a/b]c"]
)
def test_a_glob_regex_cannot_compile_is_refused_by_name(pattern: str) -> None:
    with pytest.raises(BadPattern, match=re.escape(repr(pattern))):
        LocationRules.from_mapping({"new": [pattern]})


@pytest.mark.parametrize(
    ("pattern", "path", "expected"),
    [
        ("*a" * 16 + "*b", "d/" + "a" * 400, False),
        ("*a" * 16 + "*b", "d/" + "a" * 400 + "b", True),
        ("*a*" * 16, "a" * 15, False),
        ("a/" + "**/a/" * 12 + "b", "a/" * 200 + "c", False),
        ("a/" + "**/a/" * 12 + "b", "a/" * 200 + "b", True),
        ("**/x/**/y/**/z", "x/y/x/y/z", True),
        ("**/x/**/y/**/z", "x/z/y", False),
        # past what any backtracking matcher survives: RE2 is linear in pattern and path
        ("*a" * 500 + "*b", "d/" + "a" * 20_000, False),
        ("**/a/" * 200 + "b", "a/" * 20_000 + "c", False),
    ],
)
@pytest.mark.security
def test_globs_with_many_stars_match_without_backtracking(
    pattern: str, path: str, expected: bool
) -> None:
    """Each would take longer than the test timeout if stars backtracked through every split
    (a repository's configuration is untrusted input)."""
    assert glob_matches(pattern, path) is expected
