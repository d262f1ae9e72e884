"""The configuration examples of README.md and docs/ci.md run as written: each ```toml block
becomes a repository's configuration (pyproject.toml for a [tool.archmetrics] table, else
archmetrics.toml), is read without a warning, and a scan and a diff run under it. A file the
example names (a rule pack) must exist: one that does not fails the scan."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from archmetrics.cli import main
from archmetrics.config import load_settings
from tests.gitrepo import GitRepo

ROOT = Path(__file__).resolve().parent.parent
PAGES = ("README.md", "docs/ci.md")


def _examples() -> list[tuple[str, str]]:
    found = []
    for page in PAGES:
        text = (ROOT / page).read_text(encoding="utf-8")
        for block in re.findall(r"^( *)```toml\n(.*?)^\1```", text, flags=re.S | re.M):
            indent, body = block
            lines = [line.removeprefix(indent) for line in body.splitlines()]
            found.append((page, "\n".join(lines) + "\n"))
    return found


EXAMPLES = _examples()


def test_every_page_has_its_examples() -> None:
    assert {page for page, _ in EXAMPLES} == set(PAGES) and len(EXAMPLES) >= 3


@pytest.mark.parametrize(("page", "example"), EXAMPLES)
def test_a_configuration_example_runs_as_written(
    page: str, example: str, repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    name = "pyproject.toml" if "[tool.archmetrics" in example else "archmetrics.toml"
    repo.commit("one", files={name: example, "src/app.py": "def f(a):\n    return a\n"})
    repo.commit("two", files={"src/app.py": "def f(a):\n    if a:\n        return 1\n"
                              "    return a\n"})  # fmt: skip
    settings = load_settings(repo.root)
    assert settings.source.endswith(name) and settings.notices == ()
    assert main(["scan", str(repo.root), "-q", "--no-cache"]) == 0, capsys.readouterr().err
    code = main(["diff", "-C", str(repo.root), "--base", "HEAD~1", "--head", "HEAD", "-q",
                 "--no-cache"])  # fmt: skip
    err = capsys.readouterr().err
    assert code in (0, 1), err  # its gates may fail this change; it must measure
    # the example's location globs name folders this little repository lacks: said, not more
    others = [line for line in err.splitlines() if "matched no file" not in line]
    assert not [line for line in others if "warning" in line], err
