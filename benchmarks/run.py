"""archmetrics against its peers on real code: two numpy releases' sdists (C, C++ and Python).

Run from a clean clone:
    .venv/bin/pip install -e '.[bench]' && .venv/bin/python benchmarks/run.py
Options: --repeat N (runs per measure, median taken), --jobs N, --only scan-c scan-py diff
edit edit-10x growth, --single (archmetrics with one worker too), --releases A B.
Downloads and trees are kept in benchmarks/.work (gitignored) and reused. Prints a Markdown
table for docs/performance.md and writes it, with every run, to benchmarks/.work/results.*.
Not part of the test suite.
"""

from __future__ import annotations

import argparse
import compileall
import json
import os
import shutil
import sys
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

import corpus
import report
from corpus import BenchError, Tree
from measure import Summary, power_fit, repeat

HERE = Path(__file__).resolve().parent
TASKS = ("scan-c", "scan-py", "diff", "edit", "edit-10x", "growth")


@dataclass(frozen=True, slots=True)
class Bench:
    """Where things are and how hard to measure."""

    work: Path
    bin: Path  # the folder holding archmetrics, lizard and radon
    jobs: int
    times: int
    timeout: float
    single: bool  # also measure archmetrics with one worker against single-process peers

    def out(self, name: str) -> Path:
        folder = self.work / "out"
        folder.mkdir(parents=True, exist_ok=True)
        return folder / name

    def tool(self, name: str) -> str:
        path = self.bin / name
        if not path.exists():
            raise BenchError(f"{path} is missing: run .venv/bin/pip install -e '.[bench]'")
        return str(path)

    def scan(self, tree: Path, jobs: int) -> list[str]:
        options = ["--no-cache", "-q", "-j", str(jobs), "--format", "json"]
        return [self.tool("archmetrics"), "scan", str(tree), *options]

    def repeat(
        self,
        name: str,
        command: list[str],
        before: Callable[[], None] = lambda: None,
        sample_memory: bool = False,
        ok: tuple[int, ...] = (0,),
    ) -> Summary:
        """Median runs of ``command``, its output kept in .work/out/``name``."""
        print(f"  {name}: {' '.join(command)}", flush=True)
        out = self.out(name)
        summary = repeat(
            command, self.work, self.times, self.timeout, out, before, sample_memory, ok
        )
        print(f"    median {summary.wall:.2f} s wall, {summary.cpu:.2f} s CPU", flush=True)
        return summary


def scanned_files(bench: Bench, name: str) -> int:
    """How many files the last archmetrics scan named ``name`` reported."""
    document = json.loads(bench.out(name).read_text())
    return int(document["totals"]["files"])


def scan_cfamily(bench: Bench, tree: Tree) -> list[report.Result]:
    """archmetrics scan (default jobs) against single-threaded lizard on the C/C++ files, the
    goal in docs/performance.md (>= 3x); then, for reference, against lizard -t N with as many
    threads as archmetrics has workers (lizard's threads share one interpreter's lock)."""
    ours = bench.repeat("scan-c.archmetrics", bench.scan(tree.path, bench.jobs))
    lizard = bench.tool("lizard")
    single = bench.repeat("scan-c.lizard", [lizard, str(tree.path)], ok=(0, 1))
    files = (
        scanned_files(bench, "scan-c.archmetrics"),
        report.lizard_files(bench.out("scan-c.lizard")),
    )
    rows: list[report.Result] = [
        report.Row("scan C/C++, cold", tree, ours, single, "lizard (one thread)", 3.0, files)
    ]
    if bench.jobs > 1:
        threads = [lizard, "-t", str(bench.jobs), str(tree.path)]
        theirs = bench.repeat("scan-c.lizard-threads", threads, ok=(0, 1))
        files = (files[0], report.lizard_files(bench.out("scan-c.lizard-threads")))
        peer = f"lizard -t {bench.jobs}"
        rows.append(report.Row("scan C/C++, cold", tree, ours, theirs, peer, 0.0, files))
    return rows


