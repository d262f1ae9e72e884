"""The benchmark corpus: two releases of a PyPI package's sdist, unpacked, as a git history.

``pip download`` cannot fetch a meson-python sdist (numpy's) without building it: pip prepares
the metadata of every sdist it downloads, and for numpy that is a full compile (pypa/pip#1884,
#11039). So the sdist is found through the registry's own index API (PEP 691 JSON, the pages
pip reads), downloaded from the URL the index gives, and checked against the index's sha256.
Everything lands in ``benchmarks/.work`` and is reused when present.
"""

from __future__ import annotations

import hashlib
import json
import os
import random
import shutil
import subprocess
import tarfile
import urllib.error
import urllib.request
from dataclasses import dataclass
from pathlib import Path

INDEX = "https://pypi.org/simple"
NET_TIMEOUT = 60.0
GIT_TIMEOUT = 600.0
# Endings archmetrics and lizard both read as C/C++ (lizard_languages/clike.py CLikeReader.ext).
CFAMILY = (".c", ".cc", ".cpp", ".cxx", ".h", ".hh", ".hpp")
PYTHON = (".py",)
# Every ending archmetrics measures by default (archmetrics/parsers/registry.py).
MEASURED = (*CFAMILY, ".c++", ".hxx", ".h++", ".ipp", ".inl", *PYTHON)


class BenchError(Exception):
    """A step of the benchmark could not run; the message says which and what to do."""


@dataclass(frozen=True, slots=True)
class Tree:
    """A folder of source files: how many and how many bytes."""

    path: Path
    files: int
    bytes: int


def _index_entry(index: str, package: str, version: str) -> dict[str, object]:
    url = f"{index.rstrip('/')}/{package}/"
    request = urllib.request.Request(url, headers={"Accept": "application/vnd.pypi.simple.v1+json"})
    try:
        with urllib.request.urlopen(request, timeout=NET_TIMEOUT) as response:
            document = json.load(response)
    except (urllib.error.URLError, TimeoutError, json.JSONDecodeError) as error:
        raise BenchError(f"cannot read the index page {url}: {error}") from error
    wanted = f"{package}-{version}.tar.gz"
    for entry in document.get("files", []):
        if entry.get("filename") == wanted:
            return dict(entry)
    raise BenchError(f"{url} lists no sdist {wanted}; choose other releases with --releases")


def fetch_sdist(package: str, version: str, folder: Path, index: str = INDEX) -> Path:
    """The sdist of ``package==version`` in ``folder``, downloaded and verified if missing."""
    target = folder / f"{package}-{version}.tar.gz"
    if target.is_file():
        return target
    folder.mkdir(parents=True, exist_ok=True)
    entry = _index_entry(index, package, version)
    url, hashes = str(entry["url"]), entry.get("hashes")
    expected = hashes.get("sha256") if isinstance(hashes, dict) else None
    partial = target.with_suffix(".part")
    print(f"downloading {url}", flush=True)
    try:
        with (
            urllib.request.urlopen(url, timeout=NET_TIMEOUT) as response,
            partial.open("wb") as out,
        ):
            shutil.copyfileobj(response, out)
    except (urllib.error.URLError, TimeoutError, OSError) as error:
        raise BenchError(
            f"cannot download {url}: {error}; put the sdist at {target} by hand and run again"
        ) from error
    digest = hashlib.sha256(partial.read_bytes()).hexdigest()
    if expected and digest != expected:
        partial.unlink()
        raise BenchError(f"{url}: sha256 {digest} is not the index's {expected}")
    partial.replace(target)
    return target


def unpack(sdist: Path, folder: Path) -> Path:
    """The sdist's top folder, unpacked under ``folder`` (once; a marker says it is complete)."""
    name = sdist.name.removesuffix(".tar.gz")
    top, marker = folder / name, folder / f"{name}.unpacked"
    if marker.is_file() and top.is_dir():
        return top
    shutil.rmtree(top, ignore_errors=True)
    folder.mkdir(parents=True, exist_ok=True)
    try:
        with tarfile.open(sdist) as archive:
            archive.extractall(folder, filter="data")
    except (tarfile.TarError, OSError) as error:
        raise BenchError(f"{sdist}: cannot unpack: {error}; delete it to download again") from error
    if not top.is_dir():
        raise BenchError(f"{sdist}: expected a top folder {name}/ in the archive")
    marker.write_text("ok\n")
    return top


