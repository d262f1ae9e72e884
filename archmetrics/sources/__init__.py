"""The edges: where file versions come from (a directory, a git revision, the index, the cache).

Everything here reads; nothing here changes a repository, its index or its working tree.
"""

from archmetrics.sources.checkout import open_snapshot
from archmetrics.sources.snapshot import (
    EMPTY,
    INDEX,
    WORKTREE,
    Snapshot,
    SourceError,
    SourceFile,
)

__all__ = ["EMPTY", "INDEX", "WORKTREE", "Snapshot", "SourceError", "SourceFile", "open_snapshot"]
