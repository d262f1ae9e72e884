"""The repositories of the history benchmark: clones of real ones, the synthetic 40,000-commit
one, and the one-file commits picked from a history (benchmarks/history_bench.py)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import corpus
from corpus import BenchError

MIRRORS = Path("/work/.mirror")
DEFAULT_REPOS = {
    "libuv": ("libuv+libuv", "https://github.com/libuv/libuv"),
    "lua": ("lua+lua", "https://github.com/lua/lua"),
}
DEFAULT_PYTHON = ("click", "pallets+click", "https://github.com/pallets/click")
SYNTHETIC_FILES = 8  # C files, in two folders (two elements that call each other)
SYNTHETIC_FUNCTIONS = 12  # functions per file


def default_source(mirror: str, url: str) -> str:
    """The local mirror's path if it is here, else the public URL."""
    path = MIRRORS / mirror / "repo"
    return str(path) if path.is_dir() else url


def parse_repo(text: str) -> tuple[str, str]:
    """``NAME=PATH_OR_URL`` as (name, source)."""
    name, _, source = text.partition("=")
    if not name or not source or "/" in name:
        raise BenchError(f"--repo wants NAME=PATH_OR_URL, not {text!r}")
    return name, source


def clone(source: str, folder: Path) -> Path:
    """A working clone of ``source`` in ``folder`` (made once, then reused as it is)."""
    if (folder / ".git").is_dir():
        return folder
    if folder.exists():
        shutil.rmtree(folder)
    folder.parent.mkdir(parents=True, exist_ok=True)
    print(f"  cloning {source} into {folder}", flush=True)
    corpus.git(folder.parent, "clone", "-q", source, str(folder))
    return folder


def first_parents(repo: Path, rev: str = "HEAD", count: int | None = None) -> list[str]:
    """The first-parent commits of ``rev``, newest first (at most ``count``)."""
    limit = [f"--max-count={count}"] if count else []
    return corpus.git(repo, "rev-list", "--first-parent", *limit, rev).split()


def one_file_commits(repo: Path, count: int | None, wanted: int) -> list[str]:
    """The newest ``wanted`` first-parent commits (within the newest ``count``) that change
    exactly one file, a measured one (corpus.MEASURED), and have a parent: a
    deterministic pick, the same on every run of the same repository."""
    commits = first_parents(repo, "HEAD", count)
    picked: list[str] = []
    for commit in commits[:-1]:  # the oldest may be a root commit
        changed = corpus.git(repo, "diff-tree", "--no-commit-id", "--name-only", "-r",
                             f"{commit}^", commit).split()  # fmt: skip
        if len(changed) == 1 and changed[0].endswith(corpus.MEASURED):
            picked.append(commit)
            if len(picked) == wanted:
                break
    return picked


def synthetic_repository(folder: Path, commits: int) -> Path:
    """A repository of ``commits`` small commits to a few C files, made with ``git
    fast-import`` (deterministic: the same bytes, hence the same ids, every time). Commit k
    rewrites one function of one file; the files of ``core`` call those of ``io``."""
    marker = folder / ".git" / f"synthetic-{commits}"
    if marker.exists():
        return folder
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    corpus.git(folder, "init", "-q")
    versions = [[0] * SYNTHETIC_FUNCTIONS for _ in range(SYNTHETIC_FILES)]
    stream = bytearray()
    for k in range(commits):
        file, function = k % SYNTHETIC_FILES, (k // SYNTHETIC_FILES) % SYNTHETIC_FUNCTIONS
        versions[file][function] = k
        data = _c_file(file, versions[file]).encode()
        message = f"synthetic commit {k}\n".encode()
        stream += b"commit refs/heads/main\n"
        stream += f"mark :{k + 1}\n".encode()
        stream += f"committer bench <bench@localhost> {1_600_000_000 + 60 * k} +0000\n".encode()
        stream += b"data %d\n%s" % (len(message), message)
        if k:
            stream += f"from :{k}\n".encode()
        paths = range(SYNTHETIC_FILES) if k == 0 else (file,)
        for each in paths:
            text = data if each == file else _c_file(each, versions[each]).encode()
            stream += f"M 100644 inline {_c_path(each)}\ndata {len(text)}\n".encode()
            stream += text + b"\n"
    done = subprocess.run(["git", "fast-import", "--quiet"], cwd=folder, input=bytes(stream),
                          capture_output=True, timeout=600)  # fmt: skip
    if done.returncode:
        raise BenchError(f"git fast-import failed: {done.stderr.decode(errors='replace')}")
    corpus.git(folder, "symbolic-ref", "HEAD", "refs/heads/main")
    corpus.git(folder, "checkout", "-q", "-f", "main")
    marker.touch()
    return folder


def _c_path(file: int) -> str:
    return f"{'core' if file % 2 else 'io'}/unit{file}.c"


def _c_file(file: int, versions: list[int]) -> str:
    """File ``file``'s text: its functions, each returning its version; a ``core`` file's
    functions also call the ``io`` file before it."""
    lines = [f'#include "unit{file - 1}.h"' if file % 2 else "#include <stddef.h>", ""]
    for index, version in enumerate(versions):
        body = f"    int x = x0 + {version};\n"
        if file % 2:
            body += f"    x += unit{file - 1}_f{index}(x);\n"
        body += f"    if (x > {index}) {{\n        x -= {index};\n    }}\n    return x;\n"
        lines.append(f"int unit{file}_f{index}(int x0)\n{{\n{body}}}\n")
    return "\n".join(lines)
