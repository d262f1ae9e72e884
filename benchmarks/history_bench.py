"""``archmetrics history`` against its goals: rate cold and warm, one commit's step against a
``diff``, Dask's scaling, wily, and the client's memory over 40,000 commits.

Run from a clean clone:
    .venv/bin/pip install -e '.[bench,dask]' && .venv/bin/python benchmarks/history_bench.py
Steps (--only STEP...): cold (warm runs after it), incremental, dask, wily, memory.
Options: --repo NAME=PATH_OR_URL (repeatable; default libuv and lua: the mirrors under
/work/.mirror if present, else their GitHub URLs), --python-repo NAME=PATH_OR_URL (wily's;
default click, likewise), --max-count N (every history limited to its newest N commits, for
a quick run; default all first-parent commits), --python-count N (wily's commits when
--max-count is not given; default 1000), --one-file K (one-file commits; default 5),
--synthetic N (the memory row's commits; default 40,000), --repeat N, --jobs N (parser
processes and Dask workers; default the cores), --work FOLDER. A quick run proving every
step works: ``--max-count 50 --repeat 1 --one-file 2``. Repositories are cloned once into the
work folder (default benchmarks/.work/history-bench; .work/history is run.py's repository of
two releases) and reused; every command's output is kept in its out/, the results in
results.md and results.json. A step that fails is reported (and
the script exits 1); the others still run.

The choices behind each row:
- cold: ``archmetrics history -j JOBS`` (first parents of HEAD) with an empty facts cache;
  warm: the same command again on the cache the cold run filled. Rate = commits / wall
  seconds. Commits and "distinct blobs parsed" are the JSON report's ``commits`` (its
  length) and ``parsed`` (the file versions the run parsed: every distinct blob the commits
  add, and the first tree read whole).
- one-file commit, incremental: the newest --one-file first-parent commits C (within the
  history) that change exactly one file, a measured one. For each, a cache is prepared with
  ``history C^ -n 20`` and ``diff --base C^ --head C`` (so every fact is in it, and C^'s
  state is kept, as after a history run), and saved. Incremental = the wall (and CPU) of
  ``history C -n 21`` on a fresh copy of that cache (only C's step missing) minus the same
  command again (every step kept): what measuring C adds to a warm history when C arrives,
  start-up and reading the kept steps cancelled out. Against the wall of ``diff --base C^
  --head C`` run a second time on the same cache (warm). Medians per commit, then the
  median over the commits. History reports no per-step time, hence the difference.
- Dask: the cold history of the first repository with ``--workers 2`` against
  ``--workers 1`` (an empty cache each run; the cluster's start-up is in both).
- wily: ``wily build -n N`` (its default operators) against ``archmetrics history
  --no-first-parent -n N`` cold on the same clone: wily follows every parent
  (``git log`` order), so archmetrics does too, for the same N newest commits. wily 1.25
  pins radon < 5.2 while the bench extra's radon (>= 6.0) is run.py's peer, so the script
  installs wily (pinned) with pip into a virtual environment of its own in the work folder.
- memory: a synthetic repository (40,000 commits, each rewriting one function of one of 8
  small C files in two folders; made by ``git fast-import``; no real one of that length is at
  hand offline), ``history --workers JOBS`` cold; the client's own peak RSS (VmHWM, read as
  it exits), and PSS summed over the process tree (client, scheduler, workers) beside it.
- the estimate under the table: a 1,000,000-commit history on 100 cores, from the cold run
  of the first repository and the incremental step (see ``estimate``).
Not part of the test suite.
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import subprocess
import sys
import traceback
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from functools import partial
from pathlib import Path

import history_repos as repos
import report
from corpus import BenchError
from history_table import Line, render
from measure import Summary, repeat
from run import _compiled, _cores

HERE = Path(__file__).resolve().parent
STEPS = ("cold", "warm", "incremental", "dask", "wily", "memory")
CONTEXT = 20  # commits of history before each one-file commit
WILY = "1.25.0"
PEAK = "archmetrics-bench client peak kB"
CLIENT = f"""import atexit, sys
def peak():
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            sys.stderr.write("{PEAK} " + line.split()[1] + "\\n")
atexit.register(peak)
from archmetrics.cli import main
sys.exit(main(sys.argv[1:]))
"""


@dataclass(slots=True)
class Bench:
    """Where things are, how hard to measure, and what the steps found so far."""

    work: Path
    bin: Path
    jobs: int
    times: int
    timeout: float
    count: int | None
    found: dict[str, float] = field(default_factory=dict)  # inputs of the estimate

    def tool(self, name: str) -> str:
        path = self.bin / name
        if not path.exists():
            raise BenchError(f"{path} is missing: run .venv/bin/pip install -e '.[bench,dask]'")
        return str(path)

    def out(self, name: str) -> Path:
        (self.work / "out").mkdir(parents=True, exist_ok=True)
        return self.work / "out" / name

    def cache(self, name: str) -> Path:
        (self.work / "caches").mkdir(parents=True, exist_ok=True)
        return self.work / "caches" / f"{name}.sqlite3"

    def command(self, verb: str, repo: Path, cache: Path, *more: str) -> list[str]:
        """``archmetrics VERB`` on ``repo`` with ``cache``, JSON on stdout, no progress."""
        command = [self.tool("archmetrics"), verb, "-C", str(repo), "-q", "-j", str(self.jobs)]
        return [*command, "--format", "json", "--cache-path", str(cache), *more]

    def history(self, repo: Path, cache: Path, *more: str) -> list[str]:
        limit = ["-n", str(self.count)] if self.count else []
        return self.command("history", repo, cache, *limit, *more)

    def run(
        self,
        name: str,
        command: list[str],
        before: Callable[[], None] = lambda: None,
        memory: bool = False,
        times: int | None = None,
    ) -> Summary:
        print(f"  {name}: {' '.join(command)}", flush=True)
        summary = repeat(
            command, self.work, times or self.times, self.timeout, self.out(name), before, memory
        )
        print(f"    median {summary.wall:.2f} s wall, {summary.cpu:.2f} s CPU", flush=True)
        return summary

    def document(self, name: str) -> dict[str, object]:
        try:
            loaded: dict[str, object] = json.loads(self.out(name).read_text())
        except ValueError as error:
            raise BenchError(f"{name}: the output is not JSON ({error})") from error
        return loaded


def remover(path: Path) -> Callable[[], None]:
    def remove() -> None:
        for candidate in (path, path.with_name(path.name + "-journal")):
            candidate.unlink(missing_ok=True)

    return remove


def pair(summary: Summary) -> str:
    return f"{summary.wall:.2f} / {summary.cpu:.2f} s"


def counts(document: dict[str, object]) -> tuple[int, int]:
    """(commits, file versions parsed) of a history's JSON report."""
    commits = document.get("commits")
    if not isinstance(commits, list):
        raise BenchError("the history report has no list of commits")
    return len(commits), int(str(document.get("parsed", 0)))