def scan_python(bench: Bench, tree: Tree) -> list[report.Result]:
    """archmetrics scan against radon cc + radon raw on the Python files (and with --single,
    archmetrics with one worker too: radon has no parallel mode)."""
    radon = bench.tool("radon")
    cc, raw = bench.out("scan-py.radon-cc.json"), bench.out("scan-py.radon-raw.json")
    script = f'"{radon}" cc -j -O "{cc}" "$1" && "{radon}" raw -j -O "{raw}" "$1"'
    theirs = bench.repeat("scan-py.radon", ["sh", "-c", script, "sh", str(tree.path)])
    radon_files = len(json.loads(raw.read_text()))  # cc leaves out files with no blocks
    rows: list[report.Result] = []
    for jobs in sorted({bench.jobs, 1} if bench.single else {bench.jobs}, reverse=True):
        name = f"scan-py.archmetrics-j{jobs}"
        ours = bench.repeat(name, bench.scan(tree.path, jobs))
        files = (scanned_files(bench, name), radon_files)
        label = f"scan Python, cold ({jobs} worker{'s' if jobs > 1 else ''} vs radon's 1)"
        rows.append(report.Row(label, tree, ours, theirs, "radon cc + raw", 2.0, files))
    return rows


def diff_rows(
    bench: Bench, history: Path, sources: tuple[Path, Path], tags: tuple[str, str]
) -> list[report.Result]:
    """archmetrics diff cold against cloc --diff, warm against cold, and its peak memory."""
    cache = bench.work / "diff-cache.sqlite3"
    command = [bench.tool("archmetrics"), "diff", "-C", str(history), "--base", tags[0]]
    command += ["--head", tags[1], "-q", "-j", str(bench.jobs), "--format", "json"]
    command += ["--cache-path", str(cache)]
    cold = bench.repeat("diff.cold", command, before=lambda: _remove(cache), sample_memory=True)
    warm = bench.repeat("diff.warm", command)
    rows: list[report.Result] = [
        report.Row("diff two releases, warm vs cold", None, warm, cold, "archmetrics cold", 10.0)
    ]
    cloc = report.ensure_cloc()
    if cloc is None:
        rows.append(
            report.Row("diff two releases, cold", None, cold, None, "cloc --diff (missing)", 2.0)
        )
    else:
        endings = ",".join(e.lstrip(".") for e in corpus.MEASURED)
        theirs = bench.repeat(
            "diff.cloc",
            [
                cloc,
                "--diff",
                str(sources[0]),
                str(sources[1]),
                f"--include-ext={endings}",
                "--quiet",
            ],
        )
        rows.insert(
            0, report.Row("diff two releases, cold", None, cold, theirs, "cloc --diff", 2.0)
        )
    rows.append(report.MemoryRow("peak memory, diff cold", cold, 400.0))
    return rows


EDITED = "numpy/_core/src/multiarray/ctors.c"  # if the head has it; else its largest C file


def edit_rows(bench: Bench, history: Path, tag: str) -> list[report.Result]:
    """``diff --base HEAD --head WORKTREE`` with a warm cache, each run after a new
    edit of one C file (a function appended), against ``scan`` of that file (its facts
    cached by the diff); goal: the diff at most 3x the scan (a speed-up of at least 1/3)."""
    clone = bench.work / "edit"
    if clone.exists():
        shutil.rmtree(clone)
    corpus.git(bench.work, "clone", "-q", "--shared", str(history), str(clone))
    corpus.git(clone, "checkout", "-q", tag)
    target = clone / EDITED
    if not target.is_file():
        target = max(clone.rglob("*.c"), key=lambda p: p.stat().st_size)
    cache = bench.work / "edit-cache.sqlite3"
    _remove(cache)
    tool = bench.tool("archmetrics")
    diff = [tool, "diff", "-C", str(clone), "--base", "HEAD", "--head", "WORKTREE", "-q"]
    diff += ["-j", str(bench.jobs), "--format", "json", "--cache-path", str(cache)]
    bench.repeat("edit.warm-up", diff)  # both trees' facts and coupling cached
    ours = bench.repeat("edit.diff", diff, before=_appender(target))
    scan = [tool, "scan", str(target), "-q", "--format", "json", "--cache-path", str(cache)]
    theirs = bench.repeat("edit.scan", scan)
    measure = f"diff HEAD..WORKTREE after editing {target.relative_to(clone)}, warm"
    return [report.Row(measure, None, ours, theirs, "one-file scan", 1 / 3)]


