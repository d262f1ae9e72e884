"""A study subject's manifest: its stages and which paths are base, new and framework."""

from __future__ import annotations

import itertools
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any


class ManifestError(ValueError):
    """A manifest that cannot be used; the message names the file and the key."""


# "as-described": every stage follows a sentence of the thesis about the code it measured;
# "idiomatic": the same integration written the way the framework is usually written.
VARIANTS = ("as-described", "idiomatic")


@dataclass(frozen=True, slots=True)
class Follows:
    """The sentence of the thesis (and its PDF page) that one stage of a subject follows."""

    stage: str
    sentence: str
    page: int


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
    variant: str = "idiomatic"
    follows: tuple[Follows, ...] = ()  # one per stage in an as-described manifest

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


def _variant(table: dict[str, Any], where: str) -> str:
    variant = _text(table, "variant", where)
    if variant not in VARIANTS:
        raise ManifestError(f"{where}: variant must be one of {', '.join(VARIANTS)}")
    return variant


def _follows(
    table: dict[str, Any], stages: tuple[str, ...], variant: str, where: str
) -> tuple[Follows, ...]:
    """[stage.<name>] follows = "<sentence>", page = <n>: required of every as-described stage."""
    given = table.get("stage", {})
    if not isinstance(given, dict):
        raise ManifestError(f"{where}: [stage] must be a table of stages")
    for name in given:
        if name not in stages:
            raise ManifestError(f"{where}: stage.{name}: no such stage in 'stages'")
    found = []
    for stage in stages:
        entry = given.get(stage)
        if entry is None:
            if variant == "as-described":
                raise ManifestError(f"{where}: stage.{stage}: an as-described stage needs follows")
            continue
        key = f"{where}: stage.{stage}"
        page = entry.get("page") if isinstance(entry, dict) else None
        if not isinstance(page, int) or isinstance(page, bool) or page <= 0:
            raise ManifestError(f"{key}: 'page' must be a positive whole number")
        found.append(Follows(stage, _text(entry, "follows", key), page))
    return tuple(found)


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
    subject = _text(table, "subject", where)
    variant = _variant(table, where)
    return Manifest(
        path=folder,
        subject=subject,
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
        variant=variant,
        follows=_follows(table, stages, variant, where),
    )


def find_manifests(root: Path) -> tuple[Manifest, ...]:
    """Every manifest under ``root`` (``<subject>/<approach>/`` for the idiomatic variant,
    ``as-described/<subject>/<approach>/`` for the other), sorted by variant, subject and
    approach. Two manifests for the same variant, subject and approach are an error."""
    folders = [*root.glob("*/*/manifest.toml"), *root.glob("*/*/*/manifest.toml")]
    found = sorted(
        (load_manifest(p.parent) for p in folders),
        key=lambda m: (m.variant, m.subject, m.approach),
    )
    for a, b in itertools.pairwise(found):
        if (a.variant, a.subject, a.approach) == (b.variant, b.subject, b.approach):
            raise ManifestError(
                f"{b.path / 'manifest.toml'}: {b.variant} {b.subject}/{b.approach} is also"
                f" {a.path / 'manifest.toml'}"
            )
    return tuple(found)
