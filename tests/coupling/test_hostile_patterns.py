"""Threat: a rule pack's regular expression that exhausts memory when compiled
(``a{30000000}``: 8 GB for 13 bytes, ``a{4294967294}`` until the kernel killed the run), in
an endpoint rule or a ``[[configuration]]`` rule, or a stream of distinct patterns that the
pattern caches keep (docs/security.md, threat table).

Patterns are checked before they are compiled (archmetrics/coupling/patterns.py); what the
check lets through compiles in bounded memory. The CLI runs here under an address-space
limit, so that the unfixed code fails the test instead of the machine."""

from __future__ import annotations

import resource
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from archmetrics.coupling.loader import load_rule_pack
from archmetrics.coupling.patterns import (
    MAX_WEIGHT,
    PatternError,
    check_pattern,
    compile_pattern,
    search,
)
from archmetrics.coupling.rules import RulePackError
from tests.gitrepo import GitRepo

pytestmark = pytest.mark.security

LIMIT = 1 << 30  # the address space a CLI run gets here (it needs about 300 MB)

ENDPOINT_PACK = """\
[pack]
name = "evil"
[[rules]]
id = "r"
language = "python"
match = "*.connect"
kind = "messaging"
role = "initiate"
endpoint = {{ type = "address", arg = 0, pattern = '{pattern}' }}
"""
CONFIGURATION_PACK = """\
[pack]
name = "evilcfg"
[[configuration]]
id = "c"
files = ["rules.toml"]
format = "toml"
table = "rules"
kind = "messaging"
role = "initiate"
endpoint = {{ type = "topic", key = "topic", pattern = '{pattern}' }}
"""
SOURCE = 'import zmq\ns = zmq.Context().socket(zmq.REQ)\ns.connect("tcp://aaaa:1")\n'


def _limited() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (LIMIT, LIMIT))


def _run_limited(argv: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "archmetrics", *argv], cwd=cwd, capture_output=True, text=True,
        preexec_fn=_limited, timeout=120, check=False,
    )  # fmt: skip


TEMPLATES = pytest.mark.parametrize(
    "template", [ENDPOINT_PACK, CONFIGURATION_PACK], ids=["endpoint", "configuration"]
)


@TEMPLATES
@pytest.mark.parametrize("pattern", ["a{30000000}", "a{4294967294}"])
def test_the_reported_patterns_are_one_line_errors(
    repo: GitRepo, template: str, pattern: str
) -> None:
    """The issue's two patterns, through the CLI (scan; and rules, diff for one)."""
    config = '[tool.archmetrics.coupling]\nrule-packs = ["pack.toml"]\n'
    files = {"pyproject.toml": config, "a.py": SOURCE, "rules.toml": '[[rules]]\ntopic = "t"\n'}
    repo.commit("v1", files={**files, "pack.toml": template.format(pattern=pattern)})
    commands = [["scan", ".", "--no-cache"]]
    if template is ENDPOINT_PACK and pattern == "a{30000000}":
        # a diff reads its base's configuration (EMPTY has none): the head's blobs here
        diff = ["diff", "--base", "EMPTY", "--head", "HEAD", "--config-from", "head"]
        commands += [["rules"], [*diff, "--no-cache"]]
    for argv in commands:
        done = _run_limited(argv, repo.root)
        assert done.returncode == 2, (argv, done.stderr)
        assert "Traceback" not in done.stderr and done.stderr.count("\n") == 1, done.stderr
        assert "pack.toml" in done.stderr and "endpoint.pattern" in done.stderr, done.stderr
        assert "a repetition count over 1000" in done.stderr, done.stderr


@TEMPLATES
@pytest.mark.parametrize(
    ("pattern", "problem"),
    [
        ("(?:a{1000}){1000}", "counted repetitions are too large"),
        ("(?:(?:(?:a{20}){20}){20}){20}", "counted repetitions are too large"),
        ("a{1001}", "a repetition count over 1000"),
        ("a{0,5000}", "a repetition count over 1000"),
        ("(?:abc){e<=2}", "fuzzy matching is not allowed"),
        ("a{ 3 }", "is not a repetition count"),
        ("a" * 1001, "longer than 1000 characters"),
        ("(" * 150 + "a" + ")" * 150, "groups nested more than 100 deep"),
    ],
    ids=["nested", "nested4", "1001", "upper", "fuzzy", "verbose", "long", "deep"],
)
def test_a_pattern_is_refused_before_it_is_compiled(
    tmp_path: Path, template: str, pattern: str, problem: str
) -> None:
    path = tmp_path / "pack.toml"
    path.write_text(template.format(pattern=pattern))
    with pytest.raises(RulePackError) as refused:
        load_rule_pack(path)
    assert refused.value.key == "endpoint.pattern" and problem in refused.value.problem


@pytest.mark.parametrize(
    "pattern",
    [r"\d{4}-\d{2}-\d{2}", r"[0-9a-f]{40}", r"(?:[a-z]{2,8}\.){1,5}", r"x\{3\}", r"[{]{2}",
     r"\p{L}{3}", r"\N{LATIN SMALL LETTER A}{2}", r"^playerc_(?!device_)(\w+?)_subscribe$",
     "a{,5}", "a{5,}"],
)  # fmt: skip
def test_ordinary_patterns_pass(pattern: str) -> None:
    assert check_pattern(pattern) <= MAX_WEIGHT
    compile_pattern(pattern)


def test_the_heaviest_patterns_allowed_compile_in_bounded_memory(tmp_path: Path) -> None:
    """The heaviest shapes the check lets through, and 400 distinct heavy patterns in a row
    (each compiled once: the cache keeps at most CACHE_WEIGHT of them, the engine's own
    cache none), in a process allowed 256 MiB more address space than it starts with."""
    script = textwrap.dedent(
        """
        import resource, sys
        from archmetrics.coupling.patterns import compile_pattern, search
        heaviest = ["(?fi)ß{1000}", "(?fi)(?:ß|ẞ){1000}", "(?fi)((ß)){1000}",
                    "(?:(?:ab){10}){100}", "[\\\\p{L}\\\\p{N}]{1000}", "(\\\\w){1000}"]
        for pattern in heaviest:
            compile_pattern(pattern)
        used = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        for n in range(400):
            search(f"(?fi)(?:ß|{n:04d}){{999}}", "ß")
        grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - used
        print(grown)
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=300,
        preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30)),
        check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert int(done.stdout) < 60_000, done.stdout  # KiB of peak memory the 400 added


def test_a_refused_pattern_is_one_error() -> None:
    with pytest.raises(PatternError, match="repetition count"):
        compile_pattern("x{1001}")
    with pytest.raises(PatternError):
        search("a{99999}", "aaa")
