"""The rule packs' digest (app/coupling.py): what names the packs in the keys of cached tree
states and link sites, so any change to a pack in force makes those records miss."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from archmetrics.app.coupling import packs_digest
from archmetrics.coupling import load_rule_packs
from archmetrics.coupling.rules import RuleSet
from tests.coupling.test_rule_packs import GOOD_RULE

PACK = '[pack]\nname = "custom"\n' + GOOD_RULE


def _digest(path: Path, text: str) -> str:
    path.write_text(text, encoding="utf-8")
    return packs_digest(load_rule_packs([path], plugins=False))


def test_the_same_packs_read_twice_have_one_digest(tmp_path: Path) -> None:
    path = tmp_path / "custom.toml"
    assert _digest(path, PACK) == _digest(path, PACK)
    assert all(p.digest for p in load_rule_packs([path], plugins=False).packs)


def test_a_packs_text_or_place_changed_changes_the_digest(tmp_path: Path) -> None:
    path = tmp_path / "custom.toml"
    first = _digest(path, PACK)
    assert _digest(path, PACK.replace('"*.ping"', '"*.pong"')) != first
    assert _digest(path, PACK + "# a comment\n") != first  # the text, not only the rules
    assert _digest(tmp_path / "other.toml", PACK) != first
    assert packs_digest(load_rule_packs([], plugins=False)) != first  # a pack fewer


def test_packs_made_in_memory_are_named_by_every_field() -> None:
    shipped = load_rule_packs([], plugins=False)
    made = RuleSet(tuple(dataclasses.replace(p, digest="") for p in shipped.packs))
    first = made.packs[0]
    changed = dataclasses.replace(first, rules=first.rules[1:])
    other = RuleSet((changed, *made.packs[1:]))
    assert packs_digest(made) != packs_digest(other) != packs_digest(shipped)
