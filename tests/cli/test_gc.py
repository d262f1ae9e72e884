"""The collector thresholds a command runs with, and that they are given back."""

from __future__ import annotations

import gc

import pytest

from archmetrics.cli import GC_THRESHOLD, few_collections


def test_a_command_runs_with_few_collections_and_restores_the_thresholds() -> None:
    before = gc.get_threshold()
    assert before != GC_THRESHOLD
    with few_collections():
        assert gc.get_threshold() == GC_THRESHOLD
    assert gc.get_threshold() == before
    with pytest.raises(KeyError), few_collections():
        raise KeyError("a failing command")
    assert gc.get_threshold() == before
