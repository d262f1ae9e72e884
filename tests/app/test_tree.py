"""Incremental diffs (app/tree.py): a head state patched from the base's kept state gives a
report byte-identical to one measured from scratch (``--no-cache``), on real histories:
the study's subjects committed stage after stage and edited in the work tree, in the index
and between commits -- contents changed, files added, removed, renamed, turned into links,
left untracked or ignored."""

from __future__ import annotations

import json
import os
import random
import shutil
from pathlib import Path

import pytest

from archmetrics.app.diff import run_diff
from archmetrics.app.diff_options import DiffRequest
from archmetrics.cli import main
from archmetrics.config import load_settings
from archmetrics.sources.cache import FactsCache
from tests.app.test_diff import _Steps
from tests.gitrepo import GitRepo

STUDY = Path(__file__).resolve().parents[2] / "fixtures" / "study"
SUBJECTS = ("wdb/p2p", "pragmatics/soa", "as-described/wdb/player")
TAILS = {
    ".c": '\n#include <sys/socket.h>\nint am_send(int fd) { return send(fd, "x", 1, 0) + 2; }\n',
    ".h": "\n#define AM_PORT 4242\n",
    ".py": "\n\ndef am_link(bus):\n    if bus:\n        return bus.request('wdb', 'query', {})\n",
    # a router's rules (configuration links, p. 110): one more route
    ".toml": '\n[[rules]]\nname = "am"\noperation = "am"\n[[rules.to]]\nkind = "send"\n'
    'service = "muri.am"\noperation = "am"\n',
}


def _stages(subject: str) -> list[Path]:
    return [p for p in sorted((STUDY / subject).iterdir()) if p.is_dir()]


def _load(repo: GitRepo, stage: Path) -> None:
    """The work tree made the stage's files (the rest removed)."""
    for child in repo.root.iterdir():
        if child.name != ".git":
            shutil.rmtree(child) if child.is_dir() else child.unlink()
    shutil.copytree(stage, repo.root, dirs_exist_ok=True)


def _json(repo: GitRepo, base: str, head: str, *extra: str) -> bytes:
    out = repo.root.parent / "out.json"
    command = ["diff", "-C", str(repo.root), "--base", base, "--head", head, "-q"]
    assert main([*command, "--format", "json", "-o", str(out), *extra]) == 0
    return out.read_bytes()


def _same_as_scratch(repo: GitRepo, base: str, head: str, cache: Path) -> bytes:
    kept = _json(repo, base, head, "--cache-path", str(cache))
    assert kept == _json(repo, base, head, "--no-cache")
    return kept


@pytest.fixture(params=SUBJECTS)
def history(request: pytest.FixtureRequest, tmp_path: Path) -> GitRepo:
    """A subject's stages as commits v0, v1, v2 of a real repository."""
    repo = GitRepo(tmp_path / "repo")
    for i, stage in enumerate(_stages(request.param)):
        _load(repo, stage)
        repo.commit(stage.name, tag=f"v{i}")
    return repo


def _sources(repo: GitRepo) -> list[Path]:
    return sorted(
        p for p in repo.root.rglob("*")
        if p.suffix in TAILS and ".git" not in p.parts and p.is_file() and not p.is_symlink()
        and (p.suffix != ".toml" or p.name == "rules.toml")
    )  # fmt: skip


def _edit(repo: GitRepo, rng: random.Random) -> None:
    """One edit of the kinds a work tree sees."""
    files = _sources(repo)
    target = rng.choice(files)
    kind = rng.randrange(7)
    if kind <= 2:
        with target.open("a") as f:
            f.write(TAILS[target.suffix])
    elif kind == 3:  # a new untracked file (a router's rules in a folder of their own)
        tag = rng.randrange(1000)
        new = target.parent / f"am_new_{tag}{target.suffix}"
        if target.suffix == ".toml":
            new = target.parent / f"am_{tag}" / "rules.toml"
            new.parent.mkdir(exist_ok=True)
        new.write_text(target.read_text() + TAILS[target.suffix])
    elif kind == 4:  # a removal
        target.unlink()
    elif kind == 5:  # a rename (staged, so that git pairs it)
        old = target.relative_to(repo.root)
        repo.git("mv", str(old), f"{old}.moved{target.suffix}")
    else:  # a file made a symbolic link
        target.unlink()
        os.symlink(files[0].name, target)


