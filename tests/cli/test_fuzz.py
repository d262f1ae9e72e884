"""Fuzzing the CLI with what a hostile repository can hold: random bytes and deep nesting in
source files, odd file names, random configurations and rule packs.

Whatever the input, a run ends with exit 0, 1 (only when a gate failed) or 2, prints no
traceback, writes only the cache directory and the ``--output`` file, and leaves the
repository (work tree and ``.git``) exactly as it was. Examples are bounded and, in CI,
derandomized, so the suite stays fast and repeatable.
"""

from __future__ import annotations

import io
import os
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager, redirect_stderr, redirect_stdout
from pathlib import Path
from tempfile import TemporaryDirectory
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from archmetrics.cli import main
from tests.gitrepo import _ENV
from tests.untrusted import checksums

FUZZ = settings(
    max_examples=int(os.environ.get("ARCHMETRICS_FUZZ_EXAMPLES", "25")),
    deadline=None,
    derandomize=os.environ.get("CI") == "true",
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    database=None,
)

# ---------------------------------------------------------------------------- strategies

OPENERS = ["(", "[", "{", "if (x) {", "#if A\n", "#else\n", "def f():\n ", "class A {", "x = "]
PIECES = ["a", "1", " + ", " if c else ", ".b", ",", ";", "\n", '"', "'''", "\\", "#endif\n",
          "else if (y) ", "elif z:\n  ", "lambda: ", "}", ")", "]", "\t", "\x00", "é",
          "\x1b["]  # fmt: skip


@st.composite
def nested_source(draw: st.DrawFn) -> bytes:
    """Code-shaped text nested up to thousands deep, often unbalanced."""
    opener = draw(st.sampled_from(OPENERS))
    depth = draw(st.integers(0, 3000))
    body = "".join(draw(st.lists(st.sampled_from(PIECES), max_size=40)))
    closer = {"(": ")", "[": "]", "{": "}"}.get(opener[-1], "")
    close = draw(st.integers(0, depth))
    return (opener * depth + body + closer * close).encode("utf-8")


sources = st.one_of(st.binary(max_size=3000), nested_source())
endings = st.sampled_from([".py", ".c", ".h", ".cpp", ".hpp"])
plain_names = st.sampled_from(["a", "src/b", "lib/deep/c", "x y", "-rf"])
odd_names = (
    st.binary(min_size=1, max_size=10)
    .filter(lambda b: b"/" not in b and b"\0" not in b and b.strip(b".") != b"")
    .map(os.fsdecode)
)
file_names = st.tuples(st.one_of(plain_names, odd_names), endings).map("".join)
trees = st.dictionaries(file_names, sources, min_size=1, max_size=4)

SCALARS = st.one_of(
    st.integers(-(2**70), 2**70),
    st.floats(allow_nan=True, allow_infinity=True),
    st.booleans(),
    st.text(max_size=30),
    st.sampled_from(["/", ".git", "~", "../x", "/dev/null", "[z-a]", "**/*.py", "*a*a*a*a*b"]),
)
VALUES = st.recursive(
    SCALARS,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=8), inner, max_size=3)
    ),
    max_leaves=8,
)
KEYS = ["languages", "exclude", "include-generated", "locations", "coupling", "gates",
        "cache-path", "cache", "jobs", "limits", "unknown"]  # fmt: skip
SUBKEYS = {
    "locations": ["new", "framework", "base", "other"],
    "coupling": ["per-file", "include-dirs", "ignore-includes", "ignore-imports"],
    "limits": ["file-seconds", "worker-memory-mb", "other"],
}


@st.composite
def settings_tables(draw: st.DrawFn) -> dict[str, Any]:
    table: dict[str, Any] = {}
    for key in draw(st.lists(st.sampled_from(KEYS), max_size=5, unique=True)):
        if key in SUBKEYS and draw(st.booleans()):
            sub = draw(st.lists(st.sampled_from(SUBKEYS[key]), max_size=3, unique=True))
            table[key] = {k: draw(VALUES) for k in sub}
        elif key == "gates":
            table[key] = draw(st.lists(st.sampled_from(GATES) | st.text(max_size=20), max_size=3))
        else:
            table[key] = draw(VALUES)
    return table