def source_files(root: Path, endings: tuple[str, ...]) -> list[Path]:
    """Files under ``root`` with one of ``endings``, sorted, outside hidden folders."""
    found = []
    for folder, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        for name in sorted(files):
            if not name.startswith(".") and name.lower().endswith(endings):
                found.append(Path(folder) / name)
    return found


def git(repo: Path, *args: str) -> str:
    """Run git in ``repo`` with a fixed identity; BenchError with its stderr when it fails."""
    command = ["git", "-c", "user.name=bench", "-c", "user.email=bench@localhost", *args]
    try:
        done = subprocess.run(
            command, cwd=repo, capture_output=True, text=True, timeout=GIT_TIMEOUT, check=True
        )
    except subprocess.CalledProcessError as error:
        raise BenchError(
            f"git {' '.join(args)} failed in {repo}: {error.stderr.strip()}"
        ) from error
    except subprocess.TimeoutExpired as error:
        raise BenchError(f"git {' '.join(args)} timed out in {repo}") from error
    return done.stdout


def _init(repo: Path) -> None:
    repo.mkdir(parents=True, exist_ok=True)
    if not (repo / ".git").exists():
        git(repo, "init", "-q")
        git(repo, "config", "core.autocrlf", "false")


def make_history(releases: list[tuple[str, Path]], repo: Path) -> Path:
    """A git repository whose tags are the releases, committed in order (all files, forced
    past any .gitignore the sdist carries). Reused when every tag is already there."""
    _init(repo)
    tags = set(git(repo, "tag", "--list").split())
    if all(tag in tags for tag, _ in releases):
        return repo
    shutil.rmtree(repo)
    _init(repo)
    for tag, tree in releases:
        for entry in repo.iterdir():
            if entry.name != ".git":
                shutil.rmtree(entry) if entry.is_dir() else entry.unlink()
        shutil.copytree(tree, repo, dirs_exist_ok=True, symlinks=True)
        git(repo, "add", "--all", "--force", ".")
        git(repo, "commit", "-q", "--no-verify", "--allow-empty", "-m", f"release {tag}")
        git(repo, "tag", tag)
    return repo


def subset_tree(
    root: Path, endings: tuple[str, ...], dest: Path, fraction: float = 1.0, seed: int = 7
) -> Tree:
    """A copy (hard links where possible) of the files of ``root`` with ``endings``, one file
    per distinct content (lizard silently skips duplicates; this makes every tool see the same
    set), keeping a seeded random ``fraction`` of them. The copy is made a git repository of
    its own so archmetrics reads it as a working tree and not as part of an outer repository."""
    chosen, seen = [], set()
    for path in source_files(root, endings):
        digest = hashlib.md5(path.read_bytes()).hexdigest()
        if digest not in seen:
            seen.add(digest)
            chosen.append(path)
    if fraction < 1.0:  # a prefix of one seeded shuffle: smaller subsets nest in larger ones
        shuffled = random.Random(seed).sample(chosen, len(chosen))
        chosen = sorted(shuffled[: round(len(chosen) * fraction)])
    shutil.rmtree(dest, ignore_errors=True)
    for path in chosen:
        target = dest / path.relative_to(root)
        target.parent.mkdir(parents=True, exist_ok=True)
        try:
            os.link(path, target)
        except OSError:
            shutil.copy2(path, target)
    _init(dest)
    return Tree(dest, len(chosen), sum(p.stat().st_size for p in chosen))


def describe_sources(root: Path) -> dict[str, int]:
    """How many files of each measured ending ``root`` holds, for the record."""
    counts: dict[str, int] = {}
    for path in source_files(root, MEASURED):
        ending = path.suffix.lower()
        counts[ending] = counts.get(ending, 0) + 1
    return dict(sorted(counts.items(), key=lambda item: -item[1]))
