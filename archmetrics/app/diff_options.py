"""A diff's request and its options: the command line's flags and the settings merged once
into one frozen value, which every step of a diff (and each stage of a series, a compare,
an estimate or a history) reads."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from archmetrics.app.collect import worker_limits
from archmetrics.app.coupling import coupling_options, rule_set
from archmetrics.app.workers import WorkerLimits
from archmetrics.changeset import LocationRules
from archmetrics.changeset.gates import Gate, split_gates
from archmetrics.complexity.baseline import Baseline
from archmetrics.complexity.thresholds import Threshold
from archmetrics.config import Settings
from archmetrics.coupling import CouplingOptions
from archmetrics.coupling.rules import RuleSet
from archmetrics.sources.checkout import Checkout


@dataclass(frozen=True, slots=True)
class DiffRequest:
    """Compare ``base`` with ``head`` (revisions, EMPTY, WORKTREE or INDEX) in the repo at root."""

    root: Path
    base: str
    head: str
    settings: Settings
    new: tuple[str, ...] = ()  # --new globs, ahead of the configured ones
    framework: tuple[str, ...] = ()
    gates: tuple[str, ...] = ()  # --fail-on, after the configured ones
    jobs: int = 0
    dynamic_pre_zero: bool = False
    base_label: str = ""  # how reports name the base (``A...B``), when not ``base`` itself
    baseline: Baseline | None = None  # offenders already known (--baseline FILE)
    base_settings: Settings | None = None  # the base's, when ``settings`` are not (they
    # came from the head or a file): what the implicit gate unmeasured(head) judges by


@dataclass(frozen=True, slots=True)
class DiffOptions:
    """A request's command-line flags and its settings merged, once per command: every step
    of a diff (and each stage of a series) reads these, never the two sources again."""

    rules: LocationRules
    gates: tuple[Gate, ...]  # on the change's summaries (cost(new) > 20)
    unit_gates: tuple[Threshold, ...]  # on the functions and files it touches (app/unit_gates)
    languages: tuple[tuple[str, str], ...]  # file ending -> language
    limits: WorkerLimits
    jobs: int
    coupling: CouplingOptions
    packs: RuleSet
    dynamic_pre_zero: bool


def diff_options(request: DiffRequest, root: Path, checkout: Checkout | None = None) -> DiffOptions:
    """The options of ``request`` for the repository at ``root`` (its rule packs are read
    from there, or from the revision the settings came from; ``checkout``: the repository,
    if the caller opened it). A bad gate or rule pack fails here, before any work."""
    settings = request.settings
    limits = worker_limits(settings.limits, settings.macros)
    gates, unit_gates = split_gates((*settings.gates, *request.gates))
    return DiffOptions(
        rules=location_rules(request),
        gates=gates,
        unit_gates=unit_gates,
        languages=settings.languages,
        # generated files count nowhere unless asked for: the first lines that say so suffice
        limits=replace(limits, skip_generated=not settings.include_generated),
        jobs=request.jobs or settings.jobs,
        coupling=coupling_options(settings),
        packs=rule_set(settings, root, checkout),
        dynamic_pre_zero=request.dynamic_pre_zero,
    )


def location_rules(request: DiffRequest) -> LocationRules:
    """``--new`` and ``--framework`` globs first, then the configured new, framework and base
    globs, in that order: the first that matches a path decides its location."""
    configured = request.settings.locations
    cli = LocationRules.from_mapping({"new": request.new, "framework": request.framework})
    rest = LocationRules.from_mapping(
        {"new": configured.new, "framework": configured.framework, "base": configured.base}
    )
    return LocationRules(
        cli.rules + rest.rules, request.settings.exclude, not request.settings.include_generated
    )
