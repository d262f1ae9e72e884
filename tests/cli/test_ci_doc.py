"""docs/ci.md's snippets are what a newcomer copies: each YAML block parses, the workflow's
action inputs and outputs are the ones action.yml declares, and its commands parse."""

from __future__ import annotations

import re
import shlex
import subprocess
from pathlib import Path
from typing import Any

import pytest
import yaml

from archmetrics.cli.parser import build_parser

ROOT = Path(__file__).resolve().parents[2]
PAGE = (ROOT / "docs" / "ci.md").read_text(encoding="utf-8")


def _blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", PAGE, flags=re.S)


def _workflow() -> Any:
    [whole] = [b for b in _blocks("yaml") if b.startswith("name: archmetrics")]
    return yaml.safe_load(whole)


def test_every_yaml_block_parses() -> None:
    blocks = _blocks("yaml")
    assert len(blocks) >= 3
    for block in blocks:
        yaml.safe_load(block)


def test_the_workflow_uses_the_action_as_it_is_declared() -> None:
    action = yaml.safe_load((ROOT / "action.yml").read_text(encoding="utf-8"))
    steps = _workflow()["jobs"]["measure"]["steps"]
    [ours] = [s for s in steps if "archmetrics@" in s.get("uses", "")]
    assert set(ours["with"]) <= set(action["inputs"])
    used = set(re.findall(r"steps\.archmetrics\.outputs\.(\w+)", yaml.safe_dump(steps)))
    assert used and used <= set(action["outputs"])
    assert steps[0]["with"]["fetch-depth"] == 0
    # the action sets Python up itself (action.yml's first step)
    assert any("setup-python" in s.get("uses", "") for s in action["runs"]["steps"])


def _scripts(node: Any) -> list[str]:
    """Every shell text of a workflow or job: run steps, script and after_script lines."""
    if isinstance(node, dict):
        found = [node["run"]] if isinstance(node.get("run"), str) else []
        for key in ("script", "after_script"):
            found += [line for line in node.get(key, []) if isinstance(line, str)]
        return found + [s for value in node.values() for s in _scripts(value)]
    if isinstance(node, list):
        return [s for item in node for s in _scripts(item)]
    return []


def test_the_commands_of_the_page_parse() -> None:
    """Every `archmetrics diff|scan` command of the workflow's and GitLab's scripts is a
    command line archmetrics accepts (a variable stands for itself)."""
    shell = "\n".join(s for b in _blocks("yaml") for s in _scripts(yaml.safe_load(b)))
    commands = re.findall(r"archmetrics (?:diff|scan) [^\n|]*", shell.replace("\\\n", " "))
    assert len(commands) >= 6 and any("codeclimate" in c for c in commands)
    for command in commands:
        argv = shlex.split(command.replace("$", ""))[1:]
        try:
            build_parser().parse_args(argv)
        except SystemExit as error:
            pytest.fail(f"{command}: exit {error.code}")


def test_no_page_pins_a_tag_that_does_not_exist() -> None:
    """archmetrics has no release tags: the pages pin a commit (`@COMMIT`), never a `@v0.1.0`
    a reader cannot fetch."""
    tags = subprocess.run(
        ["git", "-C", str(ROOT), "tag", "--list"], capture_output=True, text=True
    ).stdout.split()
    pages = [ROOT / "README.md", *(ROOT / "docs").rglob("*.md")]
    for page in pages:
        for tag in re.findall(r"archmetrics@(v[0-9][\w.]*)", page.read_text(encoding="utf-8")):
            assert tag in tags, f"{page.name} pins {tag}, which is no tag of archmetrics"
