"""A tree's state to and from a cache record (sources/statecodec.py): the state of a real
tree comes back equal, and a record a stranger changed is refused with CodecError, never
with another exception and never believed when it breaks what a diff relies on."""

from __future__ import annotations

import json
import zlib
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from archmetrics.app.diff_options import DiffRequest, diff_options
from archmetrics.app.progress import NoProgress
from archmetrics.app.tree import whole_side
from archmetrics.changeset.state import TreeState
from archmetrics.config import load_settings
from archmetrics.sources.codec import CodecError
from archmetrics.sources.snapshot import DirectorySnapshot
from archmetrics.sources.statecodec import decode, encode

STUDY = Path(__file__).resolve().parents[2] / "fixtures" / "study"


def _state(folder: Path, **settings: object) -> TreeState:
    request = DiffRequest(folder, "EMPTY", "WORKTREE", load_settings(folder), jobs=1)
    options = diff_options(request, folder)
    return whole_side(DirectorySnapshot(folder), options, None, NoProgress()).state


@pytest.fixture(scope="module")
def state() -> TreeState:
    """The state of the as-described Pragmatics SOA subject's last stage: Python with
    imports and bus links, a file excluded as generated."""
    return _state(STUDY / "as-described" / "pragmatics" / "soa" / "second")


def _same(a: TreeState, b: TreeState) -> None:
    assert a.rows == b.rows
    assert a.index.paths == b.index.paths
    assert a.index.elements == b.index.elements
    assert dict(a.index.deps) == dict(b.index.deps)
    assert dict(a.index.sites) == dict(b.index.sites)
    assert dict(a.index.values) == dict(b.index.values)
    assert dict(a.index.receivers) == dict(b.index.receivers)
    assert a.index.whole == b.index.whole
    assert [(e.name, e.files) for e in a.groups] == [(e.name, e.files) for e in b.groups]
    assert dict(a.table) == dict(b.table)
    assert a.excluded == b.excluded


@pytest.mark.parametrize(
    "stage",
    ["as-described/pragmatics/soa/second", "wdb/p2p/second", "pragmatics/soa/second",
     "as-described/wdb/player/second"],
)  # fmt: skip
def test_a_real_trees_state_comes_back_equal(stage: str) -> None:
    state = _state(STUDY / stage)
    assert state.index.deps and state.table
    _same(decode(encode(state)), state)


def test_a_state_whose_groups_differ_from_the_coupled_elements(tmp_path: Path) -> None:
    """A file that cannot be parsed is grouped for the diff but not coupled: the record
    keeps the difference, and both come back."""
    (tmp_path / "ok.py").write_text("import bad\n")
    (tmp_path / "bad.py").write_text("def f(:\n")
    state = _state(tmp_path)
    assert [e.name for e in state.groups] != [e.name for e in state.index.elements]
    _same(decode(encode(state)), state)


def test_a_ros_trees_receivers_and_whole_flag_come_back(tmp_path: Path) -> None:
    """A parameter file receives the code that reads it, without a site of its own; the
    record keeps such receivers, and that the tree is coupled whole on a patch."""
    from tests.coupling.test_ros import LAUNCH, PARAMS, WORKSPACE

    files = {**WORKSPACE, "talker_pkg/config/params.yaml": PARAMS,
             "bringup/package.xml": "<package><name>bringup</name></package>\n",
             "bringup/launch/demo.launch.py": LAUNCH}  # fmt: skip
    for path, text in files.items():
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text(text)
    state = _state(tmp_path)
    assert state.index.whole
    assert state.index.receivers["parameter:/robot1/talker/topic"] == frozenset(
        {"talker_pkg/config/params.yaml"}
    )
    _same(decode(encode(state)), state)


def _document(data: bytes) -> dict[str, Any]:
    return json.loads(zlib.decompress(data))  # type: ignore[no-any-return]


def _paths(value: object, prefix: tuple[object, ...] = ()) -> list[tuple[object, ...]]:
    """Every place in a JSON document where a value sits."""
    found: list[tuple[object, ...]] = [prefix]
    if isinstance(value, dict):
        for key, item in value.items():
            found += _paths(item, (*prefix, key))
    elif isinstance(value, list):
        for i, item in enumerate(value[:3]):
            found += _paths(item, (*prefix, i))
    return found


STRANGE = st.one_of(
    st.none(), st.booleans(), st.integers(-(2**70), 2**70), st.floats(allow_nan=False),
    st.text(max_size=5), st.lists(st.integers(-3, 3), max_size=3), st.just({}),
)  # fmt: skip


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_a_record_changed_anywhere_is_refused_or_read_never_crashes(
    state: TreeState, data: st.DataObject
) -> None:
    document = _document(encode(state))
    place = data.draw(st.sampled_from(_paths(document)[1:]))
    target: Any = document
    for key in place[:-1]:
        target = target[key]
    target[place[-1]] = data.draw(STRANGE)
    try:
        decoded = decode(zlib.compress(json.dumps(document).encode()))
    except CodecError:
        return
    # believed: then it is a state a diff can use without failing
    assert isinstance(decoded, TreeState)
    paths = set(decoded.index.paths)
    assert all(p in paths for e in decoded.index.elements for p in e.files)


@pytest.mark.parametrize("data", [b"", b"x" * 10, zlib.compress(b"[]"), zlib.compress(b"{}"),
                                  zlib.compress(b'{"format": 99}')])  # fmt: skip
def test_what_is_not_a_state_is_refused(data: bytes) -> None:
    with pytest.raises(CodecError):
        decode(data)
