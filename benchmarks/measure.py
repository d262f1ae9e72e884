"""Running a command and measuring it: wall time, CPU time, and peak memory of its process tree.

Wall time is what a user waits; CPU time (user + system of the whole tree, from ``wait4``)
is steadier on a shared machine, so both are kept. Memory is measured two ways: the peak RSS
of the largest single process (exact, from the kernel's rusage) and the peak of the
proportional set size (PSS: shared pages split between their sharers, so forked workers do
not count their parent's pages again) summed over the whole tree, sampled from /proc every
100 ms (Linux only).

Descendants that outlive their parent are counted too: archmetrics's parser workers are
children of a multiprocessing fork server, which its parent never waits for, so ``wait4`` on
the command alone would miss their CPU. This process makes itself a child subreaper
(``PR_SET_CHILD_SUBREAPER``): such orphans become its children, and their usage is added when
it reaps them.
"""

from __future__ import annotations

import contextlib
import ctypes
import math
import os
import signal
import statistics
import subprocess
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from corpus import BenchError

SAMPLE_EVERY = 0.1
_PR_SET_CHILD_SUBREAPER = 36


def _become_subreaper() -> bool:
    """Adopt orphaned descendants (Linux); False where the platform has no such thing."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return bool(libc.prctl(_PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) == 0)
    except (OSError, AttributeError):
        return False


SUBREAPER = _become_subreaper()


def _reap_orphans(deadline: float) -> tuple[float, int]:
    """Wait for the adopted descendants still running: their CPU seconds, summed, and the
    largest peak RSS among them (kB)."""
    cpu, max_rss = 0.0, 0
    while SUBREAPER:
        try:
            pid, _, usage = os.wait4(-1, os.WNOHANG)
        except ChildProcessError:
            break  # none left
        if pid == 0:
            if time.monotonic() > deadline:
                break
            time.sleep(0.01)
            continue
        cpu += usage.ru_utime + usage.ru_stime
        max_rss = max(max_rss, usage.ru_maxrss)
    return cpu, max_rss


@dataclass(frozen=True, slots=True)
class Run:
    """One run of a command."""

    wall: float  # seconds
    cpu: float  # user + system seconds over the process and every descendant it waited for
    max_rss_mb: float  # the largest single process's peak resident set
    tree_pss_mb: float  # the peak of PSS summed over the process tree (0 if not sampled)


@dataclass(frozen=True, slots=True)
class Summary:
    """Medians over several runs of one command."""

    command: tuple[str, ...]
    runs: tuple[Run, ...]

    @property
    def wall(self) -> float:
        return statistics.median(r.wall for r in self.runs)

    @property
    def cpu(self) -> float:
        return statistics.median(r.cpu for r in self.runs)

    @property
    def max_rss_mb(self) -> float:
        return max(r.max_rss_mb for r in self.runs)

    @property
    def tree_pss_mb(self) -> float:
        return max(r.tree_pss_mb for r in self.runs)


def _children(pid: int) -> list[int]:
    found: list[int] = []
    try:
        for task in os.listdir(f"/proc/{pid}/task"):
            with open(f"/proc/{pid}/task/{task}/children") as handle:
                found.extend(int(c) for c in handle.read().split())
    except OSError:
        pass
    return found


def _pss_kb(pid: int) -> int:
    """The process's PSS (its RSS where the kernel has no smaps_rollup), in kB."""
    for name, key in ((f"/proc/{pid}/smaps_rollup", "Pss:"), (f"/proc/{pid}/status", "VmRSS:")):
        try:
            with open(name) as handle:
                for line in handle:
                    if line.startswith(key):
                        return int(line.split()[1])
        except OSError:
            continue
    return 0


def tree_pss_kb(root: int) -> int:
    """The PSS of ``root`` and all its descendants, in kB, right now."""
    total, todo = 0, [root]
    while todo:
        pid = todo.pop()
        total += _pss_kb(pid)
        todo.extend(_children(pid))
    return total


class _Sampler(threading.Thread):
    def __init__(self, pid: int):
        super().__init__(daemon=True)
        self.pid, self.peak_kb, self.done = pid, 0, threading.Event()

    def run(self) -> None:
        while not self.done.wait(SAMPLE_EVERY):
            self.peak_kb = max(self.peak_kb, tree_pss_kb(self.pid))


def run_once(
    command: Sequence[str],
    cwd: Path,
    timeout: float,
    out: Path,
    sample_memory: bool = False,
    ok: tuple[int, ...] = (0,),
) -> Run:
    """Run ``command`` to completion, its stdout to ``out`` and its stderr next to it;
    BenchError if it fails or outlives ``timeout`` seconds."""
    log = out.with_name(out.name + ".err")
    with open(out, "wb") as output, open(log, "wb") as errors:
        start = time.perf_counter()
        process = subprocess.Popen(
            list(command),
            cwd=cwd,
            stdout=output,
            stderr=errors,
            start_new_session=True,
        )
        killed = threading.Event()

        def kill() -> None:
            killed.set()
            with contextlib.suppress(ProcessLookupError):
                os.killpg(process.pid, signal.SIGKILL)

        timer = threading.Timer(timeout, kill)
        timer.start()
        sampler = _Sampler(process.pid)
        if sample_memory:
            sampler.start()
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.perf_counter() - start
        orphans_cpu, orphans_rss = _reap_orphans(time.monotonic() + 30)
        timer.cancel()
        sampler.done.set()
        process.returncode = os.waitstatus_to_exitcode(status)
    if killed.is_set():
        raise BenchError(f"timed out after {timeout:.0f} s: {' '.join(command)}")
    if process.returncode not in ok:
        tail = log.read_text(errors="replace")[-2000:]
        raise BenchError(f"exit {process.returncode}: {' '.join(command)}\n{tail}")
    return Run(
        wall,
        usage.ru_utime + usage.ru_stime + orphans_cpu,
        max(usage.ru_maxrss, orphans_rss) / 1024,
        sampler.peak_kb / 1024,
    )


def repeat(
    command: Sequence[str],
    cwd: Path,
    times: int,
    timeout: float,
    out: Path,
    before: Callable[[], None] = lambda: None,
    sample_memory: bool = False,
    ok: tuple[int, ...] = (0,),
) -> Summary:
    """``times`` runs of ``command``, calling ``before`` ahead of each (to empty a cache)."""
    runs = []
    for _ in range(times):
        before()
        runs.append(run_once(command, cwd, timeout, out, sample_memory, ok))
    return Summary(tuple(command), tuple(runs))


def power_fit(sizes: Sequence[float], seconds: Sequence[float]) -> tuple[float, float]:
    """``(a, b)`` of the least-squares fit ``seconds = a * size ** b`` in log-log space."""
    xs, ys = [math.log(s) for s in sizes], [math.log(t) for t in seconds]
    mean_x, mean_y = statistics.fmean(xs), statistics.fmean(ys)
    sxx = sum((x - mean_x) ** 2 for x in xs)
    if sxx == 0:
        raise BenchError("a growth fit needs at least two different sizes")
    b = sum((x - mean_x) * (y - mean_y) for x, y in zip(xs, ys, strict=True)) / sxx
    return math.exp(mean_y - b * mean_x), b