def cold_warm(bench: Bench, name: str, checkout: Callable[[], Path], first: bool) -> list[Line]:
    """The history cold (an empty cache), then warm (the cache it filled)."""
    repo = checkout()
    cache = bench.cache(f"{name}-history")
    command = bench.history(repo, cache)
    cold = bench.run(f"{name}.cold", command, before=remover(cache), memory=True)
    commits, blobs = counts(bench.document(f"{name}.cold"))
    per = blobs / max(commits, 1)
    note = f"{commits} commits, {blobs} distinct blobs parsed ({per:.2f} per commit)"
    note += f"; peak PSS {cold.tree_pss_mb:.0f} MB"
    measure = f"history cold, {name}, {bench.jobs} cores"
    lines = [Line(measure, pair(cold), "-", commits / cold.wall, "commits/s", 40.0, note=note)]
    if first:
        bench.found.update(commits=commits, blobs=blobs, cold_cpu=cold.cpu, cold_wall=cold.wall)
    warm = bench.run(f"{name}.warm", command)
    measured = int(str(bench.document(f"{name}.warm").get("measured", -1)))
    note = f"{measured} commits measured again"
    rate = commits / warm.wall
    lines.append(
        Line(f"history warm, {name}", pair(warm), "-", rate, "commits/s", 500.0, note=note)
    )
    return lines


