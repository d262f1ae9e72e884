"""Time the parsers on pathological input: deep nesting, long chains, one-line files.

Run:  .venv/bin/python benchmarks/pathological.py [--only WORD] [--scale 0.5] [--timeout 120]

Each input is generated, written to a temporary file and parsed by parse_source (default
ParseLimits) in a child process of its own, so that a crash or a runaway costs one row:
the row gives the input's size, the child's wall-clock seconds and peak RSS, and whether
the file was measured or refused (the warning). Sizes are those of the reports the limits
were made for (docs/metrics.md, "Limits"); ``--scale`` shrinks or grows them. Not a test:
the tests (tests/parsers/test_*_limits.py) assert outcomes, never times.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

Make = Callable[[int], str]


def _ifexp(n: int) -> str:
    return "def f():\n    return " + "".join(f"{i} if c{i} else " for i in range(n)) + "0\n"


def _elif(n: int) -> str:
    arms = "".join(f"    elif x == {i}:\n        return {i}\n" for i in range(1, n + 1))
    return f"def f(x):\n    if x == 0:\n        return 0\n{arms}"


def _stdlib(megabytes: int) -> str:
    """Real code: the standard library's modules that parse, concatenated to the size."""
    import ast
    import sysconfig

    parts, size = [], 0
    folder = Path(sysconfig.get_paths()["stdlib"])
    while size < megabytes * 1_000_000:
        for path in sorted(folder.glob("*.py")):
            text = path.read_text("utf-8", "replace").replace("from __future__", "import os #")
            try:
                ast.parse(text)
            except SyntaxError:
                continue
            parts.append(text if text.endswith("\n") else text + "\n")
            size += len(parts[-1])
            if size >= megabytes * 1_000_000:
                break
    return "".join(parts)


def _c(body: str) -> str:
    return "int f(int x) {\n" + body + "\n}\n"


# (name, language, make, size) — the sizes of the reproductions
CASES: list[tuple[str, str, Make, int]] = [
    ("py parentheses", "python", lambda n: "x = " + "(" * n + "1" + ")" * n + "\n", 10_000),
    ("py attribute chain", "python", lambda n: "x = a" + ".b" * n + "\n", 10_000),
    ("py sum chain", "python", lambda n: "x = " + " + ".join(["a"] * n) + "\n", 10_000),
    ("py ifexp chain", "python", _ifexp, 3_000),
    ("py elif chain", "python", _elif, 1_000),
    ("py method chain", "python", lambda n: "x = a" + ".m(1)" * n + "\n", 8_000),
    ("py 3.12 + ifexp", "python", lambda n: "type T = int\n" + _ifexp(n), 3_000),
    ("py stdlib MB", "python", _stdlib, 10),
    ("c nested ifs", "c", lambda n: _c("if (x) {\n" * n + "x++;\n" + "}\n" * n), 8_000),
    (
        "c else-if chain",
        "c",
        lambda n: _c(
            "".join(f"else if (x=={i}) x={i};\n" for i in range(n)).replace("else ", "", 1)
        ),
        4_000,
    ),
    ("c unbalanced ([{", "c", lambda n: _c("([{" * n), 10_000),
    ("c nested calls", "c", lambda n: _c("return " + "g(" * n + "x" + ")" * n + ";"), 9_000),
    ("c call chain", "cpp", lambda n: _c("x" + ".m()" * n + ";"), 9_000),
    (
        "c ternary chain",
        "c",
        lambda n: _c("return " + "".join(f"x=={i}?{i}:" for i in range(n)) + "0;"),
        4_000,
    ),
    (
        "c #elif chain",
        "c",
        lambda n: (
            "#if A0\n" + "".join(f"#elif A{i}\nint a{i};\n" for i in range(1, n)) + "#endif\n"
        ),
        4_000,
    ),
    ("cpp classes in methods", "cpp", lambda n: "class A { void f() {" * n + "}" * n + ";", 4_000),
    ("cpp deep templates", "cpp", lambda n: _c("A<" * n + "int" + ">" * n + "::g();"), 3_000),
    # the token reading (damage everywhere): a head across thousands of #if groups, a K&R
    # head with thousands of declarations, thousands of macro calls without `;`
    ("c #if around one head", "c", lambda n: "@\n" + "#if A\nX(a)\n#endif\n" * n + "{}\n", 20_000),
    ("c K&R declarations", "c", lambda n: "@\nint f(a)\n" + "int a;\n" * n + "{ }\n", 20_000),
    ("c macro calls no ;", "c", lambda n: "@\n" + "DECLARE(x)\n" * n + "int f(void) { }\n", 40_000),
    (
        "c one-line initializer",
        "c",
        lambda n: "int t[] = {" + ",".join(map(str, range(n))) + "};\n",
        1_000_000,
    ),
]


