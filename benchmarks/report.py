"""The benchmark's rows, the machine they ran on, and the Markdown table that shows them."""

from __future__ import annotations

import argparse
import os
import platform
import re
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import corpus
from corpus import Tree
from measure import Summary

_NUMBERS = re.compile(r"[\d.\s]+")  # lizard's totals line
_LIZARD_FILE_LINE = re.compile(r"^\s*\d+\s+\d+\.\d+\s+\d+\.\d+\s+\d+\.\d+\s+\d+\s+\S")


@dataclass(frozen=True, slots=True)
class Row:
    """archmetrics (``ours``) against a peer on the same files; ``goal`` is the speed-up wanted
    (0: none, a row for reference)."""

    measure: str
    tree: Tree | None
    ours: Summary
    theirs: Summary | None
    peer: str
    goal: float
    files: tuple[int, int] | None = None  # files each side reported measuring


@dataclass(frozen=True, slots=True)
class MemoryRow:
    measure: str
    ours: Summary
    limit_mb: float


@dataclass(frozen=True, slots=True)
class GrowthRow:
    measure: str
    sizes: tuple[float, ...]  # bytes of source
    seconds: tuple[float, ...]  # median wall seconds
    cpu: tuple[float, ...]  # median CPU seconds
    exponent: float  # b in seconds = a * size ** b, wall time
    cpu_exponent: float  # the same for CPU time


Result = Row | MemoryRow | GrowthRow


def lizard_files(output: Path) -> int:
    """How many files lizard's default report lists."""
    return sum(
        1
        for line in output.read_text(errors="replace").splitlines()
        if _LIZARD_FILE_LINE.match(line) and not _NUMBERS.fullmatch(line)
    )


def ensure_cloc() -> str | None:
    """The cloc executable; installed from Debian when missing and we are root, else None."""
    found = shutil.which("cloc")
    if found or not (hasattr(os, "geteuid") and os.geteuid() == 0 and shutil.which("apt-get")):
        if not found:
            print(
                "  cloc is missing: install it (Debian: sudo apt-get install -y cloc); skipping it"
            )
        return found
    print("  cloc is missing: apt-get install -y cloc", flush=True)
    try:
        subprocess.run(
            ["apt-get", "install", "-y", "cloc"], capture_output=True, timeout=600, check=True
        )
    except (subprocess.CalledProcessError, subprocess.TimeoutExpired) as error:
        print(f"  could not install cloc ({error}); skipping it")
    return shutil.which("cloc")


def _version(command: list[str]) -> str:
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return "missing"
    lines = (done.stdout or done.stderr).strip().splitlines()
    return lines[0] if lines else "?"


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "?"


def machine(bin_folder: Path) -> dict[str, str]:
    """What the figures were measured on."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    load = " ".join(f"{x:.1f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "?"
    return {
        "cpu": _cpu_model(),
        "cores": str(cores),
        "load average at start (1, 5, 15 min)": load,
        "os": platform.platform(),
        "python": platform.python_version(),
        "archmetrics": _version([str(bin_folder / "archmetrics"), "--version"]),
        "lizard": _version([str(bin_folder / "lizard"), "--version"]),
        "radon": _version([str(bin_folder / "radon"), "--version"]),
        "cloc": _version(["cloc", "--version"]),
        "git": _version(["git", "--version"]),
    }


def describe_tree(root: Path) -> str:
    """A line on a release: its measured files by ending and the git submodules it carries
    (numpy vendors several; an sdist without their sources would be a poorer benchmark)."""
    counts = corpus.describe_sources(root)
    lines = [f"{root.name}: " + ", ".join(f"{n} {e}" for e, n in counts.items())]
    modules = root / ".gitmodules"
    if modules.is_file():
        for path in re.findall(r"path\s*=\s*(\S+)", modules.read_text()):
            held = sum(1 for p in (root / path).rglob("*") if p.is_file())
            lines.append(f"  submodule {path}: {held} files" + ("" if held else " (MISSING)"))
    return "\n".join(lines)


def _pair(s: Summary) -> str:
    return f"{s.wall:.1f} / {s.cpu:.1f}"


def _speed_row(row: Row) -> str:
    files = f"{row.files[0]} / {row.files[1]}" if row.files else "-"
    if row.tree is not None:
        files += f" ({row.tree.bytes / 1e6:.1f} MB)"
    goal = f"≥ {row.goal:.3g}x" if row.goal else "(reference)"
    if row.theirs is None:
        return f"| {row.measure} | {files} | {_pair(row.ours)} | {row.peer} | - | {goal} | - |"
    wall, cpu = row.theirs.wall / row.ours.wall, row.theirs.cpu / row.ours.cpu
    met = "-" if not row.goal else "yes" if wall >= row.goal else "**no**"
    return (
        f"| {row.measure} | {files} | {_pair(row.ours)} | {row.peer}: {_pair(row.theirs)} "
        f"| {wall:.2f}x / {cpu:.2f}x | {goal} | {met} |"
    )


def _line(row: Result) -> str:
    if isinstance(row, Row):
        return _speed_row(row)
    if isinstance(row, MemoryRow):
        peak = row.ours.tree_pss_mb
        met = "yes" if peak < row.limit_mb else "**no**"
        return (
            f"| {row.measure} | - | {peak:.0f} MB (PSS summed over the process tree; "
            f"largest process RSS {row.ours.max_rss_mb:.0f} MB) | - | - "
            f"| < {row.limit_mb:g} MB | {met} |"
        )
    points = ", ".join(
        f"{s / 1e6:.1f} MB: {t:.1f} / {c:.1f} s"
        for s, t, c in zip(row.sizes, row.seconds, row.cpu, strict=True)
    )
    met = "yes" if max(row.exponent, row.cpu_exponent) <= 1.15 else "**no**"
    fit = f"b = {row.exponent:.2f} (wall) / {row.cpu_exponent:.2f} (CPU)"
    return f"| {row.measure} | {points} | {fit} | - | - | b ≈ 1 | {met} |"


def render(machine_info: dict[str, str], rows: list[Result], args: argparse.Namespace) -> str:
    """The results as Markdown: the machine, then one table row per measure."""
    head = [f"- {key}: {value}" for key, value in machine_info.items()]
    head.append(f"- runs per measure: {args.repeat} (medians), workers: {args.jobs}")
    head.append(f"- corpus: {args.package} {args.releases[0]} and {args.releases[1]} sdists")
    table = [
        "| measure | files ours / peer | archmetrics wall / CPU s | peer wall / CPU s "
        "| speed-up wall / CPU | goal | met |",
        "|---|---|---|---|---|---|---|",
        *(_line(row) for row in rows),
    ]
    return "\n".join(head) + "\n\n" + "\n".join(table) + "\n"
