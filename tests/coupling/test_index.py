"""The coupling index (coupling/index.py): built from a whole tree it counts what
measure_coupling counts, and patched after content edits it equals the index of the edited
tree built whole, on the study's real subjects and on edits made to them."""

from __future__ import annotations

import random
from collections.abc import Mapping
from itertools import pairwise
from pathlib import Path

import pytest

from archmetrics.coupling import CouplingOptions, measure_coupling
from archmetrics.coupling.index import CouplingIndex, LazyFacts, build_index
from archmetrics.coupling.index_patch import patch_index
from archmetrics.coupling.measure import link_tree
from archmetrics.coupling.sitememo import SiteMemo
from archmetrics.facts import FileFacts
from tests.coupling.test_sitememo import Store
from tests.coupling.trees import BUILTIN, tree_facts

STUDY = Path(__file__).resolve().parents[2] / "fixtures" / "study"
OPTIONS = CouplingOptions(include_dirs=("player_stub",))


def _stages() -> list[Path]:
    """Every stage folder of every study subject (both variants)."""
    return sorted(s for manifest in STUDY.glob("**/manifest.toml") for s in _stage_dirs(manifest))


def _stage_dirs(manifest: Path) -> list[Path]:
    return [p for p in sorted(manifest.parent.iterdir()) if p.is_dir()]


def _sources(folder: Path) -> dict[str, str]:
    found = {}
    for path in sorted(folder.rglob("*")):
        if path.is_file() and path.suffix in {".c", ".h", ".cc", ".cpp", ".hpp", ".py"}:
            found[path.relative_to(folder).as_posix()] = path.read_text("utf-8", "replace")
    stub = STUDY / "player_stub"
    for path in sorted(stub.rglob("*.h")):
        found["player_stub/" + path.relative_to(stub).as_posix()] = path.read_text()
    return found


def _whole(facts: list[FileFacts], memo: SiteMemo | None = None) -> CouplingIndex:
    return build_index(link_tree(facts, OPTIONS, BUILTIN, memo), [f.path for f in facts])


def _values(facts: list[FileFacts]) -> dict[str, tuple[int, int, int, int]]:
    report = measure_coupling(facts, OPTIONS, BUILTIN)
    return {c.element.name: (c.s_a, c.s_e, c.d_a, c.d_e) for c in report.elements}


STAGES = _stages()


@pytest.mark.parametrize("stage", STAGES, ids=lambda p: str(p.relative_to(STUDY)))
def test_values_counted_from_the_index_are_measure_couplings(stage: Path) -> None:
    facts = tree_facts(_sources(stage))
    index = _whole(facts)
    assert dict(index.values) == _values(facts)
    assert index.sites or "baseline" in str(stage)  # every later stage has run-time links


def _patched(
    before: Mapping[str, str], after: Mapping[str, str], memo: SiteMemo | None = None
) -> tuple[CouplingIndex, CouplingIndex]:
    """The index of ``after`` patched from ``before``'s (same paths), and built whole."""
    assert before.keys() == after.keys()
    old = {f.path: f for f in tree_facts(before)}
    edited = {p: s for p, s in after.items() if s != before[p]}
    return _patched_facts(old, dict(old, **{f.path: f for f in tree_facts(edited)}), memo)


def _patched_facts(
    old: Mapping[str, FileFacts], new: Mapping[str, FileFacts], memo: SiteMemo | None = None
) -> tuple[CouplingIndex, CouplingIndex]:
    changed = {p: f for p, f in new.items() if f is not old[p]}
    lazy = LazyFacts(new.keys(), new.__getitem__)
    patched = patch_index(_whole(list(old.values()), memo), changed, lazy, OPTIONS, BUILTIN, memo)
    return patched, _whole(list(new.values()))


def _same(patched: CouplingIndex, whole: CouplingIndex) -> None:
    assert dict(patched.values) == dict(whole.values)
    assert dict(patched.deps) == dict(whole.deps)
    assert dict(patched.sites) == dict(whole.sites)
    assert patched.elements == whole.elements


def _pairs() -> list[tuple[Path, Path]]:
    found = []
    for manifest in STUDY.glob("**/manifest.toml"):
        stages = _stage_dirs(manifest)
        found += list(pairwise(stages))
    return sorted(found)


@pytest.mark.parametrize("pair", _pairs(), ids=lambda p: str(p[1].relative_to(STUDY)))
def test_a_stage_patched_from_the_one_before_equals_it_coupled_whole(
    pair: tuple[Path, Path],
) -> None:
    """The next stage's contents at the paths both stages have (its additions left out: a
    patch keeps the path set)."""
    before, after = _sources(pair[0]), _sources(pair[1])
    shared = {p: after.get(p, before[p]) for p in before}
    patched, whole = _patched(before, shared)
    _same(patched, whole)
    patched, _ = _patched(shared, before)  # and back
    _same(patched, _whole(tree_facts(before)))