def one_step(bench: Bench, name: str, repo: Path, commit: str) -> tuple[float, ...]:
    """``commit``'s step in a warm history and ``diff C^..C`` warm: wall and CPU of each."""
    cache, saved = bench.cache(f"{name}-one"), bench.cache(f"{name}-one-saved")
    remover(cache)()
    label = f"{name}.{commit[:10]}"
    context = bench.command("history", repo, cache, "-n", str(CONTEXT), f"{commit}^")
    bench.run(f"{label}.context", context, times=1)
    diff = bench.command("diff", repo, cache, "--base", f"{commit}^", "--head", commit)
    bench.run(f"{label}.diff-cold", diff, times=1)
    shutil.copyfile(cache, saved)

    def restore() -> None:
        remover(cache)()
        shutil.copyfile(saved, cache)

    history = bench.command("history", repo, cache, "-n", str(CONTEXT + 1), commit)
    new = bench.run(f"{label}.step", history, before=restore)
    if bench.document(f"{label}.step").get("measured") != 1:
        raise BenchError(f"{name}: history {commit} measured more than its one new commit")
    kept = bench.run(f"{label}.kept", history)
    warm = bench.run(f"{label}.diff-warm", diff)
    return new.wall - kept.wall, new.cpu - kept.cpu, warm.wall, warm.cpu


def incremental(bench: Bench, name: str, checkout: Callable[[], Path], wanted: int) -> list[Line]:
    """Per one-file commit C: ``history C -n 21`` with only C's step missing, minus the
    same with every step kept, against ``diff --base C^ --head C`` warm."""
    repo = checkout()
    picked = repos.one_file_commits(repo, bench.count, wanted)
    if not picked:
        raise BenchError(f"{name}: no first-parent commit changes exactly one measured file")
    found = [one_step(bench, name, repo, commit) for commit in picked]
    step, step_cpu, diff, diff_cpu = (statistics.median(v) for v in zip(*found, strict=True))
    if step <= 0 or step_cpu <= 0:  # a difference of two whole runs: their noise can win
        steps = ", ".join(f"{f[0]:.3f}" for f in found)
        raise BenchError(
            f"{name}: a one-file step is below the noise of two whole runs (steps, wall s: "
            f"{steps}; CPU median {step_cpu:.3f} s): run again with --repeat 5 or more"
        )
    bench.found.setdefault("step_cpu", step_cpu)
    measure = f"one-file commit's step in a warm history, {name} ({len(picked)} commits)"
    ours = f"{step:.3f} / {step_cpu:.3f} s"
    peer = f"diff C^..C warm: {diff:.3f} / {diff_cpu:.3f} s"
    note = f"CPU: {diff_cpu / max(step_cpu, 1e-4):.1f}x; steps (wall s): "
    note += ", ".join(f"{f[0]:.3f}" for f in found)
    return [Line(measure, ours, peer, diff / max(step, 1e-4), "x", 10.0, note=note)]


def dask(bench: Bench, name: str, checkout: Callable[[], Path]) -> list[Line]:
    """The cold history on a local Dask cluster of 2 workers against 1."""
    repo = checkout()
    runs = {}
    for workers in (1, 2):
        cache = bench.cache(f"{name}-dask{workers}")
        command = bench.history(repo, cache, "--workers", str(workers))
        runs[workers] = bench.run(f"{name}.dask{workers}", command, before=remover(cache))
    bench.found.update(dask1=runs[1].wall, dask2=runs[2].wall)
    measure, peer = f"history cold on Dask, {name}, 2 workers vs 1", f"1 worker: {pair(runs[1])}"
    return [Line(measure, pair(runs[2]), peer, runs[1].wall / runs[2].wall, "x", 1.7)]


