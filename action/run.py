"""The steps of the composite action (action.yml), run by the runner's Python (standard library
only): ``prepare`` names the caches, ``measure`` works out what to compare from the event
that started the job, makes sure the clone holds it, runs ``archmetrics diff`` and writes the
job summary and the step's outputs. tests/cli/test_action.py runs it with the variables a
runner sets (GITHUB_EVENT_NAME, GITHUB_EVENT_PATH ...) on real repositories.

What is compared, by event (unless the ``base`` input names a base):

- ``pull_request``, ``pull_request_target``: the head against the merge base of the pull
  request's base commit and the head (``git diff BASE...HEAD``): the pull request's own changes;
- ``push``: ``before...after``: every commit the push brought, however many; the first push
  of a branch (``before`` all zeros) from its merge base with the default branch, or from the
  empty tree when it is the default branch; a deleted branch: nothing to measure;
- ``merge_group``: the queue's base commit against its head; anything else: ``HEAD~1``.

A shallow clone is deepened (``git fetch --deepen``) until the merge base is in it, or, with
the ``deepen`` input false or no history to fetch, refused with the exact fix.
"""

from __future__ import annotations

import hashlib
import json
import os
import shlex
import subprocess
import sys
from pathlib import Path
from typing import Any

ZERO = "0" * 40
DEPTHS = (50, 200, 1000)  # commits fetched per try, before asking for the whole history
FIX = (
    "fetch the history: give actions/checkout `fetch-depth: 0` (or let this action deepen the"
    " clone: `deepen: true`, and the job a token that may fetch)"
)


class Refused(Exception):
    """What cannot be measured: the one line the job summary and the log show."""


def _env(name: str, default: str = "") -> str:
    return os.environ.get(name, default).strip() or default


def _git(*args: str, check: bool = True) -> subprocess.CompletedProcess[str]:
    return subprocess.run(["git", *args], capture_output=True, text=True, check=check)


def _has_commit(rev: str) -> bool:
    return _git("cat-file", "-e", f"{rev}^{{commit}}", check=False).returncode == 0


def _merge_base(first: str, second: str) -> bool:
    return _git("merge-base", first, second, check=False).returncode == 0


def _shallow() -> bool:
    return _git("rev-parse", "--is-shallow-repository").stdout.strip() == "true"


def _event() -> dict[str, Any]:
    path = _env("GITHUB_EVENT_PATH")
    if not path:
        return {}
    try:
        found = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise Refused(f"cannot read the event {path}: {error}") from None
    return found if isinstance(found, dict) else {}


def revisions(event_name: str, event: dict[str, Any]) -> tuple[str, str, bool]:
    """The base, the head and whether to compare from their merge base, for this event."""
    base, head = _env("ARCHMETRICS_BASE"), _env("ARCHMETRICS_HEAD", "HEAD")
    if base:
        return base, head, False
    if event_name in ("pull_request", "pull_request_target"):
        return event["pull_request"]["base"]["sha"], head, True
    if event_name == "merge_group":
        group = event["merge_group"]
        return group["base_sha"], group["head_sha"], True
    if event_name == "push":
        return _pushed(event)
    return "HEAD~1", head, False


def _pushed(event: dict[str, Any]) -> tuple[str, str, bool]:
    before, after = event.get("before") or ZERO, event.get("after") or ZERO
    if after == ZERO:
        raise Refused("the push deleted a branch: nothing to measure")
    if before != ZERO:
        return before, after, True
    default = (event.get("repository") or {}).get("default_branch") or ""
    ref = event.get("ref", "")
    if default and ref != f"refs/heads/{default}":
        return f"origin/{default}", after, True  # a new branch: from where it left
    return "EMPTY", after, False  # the default branch's first push: all of it is new


def _fetch(*args: str) -> bool:
    return _git("fetch", "--no-tags", "--quiet", *args, check=False).returncode == 0


def ensure_history(base: str, head: str, merge: bool, deepen: bool) -> None:
    """Make the clone hold ``base`` and ``head`` (and their merge base when ``merge``),
    fetching as much history as it takes when allowed, else say what to do. Two complete
    histories that share no commit are left to archmetrics, which says so."""
    ends = [rev for rev in (base, head) if rev not in ("EMPTY", "WORKTREE", "INDEX")]

    def complete() -> bool:
        if not all(_has_commit(rev) for rev in ends):
            return False
        return not (merge and len(ends) == 2) or _merge_base(*ends)

    if complete():
        return
    names = [_refspec(rev) for rev in ends]
    missing = [name for rev, name in zip(ends, names, strict=True) if not _has_commit(rev)]
    if not _shallow():  # a complete history: fetch what it lacks, archmetrics says the rest
        if deepen and missing:
            _fetch("origin", *missing)
        return
    if not deepen:
        raise Refused(f"{base} and {head}: not both in this shallow clone with their merge"
                      f" base; {FIX}")  # fmt: skip
    if missing:
        _fetch("--depth=1", "origin", *missing)
    for depth in DEPTHS:
        if complete() or not _shallow():
            break
        _fetch(f"--deepen={depth}", "origin", *names)
    if not complete() and _shallow():
        _fetch("--unshallow", "origin", *names)
    if not complete() and _shallow():
        raise Refused(f"{base} and {head}: not in this shallow clone after fetching; {FIX}")


