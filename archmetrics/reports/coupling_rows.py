"""Rows for coupling views (``scan --by element`` and ``--by link``), shared by every format."""

from __future__ import annotations

from typing import Any

from archmetrics.coupling import CouplingReport, LinkSite, StaticDependency
from archmetrics.reports.model import ScanReport

ELEMENT_HEADER = ("element", "files", "λ", "SLOC", "v_g", "s_a", "s_e", "d_a", "d_e")
LINK_HEADER = ("element", "where", "link", "rule", "kind", "role", "target", "status")


def element_rows(report: ScanReport) -> list[list[str]]:
    return [
        [
            r.element,
            " ".join(r.files),
            *(str(v) for v in (r.loc, r.sloc, r.vg, r.s_a, r.s_e, r.d_a, r.d_e)),
        ]
        for r in report.element_rows()
    ]


def _static_target(dep: StaticDependency) -> str:
    target = dep.name + (f" → {dep.target_element}" if dep.target_element else "")
    return target if dep.counted else target + " (own element, not counted)"


def _dynamic_target(site: LinkSite) -> str:
    unknown = "?" + (f" ({site.note})" if site.note else "")
    endpoint = site.endpoint.key if site.endpoint else unknown
    return endpoint + (f" → {', '.join(site.targets)}" if site.targets else "")


def link_rows(coupling: CouplingReport | None) -> list[list[str]]:
    """Every static dependency (one row per site) and every dynamic link site, traced to lines."""
    rows: list[list[str]] = []
    for c in coupling.elements if coupling else ():
        name = c.element.name
        for dep in c.dependencies:
            for site in dep.sites:
                rows.append(
                    [
                        name,
                        f"{site.path}:{site.line}",
                        "static",
                        str(dep.kind),
                        "",
                        "",
                        _static_target(dep),
                        str(dep.resolution),
                    ]
                )
        for s in c.link_sites:
            rows.append(
                [
                    name,
                    f"{s.path}:{s.line}",
                    "dynamic",
                    s.rule,
                    str(s.kind),
                    str(s.role),
                    _dynamic_target(s),
                    str(s.status),
                ]
            )
    return rows


def dependency_dict(dep: StaticDependency) -> dict[str, Any]:
    return {
        "name": dep.name,
        "kind": str(dep.kind),
        "resolution": str(dep.resolution),
        "target_file": dep.target_file,
        "target_element": dep.target_element,
        "counted": dep.counted,
        "sites": [{"path": s.path, "line": s.line} for s in dep.sites],
    }


def site_dict(site: LinkSite) -> dict[str, Any]:
    return {
        "path": site.path,
        "line": site.line,
        "rule": site.rule,
        "kind": str(site.kind),
        "role": str(site.role),
        "callee": site.callee,
        "endpoint": site.endpoint.key if site.endpoint else None,
        "endpoint_text": site.endpoint.text if site.endpoint else None,
        "status": str(site.status),
        "targets": list(site.targets),
        "function": site.function,
        "note": site.note or None,
        # graph names (ROS): the data type, the name as written, the node, further keys
        "endpoint_type": site.data_type or None,
        "endpoint_name": site.name or None,
        "node": site.node or None,
        "also_endpoints": list(site.endpoint.also) if site.endpoint else [],
    }


def elements_json(report: ScanReport) -> list[dict[str, Any]]:
    if report.coupling is None:
        return []
    detail = {c.element.name: c for c in report.coupling.elements}
    out = []
    for row in report.element_rows():
        c = detail[row.element]
        out.append(
            {
                "element": row.element,
                "files": list(row.files),
                "loc": row.loc,
                "sloc": row.sloc,
                "vg": row.vg,
                "s_a": row.s_a,
                "s_e": row.s_e,
                "d_a": row.d_a,
                "d_e": row.d_e,
                "dependents": list(c.dependents),
                "dependencies": [dependency_dict(d) for d in c.dependencies],
                "link_sites": [site_dict(s) for s in c.link_sites],
            }
        )
    return out
