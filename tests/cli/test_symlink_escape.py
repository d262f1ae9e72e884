"""Threat: a committed symbolic link that takes a path out of the checkout. With
``src -> $HOME`` committed, ``scan src`` (and ``graph src``) measured the home folder and
published its file and function names; a committed ``report.md -> ~/.bashrc`` would take
``-o report.md``'s report; a configuration file linked out of the repository was read
(docs/security.md, threat table).

Every path the command line names is followed only as far as the repository holding it
(archmetrics/sources/confine.py), a report is never written through a link inside a
repository, and a configuration file leading out is refused. The "home" here is a folder of
the test's own."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.gitrepo import GitRepo
from tests.untrusted import run_main

pytestmark = pytest.mark.security

SECRET = "def private_function_name():\n    return 1\n"
PLAN = '[architecture.a]\n[[architecture.a.element]]\nname = "a.py"\nstatements_added = 1\n'


@pytest.fixture
def home(tmp_path: Path) -> Path:
    home = tmp_path / "home"
    (home / "work").mkdir(parents=True)
    (home / "work" / "private_project.py").write_text(SECRET)
    (home / "plan.toml").write_text(PLAN)
    (home / "gates.toml").write_text('gates = ["changes > 1000"]\n')
    return home


@pytest.fixture
def linked(repo: GitRepo, home: Path) -> GitRepo:
    """A repository that commits links out to ``home``: src, a plan, a report's name."""
    (repo.root / "src").symlink_to(home)
    (repo.root / "plan.toml").symlink_to(home / "plan.toml")
    (repo.root / "report.md").symlink_to(home / "work" / "private_project.py")
    repo.commit("v1", tag="v1", files={"a.py": "x = 1\n", "lib/inner.py": "y = 2\n"})
    (repo.root / "inner").symlink_to("lib")  # a link that stays inside is fine
    return repo


@pytest.mark.parametrize(
    "argv",
    [
        ["scan", "src"],
        ["scan", "src/work"],
        ["scan", "src/work/private_project.py"],
        ["graph", "src"],
        ["diff", "-C", "src"],
        ["series", "-C", "src", "v1"],
        ["rules", "-C", "src"],
        ["compare", "x=src", "--revisions", "v1"],
        ["estimate", "plan.toml"],
        ["diff", "--config-from", "src/gates.toml"],
    ],
    ids=lambda argv: "-".join(argv[:3]),
)
def test_a_path_argument_does_not_leave_the_repository(linked: GitRepo, argv: list[str]) -> None:
    run = run_main([*argv, "--no-cache"] if argv[0] != "rules" else argv, linked.root)
    assert run.code == 2, run.err
    line = run.one_line_error()
    assert "is a symbolic link leading out of" in line and "not followed" in line, line
    assert "private_function_name" not in run.out + run.err


@pytest.mark.parametrize("flag", ["-o", "--chart"])
def test_a_report_is_not_written_through_a_link(
    linked: GitRepo, home: Path, flag: str
) -> None:
    target = "report.md" if flag == "-o" else "report.svg"
    if flag == "--chart":
        (linked.root / target).symlink_to(home / "work" / "private_project.py")
    argv = ["diff", "--base", "EMPTY", "--head", "v1", flag, target, "--no-cache"]
    run = run_main(argv, linked.root)
    assert run.code == 2
    assert "a symbolic link inside the repository; not written through" in run.one_line_error()
    assert (home / "work" / "private_project.py").read_text() == SECRET


def test_paths_inside_the_repository_and_the_runners_own_are_followed(
    linked: GitRepo, home: Path, tmp_path: Path
) -> None:
    """A link that stays inside, ``..`` the runner wrote, a report written to a plain file,
    a folder outside any repository named directly."""
    inner = run_main(["scan", "inner", "--format", "json", "--no-cache"], linked.root)
    assert inner.code == 0, inner.err
    assert [f["path"] for f in json.loads(inner.out)["files"]] == ["lib/inner.py"]
    up = run_main(["scan", "../home/work", "--no-cache", "--format", "csv"], linked.root)
    assert up.code == 0 and "private_project.py" in up.out, up.err
    out = tmp_path / "out.md"
    written = run_main(["scan", ".", "-o", str(out), "--no-cache"], linked.root)
    assert written.code == 0 and out.read_text().startswith("## archmetrics scan")


def test_a_configuration_file_leading_out_is_refused(repo: GitRepo, home: Path) -> None:
    (repo.root / "archmetrics.toml").symlink_to(home / "gates.toml")
    repo.commit("v1", files={"a.py": "x = 1\n"})
    for argv in (["scan", "."], ["diff", "--config-from", "head"], ["rules"]):
        run = run_main(argv, repo.root)
        assert run.code == 2, (argv, run.err)
        assert "a symbolic link leading out of the repository; not read" in run.one_line_error()
    inside = repo.root / "conf" / "real.toml"
    inside.parent.mkdir()
    inside.write_text('gates = ["changes > 1000"]\n')
    (repo.root / "archmetrics.toml").unlink()
    (repo.root / "archmetrics.toml").symlink_to("conf/real.toml")
    assert run_main(["scan", ".", "--no-cache"], repo.root).code == 0