def child(path: str, language: str) -> None:
    from archmetrics.parsers import LanguageTable, parse_source

    data = Path(path).read_bytes()
    started = time.perf_counter()
    facts = parse_source(path, data, language, LanguageTable.default(plugins=False))
    seconds = time.perf_counter() - started
    warning = next((w.message for w in facts.warnings if w.severity == "error"), "")
    print(json.dumps({"seconds": seconds, "parsed": facts.parsed, "warning": warning}))


def run(path: str, language: str, timeout: float) -> tuple[dict[str, object], float]:
    """The child's answer and its peak RSS in MB (timeouts and crashes say so)."""
    command = [sys.executable, __file__, "--child", path, language]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + timeout
    while True:
        pid, status, usage = os.wait4(process.pid, os.WNOHANG)
        if pid:
            break
        if time.monotonic() > deadline:
            process.kill()
            _, status, usage = os.wait4(process.pid, 0)
            return {"outcome": f"killed after {timeout:g} s"}, usage.ru_maxrss / 1024
        time.sleep(0.05)
    assert process.stdout is not None
    out = process.stdout.read().decode()
    if os.WIFSIGNALED(status):
        return {"outcome": f"crashed: signal {os.WTERMSIG(status)}"}, usage.ru_maxrss / 1024
    if status:
        return {"outcome": f"exit status {os.WEXITSTATUS(status)}"}, usage.ru_maxrss / 1024
    answer: dict[str, object] = json.loads(out)
    return answer, usage.ru_maxrss / 1024


def main() -> int:
    if len(sys.argv) == 4 and sys.argv[1] == "--child":
        child(sys.argv[2], sys.argv[3])
        return 0
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--only", default="", help="cases whose name holds this word")
    parser.add_argument("--scale", type=float, default=1.0, help="multiply every size")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds per case")
    args = parser.parse_args()
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))  # a crash leaves no core file
    print(f"{'case':24} {'size':>8} {'bytes':>11} {'seconds':>8} {'peak MB':>8}  outcome")
    for name, language, make, size in CASES:
        if args.only not in name:
            continue
        scaled = max(1, int(size * args.scale))
        source = make(scaled)
        suffix = {"python": ".py", "c": ".c", "cpp": ".cpp"}[language]
        with tempfile.NamedTemporaryFile("w", suffix=suffix, delete=False) as handle:
            handle.write(source)
        try:
            answer, peak = run(handle.name, language, args.timeout)
        finally:
            os.unlink(handle.name)
        seconds = answer.get("seconds")
        shown = f"{seconds:8.2f}" if isinstance(seconds, float) else f"{'-':>8}"
        outcome = answer.get("outcome") or (
            "measured" if answer.get("parsed") else f"refused: {answer.get('warning', '')}"
        )
        size_bytes = len(source.encode())
        print(f"{name:24} {scaled:>8} {size_bytes:>11,} {shown} {peak:8.0f}  {outcome}"[:200])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
