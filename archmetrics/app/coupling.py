"""Settings to coupling options and rule packs, shared by every use case that measures coupling."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from archmetrics.config import Settings
from archmetrics.coupling import CouplingOptions, CouplingReport, load_rule_packs, measure_coupling
from archmetrics.coupling.rules import RulePackError, RuleSet
from archmetrics.facts import FileFacts


def coupling_options(settings: Settings) -> CouplingOptions:
    c = settings.coupling
    return CouplingOptions(
        ignore_includes=c.ignore_includes,
        ignore_imports=c.ignore_imports,
        include_dirs=c.include_dirs,
        per_file=c.per_file,
    )


def rule_set(settings: Settings, root: Path) -> RuleSet:
    """The built-in packs, the configured ones (paths relative to the root) and plugins."""
    return load_rule_packs([pack_path(root, p) for p in settings.coupling.rule_packs])


def pack_path(root: Path, text: str) -> Path:
    """A configured rule pack: a file inside the repository (the configuration is the
    repository's word, so it may not make archmetrics read the runner's other files)."""
    real_root = os.path.realpath(root)
    path = os.path.realpath(root / text)
    if os.path.commonpath([real_root, path]) != real_root:
        raise RulePackError(
            text, None, None, "a configured rule pack must be inside the repository"
        )
    return Path(path)


def measure(files: Sequence[FileFacts], settings: Settings, root: Path) -> CouplingReport:
    """Coupling of the elements the readable ``files`` make up."""
    readable = [f for f in files if f.parsed]
    return measure_coupling(readable, coupling_options(settings), rule_set(settings, root))
