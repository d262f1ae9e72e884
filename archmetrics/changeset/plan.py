"""An integration plan (thesis p. 109): per candidate architecture, the change each element
is planned to undergo, as frozen values. Reading one from TOML: changeset/plan_read.py;
applying one to a measured base: changeset/estimate.py.

"The metrics have the potential to be used predictively ... creating an integration plan for
each capability to be integrated and for each architecture to be considered" (Hestand 2011,
p. 109). Every value carries the plan key it came from, so an error or a figure names it.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from archmetrics.changeset.locations import Location

PLAN_SCHEMA = "archmetrics.plan/1"


class PlanError(ValueError):
    """A plan that cannot be used: one line naming the plan's file and the bad key."""

    def __init__(self, source: str, key: str, problem: str) -> None:
        self.source, self.key, self.problem = source, key, problem
        super().__init__(f"{source}: {key}: {problem}" if key else f"{source}: {problem}")


@dataclass(frozen=True, slots=True)
class PlannedLink:
    """Dynamic link sites the element gains: ``count`` uses of ``rule`` (+count to its d_e);
    with ``to``, an initiating rule's sites land in that element (+count to its d_a)."""

    rule: str
    count: int
    to: str | None
    key: str


@dataclass(frozen=True, slots=True)
class PlannedElement:
    """One element's planned change set: Γ_A, Γ_R, Γ_M in logical statements, the v_g it
    gains or loses, and the static dependencies and dynamic links it gains."""

    name: str
    key: str  # e.g. architecture.soa.element[2]
    new: bool = False
    location: Location | None = None  # None: the base's (existing) or the location globs'
    added: int = 0
    removed: int = 0
    modified: int = 0
    decisions_added: int = 0
    decisions_removed: int = 0
    functions_added: int = 0
    functions_removed: int = 0
    static_dependencies: tuple[str, ...] = ()
    dynamic_links: tuple[PlannedLink, ...] = ()

    @property
    def delta_loc(self) -> int:
        """λ_post − λ_pre: a planned statement is one logical line (docs/estimate.md)."""
        return self.added - self.removed

    @property
    def delta_vg(self) -> int:
        """v_g_post − v_g_pre: +1 per decision point, +1 per function (v_g = 1 + decisions)."""
        return (
            self.decisions_added
            - self.decisions_removed
            + self.functions_added
            - self.functions_removed
        )


class SketchKind(StrEnum):
    """What a sketch is: a revision of the repository, a patch file, or a folder of stubs."""

    REVISION = "revision"
    PATCH = "patch"
    STUBS = "stubs"


@dataclass(frozen=True, slots=True)
class Sketch:
    """An architecture drawn as code: measured against the base as ``diff`` would."""

    kind: SketchKind
    value: str  # the revision, or a path relative to the plan's folder
    key: str


@dataclass(frozen=True, slots=True)
class PlannedStage:
    """One stage (baseline, first, second ...): planned elements or a sketch, not both."""

    label: str
    key: str
    elements: tuple[PlannedElement, ...] = ()
    sketch: Sketch | None = None


@dataclass(frozen=True, slots=True)
class Architecture:
    """One candidate architecture: its stages in order (one stage when the plan has none)."""

    name: str
    key: str
    stages: tuple[PlannedStage, ...]
    description: str = ""
    base: str | None = None  # the revision its stages start from (default: --base)


@dataclass(frozen=True, slots=True)
class Plan:
    """The whole plan: where it was read from, and its architectures in the plan's order."""

    source: str
    architectures: tuple[Architecture, ...]
    title: str = ""
