"""Settings to coupling options and rule packs, shared by every use case that measures coupling."""

from __future__ import annotations

import copy
import hashlib
import os
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from archmetrics.config import Settings
from archmetrics.coupling import CouplingOptions, CouplingReport, load_rule_packs, measure_coupling
from archmetrics.coupling.loader import MAX_PACK_BYTES, PackBytes, PackSource
from archmetrics.coupling.rules import RulePackError, RuleSet
from archmetrics.facts import FileFacts
from archmetrics.globs import BadPattern, compile_glob, normalize_path
from archmetrics.sources.checkout import Checkout, open_checkout
from archmetrics.sources.revision_files import repository_path

if TYPE_CHECKING:
    from pathspec import GitIgnoreSpec


def coupling_options(settings: Settings) -> CouplingOptions:
    c = settings.coupling
    return CouplingOptions(
        ignore_includes=c.ignore_includes,
        ignore_imports=c.ignore_imports,
        include_dirs=c.include_dirs,
        per_file=c.per_file,
        group=c.group,
    )


def rule_set(settings: Settings, root: Path, checkout: Checkout | None = None) -> RuleSet:
    """The built-in packs, the configured ones (paths relative to the root: files on disk,
    or the blobs of the revision the settings were read from) and plugins; a configuration
    rule's bad ``files`` glob fails here, naming the pack, rule and key. ``checkout``: the
    repository at ``root``, if the caller opened it already."""
    configured = settings.coupling.rule_packs
    sources: list[PackSource]
    if settings.revision is None:
        sources = [pack_path(root, p) for p in configured]
    else:
        checkout = checkout or open_checkout(root)
        sources = [pack_at(checkout, settings.revision, p) for p in configured]
    packs = load_rule_packs(sources)
    configuration_files(packs)
    return packs


def pack_at(checkout: Checkout, revision: str, text: str) -> PackBytes:
    """A configured rule pack as the blob at ``revision`` holds it (inside the repository,
    a regular file: never a symbolic link)."""
    path = repository_path(text)
    if path is None:
        raise RulePackError(
            text, None, None, "a configured rule pack must be inside the repository"
        )
    data = checkout.file_at(revision, path, MAX_PACK_BYTES)
    if data is None:
        raise RulePackError(f"{revision}:{path}", None, None, "no such file at that revision")
    return PackBytes(f"{revision}:{path}", data)


_DIGESTS: dict[int, tuple[RuleSet, str]] = {}


def packs_digest(packs: RuleSet) -> str:
    """A digest of the rule packs in force, made once per loaded set: a key a cached record
    depends on (a tree's state, each file's link sites) names the packs by it. Packs read
    from text are named by their names, sources and the SHA-256 of their text (the keys
    also hold archmetrics's code, which decides what a text parses to); a pack made in
    memory by its ``repr``, every rule field by field (the shipped packs' ``repr`` took
    90 ms, every diff)."""
    known = _DIGESTS.get(id(packs))
    if known is None or known[0] is not packs:
        parts = [
            f"text\0{pack.name}\0{pack.source}\0{pack.digest}" if pack.digest else f"repr\0{pack!r}"
            for pack in packs.packs
        ]
        known = (packs, hashlib.sha256("\0\0".join(parts).encode()).hexdigest())
        _DIGESTS.clear()  # one set of packs per command: keep the last
        _DIGESTS[id(packs)] = known
    return known[1]


class ConfigurationFiles:
    """A path's configuration format, by the ``files`` globs of the packs' configuration
    rules (the first rule, in load order, that names the path decides), or None: which files
    a scan or diff reads as configuration (docs/metrics.md, "Configuration links"). A rule
    with ``within`` (``package.xml``) names files only in a tree holding that file (a ROS
    workspace; a launch file or plugin description need not sit in a package of its own):
    :meth:`in_tree` says which folders hold it, from the tree's paths; until then such
    rules name nothing."""

    def __init__(self, packs: RuleSet) -> None:
        self.globs: list[tuple[GitIgnoreSpec, str, str | None]] = []
        for pack in packs.packs:
            for rule in pack.configuration:
                for glob in rule.files:
                    try:
                        self.globs.append((compile_glob(glob), rule.format, rule.within))
                    except BadPattern as error:
                        raise RulePackError(pack.source, rule.id, "files", str(error)) from None
        self.markers = frozenset(w for _, _, w in self.globs if w)
        self.folders: dict[str, frozenset[str]] = {}

    def in_tree(self, paths: Iterable[str]) -> ConfigurationFiles:
        """These rules for the tree of ``paths``: the folders holding each marker known."""
        if not self.markers:
            return self
        bound = copy.copy(self)
        found: dict[str, set[str]] = {marker: set() for marker in self.markers}
        for path in paths:
            folder, _, name = path.rpartition("/")
            if name in found:
                found[name].add(folder)
        bound.folders = {marker: frozenset(f) for marker, f in found.items()}
        return bound

    def __call__(self, path: str) -> str | None:
        if not self.globs:
            return None
        clean = normalize_path(path)
        for glob, fmt, within in self.globs:
            if glob.match_file(clean) and (within is None or self._inside(clean, within)):
                return fmt
        return None

    def _inside(self, path: str, marker: str) -> bool:
        """Whether the tree of ``path`` holds ``marker`` (in any folder)."""
        return bool(self.folders.get(marker))


def configuration_files(packs: RuleSet) -> ConfigurationFiles:
    """Which files the packs read as configuration, and in which format (ConfigurationFiles)."""
    return ConfigurationFiles(packs)


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


def measure(files: Sequence[FileFacts], settings: Settings, packs: RuleSet) -> CouplingReport:
    """Coupling of the elements the readable ``files`` make up, under the rule ``packs``."""
    readable = [f for f in files if f.parsed]
    return measure_coupling(readable, coupling_options(settings), packs)
