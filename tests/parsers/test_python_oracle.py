"""Cross-validation against radon: our McCabe v_g per function equals radon's default count.

The corpus is real Python nobody here wrote: the installed sources of rich, GitPython,
libcst and part of pandas.core (about 400 files, deterministic selection). Functions are
matched by (file, def line). The deliberate differences are listed in
docs/metrics.md, each with a golden test; any disagreement printed here that is
not one of them is a bug on one side.
"""

from __future__ import annotations

import sys
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from radon.complexity import cc_visit

from archmetrics.parsers.python import parse

SITE_PACKAGES = (
    Path(sys.prefix)
    / "lib"
    / f"python{sys.version_info[0]}.{sys.version_info[1]}"
    / "site-packages"
)
CORPUS = (("rich", 120), ("git", 60), ("libcst", 250), ("pandas/core", 150))
MAX_BYTES = 60_000  # keeps the run well under a minute on a shared machine
REQUIRED_AGREEMENT = 0.98


def corpus() -> list[Path]:
    """Sorted, size-bounded, test-free sources of each package: the same files every run."""
    files: list[Path] = []
    for package, limit in CORPUS:
        found = sorted(
            path
            for path in (SITE_PACKAGES / package).rglob("*.py")
            if "tests" not in path.parts and path.stat().st_size < MAX_BYTES
        )
        files.extend(found[:limit])
    return files


def radon_functions(source: str) -> dict[int, tuple[str, int]]:
    """def line -> (name, complexity) for every function radon reports, nested ones flattened."""
    found: dict[int, tuple[str, int]] = {}

    def visit(block: object, prefix: str) -> None:
        if hasattr(block, "methods"):
            name = prefix + block.name  # type: ignore[attr-defined]
            for child in (*block.methods, *block.inner_classes):  # type: ignore[attr-defined]
                visit(child, name + ".")
            return
        name = prefix + block.name  # type: ignore[attr-defined]
        found[block.lineno] = (name, block.complexity)  # type: ignore[attr-defined]
        for closure in block.closures:  # type: ignore[attr-defined]
            visit(closure, name + ".")

    for block in cc_visit(source):
        if hasattr(block, "methods") or not block.is_method:
            visit(block, "")
    return found


@dataclass
class Comparison:
    agree: int = 0
    compared: int = 0
    only_ours: int = 0
    classes: Counter[str] = field(default_factory=Counter)
    examples: dict[str, list[str]] = field(default_factory=lambda: defaultdict(list))

    def disagree(self, kind: str, example: str) -> None:
        self.classes[kind] += 1
        if len(self.examples[kind]) < 5:
            self.examples[kind].append(example)

    def report(self) -> str:
        lines = [f"{self.agree}/{self.compared} functions agree; {self.only_ours} only ours"]
        for kind, count in self.classes.most_common():
            lines.append(f"  {kind}: {count}")
            lines.extend(f"      {example}" for example in self.examples[kind])
        return "\n".join(lines)


def compare(files: list[Path]) -> Comparison:
    result = Comparison()
    for path in files:
        source = path.read_text(encoding="utf-8")
        facts = parse(str(path), source)
        if not facts.parsed:
            result.disagree("unparsed by us", f"{path}: {facts.warnings}")
            continue
        ours = {f.span.start: f for f in facts.functions}
        theirs = radon_functions(source)
        result.only_ours += len(ours.keys() - theirs.keys())
        for line, (name, complexity) in theirs.items():
            where = f"{path.relative_to(SITE_PACKAGES)}:{line} {name}"
            function = ours.get(line)
            if function is None:
                result.disagree("radon function we do not find", where)
                continue
            result.compared += 1
            if function.complexity == complexity:
                result.agree += 1
                continue
            delta = function.complexity - complexity
            kinds = sorted({d.kind for d in function.decisions})
            result.disagree(
                f"ours {delta:+d}",
                f"{where}: ours {function.complexity} {kinds}, radon {complexity}",
            )
    return result


@pytest.mark.slow
def test_python_complexity_matches_radon_on_real_code() -> None:
    files = corpus()
    assert len(files) >= 300, f"corpus too small ({len(files)} files): packages missing?"
    result = compare(files)
    print(result.report())
    assert result.compared > 3000
    assert result.agree / result.compared >= REQUIRED_AGREEMENT, result.report()