GATES = ["cost(new) > 0", "vg(total) >= 0", "loc(base) < -1", "cost(total) > 1e308"]
REGEXES = st.text(alphabet="a()|+*?[]{}\\^$.w0-9:", max_size=16)
GLOBS = st.text(alphabet="ab*?[]!/._", min_size=1, max_size=12)


@st.composite
def rule_packs(draw: st.DrawFn) -> dict[str, Any]:
    rules = []
    for number in range(draw(st.integers(0, 3))):
        rule: dict[str, Any] = {
            "id": draw(st.sampled_from([f"r{number}", "", "bad id", "x" * 200])),
            "language": draw(st.lists(st.sampled_from(["python", "c", "cpp", "cobol"]))),
            "match": draw(st.lists(GLOBS, max_size=3)),
            "kind": draw(st.sampled_from(["messaging", "rpc", "nonsense"])),
            "role": draw(st.sampled_from(["initiate", "receive", "use", "both"])),
        }
        if draw(st.booleans()):
            rule["endpoint"] = {
                "type": draw(st.sampled_from(["address", "name", "interface", "port", "x"])),
                "pattern": draw(REGEXES),
                **({"arg": draw(st.integers(-2, 5))} if draw(st.booleans()) else {}),
            }
        rules.append(rule)
    return {"pack": {"name": draw(st.sampled_from(["fuzz", "zeromq", ""]))}, "rules": rules}


# ------------------------------------------------------------------------------ TOML out


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if value != value:
            return "nan"
        if value in (float("inf"), float("-inf")):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return '"' + "".join(c if c.isprintable() and c not in '"\\' else f"\\u{ord(c):04x}"
                             for c in value) + '"'  # fmt: skip
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return (
        "{" + ", ".join(f"{_toml_value(str(k))} = {_toml_value(v)}" for k, v in value.items()) + "}"
    )


def _toml_table(name: str, table: dict[str, Any]) -> str:
    lines = [f"[{name}]"]
    lines += [f"{_toml_value(str(k))} = {_toml_value(v)}" for k, v in table.items()]
    return "\n".join(lines) + "\n"


def _pack_toml(pack: dict[str, Any]) -> str:
    text = _toml_table("pack", pack["pack"])
    for array in ("rules", "configuration"):
        for rule in pack.get(array, []):
            text += "\n" + _toml_table(f"[{array}]", rule)
    return text


FILE_GLOBS = st.sampled_from(["rules.toml", "*.toml", "[", "!x"]) | GLOBS


@st.composite
def configuration_packs(draw: st.DrawFn) -> dict[str, Any]:
    """Packs of [[configuration]] rules, valid or not, reading routes from rules.toml files."""
    entries = []
    for number in range(draw(st.integers(1, 3))):
        entry: dict[str, Any] = {
            "id": draw(st.sampled_from([f"c{number}", "", "bad id"])),
            "files": draw(st.lists(FILE_GLOBS, max_size=3)),
            "format": draw(st.sampled_from(["toml", "yaml"])),
            "table": draw(st.sampled_from(["rules.to", "rules", "", "a..b", "routes"])),
            "kind": draw(st.sampled_from(["messaging", "config", "nonsense"])),
            "role": draw(st.sampled_from(["initiate", "receive", "both"])),
            "endpoint": {
                "type": draw(st.sampled_from(["service", "topic", "x"])),
                "key": draw(st.sampled_from(["service", "topic", ""])),
                **({"pattern": draw(REGEXES)} if draw(st.booleans()) else {}),
            },
        }
        if draw(st.booleans()):
            entry["when"] = {"kind": draw(st.lists(st.sampled_from(["send", "request", 3])))}
        if draw(st.booleans()):
            entry["defaults"] = {"kind": draw(st.sampled_from(["request", 4]))}
        entries.append(entry)
    return {"pack": {"name": "fuzzcfg"}, "configuration": entries}


ROUTER_FILES = st.one_of(
    st.text(alphabet='[]{}=."\'#\n \\rulestokindsvc01', max_size=300),
    st.lists(st.sampled_from(["service", "topic", "kind", "to"]), max_size=6).map(
        lambda keys: "[[rules]]\n" + "".join(f'[[rules.to]]\n{k} = "{k}"\n' for k in keys)
    ),
)


# ------------------------------------------------------------------------------ harness