def wily_tool(bench: Bench) -> str:
    """wily, in a virtual environment of its own in the work folder (made once): wily
    1.25 pins radon < 5.2, and the bench extra's radon (>= 6.0) is run.py's peer."""
    folder = bench.work / "wily-venv"
    tool = folder / "bin" / "wily"
    if not tool.exists():
        print(f"  installing wily {WILY} into {folder}", flush=True)
        for command in (
            [sys.executable, "-m", "venv", str(folder)],
            [str(folder / "bin" / "python"), "-m", "pip", "install", "-q", f"wily=={WILY}"],
        ):
            done = subprocess.run(command, capture_output=True, text=True, timeout=900)
            if done.returncode:
                raise BenchError(f"cannot install wily: {done.stderr.strip()[-500:]}")
    return str(tool)


def wily(bench: Bench, name: str, checkout: Callable[[], Path], count: int) -> list[Line]:
    """wily build -n N against archmetrics history --no-first-parent -n N, both cold."""
    repo = checkout()
    tool = wily_tool(bench)
    wily_cache = bench.work / "caches" / f"{name}-wily"
    cache = bench.cache(f"{name}-python")
    ours_command = bench.history(repo, cache, "--no-first-parent")
    if not bench.count:
        ours_command += ["-n", str(count)]
    ours = bench.run(f"{name}.archmetrics", ours_command, before=remover(cache))
    commits, blobs = counts(bench.document(f"{name}.archmetrics"))

    def clean() -> None:
        shutil.rmtree(wily_cache, ignore_errors=True)

    build = [tool, "--cache", str(wily_cache), "-p", str(repo), "build", "-n", str(commits)]
    theirs = bench.run(f"{name}.wily", [*build, str(repo)], before=clean)
    measure = f"history of {commits} commits of {name} (Python), cold"
    peer, note = f"wily build -n {commits}: {pair(theirs)}", f"{blobs} blobs parsed"
    return [Line(measure, pair(ours), peer, theirs.wall / ours.wall, "x", 1.0, note=note)]


def memory(bench: Bench, commits: int) -> list[Line]:
    """The client's peak RSS over a synthetic history, on a local Dask cluster."""
    repo = repos.synthetic_repository(bench.work / "repos" / f"synthetic-{commits}", commits)
    cache = bench.cache("synthetic")
    command = bench.history(repo, cache, "--workers", str(bench.jobs))
    command = [sys.executable, "-c", CLIENT, *command[1:]]
    name = "synthetic.memory"
    run = bench.run(name, command, before=remover(cache), memory=True, times=1)
    measured, _ = counts(bench.document(name))
    errors = bench.out(name).with_name(name + ".err").read_text(errors="replace")
    peaks = [line.split()[-1] for line in errors.splitlines() if line.startswith(PEAK)]
    if not peaks:
        raise BenchError("the client did not report its peak RSS")
    client = int(peaks[-1]) / 1024
    measure = f"client peak RSS, synthetic history of {measured} commits, Dask"
    ours, note = f"{client:.0f} MB ({pair(run)})", f"tree peak PSS {run.tree_pss_mb:.0f} MB"
    return [Line(measure, ours, "-", client, "MB", 1000.0, under=True, note=note)]


