"""The rule table in docs/metrics.md is generated from the shipped packs and in sync."""

from __future__ import annotations

from pathlib import Path

from archmetrics.coupling import rule_rows, rules_markdown
from tests.coupling.trees import BUILTIN

DOC = Path(__file__).resolve().parents[2] / "docs" / "metrics.md"
BEGIN, END = "<!-- rules:begin", "<!-- rules:end -->"
REGENERATE = (
    "regenerate the section with: .venv/bin/python -c 'from archmetrics.coupling import *;"
    ' print(rules_markdown(load_rule_packs(plugins=False), "####"), end="")\''
)


def test_the_documented_rule_table_matches_the_shipped_packs() -> None:
    text = DOC.read_text(encoding="utf-8")
    start = text.index("\n", text.index(BEGIN)) + 1
    documented = text[start : text.index(END)]
    assert documented.strip() == rules_markdown(BUILTIN, "####").strip(), REGENERATE


def test_every_rule_has_a_row_and_every_pack_a_section() -> None:
    markdown = rules_markdown(BUILTIN)
    rows = rule_rows(BUILTIN)
    assert len(rows) == len(BUILTIN.rules) + len(BUILTIN.configuration)
    for pack in BUILTIN.packs:
        assert f"### `{pack.name}`" in markdown
    for row in rows:
        assert f"| `{row.rule}` | `{row.language}` |" in markdown
    socket_connect = next(r for r in rows if (r.pack, r.rule) == ("posix-sockets", "c-connect"))
    assert (socket_connect.kind, socket_connect.role, socket_connect.match) == (
        "socket", "initiate", "connect",
    )  # fmt: skip
    assert socket_connect.endpoint == (
        "port: same function: htons(arg 0), getaddrinfo(arg 1) / else same file"
    )
