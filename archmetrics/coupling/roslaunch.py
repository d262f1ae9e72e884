"""What a launch file starts, read from its facts, never run (docs/metrics.md, "ROS: launch
files"): each node or component with its package, executable or plugin, name, namespace,
remappings and parameters.

Python launch files are read from their call sites (``Node(package=..., executable=...,
remappings=[...])``, ``ComposableNode(...)``): a keyword's value is read when it is a literal
(a list of pairs, a dictionary) or a name the same function gives one literal value
(``remappings = [('/tf', 'tf')]`` then ``remappings=remappings``); anything computed
(``LaunchConfiguration('namespace')``) is not known. XML launch files (ROS 2's and ROS 1's
``.launch``) and YAML launch files are read from their tables: ``<node pkg exec name
namespace>`` (ROS 1: ``type``, ``ns``) with its ``<remap from to>`` and ``<param>``, inside
``<group ns>`` or after ``<push-ros-namespace namespace>``; ``<composable_node pkg plugin>``;
a ROS 1 ``nodelet`` node's ``args="load pkg/Name manager"``.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass

from archmetrics.coupling.graphnames import imported_names, qualified
from archmetrics.coupling.matching import matches, requirement_met
from archmetrics.facts import CallSite, ConfigTable, FileFacts, Language

_PUSHES = (("push-ros-namespace",), ("push_ros_namespace",))
NODE_CALLS = (
    "launch_ros.actions.Node", "actions.Node",
    "launch_ros.actions.ComposableNodeContainer", "actions.ComposableNodeContainer",
)  # fmt: skip
GROUP_CALLS = ("launch.actions.GroupAction", "actions.GroupAction")
PUSH_CALLS = ("launch_ros.actions.PushRosNamespace", "actions.PushRosNamespace",
              "launch_ros.actions.PushROSNamespace", "actions.PushROSNamespace")  # fmt: skip
ARGUMENT_CALLS = ("launch.actions.DeclareLaunchArgument", "actions.DeclareLaunchArgument")
# ExecuteProcess(cmd=["ros2", "run", pkg, executable]) starts that node
PROCESS_CALLS = ("launch.actions.ExecuteProcess", "actions.ExecuteProcess")
COMPONENT_CALLS = ("launch_ros.descriptions.ComposableNode", "descriptions.ComposableNode")


@dataclass(frozen=True, slots=True)
class Launched:
    """One node or component a launch file starts (a field is "" when not known)."""

    path: str
    line: int
    package: str
    executable: str = ""
    plugin: str = ""  # a component's class, or a nodelet's lookup name
    name: str = ""
    namespace: str = ""
    remaps: tuple[tuple[str, str], ...] = ()
    parameters: tuple[tuple[str, str], ...] = ()  # name -> value, set in the launch file
    known: bool = True  # False: some remapping or namespace was computed, not written

    @property
    def full_name(self) -> str:
        """The node's name as ROS gives it (``/robot1/talker``): its ``name``, else its
        executable's, under its namespace; "" when neither is written."""
        name = self.name or ("" if self.plugin else self.executable.rpartition("/")[2])
        if not name or name.startswith("/"):
            return name
        return "/" + "/".join(p for p in (*self.namespace.split("/"), name) if p)

    @property
    def key(self) -> str:
        """The endpoint of the launch site: ``node:pkg/exec`` or ``plugin:Class``."""
        if self.plugin:
            return f"plugin:{self.plugin}"
        return (
            f"node:{self.package}/{self.executable}" if self.package else f"node:{self.executable}"
        )


def python_value(text: str) -> object:
    """The value of a Python literal (lists and dictionaries too), or None."""
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError):
        return None


def _keyword(call: CallSite, names: Sequence[str]) -> str | None:
    for argument in call.arguments:
        if argument.keyword in names:
            return argument.text
    return None


def _named(facts: FileFacts, call: CallSite, text: str | None) -> object:
    """A keyword's value: its literal, or the one literal the call's function binds the name
    to before the call; None when computed."""
    if text is None:
        return None
    value = python_value(text)
    if value is not None or not text.isidentifier():
        return value
    found = {
        b.value for b in facts.bindings
        if b.name == text and b.function == call.function and b.line <= call.span.start
    }  # fmt: skip
    return python_value(found.pop()) if len(found) == 1 else None


