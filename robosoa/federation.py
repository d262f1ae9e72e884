"""Asking several federated location services at once, within one overall deadline.

A lookup must not take ``peers x timeout``: each peer is asked on its own short-lived daemon
thread, and whatever has not answered when the deadline passes counts as failed.
"""

from __future__ import annotations

import queue
import threading
import time
from collections.abc import Callable, Mapping
from typing import TypeVar

T = TypeVar("T")


def _ask(address: str, call: Callable[[], T],
         answers: queue.Queue[tuple[str, T | Exception]]) -> None:
    try:
        answers.put((address, call()))
    except Exception as exc:  # handed to the asking thread, which decides what it means
        answers.put((address, exc))


def ask_all(calls: Mapping[str, Callable[[], T]], timeout: float) -> dict[str, T | Exception]:
    """Run every call concurrently; each address maps to its result, or to the exception it
    raised, or to ``TimeoutError`` if it did not finish within ``timeout`` seconds in total."""
    answers: queue.Queue[tuple[str, T | Exception]] = queue.Queue()
    for address, call in calls.items():
        threading.Thread(target=_ask, args=(address, call, answers), daemon=True,
                         name="robosoa-federation").start()
    deadline = time.monotonic() + timeout
    results: dict[str, T | Exception] = {}
    while len(results) < len(calls):
        try:
            address, outcome = answers.get(timeout=max(0.0, deadline - time.monotonic()))
        except queue.Empty:
            break
        results[address] = outcome
    late = TimeoutError(f"no answer within {timeout:g}s")
    return {address: results.get(address, late) for address in calls}  # in the callers' order
