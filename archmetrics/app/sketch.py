"""Sketched architectures: a revision, a patch or a folder of stubs, measured as ``diff``
measures, stage after stage from the measured base (docs/estimate.md)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from archmetrics.app.diff import measure_snapshots
from archmetrics.app.diff_options import DiffOptions, DiffRequest
from archmetrics.app.progress import Progress
from archmetrics.changeset import ChangeReport
from archmetrics.changeset.estimate import BaseState
from archmetrics.changeset.plan import Architecture, Plan, PlanError, Sketch, SketchKind
from archmetrics.facts import ParseWarning
from archmetrics.sources import Snapshot, SourceError
from archmetrics.sources.cache import FactsCache
from archmetrics.sources.checkout import Checkout
from archmetrics.sources.sketch import patch_overlay, stubs_overlay


@dataclass(frozen=True, slots=True)
class MeasuredBase:
    """What an architecture is estimated from: the repository (opened once), the base
    revision (its snapshot and the state measured from it) and how to measure."""

    request: DiffRequest
    checkout: Checkout  # sketch revisions and the renames between them
    options: DiffOptions
    base: Snapshot
    state: BaseState
    warnings: tuple[ParseWarning, ...]
    progress: Progress
    cache: FactsCache | None


def sketch_snapshot(
    plan: Plan, sketch: Sketch, before: Snapshot, context: MeasuredBase
) -> Snapshot:
    """The tree a sketch stands for: a revision, or the tree before with a patch or stubs."""
    folder = Path(plan.source).parent
    try:
        if sketch.kind is SketchKind.REVISION:
            return context.checkout.snapshot(sketch.value)
        path = inside(plan, sketch, folder)
        if sketch.kind is SketchKind.PATCH:
            return patch_overlay(before, path, f"{sketch.value} on {before.label}")
        return stubs_overlay(before, path, f"{sketch.value} on {before.label}")
    except SourceError as error:
        raise PlanError(plan.source, sketch.key, str(error)) from None


def inside(plan: Plan, sketch: Sketch, folder: Path) -> Path:
    """A sketch's patch file or stub folder: relative to the plan's folder, and inside it."""
    given = Path(sketch.value)
    resolved = (folder / given).resolve()
    if given.is_absolute() or not resolved.is_relative_to(folder.resolve()):
        raise PlanError(plan.source, sketch.key, "must be a path inside the plan's folder")
    return resolved


def sketched(
    plan: Plan, architecture: Architecture, context: MeasuredBase
) -> list[tuple[ChangeReport, tuple[ParseWarning, ...]]]:
    """Each sketched stage measured as ``diff`` measures, against the stage before (the
    first against the base)."""
    results = []
    before: Snapshot = context.base
    spec: str | None = context.request.base  # None once a patch or stubs made the tree
    for stage in architecture.stages:
        assert stage.sketch is not None
        after = sketch_snapshot(plan, stage.sketch, before, context)
        renames: dict[str, str] = {}
        if stage.sketch.kind is SketchKind.REVISION:
            if spec is not None:
                renames = context.checkout.renames(spec, stage.sketch.value)
            spec = stage.sketch.value
        else:
            spec = None
        pair = (before, after)
        results.append(
            measure_snapshots(context.options, pair, renames, context.progress, context.cache)
        )
        before = after
    return results
