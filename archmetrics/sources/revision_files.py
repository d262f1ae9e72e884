"""One file of a revision or of the index, read by its path: the configuration and the rule
packs a diff takes from its base revision (docs/security.md, "Whose configuration").

The file is looked up in git's tree (``ls-tree``) or index (``ls-files``), with literal
paths (no glob in a configured name matches other files); a symbolic link or a submodule
there is refused, never followed, and the blob's size is asked of git before it is read.
"""

from __future__ import annotations

import posixpath
from typing import TYPE_CHECKING

from archmetrics.sources.snapshot import INDEX, SourceError

if TYPE_CHECKING:
    import git as gitpython


def repository_path(text: str) -> str | None:
    """``text`` (a path relative to the repository's top) as git names it, or None when it
    leads out of the repository (absolute, or ``..`` past the top)."""
    clean = posixpath.normpath(text.replace("\\", "/"))
    if clean.startswith(("/", "../")) or clean in ("..", ".", ""):
        return None
    return clean


def _entry(repo: gitpython.Repo, spec: str, path: str) -> tuple[str, str] | None:
    """(mode, blob) of ``path`` at ``spec`` (a commit id or INDEX), None if it has none."""
    from git.exc import GitCommandError

    from archmetrics.sources.giterrors import explain

    if spec == INDEX:
        args = ["ls-files", "-s", "-z", "--", path]
    else:
        args = ["ls-tree", "-z", "--full-tree", spec, "--", path]
    try:
        out: str = repo.git.execute(
            ["git", "--literal-pathspecs", *args], strip_newline_in_stdout=False
        )
    except GitCommandError as error:
        raise explain(repo, error, f"{spec}:{path}") from error
    for entry in out.split("\0"):
        meta, _, name = entry.partition("\t")
        if name != path:
            continue
        fields = meta.split(" ")
        if spec == INDEX and fields[2] not in ("0", "2"):
            continue  # an unmerged entry: "ours" (stage 2) is read, as IndexSnapshot does
        return fields[0], (fields[1] if spec == INDEX else fields[2])
    return None


def file_at(
    repo: gitpython.Repo, spec: str, path: str, limit: int, label: str | None = None
) -> bytes | None:
    """The bytes of the regular file ``path`` at ``spec`` (a commit id or INDEX), or None
    when there is no file there; SourceError for a symbolic link, a submodule, a folder or a
    blob over ``limit`` bytes (its size asked first: it is not read). Errors call the
    revision ``label`` (as the user named it), or ``spec``."""
    found = _entry(repo, spec, path)
    if found is None:
        return None
    mode, blob = found
    where = f"{label or spec}:{path}"
    if mode == "120000":
        raise SourceError(f"{where}: a symbolic link; not followed")
    if mode not in ("100644", "100755"):
        raise SourceError(f"{where}: not a file (mode {mode}); not read")
    size = int(repo.odb.info(bytes.fromhex(blob)).size)
    if size > limit:
        raise SourceError(f"{where}: larger than {limit} bytes; not read")
    data: bytes = repo.odb.stream(bytes.fromhex(blob)).read()
    return data