SOCKET = "\n#include <sys/socket.h>\n"
EDITS = (
    '\n#include <sys/socket.h>\nint am_send(int fd) { return send(fd, "x", 1, 0); }\n',
    '\nint am_listen(int fd) { return bind(fd, 0, 0) + listen(fd, 5); }\n',
    "\nimport socket\n\ndef am_connect():\n    socket.create_connection(('h', 4242))\n",
    "\nimport zmq\n\ndef am_bind(ctx):\n    ctx.socket(zmq.REP).bind('tcp://*:5555')\n",
)


def _edit(path: str, source: str, tree: Mapping[str, str], rng: random.Random) -> str:
    """``source`` edited: a link site appended, an include of another tree file added or its
    first include or import removed."""
    python = path.endswith(".py")
    choice = rng.randrange(4)
    if choice == 0:
        return source + EDITS[rng.choice((2, 3)) if python else rng.choice((0, 1))]
    if choice == 1 and not python:
        headers = sorted(p for p in tree if p.endswith(".h"))
        return f'#include "{rng.choice(headers)}"\n' + source if headers else source
    lines = source.splitlines(keepends=True)
    marker = "import" if python else "#include"
    for i, line in enumerate(lines):
        if line.lstrip().startswith(marker):
            return "".join(lines[:i] + lines[i + 1 :])
    return source + "\n"


@pytest.mark.parametrize("seed", range(12))
def test_random_edits_of_a_real_subject_patch_to_the_whole_tree(seed: int) -> None:
    rng = random.Random(seed)
    stage = rng.choice(STAGES)
    before = _sources(stage)
    after = dict(before)
    own = sorted(p for p in before if not p.startswith("player_stub/"))
    for path in rng.sample(own, min(len(own), rng.randint(1, 3))):
        after[path] = _edit(path, after[path], before, rng)
    memo = SiteMemo(Store(), "context", {p: str(hash(s)) for p, s in before.items()})
    patched, whole = _patched(before, after, memo if seed % 2 else None)
    _same(patched, whole)


def test_a_patch_redoes_only_what_the_edited_file_reaches() -> None:
    """Editing a file nothing includes reads the facts of its element and of what it
    reaches, not the whole tree."""
    stage = STUDY / "as-described" / "wdb" / "p2p" / "second"
    before = _sources(stage)
    target = next(p for p in sorted(before) if p.endswith(".c"))
    after = dict(before, **{target: before[target] + EDITS[0]})
    new = {f.path: f for f in tree_facts(after)}
    asked: list[str] = []

    def read(path: str) -> FileFacts:
        asked.append(path)
        return new[path]

    index = _whole(tree_facts(before))
    patch_index(index, {target: new[target]}, LazyFacts(new.keys(), read), OPTIONS, BUILTIN)
    assert target in asked
    assert len(set(asked)) < len(new) / 2


def _brotli() -> dict[str, str]:
    """Brotli's C sources (PyPI sdist, pinned: the oracle corpus): 92 files whose headers
    include each other through folders (``../common/platform.h``)."""
    from tests.parsers.test_c_oracle import _corpus_dir, _unpacked

    folder = _corpus_dir()
    folder.mkdir(parents=True, exist_ok=True)
    root = _unpacked(folder, "brotli-1.1.0.tar.gz", "Brotli==1.1.0") / "c"
    return {
        p.relative_to(root).as_posix(): p.read_text("utf-8", "replace")
        for p in sorted(root.rglob("*"))
        if p.suffix in {".c", ".h"} and p.is_file()
    }


@pytest.fixture(scope="module")
def brotli() -> dict[str, FileFacts]:
    return {f.path: f for f in tree_facts(_brotli())}


@pytest.mark.slow
@pytest.mark.parametrize(
    "edited",
    [
        # a header nearly every file reaches: every includer's sites are redone
        ("common/platform.h", '\n#define BROTLI_AM_PORT 4242\n'),
        # a source file gains a socket call whose port is a constant of a header it reaches
        ("enc/encode.c", SOCKET + "int am_b(int fd) { return bind(fd, 0, 0); }\n"),
        ("dec/decode.c", SOCKET + 'int am_s(int f) { return send(f, "x", 1, 0); }\n'),
    ],
    ids=lambda e: e[0],
)
def test_edits_of_a_real_c_library_patch_to_the_whole_tree(
    brotli: dict[str, FileFacts], edited: tuple[str, str]
) -> None:
    path, tail = edited
    sources = _brotli()
    after = dict(brotli, **{f.path: f for f in tree_facts({path: sources[path] + tail})})
    _same(*_patched_facts(brotli, after))
    encode = sources["enc/encode.c"] + EDITS[0]
    both = dict(after, **{f.path: f for f in tree_facts({"enc/encode.c": encode})})
    _same(*_patched_facts(after, both))
