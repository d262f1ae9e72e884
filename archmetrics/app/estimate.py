"""The ``estimate`` use case: an integration plan priced against a measured base (p. 109).

The base revision is parsed and coupled as ``diff`` would, so λ, Vg and coupling before are
the repository's; each architecture's stages are either planned counts applied to it
(changeset/estimate.py) or sketches (a revision, a patch, a folder of stubs) measured
against it as ``diff`` measures. Either way the result is labelled an estimate.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from archmetrics.app.diff import measure_change, parse_side, parse_warnings
from archmetrics.app.diff_cache import site_memo
from archmetrics.app.diff_options import DiffOptions, DiffRequest, diff_options
from archmetrics.app.progress import NoProgress, Progress
from archmetrics.app.settings import gate_origins
from archmetrics.app.sketch import MeasuredBase, sketched
from archmetrics.changeset import ChangeReport, FilePair, compute_change, coupling_by_element
from archmetrics.changeset.accuracy import compare_change
from archmetrics.changeset.estimate import BaseState, apply_stages, base_state, rule_roles
from archmetrics.changeset.files import measured_files
from archmetrics.changeset.gates import Gate, check_gates
from archmetrics.changeset.plan import Architecture, Plan, PlanError
from archmetrics.changeset.plan_read import MAX_PLAN_BYTES, read_plan
from archmetrics.coupling import group_elements, measure_coupling
from archmetrics.facts import ParseWarning
from archmetrics.reading import TooLarge, read_regular
from archmetrics.reports.model import (
    ArchitectureEstimate,
    DiffReport,
    EstimateFailure,
    EstimateReport,
    SeriesReport,
    Stage,
)
from archmetrics.sources import Snapshot, SourceError
from archmetrics.sources.cache import FactsCache
from archmetrics.sources.checkout import Checkout, open_checkout

__all__ = ["EstimateRequest", "measure_base", "read_plan_file", "run_estimate"]


@dataclass(frozen=True, slots=True)
class EstimateRequest:
    """Price ``plan`` against ``diff.base`` in the repository at ``diff.root`` (``diff.head``
    is not used: each architecture says what it adds)."""

    plan: Path
    diff: DiffRequest
    actual: str | None = None  # --actual --head REV: compare with the measured base..REV
    stage: str | None = None  # --stage: which stage --actual compares (default: the only one)
    architectures: tuple[str, ...] = ()  # --architecture: only these (default: all)


def read_plan_file(path: Path) -> Plan:
    """The plan in the regular file at ``path`` (a FIFO or a link to ``/dev/stdin`` is
    refused, never waited on; read at most one byte past the size limit)."""
    source = str(path)
    try:
        data = read_regular(path, MAX_PLAN_BYTES)
    except TooLarge:
        raise PlanError(source, "", f"a plan may hold at most {MAX_PLAN_BYTES} bytes") from None
    except OSError as error:
        raise PlanError(source, "", f"cannot read: {error.strerror or error}") from None
    return read_plan(data, source)


def measure_base(
    options: DiffOptions,
    snapshot: Snapshot,
    progress: Progress | None = None,
    cache: FactsCache | None = None,
) -> tuple[BaseState, tuple[ParseWarning, ...]]:
    """Every element of the base with its λ, Vg, location and coupling, as ``diff`` counts
    them (the base compared with itself: same exclusions, elements and coupling)."""
    progress = progress or NoProgress()
    blobs: dict[str, str] = {}
    files = parse_side(snapshot, options, progress, cache, blobs)
    rules, coupling_options, packs = options.rules, options.coupling, options.packs
    progress.phase(f"coupling {snapshot.label}")
    measured = measured_files(files, rules)
    memo = site_memo(cache, measured, blobs, coupling_options, packs) if cache else None
    coupling = measure_coupling(measured, coupling_options, packs, memo)
    values = coupling_by_element(coupling)
    change = compute_change(
        [FilePair(f, f) for f in files],
        group_elements({f.path for f in files}, coupling_options.grouping),
        rules,
        values,
        values,
    )
    progress.stop()
    return base_state(change, coupling), parse_warnings(files)


def _planned(plan: Plan, architecture: Architecture, context: MeasuredBase) -> list[ChangeReport]:
    """Each planned stage applied to what the one before left, the first to the base."""
    options = context.options
    return apply_stages(
        plan.source,
        context.state,
        architecture.stages,
        options.rules,
        rule_roles(options.packs),
        dynamic_pre_zero=options.dynamic_pre_zero,
    )


def _kind(plan: Plan, architecture: Architecture) -> str:
    sketches = [s.sketch for s in architecture.stages if s.sketch is not None]
    if not sketches:
        return "plan"
    if len(sketches) != len(architecture.stages):
        raise PlanError(
            plan.source,
            architecture.key,
            "mixes planned and sketched stages: a sketch is measured against the code"
            " before it, which a planned stage does not leave",
        )
    return "sketch:" + ",".join(dict.fromkeys(s.kind.value for s in sketches))


def _estimate(
    plan: Plan, architecture: Architecture, context: MeasuredBase, gates: Sequence[Gate]
) -> tuple[ArchitectureEstimate, list[EstimateFailure]]:
    kind = _kind(plan, architecture)
    if kind == "plan":
        found = [(r, context.warnings) for r in _planned(plan, architecture, context)]
    else:
        found = sketched(plan, architecture, context)
    stages, failures = [], []
    texts = tuple(g.text for g in gates)
    origins = gate_origins(context.request.settings, context.checkout.root)
    before = context.request.base  # each stage is estimated on the one before it
    for stage, (change, warnings) in zip(architecture.stages, found, strict=True):
        head = f"{architecture.name}/{stage.label} (estimate)"
        report = DiffReport(before, head, change, warnings, texts, origins=origins)
        before = head
        failed = check_gates(gates, report.summaries())
        stages.append(Stage(stage.label, replace(report, failures=failed)))
        failures += [EstimateFailure(architecture.name, stage.label, f) for f in failed]
    series = SeriesReport(str(context.checkout.root), tuple(stages))
    return ArchitectureEstimate(architecture.name, kind, series, architecture.description), failures


def _one_stage(plan: Plan, architecture: Architecture, label: str | None) -> Architecture:
    """The stage ``--actual`` compares, alone: estimated from the base it is compared from."""
    if label is None:
        if len(architecture.stages) > 1:
            labels = ", ".join(s.label for s in architecture.stages)
            raise PlanError(
                plan.source,
                architecture.key,
                f"has stages {labels}: --stage names the one --actual compares",
            )
        return architecture
    for stage in architecture.stages:
        if stage.label == label:
            return replace(architecture, stages=(stage,))
    raise PlanError(plan.source, architecture.key, f"has no stage {label!r} (--stage)")


def _selected(plan: Plan, request: EstimateRequest) -> Plan:
    """The architectures ``--architecture`` names (all when none), each with only the stage
    ``--actual`` compares."""
    chosen = plan.architectures
    if request.architectures:
        known = {a.name for a in chosen}
        for name in request.architectures:
            if name not in known:
                names = ", ".join(a.name for a in chosen)
                raise PlanError(plan.source, "", f"no architecture {name!r} (the plan has {names})")
        chosen = tuple(a for a in chosen if a.name in request.architectures)
    if request.actual is not None:
        chosen = tuple(_one_stage(plan, a, request.stage) for a in chosen)
    return replace(plan, architectures=chosen)


def run_estimate(
    request: EstimateRequest,
    progress: Progress | None = None,
    cache: FactsCache | None = None,
    checkout: Checkout | None = None,
) -> EstimateReport:
    """Read the plan, measure the base, estimate every architecture, check the gates; with
    ``actual``, measure base..actual too and the error of every estimated figure.
    ``checkout``: the repository, if the caller opened it already."""
    checkout = checkout or open_checkout(request.diff.root)
    options = diff_options(request.diff, checkout.root, checkout)  # a bad gate or plan
    gates = options.gates  # fails before any work
    plan = _selected(read_plan_file(request.plan), request)
    progress = progress or NoProgress()
    bases: dict[str, MeasuredBase] = {}
    estimates, failures = [], []
    for architecture in plan.architectures:
        revision = request.diff.base
        if architecture.base is not None and request.actual is None:
            revision = architecture.base
        if revision not in bases:
            progress.phase(f"reading {revision}")
            diff = replace(request.diff, base=revision)
            try:
                snapshot = checkout.snapshot(revision)
            except SourceError as error:
                if revision == request.diff.base:
                    raise
                raise PlanError(plan.source, f"{architecture.key}.base", str(error)) from None
            state, warnings = measure_base(options, snapshot, progress, cache)
            bases[revision] = MeasuredBase(
                diff, checkout, options, snapshot, state, warnings, progress, cache
            )
        estimate, failed = _estimate(plan, architecture, bases[revision], gates)
        estimates.append(estimate)
        failures += failed
    report = EstimateReport(
        plan.source,
        ", ".join(bases),  # the revisions the architectures start from
        tuple(estimates),
        tuple(g.text for g in gates),
        tuple(failures),
        plan_path=_inside(request.plan, checkout.root),
    )
    if request.actual is not None:
        actual = replace(request.diff, head=request.actual)
        report = _with_actual(report, actual, checkout, options, progress, cache)
    progress.stop()
    return report


def _inside(path: Path, root: Path) -> str | None:
    """``path`` relative to the repository's top ``root``, None when it lies outside."""
    try:
        return path.resolve().relative_to(root.resolve()).as_posix()
    except (ValueError, OSError):
        return None


def _with_actual(
    report: EstimateReport,
    request: DiffRequest,
    checkout: Checkout,
    options: DiffOptions,
    progress: Progress,
    cache: FactsCache | None,
) -> EstimateReport:
    """The report with the measured change and each architecture's errors against it."""
    change, warnings, reading = measure_change(request, progress, cache, checkout, options)
    actual = DiffReport(request.base, request.head, change, warnings, reading=reading)
    accuracy = tuple(
        (a.name, compare_change(a.series.stages[0].report.change, change))
        for a in report.architectures
    )
    return replace(report, actual=actual, accuracy=accuracy)