@contextmanager
def _environment(cache_home: Path, cwd: Path) -> Iterator[None]:
    """No ARCHMETRICS_CACHE (the repository's cache-path counts), the cache directory in
    ``cache_home``, and ``cwd`` as the working directory, so a stray write shows."""
    saved = {k: os.environ.get(k) for k in ("ARCHMETRICS_CACHE", "XDG_CACHE_HOME")}
    os.environ["ARCHMETRICS_CACHE"] = ""
    os.environ["XDG_CACHE_HOME"] = str(cache_home)
    previous = os.getcwd()
    os.chdir(cwd)
    try:
        yield
    finally:
        os.chdir(previous)
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def _git(root: Path, *args: str) -> None:
    subprocess.run(
        ["git", "-c", "commit.gpgsign=false", *args],
        cwd=root,
        env={**os.environ, **_ENV},
        check=True,
        capture_output=True,
    )


def _write(root: Path, files: dict[str, bytes]) -> None:
    for name, data in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)


def _run(argv: list[str]) -> tuple[int, str]:
    err = io.StringIO()
    with redirect_stdout(io.StringIO()), redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exit:  # argparse's own usage errors
            code = exit.code if isinstance(exit.code, int) else 2
    return code, err.getvalue()


def _check(
    committed: dict[str, bytes], worktree: dict[str, bytes], config: str, pack: str = ""
) -> None:
    with TemporaryDirectory() as folder:
        top = Path(folder)
        repo, cache_home, out = top / "repo", top / "cache-home", top / "out" / "report"
        repo.mkdir()
        out.parent.mkdir()
        (top / "cwd").mkdir()
        _git(repo, "init", "-q", "-b", "main")
        _write(repo, {**committed, "pyproject.toml": config.encode(), "pack.toml": pack.encode()})
        _git(repo, "add", "-A")
        _git(repo, "commit", "-q", "--allow-empty", "-m", "v1")
        _write(repo, worktree)
        before = checksums(top)
        runs = [
            ["scan", str(repo), "--format", "json", "-o", str(out)],
            ["scan", str(repo), "--by", "link"],
            ["diff", "-C", str(repo), "--format", "markdown", "-o", str(out)],
            ["diff", "-C", str(repo), "--base", "EMPTY", "--head", "HEAD", "--format", "csv"],
        ]
        with _environment(cache_home, top / "cwd"):
            for argv in runs:
                code, err = _run(argv)
                assert "Traceback" not in err, (argv, err)
                assert code in (0, 1, 2), (argv, code, err)
                if code == 1:
                    assert "archmetrics: gate failed:" in err, (argv, err)
                if code == 2:
                    assert err.count("\n") >= 1 and "archmetrics" in err, (argv, err)
        after = checksums(top)
        changed = {
            path
            for path in set(before) | set(after)
            if before.get(path) != after.get(path) and not path.startswith(("cache-home", "out"))
        }
        assert not changed, changed


# -------------------------------------------------------------------------------- tests


@FUZZ
@given(trees, trees)
def test_random_source_files(committed: dict[str, bytes], worktree: dict[str, bytes]) -> None:
    _check(committed, worktree, "")


@FUZZ
@given(st.one_of(settings_tables().map(lambda t: _toml_table("tool.archmetrics", t)),
                 st.binary(max_size=200).map(lambda b: b.decode("latin-1"))))  # fmt: skip
def test_random_configurations(config: str) -> None:
    _check({"a.py": b"def f(a):\n    return a or 1\n"}, {"b.c": b"int g(int x){return x?1:2;}"},
           config)  # fmt: skip


@FUZZ
@given(configuration_packs(), ROUTER_FILES, ROUTER_FILES)
def test_random_configuration_rules_and_router_files(
    pack: dict[str, Any], committed: str, edited: str
) -> None:
    config = '[tool.archmetrics.coupling]\nrule-packs = ["pack.toml"]\n'
    _check({"rules.toml": committed.encode(), "a/x.rules.toml": edited.encode()},
           {"rules.toml": edited.encode()}, config, _pack_toml(pack))  # fmt: skip


@FUZZ
@given(rule_packs())
def test_random_rule_packs(pack: dict[str, Any]) -> None:
    config = '[tool.archmetrics.coupling]\nrule-packs = ["pack.toml"]\n'
    source = b"import zmq\ns = zmq.Context().socket(zmq.REQ)\ns.connect('tcp://h:5')\n"
    _check({"a.py": source, "b.py": b"def ab(x):\n    return x\n"}, {}, config, _pack_toml(pack))
