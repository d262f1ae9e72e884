"""The ``replicate`` use case: the thesis's study, run on the subjects shipped with archmetrics.

Every subject/approach becomes a temporary git repository (a commit and tag per stage); each
is measured as a series, the approaches of a subject are compared, and the thesis's findings
are checked against what was measured.
"""

from __future__ import annotations

import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from archmetrics.app.diff_options import DiffRequest
from archmetrics.app.progress import Progress
from archmetrics.app.series import SeriesRequest, run_compare
from archmetrics.config import LocationSettings, Settings
from archmetrics.sources.cache import FactsCache
from archmetrics.sources.staging import build_stage_repository
from archmetrics.study.findings import check_findings
from archmetrics.study.manifest import VARIANTS, Manifest, ManifestError, find_manifests
from archmetrics.study.report import StudyReport, SubjectResult, VariantResult


def subjects_root() -> Path:
    """The bundled subjects: inside the installed package, or fixtures/study in a checkout."""
    package = Path(__file__).resolve().parent.parent
    for candidate in (package / "study_subjects", package.parent / "fixtures" / "study"):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError("the bundled study subjects are missing from this installation")


@dataclass(frozen=True, slots=True)
class ReplicateRequest:
    subjects: Path
    only: tuple[str, ...] = ()  # subject names; empty: all
    jobs: int = 0
    keep_repositories: Path | None = None  # build the repositories here and keep them


def settings_for(manifest: Manifest) -> Settings:
    """The manifest's locations and exclusions as archmetrics settings."""
    globs = dict(manifest.locations)
    return Settings(
        source=str(manifest.path / "manifest.toml"),
        exclude=manifest.exclude,
        include_generated=not manifest.exclude_generated,
        locations=LocationSettings(
            new=globs.get("new", ()),
            framework=globs.get("framework", ()),
            base=globs.get("base", ()),
        ),
    )


def _series_request(manifest: Manifest, repo: Path, jobs: int) -> SeriesRequest:
    diff = DiffRequest(root=repo, base="", head="", settings=settings_for(manifest), jobs=jobs)
    return SeriesRequest(diff, manifest.stages, manifest.stages)


def _build(manifests: Sequence[Manifest], where: Path) -> dict[Manifest, Path]:
    repos = {}
    for m in manifests:
        dest = where / m.variant / m.subject / m.approach
        build_stage_repository(dest, [(stage, m.stage_dir(stage)) for stage in m.stages])
        repos[m] = dest
    return repos


def run_replicate(
    request: ReplicateRequest, progress: Progress | None = None, cache: FactsCache | None = None
) -> StudyReport:
    found = find_manifests(request.subjects)
    known = sorted({m.subject for m in found})
    unknown = [name for name in request.only if name not in known]
    if unknown:
        raise ManifestError(
            f"no study subject {unknown[0]!r}; the subjects are: {', '.join(known) or 'none'}"
        )
    manifests = [m for m in found if not request.only or m.subject in request.only]
    if not manifests:
        raise ManifestError(f"no study subjects found under {request.subjects}")
    with tempfile.TemporaryDirectory(prefix="archmetrics-study-") as scratch:
        where = request.keep_repositories or Path(scratch)
        repos = _build(manifests, where)
        variants = [
            _measure_variant(
                variant,
                [m for m in manifests if m.variant == variant],
                repos,
                request.jobs,
                progress,
                cache,
            )
            for variant in VARIANTS
        ]
    return StudyReport(tuple(variants))


def _measure_variant(
    variant: str,
    manifests: Sequence[Manifest],
    repos: dict[Manifest, Path],
    jobs: int,
    progress: Progress | None,
    cache: FactsCache | None,
) -> VariantResult:
    """Every subject of one variant compared across its approaches, and the findings checked."""
    results = []
    for subject in sorted({m.subject for m in manifests}):
        ours = [m for m in manifests if m.subject == subject]
        named = [(m.approach, _series_request(m, repos[m], jobs)) for m in ours]
        compare = run_compare(named, progress, cache)
        results.append(SubjectResult(subject, tuple(ours), compare))
    subjects = {r.subject: r.compare for r in results}
    return VariantResult(variant, tuple(results), check_findings(subjects))