def copies_repository(bench: Bench, tree: Path, copies: int) -> Path:
    """A repository whose one commit holds ``copies`` copies of ``tree``, under c0, c1 ...:
    the same code base, ``copies`` times the files. Reused. Real copies, not hard links: the
    edits the benchmark appends must not reach the unpacked release or the other copies."""
    repo = bench.work / f"copies-{copies}"
    if (repo / ".git").exists() and corpus.git(repo, "tag", "--list").split() == ["built"]:
        corpus.git(repo, "checkout", "-q", "--", ".")  # an earlier run's edits undone
        return repo
    if repo.exists():
        shutil.rmtree(repo)
    repo.mkdir(parents=True)
    for index in range(copies):
        shutil.copytree(tree, repo / f"c{index}", symlinks=True)
    corpus.git(repo, "init", "-q")
    corpus.git(repo, "add", "--all", "--force", ".")
    corpus.git(repo, "commit", "-q", "--no-verify", "-m", f"{copies} copies")
    corpus.git(repo, "tag", "built")
    return repo


def edit_growth_rows(bench: Bench, tree: Path) -> list[report.Result]:
    """The warm edit diff of ``edit_rows`` in a repository of ten copies of the
    head tree against the same in a repository of one copy; goal: at most 1.5x."""
    summaries = []
    for copies in (1, 10):
        repo = copies_repository(bench, tree, copies)
        target = repo / "c0" / EDITED
        if not target.is_file():
            target = max((repo / "c0").rglob("*.c"), key=lambda p: p.stat().st_size)
        cache = bench.work / f"copies-{copies}-cache.sqlite3"
        _remove(cache)
        tool = bench.tool("archmetrics")
        diff = [tool, "diff", "-C", str(repo), "--base", "HEAD", "--head", "WORKTREE", "-q"]
        diff += ["-j", str(bench.jobs), "--format", "json", "--cache-path", str(cache)]
        bench.repeat(f"edit-{copies}x.warm-up", diff)
        edit = _appender(target)
        name = f"edit-{copies}x.diff"
        summaries.append(bench.repeat(name, diff, before=edit, sample_memory=True))
    measure = "diff HEAD..WORKTREE after an edit, warm, 10 copies of the tree"
    return [
        report.Row(measure, None, summaries[1], summaries[0], "the same with 1 copy", 1 / 1.5),
        report.MemoryRow("peak memory, edit diff, 10 copies", summaries[1], 1000.0),
    ]


def _appender(target: Path) -> Callable[[], None]:
    """An edit of ``target``: a new function appended at each call."""
    edits = iter(range(1_000_000))

    def edit() -> None:
        with target.open("a") as file:
            file.write(f"\nint archmetrics_bench_edit_{next(edits)}(int x) {{ return x; }}\n")

    return edit


def _remove(path: Path) -> None:
    for candidate in (path, path.with_name(path.name + "-journal")):
        candidate.unlink(missing_ok=True)


def growth(bench: Bench, source: Path) -> list[report.Result]:
    """archmetrics scan of 25, 50 and 100 % of the measured files (nested subsets); the
    exponents of the wall-time and CPU-time fits."""
    sizes, walls, cpus = [], [], []
    for percent in (25, 50, 100):
        folder = bench.work / f"trees/all-{percent}"
        tree = corpus.subset_tree(source, corpus.MEASURED, folder, percent / 100)
        summary = bench.repeat(f"growth.{percent}", bench.scan(tree.path, bench.jobs))
        sizes.append(float(tree.bytes))
        walls.append(summary.wall)
        cpus.append(summary.cpu)
        print(f"    {percent}%: {tree.files} files, {tree.bytes / 1e6:.1f} MB", flush=True)
    measure = "growth, scan at 25/50/100 %"
    exponents = (power_fit(sizes, walls)[1], power_fit(sizes, cpus)[1])
    return [report.GrowthRow(measure, tuple(sizes), tuple(walls), tuple(cpus), *exponents)]


def prepare(
    args: argparse.Namespace, bench: Bench
) -> tuple[Path, tuple[Path, Path], tuple[str, str]]:
    """The two releases unpacked, checked for C sources, and committed as tags of a repo."""
    trees = []
    for version in args.releases:
        sdist = corpus.fetch_sdist(args.package, version, bench.work / "downloads", args.index)
        trees.append(corpus.unpack(sdist, bench.work / "src"))
        print(report.describe_tree(trees[-1]), flush=True)
    tags = (f"v{args.releases[0]}", f"v{args.releases[1]}")
    history = corpus.make_history(list(zip(tags, trees, strict=True)), bench.work / "history")
    return history, (trees[0], trees[1]), tags