def run(
    args: argparse.Namespace, bench: Bench, save: Callable[[list[Line], list[str]], object]
) -> tuple[list[Line], list[str]]:
    defaults = repos.DEFAULT_REPOS.items()
    sources = dict(args.repo or [(n, repos.default_source(m, u)) for n, (m, u) in defaults])
    python = args.python_repo or (
        repos.DEFAULT_PYTHON[0],
        repos.default_source(*repos.DEFAULT_PYTHON[1:]),
    )
    first = next(iter(sources))

    def clone(name: str) -> Path:
        source = sources.get(name) or python[1]
        return repos.clone(source, bench.work / "repos" / name)

    steps: list[tuple[str, str, Callable[[], list[Line]]]] = []
    for name in sources:
        steps.append(
            ("cold", name, partial(cold_warm, bench, name, partial(clone, name), name == first))
        )
        steps.append(
            (
                "incremental",
                name,
                partial(incremental, bench, name, partial(clone, name), args.one_file),
            )
        )
    steps.append(("dask", first, partial(dask, bench, first, partial(clone, first))))
    count = args.max_count or args.python_count
    steps.append(
        ("wily", python[0], partial(wily, bench, python[0], partial(clone, python[0]), count))
    )
    steps.append(("memory", "synthetic", partial(memory, bench, args.synthetic)))
    lines: list[Line] = []
    failures: list[str] = []
    for step, name, call in steps:
        if step not in args.only and not (step == "cold" and "warm" in args.only):
            continue
        print(f"{step} ({name}):", flush=True)
        try:
            lines.extend(call())
        except Exception as error:  # a step that fails is reported, the others still run
            if not isinstance(error, BenchError):
                traceback.print_exc()
            print(f"benchmark: {step} ({name}) failed: {error}", file=sys.stderr)
            failures.append(f"{step} ({name}): {str(error).splitlines()[0]}")
        save(lines, failures)
    return lines, failures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument(
        "--repo", action="append", type=repos.parse_repo, metavar="NAME=PATH_OR_URL"
    )
    parser.add_argument("--python-repo", type=repos.parse_repo, metavar="NAME=PATH_OR_URL")
    parser.add_argument("--max-count", type=int, help="the newest N commits of every history")
    parser.add_argument("--python-count", type=int, default=1000, help="wily's commits")
    parser.add_argument("--one-file", type=int, default=5, help="one-file commits to measure")
    parser.add_argument("--synthetic", type=int, default=40_000, help="synthetic commits")
    parser.add_argument("--repeat", type=int, default=3, help="runs per measure (median)")
    parser.add_argument("--jobs", type=int, default=_cores(), help="parser processes, workers")
    parser.add_argument("--timeout", type=float, default=7200.0, help="seconds per run")
    parser.add_argument("--only", nargs="+", choices=STEPS, default=list(STEPS))
    parser.add_argument("--work", type=Path, default=HERE / ".work" / "history-bench")
    args = parser.parse_args(argv)
    _compiled()  # archmetrics's bytecode, as pip writes it (run.py says why)
    args.work = args.work.resolve()
    args.work.mkdir(parents=True, exist_ok=True)
    bench = Bench(
        args.work, Path(sys.executable).parent, args.jobs, args.repeat, args.timeout, args.max_count
    )
    machine = report.machine(bench.bin)
    machine["wily"] = f"{WILY} (its own virtual environment in the work folder)"
    machine["runs per measure"] = f"{args.repeat} (medians), jobs/workers: {args.jobs}"
    machine["commits per history"] = str(args.max_count or "all first-parent")

    def save(lines: list[Line], failures: list[str]) -> str:
        text = render(machine, lines, bench.found)
        text += "".join(f"\nFAILED {failure}\n" for failure in failures)
        (args.work / "results.md").write_text(text)
        document = {
            "machine": machine,
            "rows": [asdict(line) for line in lines],
            "estimate_inputs": bench.found,
            "failed": failures,
        }
        (args.work / "results.json").write_text(json.dumps(document, indent=1))
        return text

    lines, failures = run(args, bench, save)
    print(save(lines, failures))
    return 1 if failures else 0


if __name__ == "__main__":
    if shutil.which("git") is None:
        sys.exit("benchmark: error: git is not on PATH")
    raise SystemExit(main())
