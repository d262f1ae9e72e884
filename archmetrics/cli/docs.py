"""``archmetrics docs [TOPIC]``: the documentation installed with archmetrics.

The wheel carries docs/ as ``archmetrics/docs`` (pyproject's force-include), so a plain
``pip install`` has the pages ``--help`` names; a checkout reads docs/ beside the package.
The project has no public home yet: once it has one, its Project-URLs are printed here too.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from archmetrics.cli.common import EXIT_OK, UsageError, emit

_PACKAGE = Path(__file__).resolve().parent.parent


def docs_root() -> Path | None:
    """The folder of the installed pages (inside the package), or a checkout's docs/."""
    for candidate in (_PACKAGE / "docs", _PACKAGE.parent / "docs"):
        if (candidate / "metrics.md").is_file():
            return candidate
    return None


def topics(root: Path) -> dict[str, Path]:
    """Every page by its topic: its path below the docs folder without ``.md``."""
    pages = sorted(root.rglob("*.md"))
    return {page.relative_to(root).with_suffix("").as_posix(): page for page in pages}


def _title(page: Path) -> str:
    with page.open(encoding="utf-8") as text:
        return text.readline().lstrip("# ").strip()


def _project_urls() -> list[str]:
    from importlib.metadata import PackageNotFoundError, metadata

    try:
        return list(metadata("archmetrics").get_all("Project-URL") or [])
    except PackageNotFoundError:
        return []


def docs_command(args: argparse.Namespace) -> int:
    root = docs_root()
    if root is None:
        raise UsageError("the documentation is missing from this installation")
    pages = topics(root)
    if args.topic is None:
        width = max(len(topic) for topic in pages)
        lines = [f"archmetrics's documentation is installed in {root}:"]
        lines += [f"  {topic:<{width}}  {_title(page)}" for topic, page in pages.items()]
        lines.append("`archmetrics docs TOPIC` prints a page, `--path` its file.")
        lines.append(f"JSON Schemas of the reports: {_PACKAGE / 'schemas'}")
        lines += [f"Project URL: {url}" for url in _project_urls()]
        emit("\n".join(lines) + "\n", None)
        return EXIT_OK
    topic = args.topic.removesuffix(".md")
    if topic not in pages:
        raise UsageError(f"no page {args.topic!r} (pages: {', '.join(pages)})")
    if args.path:
        print(pages[topic])
    else:
        emit(pages[topic].read_text(encoding="utf-8"), None)
    return EXIT_OK
