"""Which files a comparison measures, and how the two revisions' files pair (pure).

Every use case that measures a tree (coupling on each side, the change between them) asks
here: a file is measured unless no parser could read it, an exclude glob matches its path,
or it is generated and generated files are left out (docs/metrics.md, "Exclusions").
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import TypeVar

from archmetrics.changeset.locations import LocationRules
from archmetrics.changeset.model import ExcludedFile, FilePair, MeasuredFile

_F = TypeVar("_F", bound=MeasuredFile)


def exclusion(facts: MeasuredFile, rules: LocationRules) -> str | None:
    """Why a readable file counts nowhere (its path's exclude glob, or ``generated``), or None."""
    if reason := rules.is_excluded(facts.path):
        return reason
    return "generated" if rules.exclude_generated and facts.generated else None


def measured_files(files: Iterable[_F], rules: LocationRules) -> list[_F]:
    """The files of one tree that are measured: read by a parser and not excluded."""
    return [f for f in files if f.parsed and exclusion(f, rules) is None]


def pair_files(
    pre: Sequence[MeasuredFile], post: Sequence[MeasuredFile], renames: Mapping[str, str]
) -> list[FilePair]:
    """Files paired across the revisions by path, and by git's renames (old -> new)."""
    after = {f.path: f for f in post}
    pairs, taken = [], set()
    for facts in pre:
        new_path = renames.get(facts.path, facts.path)
        if new_path not in after and facts.path in after:
            new_path = facts.path
        partner = after.get(new_path)
        if partner is not None:
            taken.add(new_path)
        pairs.append(FilePair(facts, partner))
    pairs.extend(FilePair(None, f) for f in post if f.path not in taken)
    return pairs


def _measured_pair(
    pair: FilePair, rules: LocationRules
) -> tuple[FilePair | None, list[ExcludedFile]]:
    """The measured part of a pair and what was left out of it.

    An excluded side alone drops only that side: a file that leaves ``generated/`` for
    hand-written code is an addition. A side left that could not be parsed drops the whole
    pair (diffing it would show every statement as added or removed); an excluded side is
    listed for its exclusion, whether it could be parsed or not (as ``scan`` lists it).
    """
    reasons = tuple(None if f is None else exclusion(f, rules) for f in (pair.pre, pair.post))
    excluded = {
        ExcludedFile(f.path, r)
        for f, r in zip((pair.pre, pair.post), reasons, strict=True)
        if f and r
    }
    pre = None if reasons[0] else pair.pre
    post = None if reasons[1] else pair.post
    listed = sorted(excluded, key=lambda x: (x.path, x.reason))
    if any(f is not None and not f.parsed for f in (pre, post)):
        return None, [ExcludedFile(pair.path, "not_parsed"), *listed]
    kept = FilePair(pre, post) if pre or post else None
    return kept, listed


def measured_pairs(
    pairs: Iterable[FilePair], rules: LocationRules
) -> tuple[list[FilePair], list[ExcludedFile]]:
    """The measured part of each pair, and every file left out with its reason."""
    kept: list[FilePair] = []
    excluded: list[ExcludedFile] = []
    for pair in pairs:
        measured, left_out = _measured_pair(pair, rules)
        kept += [measured] if measured else []
        excluded += left_out
    return kept, sorted(excluded, key=lambda x: (x.path, x.reason))
