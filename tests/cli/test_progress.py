"""The terminal's progress: a bar for counted steps, a spinner naming each other step."""

from __future__ import annotations

from archmetrics.cli.common import RichProgress


def test_the_terminal_progress_shows_a_step_without_a_count_until_the_next() -> None:
    progress = RichProgress()
    progress.phase("coupling v1")
    assert progress._status is not None
    progress.start("parsing", 40)  # ends the spinner, shows a bar
    assert progress._status is None and progress._task is not None
    progress.advance(40)
    progress.phase("writing the report")
    assert progress._task is None and progress._status is not None
    progress.stop()
    assert progress._status is None and progress._task is None
