"""The language table: a file's language by its ending, as ``PurePosixPath.suffix`` reads it."""

from __future__ import annotations

from pathlib import PurePosixPath

from hypothesis import given
from hypothesis import strategies as st

from archmetrics.parsers import LanguageTable

TABLE = LanguageTable.default({"PYX": "python", ".h": ""})
# paths as git gives them: no empty, `.` or `..` part (PurePosixPath would drop a `.` part,
# reading `C.C/.` as `C.C`; no path a snapshot lists has one)
_PART = st.text(alphabet="ab.CchpPyY é", min_size=1, max_size=6).filter(
    lambda part: part not in {".", ".."}
)
_PARTS = st.lists(_PART, min_size=1, max_size=3).map("/".join)


def _by_suffix(path: str) -> str | None:
    suffix = PurePosixPath(path).suffix.lower()
    return dict(TABLE.extensions).get(suffix)


@given(_PARTS)
def test_the_ending_is_the_suffix_a_path_object_gives(path: str) -> None:
    assert TABLE.language_of(path) == _by_suffix(path)


def test_endings_examples() -> None:
    assert TABLE.language_of("src/a.PY") == "python"
    assert TABLE.language_of("src/a.pyx") == "python"  # added by the overrides
    assert TABLE.language_of("src/a.h") is None  # dropped by them
    assert TABLE.language_of("src/.py") is None  # a hidden file has no ending
    assert TABLE.language_of("src.c/README") is None  # a folder's ending is not the file's
    assert TABLE.language_of("a.tar.c") == "c"
