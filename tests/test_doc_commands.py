"""The commands README.md and docs/ show are commands archmetrics takes: every command line
in a shell block parses with the real argument parser, and every option the README's usage
synopsis names exists on its command. (The configuration examples run in
tests/test_config_examples.py; the study's and the estimate's commands run in their tests.)"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from archmetrics.cli.parser import build_parser

ROOT = Path(__file__).resolve().parent.parent
PAGES = ("README.md", *sorted(str(p.relative_to(ROOT)) for p in (ROOT / "docs").glob("*.md")))
SHELLS = ("", "sh", "bash", "shell", "console")


def _blocks(text: str) -> list[list[str]]:
    """The lines of each fenced block written for a shell."""
    found: list[list[str]] = []
    inside: list[str] | None = None
    for line in text.splitlines():
        fence = re.match(r"^\s*```(\S*)\s*$", line)
        if fence and inside is None:
            inside = [] if fence.group(1) in SHELLS else None
            if inside is None:
                found.append([])  # a block in another language: skipped, but still a block
                inside = found[-1]
                inside.append("\0")
            continue
        if fence:
            if inside and inside[0] != "\0":
                found.append(inside)
            inside = None
            continue
        if inside is not None:
            inside.append(line)
    return [block for block in found if block and block[0] != "\0"]


def _commands(page: str) -> list[str]:
    """Each ``archmetrics ...`` command of the page's shell blocks, continuations joined and
    the page's shell variables (``LOC="..."`` in an earlier block) put in."""
    commands = []
    blocks = ["\n".join(block) for block in _blocks((ROOT / page).read_text(encoding="utf-8"))]
    variables = dict(re.findall(r'^(\w+)="([^"]*)"', "\n".join(blocks), flags=re.M))
    for block in blocks:
        joined = block.replace("\\\n", " ")
        for name, value in variables.items():
            joined = joined.replace(f"${name}", " ".join(value.split()))
        for line in joined.splitlines():
            line = line.strip().removeprefix("$ ")
            for part in line.split("&&"):
                words = part.strip()
                words = re.sub(r"^\S*/bin/archmetrics\b", "archmetrics", words)
                if words.startswith("archmetrics "):
                    commands.append(words)
    return commands


COMMANDS = [(page, command) for page in PAGES for command in _commands(page)]
SYNOPSIS = [(page, c) for page, c in COMMANDS if re.search(r"\[|\.\.\.|\|| [A-Z][A-Z_0-9]+\b", c)]
EXAMPLES = [(page, c) for page, c in COMMANDS if (page, c) not in SYNOPSIS]


def test_the_pages_show_commands() -> None:
    pages = {page for page, _ in EXAMPLES}
    assert {"docs/history.md", "docs/study.md"} <= pages, pages
    assert len(SYNOPSIS) >= 10  # the README's usage


@pytest.mark.parametrize(("page", "command"), EXAMPLES)
def test_a_command_example_parses(page: str, command: str) -> None:
    argv = shlex.split(command, comments=True)[1:]
    try:
        build_parser().parse_args(argv)
    except SystemExit as exit_:
        pytest.fail(f"{page}: `{command}` is refused (exit {exit_.code})")
    written = {word.partition("=")[0] for word in argv[1:] if word.startswith("--")}
    abbreviated = written - _options(argv[0])  # argparse takes a prefix; the docs spell it out
    assert not abbreviated, f"{page}: `{command}`: {sorted(abbreviated)}"


def _options(command: str) -> set[str]:
    parser = build_parser()
    sub = next(
        a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction"
    ).choices[command]  # type: ignore[union-attr]
    return {option for action in sub._actions for option in action.option_strings}


@pytest.mark.parametrize(("page", "command"), SYNOPSIS)
def test_every_option_a_synopsis_names_exists(page: str, command: str) -> None:
    name = command.split()[1]
    named = set(re.findall(r"(?<![\w-])(--?[a-z][\w-]*)", command.split(maxsplit=2)[-1]))
    missing = named - _options(name)
    assert not missing, f"{page}: `archmetrics {name}` has no {sorted(missing)}"
