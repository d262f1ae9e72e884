"""The history benchmark's rows, its Markdown table, and the paper estimate of a
1,000,000-commit history on 100 cores (benchmarks/history_bench.py)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Line:
    """A row: ``value`` (in ``unit``) against ``goal``; met when above it (or below, for
    ``under``)."""

    measure: str
    ours: str  # archmetrics wall / CPU
    peer: str
    value: float
    unit: str
    goal: float
    under: bool = False
    note: str = ""

    def met(self) -> bool:
        return self.value < self.goal if self.under else self.value >= self.goal


def estimate(found: dict[str, float]) -> str:
    """A 1,000,000-commit history on 100 cores, on paper, from the measured costs."""
    needed = ("commits", "blobs", "cold_cpu", "step_cpu")
    if any(key not in found for key in needed):
        return "Estimate: needs the cold and incremental steps of the first repository."
    n, p = 1_000_000, 100
    step = found["step_cpu"]
    blob = max(found["cold_cpu"] - found["commits"] * step, 0.0) / max(found["blobs"], 1)
    blobs = n * found["blobs"] / max(found["commits"], 1)
    work = blobs * blob + n * step
    lines = [
        "Estimate, 1,000,000 commits on 100 cores (paper):",
        f"- per-commit step c_s = {step * 1000:.1f} ms CPU (incremental row); per-blob parse "
        f"c_b = (cold CPU {found['cold_cpu']:.1f} s - {found['commits']:.0f} x c_s) / "
        f"{found['blobs']:.0f} blobs = {blob * 1000:.1f} ms; blobs per commit "
        f"{found['blobs'] / max(found['commits'], 1):.2f}",
        f"- T = (B x c_b + N x c_s) / P = ({blobs:.0f} x {blob:.4f} + {n} x {step:.4f}) / {p}"
        f" = {work / p:.0f} s ({work / p / 3600:.2f} h), perfect scaling",
    ]
    if "dask1" in found and "dask2" in found:
        speedup = found["dask1"] / found["dask2"]
        serial = min(max(2 / speedup - 1, 0.0), 1.0)  # Amdahl: S2 = 1 / (f + (1 - f) / 2)
        amdahl = work * (serial + (1 - serial) / p)
        lines.append(
            f"- with Amdahl's serial fraction from Dask 2 vs 1 worker (S2 = {speedup:.2f}, "
            f"f = 2/S2 - 1 = {serial:.2f}): T = W x (f + (1 - f) / P) = {amdahl:.0f} s "
            f"({amdahl / 3600:.2f} h)"
        )
    return "\n".join(lines)


def render(machine: dict[str, str], lines: list[Line], found: dict[str, float]) -> str:
    head = [f"- {key}: {value}" for key, value in machine.items()]
    table = [
        "| measure | archmetrics wall / CPU | peer | ratio | goal | met | notes |",
        "|---|---|---|---|---|---|---|",
    ]
    for line in lines:
        goal = f"{'<' if line.under else '≥'} {line.goal:g} {line.unit}"
        met = "yes" if line.met() else "**no**"
        table.append(
            f"| {line.measure} | {line.ours} | {line.peer} | {line.value:.2f} "
            f"{line.unit} | {goal} | {met} | {line.note} |"
        )
    return "\n".join(head) + "\n\n" + "\n".join(table) + "\n\n" + estimate(found) + "\n"
