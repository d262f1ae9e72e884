"""Threat: names the repository chooses (files, functions, endpoints, tags) read as markup by
the medium a report goes to: HTML, links and headings in the Markdown a CI job posts as its
summary or a comment, rich markup and hyperlinks in the terminal table, labels in a Mermaid
graph (docs/security.md, threat table).

The Markdown is rendered with a CommonMark renderer (markdown-it-py, tables on, as GitHub
reads them): no tag but the report's own may appear, and every hostile name must come out
whole, as the text of one ``<code>`` element."""

from __future__ import annotations

import html
import re
from pathlib import Path

import pytest
from markdown_it import MarkdownIt

from archmetrics.coupling import group_elements
from archmetrics.coupling.model import EdgeKind, ElementGraph, GraphEdge
from archmetrics.markup import code_span
from archmetrics.reports.graph import render
from tests.gitrepo import GitRepo
from tests.untrusted import run_main

pytestmark = pytest.mark.security

BODY = "def g(a):\n    if a:\n        return 1\n    return 2\n"
NAMES = [
    "<h1>GATES PASSED</h1>.py",
    "<a href=https:/evil.example>click</a>.py",
    "<img src=x onerror=alert(1)>.py",
    "back`tick.py",
    "``two``.py",
    "pi|pe.py",
    "[click](https:evil.example).py",
    "www.evil.example.py",
    "*em*_x_.py",
    "[bold]gone[_bold].py",
    "[link=https:evil.example]hyper[_link].py",
    "&lt;entity&gt;.py",
]
ENDPOINT = "ipc://<b>x</b>|`y`"
ZMQ = f'import zmq\ns = zmq.Context().socket(zmq.REQ)\ns.connect("{ENDPOINT}")\n'
CPP = "struct A { int v; };\nbool operator<(A a, A b) { return a.v < b.v; }\n"
TAG = "<b>bold</b>"
PLAN = """[architecture.a]
[[architecture.a.stage]]
label = "<h2>stage</h2>"
[[architecture.a.stage.element]]
name = "<i>planned</i>.py"
new = true
statements_added = 3
"""
# what the reports themselves write: headings, tables, lists, the folded element list
OWN_TAGS = {"h2", "h3", "h4", "p", "table", "thead", "tbody", "tr", "th", "td", "code", "ul",
            "li", "strong", "em", "details", "summary", "sub"}  # fmt: skip


@pytest.fixture(scope="module")
def repo(tmp_path_factory: pytest.TempPathFactory) -> GitRepo:
    repo = GitRepo(tmp_path_factory.mktemp("names") / "repo")
    repo.commit("base", tag="v1", files={"base.py": BODY, "plan.toml": PLAN})
    files = {name: BODY for name in NAMES}
    repo.commit("names", tag=TAG, files={**files, "net.py": ZMQ, "ops.cpp": CPP})
    return repo


def _markdown_html(text: str) -> str:
    return MarkdownIt("commonmark").enable("table").render(text)


def _check_markdown(text: str, names: list[str]) -> None:
    rendered = _markdown_html(text)
    tags = set(re.findall(r"<([a-zA-Z][a-zA-Z0-9]*)", rendered))
    assert tags <= OWN_TAGS, tags - OWN_TAGS
    codes = set(re.findall(r"<code>(.*?)</code>", rendered, re.DOTALL))
    for name in names:
        shown = html.escape(name, quote=False)
        assert any(shown in code for code in codes), (name, sorted(codes))


@pytest.mark.parametrize(
    "argv",
    [
        ["scan", "."],
        ["scan", ".", "--by", "function"],
        ["scan", ".", "--by", "element"],
        ["scan", ".", "--by", "link"],
        ["scan", ".", "--fail-on", "vg(function) > 0"],
        ["diff", "--base", "v1", "--head", TAG],
        ["diff", "--base", "v1", "--head", TAG, "--fail-on", "changes > 1"],
        ["series", "v1", TAG],
        ["compare", "r=."],
        ["estimate", "plan.toml", "--base", "v1"],
    ],
    ids=lambda argv: "-".join(argv[:4]),
)
def test_markdown_shows_names_as_text(repo: GitRepo, argv: list[str]) -> None:
    run = run_main([*argv, "--format", "markdown", "--no-cache"], repo.root)
    assert run.code in (0, 1), run.err
    names = [] if argv[0] in ("compare", "estimate") else list(NAMES)
    if argv[0] == "estimate":
        names = ["<i>planned</i>.py", "<h2>stage</h2>"]
    if "--by" in argv and argv[-1] == "link":
        names = [f"address:{ENDPOINT}"]
    if "function" in argv or ("--fail-on" in argv and argv[0] == "scan"):
        names.append("operator<")
    if argv[0] in ("series", "compare"):
        names.append(TAG)
    _check_markdown(run.out, names)


def test_a_rule_packs_text_is_shown_as_text(tmp_path: Path) -> None:
    """``archmetrics rules --format markdown`` prints what the repository's packs say."""
    pack = (
        '[pack]\nname = "evil"\ndescription = "<img src=x> [a](http:x) `"\n'
        '[[rules]]\nid = "r"\nlanguage = "python"\nmatch = "*.connect"\n'
        'kind = "messaging"\nrole = "initiate"\n'
        "endpoint = { type = \"address\", arg = 0, pattern = '<b>(x)|y</b>' }\n"
    )
    repo = GitRepo(tmp_path / "repo")
    config = '[tool.archmetrics.coupling]\nrule-packs = ["pack.toml"]\n'
    repo.commit("one", files={"pack.toml": pack, "pyproject.toml": config})
    run = run_main(["rules", "--format", "markdown"], repo.root)
    assert run.code == 0, run.err
    _check_markdown(run.out, ["<img src=x> [a](http:x) `", "<b>(x)|y</b>"])


def test_a_code_span_holds_any_text() -> None:
    """Backticks of any run length, blanks at the ends, pipes in a table, line breaks."""
    texts = ["`", "``", "a`b``c", " lead", "trail ", " both ", "x|y", "two\nlines", "\\|"]
    rows = "".join(f"| {code_span(t).replace('|', chr(92) + '|')} |\n" for t in texts)
    rendered = _markdown_html("| name |\n| --- |\n" + rows)
    codes = re.findall(r"<code>(.*?)</code>", rendered, re.DOTALL)
    expected = [html.escape(t.replace("\n", "\\n"), quote=False) for t in texts]
    assert codes == expected


def test_the_terminal_table_shows_names_as_they_are(repo: GitRepo) -> None:
    """rich reads ``[bold]`` and ``[link=...]`` as its markup unless told not to."""
    for argv in (["scan", "."], ["diff", "--base", "v1", "--head", TAG]):
        run = run_main([*argv, "--no-cache"], repo.root, {"COLUMNS": "300"})  # no wrapping
        assert run.code == 0, run.err
        for name in ("[bold]gone[_bold].py", "[link=https:evil.example]hyper[_link].py"):
            assert name in run.out, run.out


def test_mermaid_labels_hold_no_markup() -> None:
    nodes = group_elements(["<img src=x>.py", "a`b`.py"])
    edge = GraphEdge("<img src=x>.py", "a`b`.py", EdgeKind.DYNAMIC, 'topic:"<a href=x>"#')
    text = render(ElementGraph(nodes, (edge,)), "mermaid")
    labels = re.findall(r'"([^"]*)"', text)
    assert labels and all(not set(label) & set("<>`&") for label in labels), labels
    assert "#60;img src=x#62;.py" in text and "#35;" in text