def _refspec(rev: str) -> str:
    """What to fetch for ``rev``: a remote-tracking branch into itself, a commit the clone
    has by its id (``HEAD`` would name the remote's), anything else as is (a commit id)."""
    if rev.startswith("origin/"):
        branch = rev.removeprefix("origin/")
        return f"+refs/heads/{branch}:refs/remotes/origin/{branch}"
    if _has_commit(rev):
        return _git("rev-parse", f"{rev}^{{commit}}").stdout.strip()
    return rev


def arguments(base: str, head: str, merge: bool) -> list[str]:
    """``archmetrics diff``'s command line: the revisions, the gates (one a line) and the
    ``args`` input, split as a POSIX shell splits words (quotes and backslashes honoured)
    but with no expansion of any kind."""
    command = ["archmetrics", "diff", "--base", base, "--head", head, "--quiet"]
    if merge:
        command.append("--merge-base")
    for gate in _env("ARCHMETRICS_FAIL_ON").splitlines():
        if gate.strip():
            command += ["--fail-on", gate.strip()]
    try:
        return command + shlex.split(_env("ARCHMETRICS_ARGS"), comments=False, posix=True)
    except ValueError as error:  # an unclosed quote
        raise Refused(f"the args input cannot be split: {error}") from None


def _append(variable: str, text: str) -> None:
    path = _env(variable)
    if path:
        with open(path, "a", encoding="utf-8") as stream:
            stream.write(text)


def _outputs(**values: str) -> None:
    _append("GITHUB_OUTPUT", "".join(f"{name}={value}\n" for name, value in values.items()))


def _error_line(stderr: str, status: int) -> str:
    lines = [line for line in stderr.splitlines() if line.startswith("archmetrics: error:")]
    return lines[-1] if lines else f"archmetrics diff exited {status}"


def measure() -> int:
    """Run the diff twice (JSON, then the chosen format), write the summary and outputs."""
    out = Path(_env("RUNNER_TEMP", _env("TMPDIR", "/tmp"))) / "archmetrics"
    out.mkdir(parents=True, exist_ok=True)
    json_path = out / "archmetrics.json"
    fmt = _env("ARCHMETRICS_FORMAT", "markdown")
    report = out / ("archmetrics.md" if fmt == "markdown" else "archmetrics.txt")
    try:
        if fmt not in ("markdown", "table"):
            raise Refused(f"format must be markdown or table, not {fmt!r}")
        base, head, merge = revisions(_env("GITHUB_EVENT_NAME"), _event())
        ensure_history(base, head, merge, _env("ARCHMETRICS_DEEPEN", "true") == "true")
        command = arguments(base, head, merge)
    except Refused as error:
        return _refused(str(error))
    except (KeyError, TypeError) as error:
        return _refused(f"the event has no {error}: give the base input")
    first = subprocess.run([*command, "--format", "json", "-o", str(json_path)],
                           capture_output=True, text=True)  # fmt: skip
    sys.stderr.write(first.stderr)
    status = first.returncode
    if status > 1:
        return _refused(_error_line(first.stderr, status).removeprefix("archmetrics: "), status)
    # the second run reads every file's facts from the cache the first one filled
    subprocess.run([*command, "--format", fmt, "-o", str(report)], capture_output=True)
    if report.is_file():
        text = report.read_text(encoding="utf-8")
        _append("GITHUB_STEP_SUMMARY", text if fmt == "markdown" else f"```\n{text}```\n")
    found = {"json": json_path, "report": report}
    _outputs(status=str(status), **{k: str(v) for k, v in found.items() if v.is_file()})
    return status


def _refused(message: str, status: int = 2) -> int:
    """Exit 2 with the one-line error in the log, the job summary and the outputs."""
    line = " ".join(message.split())
    print(f"archmetrics action: {line}", file=sys.stderr)
    _append("GITHUB_STEP_SUMMARY", f"### archmetrics could not measure\n\n{line}\n")
    _outputs(status=str(status), error=line)
    return status


def prepare() -> int:
    """The caches' folders and keys as outputs; the facts cache's file in ARCHMETRICS_CACHE
    for this step and the job's later ones (a cache the job already chose is kept)."""
    action = Path(__file__).resolve().parent.parent
    digest = hashlib.sha256((action / "pyproject.toml").read_bytes()).hexdigest()[:16]
    system = _env("RUNNER_OS", sys.platform)
    python = f"py{sys.version_info[0]}.{sys.version_info[1]}"
    facts = Path(_env("ARCHMETRICS_CACHE") or Path(_env("RUNNER_TEMP", "/tmp"))
                 / "archmetrics-facts" / "facts.sqlite3")  # fmt: skip
    pip_dir = subprocess.run([sys.executable, "-m", "pip", "cache", "dir"],
                             capture_output=True, text=True).stdout.strip()  # fmt: skip
    prefix = f"archmetrics-facts-{system}-{python}-{digest}-"
    _append("GITHUB_ENV", f"ARCHMETRICS_CACHE={facts}\n")
    _outputs(
        **{
            "pip-dir": pip_dir or str(Path.home() / ".cache" / "pip"),
            "pip-key": f"archmetrics-pip-{system}-{python}-{digest}",
            "facts-dir": str(facts.parent),
            "facts-key": prefix + _env("GITHUB_RUN_ID", "0"),
            "facts-prefix": prefix,
        }
    )
    return 0


if __name__ == "__main__":
    step = sys.argv[1] if len(sys.argv) > 1 else ""
    if step not in ("prepare", "measure"):
        sys.exit("usage: run.py prepare|measure")
    sys.exit(prepare() if step == "prepare" else measure())