def run(
    args: argparse.Namespace, save: Callable[[list[report.Result], list[str]], object]
) -> tuple[list[report.Result], list[str]]:
    """Every step asked for, saving the results so far after each; a step that fails is
    reported and the others still run."""
    bench = Bench(
        args.work.resolve(),
        Path(sys.executable).parent,
        args.jobs,
        args.repeat,
        args.timeout,
        args.single,
    )
    history, sources, tags = prepare(args, bench)
    head = sources[1]
    steps: dict[str, Callable[[], list[report.Result]]] = {
        "scan-c": lambda: scan_cfamily(
            bench, corpus.subset_tree(head, corpus.CFAMILY, bench.work / "trees/cfamily")
        ),
        "scan-py": lambda: scan_python(
            bench, corpus.subset_tree(head, corpus.PYTHON, bench.work / "trees/python")
        ),
        "diff": lambda: diff_rows(bench, history, sources, tags),
        "edit": lambda: edit_rows(bench, history, tags[1]),
        "edit-10x": lambda: edit_growth_rows(bench, head),
        "growth": lambda: growth(bench, head),
    }
    rows: list[report.Result] = []
    failures: list[str] = []
    for name in args.only:
        print(f"{name}:", flush=True)
        try:
            rows.extend(steps[name]())
        except BenchError as error:
            print(f"benchmark: {name} failed: {error}", file=sys.stderr)
            failures.append(f"{name}: {str(error).splitlines()[0]}")
        save(rows, failures)
    return rows, failures


def _compiled() -> None:
    """archmetrics's bytecode written, as pip writes it when it installs a wheel: a checkout
    run with PYTHONDONTWRITEBYTECODE set (as some CI images and this sandbox do) would
    otherwise compile every module it imports on every run (0.16 s of a 0.45 s diff), and
    the peers, installed by pip, are measured compiled."""
    import archmetrics

    compileall.compile_dir(Path(archmetrics.__file__).parent, quiet=1)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--package", default="numpy")
    parser.add_argument("--releases", nargs=2, default=["2.1.0", "2.2.0"], metavar="VERSION")
    parser.add_argument("--index", default=corpus.INDEX, help="the package index (PEP 691)")
    parser.add_argument("--repeat", type=int, default=3, help="runs per measure (median)")
    parser.add_argument("--jobs", type=int, default=_cores(), help="workers for every tool")
    parser.add_argument("--timeout", type=float, default=1800.0, help="seconds per run")
    parser.add_argument(
        "--single", action="store_true", help="add archmetrics -j 1 against radon (1 process)"
    )
    parser.add_argument("--only", nargs="+", choices=TASKS, default=list(TASKS))
    parser.add_argument("--work", type=Path, default=HERE / ".work")
    args = parser.parse_args(argv)
    _compiled()
    try:
        if "diff" in args.only:
            report.ensure_cloc()  # installed before the machine line names its version
        machine = report.machine(Path(sys.executable).parent)
        rows, failures = run(args, lambda r, f: _save(args, machine, r, f))
    except BenchError as error:
        print(f"benchmark: error: {error}", file=sys.stderr)
        return 2
    print(_save(args, machine, rows, failures))
    return 1 if failures else 0


def _save(
    args: argparse.Namespace,
    machine: dict[str, str],
    rows: list[report.Result],
    failures: list[str],
) -> str:
    """The results as Markdown and JSON in the work folder; returns the Markdown."""
    text = report.render(machine, rows, args)
    text += "".join(f"\nFAILED {failure}\n" for failure in failures)
    (args.work / "results.md").write_text(text)
    document = {"machine": machine, "rows": [asdict(row) for row in rows], "failed": failures}
    (args.work / "results.json").write_text(json.dumps(document, indent=1, default=str))
    return text


def _cores() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


if __name__ == "__main__":
    if shutil.which("git") is None:
        sys.exit("benchmark: error: git is not on PATH")
    raise SystemExit(main())
