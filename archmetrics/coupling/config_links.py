"""Configuration links: the link sites a configuration file's tables make (thesis p. 110).

"Linkages that could be modified through configuration information changes without requiring
recompilation" count like the links code makes: each occurrence is +1 to its element's d_e.
A rule pack's ``[[configuration]]`` rules say which tables are links (a content-based
router's outputs, ``[[rules.to]]``) and where their endpoint is; the configuration reader
gave the tables (:class:`~archmetrics.facts.ConfigTable`). A table is taken by the first
rule (in load order) whose ``table``, ``when`` and endpoint key it has, and is one link per
value of that key; a table without the key is no link of that rule (the router refuses an
output that names no service). The sites then
resolve like any others: a route to ``service:muri.backend`` links into the element that
provides it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from archmetrics.coupling.elements import Element
from archmetrics.coupling.endpoints import normalize
from archmetrics.coupling.model import Endpoint, LinkSite, LinkStatus
from archmetrics.coupling.patterns import SlowPattern, search
from archmetrics.coupling.roslaunch import table_launched
from archmetrics.coupling.rules import ConfigEndpoint, ConfigRule
from archmetrics.facts import ConfigTable, FileFacts
from archmetrics.globs import glob_matches


def config_link_sites(facts: FileFacts, rules: Sequence[ConfigRule]) -> tuple[LinkSite, ...]:
    """The link sites of one configuration file under ``rules`` (those of its format): the
    tables the generic rules select, and what the first rule of each interpreter whose
    ``files`` name the file reads (a launch file's nodes, roslaunch.py)."""
    usable = [rule for rule in rules if rule.format == facts.language and not rule.interpret]
    found: list[LinkSite] = list(_interpreted(facts, rules))
    for table in facts.tables if usable else ():
        rule = next((r for r in usable if _selects(r, table)), None)
        if rule is None:
            continue
        for text in table.get(rule.endpoint.key) or ():
            endpoint, note = _endpoint(rule.endpoint, text)
            found.append(
                LinkSite(facts.path, table.line, rule.qualified_id, rule.kind, rule.role,
                         ".".join(table.keys), endpoint, LinkStatus.UNRESOLVED, note=note)
            )  # fmt: skip
    return tuple(sorted(found, key=lambda s: (s.line, s.rule)))


def _interpreted(facts: FileFacts, rules: Sequence[ConfigRule]) -> list[LinkSite]:
    seen: set[str] = set()
    found: list[LinkSite] = []
    for rule in rules:
        if rule.interpret is None or rule.interpret in seen or rule.format != facts.language:
            continue
        if not any(glob_matches(glob, facts.path) for glob in rule.files):
            continue
        seen.add(rule.interpret)
        if rule.interpret == "ros-launch":
            for entry in table_launched(facts):
                point = Endpoint(entry.key, entry.plugin or entry.executable, "configuration")
                callee = "composable_node" if entry.plugin else "node"
                found.append(LinkSite(facts.path, entry.line, rule.qualified_id, rule.kind,
                                      rule.role, callee, point, LinkStatus.UNRESOLVED))  # fmt: skip
        elif rule.interpret == "pluginlib":
            found.extend(_described(facts, rule))
    return found


def _described(facts: FileFacts, rule: ConfigRule) -> list[LinkSite]:
    """A plugin description's classes (``<library><class name=... type=...>``): one site
    each, its endpoint the C++ class (``type``) as the loads of its lookup name (``name``,
    kept as the endpoint's text) resolve to it, receiving them."""
    found = []
    for table in facts.tables:
        if table.keys[-1:] != ("class",) or table.keys[0] not in ("library", "class_libraries"):
            continue
        kind = (table.get("type") or table.get("name") or ("",))[0]
        lookup = (table.get("name") or table.get("type") or ("",))[0]
        if kind:
            point = Endpoint(f"plugin:{kind}", lookup, "configuration")
            found.append(LinkSite(facts.path, table.line, rule.qualified_id, rule.kind,
                                  rule.role, "class", point, LinkStatus.UNRESOLVED))  # fmt: skip
    return found


def with_config_sites(
    found: Mapping[str, tuple[LinkSite, ...]],
    elements: Sequence[Element],
    by_path: Mapping[str, FileFacts],
    rules: Sequence[ConfigRule],
) -> dict[str, tuple[LinkSite, ...]]:
    """Each element's sites ``found`` in its code, and then those of its configuration files."""
    sites = dict(found)
    for element in elements if rules else ():
        extra = [
            site
            for path in element.files
            if by_path[path].tables
            for site in config_link_sites(by_path[path], rules)
        ]
        if extra:
            sites[element.name] = (*sites.get(element.name, ()), *extra)
    return sites


def _selects(rule: ConfigRule, table: ConfigTable) -> bool:
    """Whether ``rule`` takes ``table`` as a link: its keys, its values, its endpoint's key."""
    held = table.get(rule.endpoint.key) is not None
    return held and rule.table == table.keys and _holds(table, rule)


def _holds(table: ConfigTable, rule: ConfigRule) -> bool:
    """Whether ``table`` holds one of the values ``rule.when`` allows for each key it names
    (a key it leaves out holds the rule's default for it, if there is one)."""
    defaults = dict(rule.defaults)
    for key, allowed in rule.when:
        values = table.get(key)
        if values is None:
            values = (defaults[key],) if key in defaults else ()
        if not any(value in allowed for value in values):
            return False
    return True


def _endpoint(spec: ConfigEndpoint, text: str) -> tuple[Endpoint | None, str]:
    """The endpoint a value names, and why it is unknown when a pattern could not tell."""
    value: str | None = text
    if spec.pattern is not None:
        try:
            match = search(spec.pattern, text)
        except SlowPattern as slow:
            return None, str(slow)
        value = (match.group(1) if match.groups() else match.group(0)) if match else None
    key = normalize(spec.type, value) if value is not None else None
    return (Endpoint(key, text, "configuration") if key else None), ""
