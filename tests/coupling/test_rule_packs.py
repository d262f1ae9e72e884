"""Rule packs: validation errors name file, rule and key; loading from paths and plugins."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from archmetrics.coupling import (
    ENTRY_POINT_GROUP,
    LinkKind,
    Role,
    RulePackError,
    load_rule_pack,
    load_rule_packs,
)

GOOD_RULE = """
[[rules]]
id = "ping"
language = "python"
match = ["*.ping"]
kind = "messaging"
role = "initiate"
endpoint = { type = "service", arg = 0 }
"""


def _pack(tmp_path: Path, body: str, name: str = "custom.toml") -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(body), encoding="utf-8")
    return path


def test_a_user_pack_loads_after_the_builtin_ones(tmp_path: Path) -> None:
    path = _pack(tmp_path, '[pack]\nname = "custom"\n' + GOOD_RULE)
    rules = load_rule_packs([path], plugins=False)
    assert [p.name for p in rules.packs][-1] == "custom"
    rule = rules.packs[-1].rules[0]
    assert (rule.qualified_id, rule.kind, rule.role) == (
        "custom/ping",
        LinkKind.MESSAGING,
        Role.INITIATE,
    )
    assert rule.match == ("*.ping",) and rule.languages == ("python",)


@pytest.mark.parametrize(
    ("body", "rule", "key", "problem"),
    [
        (
            GOOD_RULE.replace('kind = "messaging"', 'kind = "telepathy"'),
            "ping",
            "kind",
            "not one of",
        ),
        (GOOD_RULE.replace('role = "initiate"', 'rol = "initiate"'), "ping", "rol", "unknown key"),
        (GOOD_RULE.replace('role = "initiate"', ""), "ping", "role", "required"),
        (
            GOOD_RULE.replace('language = "python"', 'language = ["python", "cobol"]'),
            "ping",
            "language",
            "'cobol'",
        ),
        (GOOD_RULE.replace('match = ["*.ping"]', "match = []"), "ping", "match", "empty"),
        (
            GOOD_RULE.replace('match = ["*.ping"]', 'match = ["ping(x)"]'),
            "ping",
            "match",
            "pattern",
        ),
        (
            GOOD_RULE.replace('type = "service"', 'type = "carrier-pigeon"'),
            "ping",
            "endpoint.type",
            "not one of",
        ),
        (GOOD_RULE.replace("arg = 0", "arg = -1"), "ping", "endpoint.arg", ">= 0"),
        (GOOD_RULE.replace("arg = 0", 'arg = "first"'), "ping", "endpoint.arg", "integer"),
        (GOOD_RULE.replace("arg = 0", "argument = 0"), "ping", "endpoint.argument", "unknown key"),
        (
            GOOD_RULE.replace("arg = 0", 'pattern = "(unclosed"'),
            "ping",
            "endpoint.pattern",
            "regular expression",
        ),
        (
            GOOD_RULE.replace("arg = 0", 'same_function = [{ match = "x" }]'),
            "ping",
            "endpoint.same_function",
            "arg or keyword",
        ),
        (
            GOOD_RULE.replace("arg = 0", 'same_function = [{ match = "x", ar = 1 }]'),
            "ping",
            "endpoint.same_function.ar",
            "unknown key",
        ),
        (
            GOOD_RULE.replace("arg = 0", 'from = "callee"'),
            "ping",
            "endpoint.pattern",
            "needs a pattern",
        ),
        (
            GOOD_RULE.replace('id = "ping"', 'id = "ping"\npriority = "high"'),
            "ping",
            "priority",
            "integer",
        ),
        # match globs are the one glob dialect (archmetrics.globs): what it cannot use
        (GOOD_RULE.replace('"*.ping"', '"!x.ping"'), "ping", "match", "negation"),
        (GOOD_RULE.replace('"*.ping"', '"#ping"'), "ping", "match", "comment"),
        (GOOD_RULE.replace('"*.ping"', '"*.[z-a]ing"'), "ping", "match", "unusable glob"),
        (GOOD_RULE.replace('"*.ping"', '"net/ping"'), "ping", "match", "dotted callee"),
        (
            GOOD_RULE.replace("arg = 0", 'same_function = [{ match = "[x", arg = 1 }]'),
            "ping",
            "endpoint.same_function.match",
            "unusable glob",
        ),
        (GOOD_RULE + GOOD_RULE, "ping", "id", "duplicate"),
        (GOOD_RULE.replace('id = "ping"\n', ""), "#1", "id", "required"),
    ],
)
def test_a_bad_rule_fails_naming_file_rule_and_key(
    tmp_path: Path, body: str, rule: str, key: str, problem: str
) -> None:
    path = _pack(tmp_path, '[pack]\nname = "custom"\n' + body)
    with pytest.raises(RulePackError) as caught:
        load_rule_pack(path)
    error = caught.value
    assert (error.source, error.rule, error.key) == (str(path), rule, key)
    assert problem in error.problem
    assert str(error).startswith(f"{path}: rule {rule!r}: key {key!r}: ")


@pytest.mark.parametrize(
    ("body", "key"),
    [
        ("[pack]\nname = 'x'\n", "rules"),
        (GOOD_RULE, "pack"),
        ("[pack]\nname = 'x'\nauthor = 'me'\n" + GOOD_RULE, "pack.author"),
        ("[pack]\nname = 'has space'\n" + GOOD_RULE, "pack.name"),
        ("[pack]\nname = 'x'\n[extra]\n" + GOOD_RULE, "extra"),
    ],
)
def test_a_bad_pack_table_fails_naming_the_key(tmp_path: Path, body: str, key: str) -> None:
    path = _pack(tmp_path, body)
    with pytest.raises(RulePackError) as caught:
        load_rule_pack(path)
    assert (caught.value.source, caught.value.rule, caught.value.key) == (str(path), None, key)


def test_unreadable_and_invalid_toml_name_the_file(tmp_path: Path) -> None:
    with pytest.raises(RulePackError, match="cannot read"):
        load_rule_pack(tmp_path / "absent.toml")
    broken = _pack(tmp_path, "[pack\nname=")
    with pytest.raises(RulePackError, match="not valid TOML") as caught:
        load_rule_pack(broken)
    assert caught.value.source == str(broken)


def test_two_packs_with_one_name_are_an_error(tmp_path: Path) -> None:
    path = _pack(tmp_path, '[pack]\nname = "zeromq"\n' + GOOD_RULE)
    with pytest.raises(RulePackError, match="already loaded") as caught:
        load_rule_packs([path], plugins=False)
    assert caught.value.key == "pack.name"


def _install_plugin(root: Path, module: str, value: str) -> None:
    """A real installed distribution (a dist-info folder) announcing a rule-pack entry point."""
    dist = root / "pingpack-1.0.dist-info"
    dist.mkdir(parents=True)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: pingpack\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text(f"[{ENTRY_POINT_GROUP}]\nping = {module}:{value}\n")


def test_plugin_packs_load_through_the_entry_point_group(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pack = _pack(tmp_path, '[pack]\nname = "pingpack"\n' + GOOD_RULE)
    (tmp_path / "pingpack_rules.py").write_text(
        f"from pathlib import Path\n\ndef packs():\n    return [Path({str(pack)!r})]\n"
    )
    _install_plugin(tmp_path, "pingpack_rules", "packs")
    monkeypatch.syspath_prepend(str(tmp_path))
    names = [p.name for p in load_rule_packs().packs]
    assert names[-1] == "pingpack"
    assert "pingpack" not in [p.name for p in load_rule_packs(plugins=False).packs]


def test_a_plugin_giving_the_wrong_type_is_rejected(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "badpack_rules.py").write_text("PACKS = 42\n")
    _install_plugin(tmp_path, "badpack_rules", "PACKS")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(TypeError, match="entry point 'ping'"):
        load_rule_packs()