@pytest.mark.parametrize("seed", range(2))
def test_edits_of_the_work_tree_diff_as_from_scratch(
    history: GitRepo, tmp_path: Path, seed: int
) -> None:
    rng = random.Random(seed)
    history.git("checkout", "-q", "v1")
    cache = tmp_path / "cache.sqlite3"
    _same_as_scratch(history, "HEAD", "WORKTREE", cache)  # the base state kept
    for step in range(3):
        _edit(history, rng)
        _same_as_scratch(history, "HEAD", "WORKTREE", cache)
        if step == 1:
            _same_as_scratch(history, "HEAD", "INDEX", cache)
            history.git("add", "-A")
            _same_as_scratch(history, "HEAD", "INDEX", cache)
            _same_as_scratch(history, "v0", "WORKTREE", cache)


def test_commits_diff_as_from_scratch_along_a_history(history: GitRepo, tmp_path: Path) -> None:
    cache = tmp_path / "cache.sqlite3"
    for base, head in (("v0", "v1"), ("v1", "v2"), ("v0", "v2"), ("v2", "v0")):
        _same_as_scratch(history, base, head, cache)
    history.git("checkout", "-q", "v2")
    rng = random.Random(7)
    for i in range(3):
        _edit(history, rng)
        history.git("add", "-A")
        history.commit(f"edit {i}", tag=f"e{i}")
        _same_as_scratch(history, "v2", f"e{i}", cache)
        _same_as_scratch(history, f"e{i}", "v2", cache)


def test_an_ignored_file_stays_out_and_a_staged_one_counts(repo: GitRepo, tmp_path: Path) -> None:
    _load(repo, _stages("wdb/p2p")[0])
    repo.commit("base", tag="v0")
    cache = tmp_path / "cache.sqlite3"
    _same_as_scratch(repo, "HEAD", "WORKTREE", cache)
    (repo.root / ".gitignore").write_text("ignored.c\n")
    (repo.root / "ignored.c").write_text("int ignored(int x) { return x ? 1 : 2; }\n")
    (repo.root / "staged.c").write_text("int staged(int x) { return x ? 1 : 2; }\n")
    repo.git("add", "staged.c")
    (repo.root / "staged.c").write_text("int staged(int x) { return x ? 3 : 4; }\n")  # and edited
    report = _same_as_scratch(repo, "HEAD", "WORKTREE", cache)
    assert b'"ignored' not in report
    assert b'"staged.c"' in report
    assert b'"staged.c"' in _same_as_scratch(repo, "HEAD", "INDEX", cache)


def test_a_diff_whose_base_state_is_kept_patches_it(repo: GitRepo, tmp_path: Path) -> None:
    """The second diff after an edit asks git what differs and parses the edited file
    alone (the steps name it); its report equals one from scratch."""
    _load(repo, _stages("pragmatics/soa")[-1])
    repo.commit("base", tag="v0")
    path = tmp_path / "cache.sqlite3"
    settings = load_settings(repo.root)
    with FactsCache(path) as cache:
        run_diff(DiffRequest(repo.root, "HEAD", "WORKTREE", settings, jobs=1), None, cache)
    target = _sources(repo)[0]
    with target.open("a") as f:
        f.write(TAILS[target.suffix])
    steps = _Steps()
    with FactsCache(path) as cache:
        run_diff(DiffRequest(repo.root, "HEAD", "WORKTREE", settings, jobs=1), steps, cache)
    assert "asking git what differs from HEAD to WORKTREE" in steps.steps
    parsed = [s for s in steps.steps if s.startswith("parsing") and s != "parsing 0"]
    assert parsed == ["parsing 1"]  # the edited file; its base facts are in the cache
    _same_as_scratch(repo, "HEAD", "WORKTREE", path)


def test_an_edited_routing_file_patches_its_links(repo: GitRepo, tmp_path: Path) -> None:
    """A router's rules file is configuration with links (p. 110): one more route in the
    work tree is one more dynamic efferent link, found by the patch as from scratch."""
    _load(repo, _stages("pragmatics/soa")[-1])
    repo.commit("base", tag="v0")
    cache = tmp_path / "cache.sqlite3"
    _same_as_scratch(repo, "HEAD", "WORKTREE", cache)
    rules = repo.root / "pragmatics" / "rules.toml"
    with rules.open("a") as f:
        f.write(TAILS[".toml"])
    report = json.loads(_same_as_scratch(repo, "HEAD", "WORKTREE", cache))
    (element,) = [e for e in report["elements"] if "pragmatics/rules.toml" in e["files"]]
    assert element["post"]["d_e"] == element["pre"]["d_e"] + 1
    assert element["status"] == "modified"