def _pairs(value: object) -> tuple[tuple[tuple[str, str], ...], bool]:
    """Remappings as pairs of names, and whether every one was readable."""
    if not isinstance(value, list | tuple):
        return (), False
    pairs = [
        (str(item[0]), str(item[1]))
        for item in value
        if isinstance(item, tuple | list)
        and len(item) == 2
        and all(isinstance(p, str) for p in item)
    ]
    return tuple(pairs), len(pairs) == len(value)


def _parameters(value: object) -> tuple[tuple[str, str], ...]:
    """Parameters set by dictionaries in a ``parameters=[...]`` list."""
    found: list[tuple[str, str]] = []
    for item in value if isinstance(value, list | tuple) else ():
        if isinstance(item, dict):
            found += [(str(k), str(v)) for k, v in item.items() if isinstance(k, str)]
    return tuple(found)


def python_launched(facts: FileFacts) -> Iterator[Launched]:
    """The nodes and components a Python launch file starts."""
    if facts.language != Language.PYTHON or not requirement_met(
        ("launch_ros",), [d.target for d in facts.dependencies]
    ):
        return
    imports = imported_names(facts.dependencies)
    for call in facts.call_sites:
        callee = qualified(call.callee, imports)
        component = any(matches(p, callee) for p in COMPONENT_CALLS)
        if any(matches(p, callee) for p in PROCESS_CALLS):
            if (process := _ros2_run(facts, call)) is not None:
                yield process
            continue
        if not component and not any(matches(p, callee) for p in NODE_CALLS):
            continue
        text = {
            key: _named(facts, call, _keyword(call, names))
            for key, names in (
                ("package", ("package",)), ("executable", ("executable", "node_executable")),
                ("plugin", ("plugin",)), ("name", ("name", "node_name")),
                ("namespace", ("namespace", "node_namespace")), ("remappings", ("remappings",)),
                ("parameters", ("parameters",)),
            )
        }  # fmt: skip
        remaps, readable = _pairs(text["remappings"])
        written = _keyword(call, ("remappings",)) is None or readable
        namespace = text["namespace"]
        pushed = _pushed(facts, call, imports)
        if pushed and namespace is None and _keyword(call, ("namespace",)) is None:
            namespace = pushed
        yield Launched(
            facts.path, call.span.start, _text(text["package"]),
            executable="" if component else _text(text["executable"]),
            plugin=_text(text["plugin"]) if component else "", name=_text(text["name"]),
            namespace=_text(namespace), remaps=remaps,
            parameters=_parameters(text["parameters"]),
            known=written and (namespace is not None or _keyword(call, ("namespace",)) is None),
        )  # fmt: skip


def _pushed(facts: FileFacts, call: CallSite, imports: Mapping[str, str]) -> str | None:
    """The namespace a ``PushRosNamespace`` before ``call`` in the innermost ``GroupAction``
    around it pushes: a literal, or a ``LaunchConfiguration`` by its launch argument's
    ``default_value``; None when none is pushed or it is computed."""
    calls = [(qualified(c.callee, imports), c) for c in facts.call_sites]
    groups = [c for name, c in calls if _any(GROUP_CALLS, name) and c.span.start <= call.span.start
              and call.span.end <= c.span.end and c is not call]  # fmt: skip
    if not groups:
        return None
    group = max(groups, key=lambda c: c.span.start)
    pushes = [c for name, c in calls if _any(PUSH_CALLS, name) and c.arguments
              and group.span.start <= c.span.start <= call.span.start]  # fmt: skip
    if not pushes:
        return None
    written = pushes[-1].arguments[0].text
    value = _named(facts, call, written)
    if isinstance(value, str):
        return value
    configuration = next(
        (b.value for b in facts.bindings if b.name == written and b.function == call.function),
        written,
    )  # robot = LaunchConfiguration('robot')
    argument = _configuration_name(configuration)
    for name, other in calls:
        if (
            _any(ARGUMENT_CALLS, name) and other.arguments
            and python_value(other.arguments[0].text) == argument
        ):  # fmt: skip
            default = _named(facts, other, _keyword(other, ("default_value",)))
            return default if isinstance(default, str) else None
    return None


def _any(patterns: Sequence[str], callee: str) -> bool:
    return any(matches(p, callee) for p in patterns)


