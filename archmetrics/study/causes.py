"""Why a finding disagrees on one variant: the recorded cause, with the elements that show it.

Causes are data (``causes.toml`` beside this module), written by someone who read the
elements; the report shows a cause only beside a verdict that disagrees, and a test checks
that every disagreement of the bundled study has one and that none is left over.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from archmetrics.study.manifest import VARIANTS, ManifestError

# subject: our code is written otherwise; metric definition: archmetrics counts otherwise;
# test: the check reads the words otherwise; claim: the thesis's claim does not hold here
KINDS = ("subject", "metric definition", "test", "claim")
CAUSES_FILE = Path(__file__).with_name("causes.toml")


@dataclass(frozen=True, slots=True)
class Cause:
    finding: str
    variant: str
    kind: str
    elements: tuple[str, ...]  # "path: what in it", enough to find the lines
    text: str

    def describe(self) -> str:
        return f"{self.kind}: {self.text} [{'; '.join(self.elements)}]"


def _cause(entry: Any, where: str) -> Cause:
    if not isinstance(entry, dict):
        raise ManifestError(f"{where}: expected a table")
    values: dict[str, str] = {}
    for key in ("finding", "variant", "kind", "text"):
        value = entry.get(key)
        if not isinstance(value, str) or not value:
            raise ManifestError(f"{where}: '{key}' must be a non-empty string")
        values[key] = value
    if values["variant"] not in VARIANTS:
        raise ManifestError(f"{where}: variant must be one of {', '.join(VARIANTS)}")
    if values["kind"] not in KINDS:
        raise ManifestError(f"{where}: kind must be one of {', '.join(KINDS)}")
    elements = entry.get("elements")
    if (
        not isinstance(elements, list)
        or not elements
        or not all(isinstance(e, str) for e in elements)
    ):
        raise ManifestError(f"{where}: 'elements' must be a non-empty list of strings")
    return Cause(
        values["finding"], values["variant"], values["kind"], tuple(elements), values["text"]
    )


def load_causes(file: Path = CAUSES_FILE) -> dict[tuple[str, str], Cause]:
    """The recorded causes by (finding id, variant); one per pair."""
    try:
        table = tomllib.loads(file.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as error:
        raise ManifestError(f"{file}: cannot read: {error}") from error
    found: dict[tuple[str, str], Cause] = {}
    for number, entry in enumerate(table.get("cause", [])):
        cause = _cause(entry, f"{file}: cause[{number}]")
        key = (cause.finding, cause.variant)
        if key in found:
            raise ManifestError(f"{file}: cause[{number}]: {key[0]} ({key[1]}) given twice")
        found[key] = cause
    return found
