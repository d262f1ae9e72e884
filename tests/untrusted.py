"""Helpers for tests that treat the measured repository as hostile: run the real CLI in a
separate process and show that nothing outside the cache directory and ``--output`` changed."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Run:
    code: int
    out: str
    err: str

    def one_line_error(self) -> str:
        """The single error line on stderr (asserts there is one and no traceback)."""
        assert "Traceback" not in self.err, self.err
        errors = [line for line in self.err.splitlines() if line.startswith("archmetrics: error")]
        assert len(errors) == 1, self.err
        return errors[0]


def run_cli(
    argv: Sequence[str],
    cwd: Path,
    env: Mapping[str, str] | None = None,
    timeout: float = 120,
) -> Run:
    """``python -m archmetrics ARGV`` in ``cwd``, with the environment ``env`` added."""
    done = subprocess.run(
        [sys.executable, "-m", "archmetrics", *argv],
        cwd=cwd,
        env={**os.environ, **(env or {})},
        capture_output=True,
        timeout=timeout,
        check=False,
    )
    return Run(
        done.returncode,
        done.stdout.decode("utf-8", "backslashreplace"),
        done.stderr.decode("utf-8", "backslashreplace"),
    )


def checksums(root: Path) -> dict[str, tuple[str, int]]:
    """Every entry under ``root`` (``.git`` included): content digest or link target, and
    mode. Directories are listed too, so a renamed or added folder shows."""
    found: dict[str, tuple[str, int]] = {}
    for folder, dirs, files in os.walk(root):
        for name in [*dirs, *files]:
            path = Path(folder) / name
            info = path.lstat()
            if path.is_symlink():
                digest = "link:" + os.readlink(path)
            elif path.is_file():
                digest = hashlib.sha256(path.read_bytes()).hexdigest()
            else:
                digest = "dir"
            found[str(path.relative_to(root))] = (digest, info.st_mode)
    return found


def run_main(argv: Sequence[str], cwd: Path, env: Mapping[str, str] | None = None) -> Run:
    """``archmetrics ARGV`` in this process (no interpreter to start: the security suite
    runs hundreds of commands), in ``cwd`` with the environment ``env`` added; what it
    printed is captured."""
    import contextlib
    import io

    from archmetrics.cli import main

    out, err = io.StringIO(), io.StringIO()
    saved = {key: os.environ.get(key) for key in env or {}}
    previous = os.getcwd()
    os.environ.update(env or {})
    os.chdir(cwd)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(list(argv))
            except SystemExit as exit:  # argparse's own usage errors
                code = exit.code if isinstance(exit.code, int) else 2
    finally:
        os.chdir(previous)
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
    return Run(code, out.getvalue(), err.getvalue())
