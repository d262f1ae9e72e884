"""Loading rule packs: the only file reading in coupling.

Packs come from three places, in this order: the built-in packs shipped in
``archmetrics/coupling/rules/*.toml``, the paths a user configures, and the
``archmetrics.rulepacks`` entry-point group (each entry point loads to a path, a
:class:`~importlib.resources.abc.Traversable`, a list of them, or a callable returning them).
"""

from __future__ import annotations

import dataclasses
import hashlib
import os
import tomllib
from collections.abc import Iterable
from dataclasses import dataclass
from importlib import metadata, resources
from importlib.resources.abc import Traversable

from archmetrics.coupling.rules import RulePack, RulePackError, RuleSet
from archmetrics.coupling.validate import parse_pack
from archmetrics.reading import TooLarge, read_regular

ENTRY_POINT_GROUP = "archmetrics.rulepacks"



@dataclass(frozen=True, slots=True)
class PackBytes:
    """A pack read already, e.g. from a git revision's blob: ``name`` is what errors and
    reports call it (``v1:packs/ours.toml``)."""

    name: str
    data: bytes

    def __str__(self) -> str:
        return self.name


PackSource = str | os.PathLike[str] | Traversable | PackBytes


def builtin_pack_files() -> tuple[Traversable, ...]:
    """The rule packs shipped with archmetrics, by file name."""
    folder = resources.files("archmetrics.coupling").joinpath("rules")
    return tuple(sorted((f for f in folder.iterdir() if f.name.endswith(".toml")),
                        key=lambda f: f.name))  # fmt: skip


def load_rule_pack(source: PackSource) -> RulePack:
    """Read and validate one pack; any problem is a :class:`RulePackError` naming the file."""
    name = str(source)
    try:
        if isinstance(source, str | os.PathLike):  # a file, not a resource in a package
            text = read_regular(source, MAX_PACK_BYTES).decode("utf-8")
        elif isinstance(source, PackBytes):
            if len(source.data) > MAX_PACK_BYTES:
                raise TooLarge(name, len(source.data), MAX_PACK_BYTES)
            text = source.data.decode("utf-8")
        else:
            text = source.read_text("utf-8")
    except TooLarge:
        raise RulePackError(name, None, None, f"larger than {MAX_PACK_BYTES} bytes") from None
    except (OSError, UnicodeDecodeError) as error:
        raise RulePackError(name, None, None, f"cannot read the pack: {error}") from error
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise RulePackError(name, None, None, f"not valid TOML: {error}") from error
    except RecursionError:
        raise RulePackError(name, None, None, "not valid TOML: nested too deeply") from None
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()
    return dataclasses.replace(parse_pack(data, name), digest=digest)


MAX_PACK_BYTES = 1 << 20
"""A rule pack larger than this (1 MiB) is refused: packs are a few kilobytes."""


def _is_source(value: object) -> bool:
    return isinstance(value, str | os.PathLike | Traversable)


def plugin_pack_sources() -> tuple[PackSource, ...]:
    """Pack sources announced by installed distributions; type-checked on load."""
    found: list[PackSource] = []
    for entry in metadata.entry_points(group=ENTRY_POINT_GROUP):
        value = entry.load()
        if callable(value) and not _is_source(value):
            value = value()
        items = [value] if _is_source(value) else value
        if not isinstance(items, Iterable) or not all(_is_source(i) for i in items):
            raise TypeError(
                f"entry point {entry.name!r} in group {ENTRY_POINT_GROUP} must give rule-pack"
                f" paths or Traversables, got {type(value).__name__}"
            )
        found.extend(items)
    return tuple(found)


def load_rule_packs(
    extra_paths: Iterable[PackSource] = (), *, builtin: bool = True, plugins: bool = True
) -> RuleSet:
    """The rule set in force: built-in packs, then ``extra_paths``, then plugin packs.

    Two packs with the same name are an error (rule ids are qualified by the pack name).
    """
    sources: list[PackSource] = list(builtin_pack_files()) if builtin else []
    sources.extend(extra_paths)
    if plugins:
        sources.extend(plugin_pack_sources())
    packs: list[RulePack] = []
    for source in sources:
        pack = load_rule_pack(source)
        for other in packs:
            if other.name == pack.name:
                problem = f"pack {pack.name!r} is already loaded from {other.source}"
                raise RulePackError(pack.source, None, "pack.name", problem)
        packs.append(pack)
    return RuleSet(tuple(packs))
