"""Helpers for tests that treat the measured repository as hostile: run the real CLI (in a
separate process, or in this one where the process boundary is not under test) and show that
nothing outside the cache directory and ``--output`` changed."""

from __future__ import annotations

import contextlib
import hashlib
import io
import os
import subprocess
import sys
import threading
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
    printed is captured as bytes and decoded as :func:`run_cli` decodes a process's output.

    As in a process of its own: the exit code is what ``python -m archmetrics`` would exit
    with, stdout and stderr are byte streams in the encoding ``PYTHONIOENCODING`` names
    (UTF-8 otherwise) with the interpreter's error handlers (``strict`` on stdout,
    ``backslashreplace`` on stderr), and the environment and working folder are restored
    afterwards. Use :func:`run_cli` where the process itself is under test (a crash, a
    signal, a resource limit, a wait that must be cut off)."""
    from archmetrics.cli import main

    encoding = {**os.environ, **(env or {})}.get("PYTHONIOENCODING") or "utf-8"
    name, _, errors = encoding.partition(":")
    out = io.TextIOWrapper(io.BytesIO(), encoding=name, errors=errors or "strict")
    err = io.TextIOWrapper(io.BytesIO(), encoding=name, errors="backslashreplace")
    saved = {key: os.environ.get(key) for key in env or {}}
    previous = os.getcwd()
    os.environ.update(env or {})
    os.chdir(cwd)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(list(argv))
            except SystemExit as exit:  # argparse's own usage errors (2) and --help (0)
                code = exit.code if isinstance(exit.code, int) else int(exit.code is not None)
    finally:
        os.chdir(previous)
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
    return Run(code, _written(out), _written(err))


def run_main_past_fifos(
    argv: Sequence[str], cwd: Path, fifos: Sequence[Path], timeout: float = 60
) -> Run:
    """:func:`run_main` for a test of FIFOs that archmetrics must not wait on: a regression
    would wait forever, and in this process that would hang the suite. So, once ``timeout``
    seconds have passed (and every 0.1 s after that, until the run ends), each of ``fifos``
    is opened for writing and closed again, which ends any reader's wait with an empty
    read: the run finishes, and the test fails on what it printed, instead of hanging."""
    ended = threading.Event()

    def unblock() -> None:
        if ended.wait(timeout):
            return
        while not ended.is_set():
            for fifo in fifos:
                with contextlib.suppress(OSError):  # ENXIO: nobody waits on it just now
                    os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
            ended.wait(0.1)

    watchdog = threading.Thread(target=unblock, daemon=True)
    watchdog.start()
    try:
        return run_main(argv, cwd)
    finally:
        ended.set()
        watchdog.join()


def _written(stream: io.TextIOWrapper) -> str:
    stream.flush()
    raw = stream.buffer
    assert isinstance(raw, io.BytesIO)
    return raw.getvalue().decode("utf-8", "backslashreplace")
