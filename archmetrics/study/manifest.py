"""A study subject's manifest: its stages and which paths are base, new and framework."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any


class ManifestError(ValueError):
    """A manifest that cannot be used; the message names the file and the key."""


@dataclass(frozen=True, slots=True)
class Manifest:
    """One approach to one subject, e.g. World Database on SOA, in stages."""

    path: Path  # the folder holding manifest.toml and one folder per stage
    subject: str
    approach: str
    title: str
    thesis_pages: str
    stages: tuple[str, ...]
    locations: tuple[tuple[str, tuple[str, ...]], ...]  # in the manifest's order
    exclude: tuple[str, ...]
    exclude_generated: bool = True  # [exclude] generated = false counts generated files too

    def stage_dir(self, stage: str) -> Path:
        return self.path / stage


def _strings(value: Any, where: str) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ManifestError(f"{where}: expected a list of strings")
    return tuple(value)


def _flag(value: Any, where: str) -> bool:
    if not isinstance(value, bool):
        raise ManifestError(f"{where}: expected true or false")
    return value


def _text(table: dict[str, Any], key: str, where: str) -> str:
    value = table.get(key)
    if not isinstance(value, str) or not value:
        raise ManifestError(f"{where}: '{key}' must be a non-empty string")
    return value


def load_manifest(folder: Path) -> Manifest:
    """The manifest in ``folder``; every stage it names must be a folder beside it."""
    file = folder / "manifest.toml"
    try:
        table = tomllib.loads(file.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as error:
        raise ManifestError(f"{file}: cannot read: {error}") from error
    where = str(file)
    stages = _strings(table.get("stages"), f"{where}: stages")
    for stage in stages:
        if not (folder / stage).is_dir():
            raise ManifestError(f"{where}: stage {stage!r} has no folder {folder / stage}")
    locations = table.get("locations", {})
    if not isinstance(locations, dict):
        raise ManifestError(f"{where}: [locations] must be a table")
    exclude = table.get("exclude", {})
    return Manifest(
        path=folder,
        subject=_text(table, "subject", where),
        approach=_text(table, "approach", where),
        title=_text(table, "title", where),
        thesis_pages=str(table.get("thesis_pages", "")),
        stages=stages,
        locations=tuple(
            (name, _strings(globs, f"{where}: locations.{name}"))
            for name, globs in locations.items()
        ),
        exclude=_strings(exclude.get("paths", []), f"{where}: exclude.paths"),
        exclude_generated=_flag(exclude.get("generated", True), f"{where}: exclude.generated"),
    )


def find_manifests(root: Path) -> tuple[Manifest, ...]:
    """Every subject/approach manifest under ``root``, sorted by subject then approach."""
    found = [load_manifest(p.parent) for p in sorted(root.glob("*/*/manifest.toml"))]
    return tuple(sorted(found, key=lambda m: (m.subject, m.approach)))