def _configuration_name(text: str) -> str | None:
    """``x`` of ``LaunchConfiguration('x')`` as written; None for anything else."""
    head, _, rest = text.replace(" ", "").partition("(")
    if not head.endswith("LaunchConfiguration") or not rest.endswith(")"):
        return None
    value = python_value(rest[:-1].split(",")[0])
    return value if isinstance(value, str) else None


def _ros2_run(facts: FileFacts, call: CallSite) -> Launched | None:
    """``ExecuteProcess(cmd=["ros2", "run", pkg, executable, ...])``: that node, named after
    its executable; None for any other command."""
    cmd = _named(facts, call, _keyword(call, ("cmd",)))
    if not isinstance(cmd, list | tuple) or len(cmd) < 4 or list(cmd[:2]) != ["ros2", "run"]:
        return None
    package, executable = cmd[2], cmd[3]
    if not isinstance(package, str) or not isinstance(executable, str):
        return None
    return Launched(facts.path, call.span.start, package, executable=executable)


def _text(value: object) -> str:
    return value if isinstance(value, str) else ""


def table_launched(facts: FileFacts) -> Iterator[Launched]:
    """The nodes and components an XML or YAML launch file starts."""
    tables = facts.tables
    if not tables or not any(t.keys[:1] == ("launch",) for t in tables):
        return
    children: dict[int, list[ConfigTable]] = {}
    for table in tables:
        children.setdefault(table.parent, []).append(table)
    for index, table in enumerate(tables):
        kind = table.keys[-1] if table.keys else ""
        if kind not in ("node", "composable_node"):
            continue
        yield _from_table(facts.path, tables, index, children.get(index, []))


def _one(table: ConfigTable, *keys: str) -> str:
    for key in keys:
        values = table.get(key)
        if values:
            return values[0]
    return ""


def _from_table(
    path: str, tables: Sequence[ConfigTable], index: int, children: Sequence[ConfigTable]
) -> Launched:
    table = tables[index]
    package = _one(table, "pkg", "package")
    remaps = tuple((_one(c, "from"), _one(c, "to")) for c in children if c.keys[-1:] == ("remap",))
    parameters = tuple(
        (_one(c, "name"), _one(c, "value"))
        for c in children
        if c.keys[-1:] == ("param",) and _one(c, "name") and c.get("value") is not None
    )
    namespace = _one(table, "namespace", "ns")
    outer = _namespace_around(tables, index)
    if outer:
        namespace = (
            f"{outer}/{namespace}"
            if namespace and not namespace.startswith("/")
            else (namespace or outer)
        )
    executable = _one(table, "exec", "executable", "type")
    plugin = _one(table, "plugin") if table.keys[-1] == "composable_node" else ""
    arguments = _one(table, "args").split()
    if package == "nodelet" and len(arguments) >= 2 and arguments[0] in ("load", "standalone"):
        plugin = arguments[1]  # a nodelet: loaded by its lookup name
    return Launched(
        path, table.line, package, executable=executable, plugin=plugin,
        name=_one(table, "name"), namespace=namespace, remaps=remaps, parameters=parameters,
    )  # fmt: skip


def _namespace_around(tables: Sequence[ConfigTable], index: int) -> str:
    """The namespace the groups around a launch file's entry push (``<group ns>``,
    ``<push-ros-namespace namespace>`` before it in one of them), outermost first."""
    parts: list[str] = []
    parent = tables[index].parent
    seen = 0
    while 0 <= parent < len(tables) and seen < 64:
        group = tables[parent]
        pushed = [
            _one(t, "namespace", "ns") for t in tables[parent + 1 : index]
            if t.parent == parent and t.keys[-1:] in _PUSHES
        ]  # fmt: skip
        own = _one(group, "ns", "namespace") if group.keys[-1:] == ("group",) else ""
        parts[:0] = [p for p in (own, *pushed) if p]
        parent, seen = group.parent, seen + 1
    return "/".join(p.strip("/") for p in parts if p.strip("/"))


def launched(by_path: Mapping[str, FileFacts]) -> list[Launched]:
    """Every node and component the tree's launch files start, by path and line."""
    found: list[Launched] = []
    for facts in by_path.values():
        found += (
            python_launched(facts) if facts.language == Language.PYTHON else table_launched(facts)
        )
    return found
