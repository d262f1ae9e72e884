"""ROS link sites found by archmetrics, against a hand-checked oracle of public ROS code.

    python benchmarks/ros_oracle.py [--trees DIR] [--clone] [--only NAME ...] [--details]
                                    [--markdown] [--archmetrics CMD]

The oracle is benchmarks/ros_oracle/ (README.md there: code bases, commits, how rows were
labelled). Each pinned code base must be checked out at its commit in ``DIR/<owner>__<name>``
(default benchmarks/.work/ros). ``--clone`` makes missing ones with ``git clone`` and a
checkout of the commit, limited to the labelled slice (sparse checkout); without network,
bring the repository another way (a mirror of ``github:<owner>/<name>``, then
``git clone --no-checkout <mirror> DIR/<owner>__<name>`` and ``git -C ... checkout <commit>``).
For each one the script runs ``archmetrics scan --by link --format json`` on the slice, keeps
the sites of rule packs named ``ros*`` in labelled files, matches them to the oracle's rows
(file, and line within [line - 2, end]) and prints per repository and per kind: recall (rows
found), precision (reported ROS sites that are rows; a site that is no row counts against the
kind its rule names), and among found rows whose name is given statically the share whose
reported endpoint carries that name (or a launch file's remapped name) and the share carrying
the type. Parameter values in parameter and launch files are not labelled: sites of them are
counted apart, not judged. ``--details`` lists the unmatched rows and
sites; ``--verify`` only checks the oracle against the trees (each row's lines exist and hold
the expression its ``written`` cell quotes). Figures are printed for all rows and for rows
outside tests (the issue's count).
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import tempfile
import tomllib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests.coupling.ros_adapter import KIND_CATEGORY, is_ros_site, ros_endpoint  # noqa: E402
from tests.coupling.ros_rows import (  # noqa: E402
    NAMED_ISSUE,
    NAMED_STATIC,
    Match,
    Row,
    is_test_path,
    judged,
    match_sites,
    parse_rows,
)

ORACLE = ROOT / "benchmarks" / "ros_oracle"
TREES = ROOT / "benchmarks" / ".work" / "ros"
SCAN_TIMEOUT = 3600


@dataclass(frozen=True, slots=True)
class Repo:
    """A pinned code base and its labelled slice (repos.toml)."""

    name: str
    commit: str
    paths: tuple[str, ...]
    exclude: tuple[str, ...]
    rows: tuple[Row, ...]

    @property
    def folder(self) -> str:
        return self.name.replace("/", "__")

    def in_scope(self, path: str) -> bool:
        """Is ``path`` in the labelled slice (where every site was labelled)?"""
        inside = not self.paths or any(_under(path, p) for p in self.paths)
        return inside and not any(_under(path, p) for p in self.exclude)


def _under(path: str, prefix: str) -> bool:
    return path == prefix or path.startswith(prefix.rstrip("/") + "/")


def load_repos(folder: Path = ORACLE) -> list[Repo]:
    """Every pinned repository of ``repos.toml``, with its rows."""
    document = tomllib.loads((folder / "repos.toml").read_text(encoding="utf-8"))
    repos = []
    for entry in document["repo"]:
        sites = folder / entry["sites"]
        rows = parse_rows(sites.read_text(encoding="utf-8"), sites.name)
        repos.append(Repo(entry["name"], entry["commit"], tuple(entry.get("paths", ())),
                          tuple(entry.get("exclude", ())), tuple(rows)))  # fmt: skip
    return repos


def _git(tree: Path, *args: str) -> str:
    done = subprocess.run(["git", "-C", str(tree), *args], capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"git {' '.join(args)} in {tree}: {done.stderr.strip()}")
    return done.stdout.strip()


def checkout(repo: Repo, trees: Path, clone: bool) -> Path:
    """The tree of ``repo`` at its pinned commit; cloned when missing and ``clone`` is set."""
    tree = trees / repo.folder
    if not tree.is_dir():
        if not clone:
            raise SystemExit(f"{tree} is missing: run with --clone, or check out "
                             f"{repo.name} at {repo.commit} there (see --help)")  # fmt: skip
        url = f"https://github.com/{repo.name}.git"
        subprocess.run(["git", "clone", "-q", "--no-checkout", url, str(tree)], check=True)
        if repo.paths:
            _git(tree, "sparse-checkout", "set", "--no-cone", *(f"/{p}" for p in repo.paths))
        _git(tree, "-c", "advice.detachedHead=false", "checkout", "-q", repo.commit)
    head = _git(tree, "rev-parse", "HEAD")
    if head != repo.commit:
        raise SystemExit(f"{tree} is at {head}, the oracle is labelled at {repo.commit}")
    return tree


def scan(tree: Path, repo: Repo, command: list[str]) -> list[Mapping[str, object]]:
    """The link sites archmetrics reports for the slice of ``tree`` (paths from the tree)."""
    paths = [p for p in repo.paths if (tree / p).exists()] or ["."]
    with tempfile.TemporaryDirectory() as scratch:
        out = Path(scratch) / "scan.json"
        argv = [*command, "scan", "--by", "link", "--format", "json", "-q", "--no-cache",
                "-o", str(out), *paths]  # fmt: skip
        done = subprocess.run(argv, cwd=tree, capture_output=True, text=True,
                              timeout=SCAN_TIMEOUT)  # fmt: skip
        if done.returncode not in (0, 1) or not out.exists():
            raise SystemExit(f"{' '.join(argv)} failed in {tree}: {done.stderr.strip()[-2000:]}")
        document = json.loads(out.read_text(encoding="utf-8"))
    return [site for element in document["elements"] for site in element["link_sites"]]


@dataclass
class Tally:
    """Counts of one group of rows (a repository, a kind, a category)."""

    rows: int = 0
    found: int = 0
    named: int = 0
    named_ok: int = 0
    static: int = 0
    static_ok: int = 0
    typed: int = 0
    typed_ok: int = 0
    extra: int = 0

    def add_row(self, row: Row, site: Mapping[str, object] | None) -> None:
        self.rows += 1
        if site is None:
            return
        self.found += 1
        _, name, ros_type = ros_endpoint(site)
        if row.names and row.given in NAMED_ISSUE:
            self.named += 1
            self.named_ok += row.accepts(name)
        if row.names and row.given in NAMED_STATIC:
            self.static += 1
            self.static_ok += row.accepts(name)
        if row.types:
            self.typed += 1
            self.typed_ok += ros_type in row.types


def _share(part: int, whole: int) -> str:
    return f"{part}/{whole} ({part / whole:.1%})" if whole else "-"


def tally(match: Match, outside_tests: bool) -> dict[str, Tally]:
    """Tallies by kind, by category (``[communication]``) and in total (``all``).

    A reported site that is no row counts against the precision of the kind its rule names
    (``ros_endpoint``: a family such as ``publisher``, which also holds tf and image_transport
    publishers).
    """
    groups: dict[str, Tally] = {}
    entries: list[tuple[Row, Mapping[str, object] | None]] = [*match.pairs]
    entries += [(row, None) for row in match.missed]
    for row, site in entries:
        if outside_tests and row.test:
            continue
        for key in (row.kind, f"[{KIND_CATEGORY[row.kind]}]", "all"):
            groups.setdefault(key, Tally()).add_row(row, site)
    for site in match.extra:
        if outside_tests and is_test_path(str(site["path"])):
            continue
        kind = ros_endpoint(site)[0]
        for key in (kind, f"[{KIND_CATEGORY.get(kind, '?')}]", "all"):
            groups.setdefault(key, Tally()).extra += 1
    return groups


def report_repo(repo: Repo, match: Match, unjudged: int, markdown: bool) -> None:
    """Print the figures of one repository: per kind, per category, in total."""
    reported = len(match.pairs) + len(match.extra)
    print(f"\n## {repo.name} @ {repo.commit[:12]}: {len(repo.rows)} rows, {reported} ROS sites "
          f"reported in the slice (and {unjudged} parameter values in configuration files, "
          "not judged)")  # fmt: skip
    for label, outside in (("outside tests", True), ("all rows", False)):
        groups = tally(match, outside)
        print(f"\n{label}:")
        _print_table(groups, markdown)


def _order(item: tuple[str, Tally]) -> tuple[bool, bool, str]:
    """Categories first, then kinds, the total last."""
    return item[0] == "all", not item[0].startswith("["), item[0]


def _print_table(groups: Mapping[str, Tally], markdown: bool) -> None:
    head = ("kind", "rows", "recall", "precision", "named (issue)", "named (static)", "typed")
    lines = [head] + [
        (key, str(t.rows), _share(t.found, t.rows), _share(t.found, t.found + t.extra),
         _share(t.named_ok, t.named), _share(t.static_ok, t.static), _share(t.typed_ok, t.typed))
        for key, t in sorted(groups.items(), key=_order)
    ]  # fmt: skip
    if markdown:
        print("| " + " | ".join(head) + " |\n|" + "---|" * len(head))
        for cells in lines[1:]:
            print("| " + " | ".join(cells) + " |")
        return
    widths = [max(len(cells[i]) for cells in lines) for i in range(len(head))]
    for cells in lines:
        print("  " + "  ".join(c.ljust(w) for c, w in zip(cells, widths, strict=True)))


def details(match: Match) -> None:
    """The rows no site matched and the ROS sites no row matched."""
    for row in match.missed:
        print(f"  missed  {row.file}:{row.line} {row.kind} {';'.join(row.names) or '-'}")
    for site in match.extra:
        kind, name, _ = ros_endpoint(site)
        print(f"  extra   {site['path']}:{site['line']} {site.get('rule')} {kind} {name}")


def verify(repo: Repo, tree: Path) -> int:
    """Print and count rows whose lines are missing or do not hold what ``written`` says."""
    problems = 0
    for row in repo.rows:
        path = tree / row.file
        lines = path.read_text(errors="replace").splitlines() if path.is_file() else []
        text = "\n".join(lines[row.line - 1 : row.end])
        words = re.findall(r"[A-Za-z_~/][\w~/.:-]*", row.written)
        if not lines or not 1 <= row.line <= row.end <= len(lines):
            problem = "lines out of the file"
        elif words and words[-1] not in text and row.written.strip("\"'") not in text:
            problem = f"{row.written!r} not on these lines"
        else:
            continue
        problems += 1
        print(f"  {repo.name}: {row.file}:{row.line}-{row.end}: {problem}")
    return problems


def run(repos: Iterable[Repo], args: argparse.Namespace) -> None:
    command = args.archmetrics.split() if args.archmetrics else [
        sys.executable, "-m", "archmetrics"]  # fmt: skip
    for repo in repos:
        tree = checkout(repo, args.trees, args.clone)
        if args.verify:
            print(f"{repo.name}: {verify(repo, tree)} rows to look at")
            continue
        sites = [s for s in scan(tree, repo, command)
                 if is_ros_site(s) and repo.in_scope(str(s["path"]))]  # fmt: skip
        kept = [s for s in sites if judged(str(s["path"]), ros_endpoint(s)[0])]
        rows = [row for row in repo.rows if repo.in_scope(row.file)]
        match = match_sites(rows, kept, ros_endpoint)
        report_repo(repo, match, len(sites) - len(kept), args.markdown)
        if args.details:
            details(match)


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--trees", type=Path, default=TREES, help="checkouts, one per repo")
    parser.add_argument("--clone", action="store_true", help="git clone missing checkouts")
    parser.add_argument("--only", nargs="*", help="owner/name of the repositories to run")
    parser.add_argument("--details", action="store_true", help="list unmatched rows and sites")
    parser.add_argument("--markdown", action="store_true", help="tables as Markdown")
    parser.add_argument("--verify", action="store_true",
                        help="only check that every row's lines hold what it says")  # fmt: skip
    parser.add_argument("--archmetrics", help="command to run (default: this interpreter)")
    args = parser.parse_args()
    repos = [r for r in load_repos() if not args.only or r.name in args.only]
    print(f"{sum(len(r.rows) for r in repos)} oracle rows in {len(repos)} repositories")
    run(repos, args)


if __name__ == "__main__":
    main()
