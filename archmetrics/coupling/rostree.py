"""What a ROS tree's configuration says about its code, read from the facts of its files
(never run): the packages (``package.xml``), the executables Python packages declare
(``setup.py``'s ``console_scripts``), what the launch files start (roslaunch.py), what the
parameter files set, and the names plugin descriptions give classes (docs/metrics.md, "ROS
computation graphs").
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import PurePosixPath

from archmetrics.coupling.roslaunch import Launched, launched, python_value
from archmetrics.facts import ConfigFormat, FileFacts, Language
from archmetrics.parsers.config_xml import TEXT

PARAMETERS = "ros__parameters"


@dataclass(frozen=True, slots=True)
class Setting:
    """A parameter a parameter file sets: for the node its key names (``controller_server``,
    ``/ns/talker``, ``/**`` for every node), the parameter (dotted), the value as written."""

    path: str
    node: str
    parameter: str
    value: str


@dataclass(slots=True)
class RosTree:
    """The tree's ROS configuration."""

    packages: dict[str, str] = field(default_factory=dict)  # folder -> package name
    launched: list[Launched] = field(default_factory=list)
    settings: list[Setting] = field(default_factory=list)
    aliases: dict[str, str] = field(default_factory=dict)  # plugin lookup name -> class
    descriptions: dict[str, set[str]] = field(default_factory=dict)  # class -> files naming it
    executables: dict[tuple[str, str], str] = field(default_factory=dict)  # (folder, exe) -> file
    _by_parameter: dict[str, list[Setting]] | None = None

    def package_folders(self, name: str) -> list[str]:
        """The folders holding the package called ``name``."""
        return [folder for folder, package in self.packages.items() if package == name]

    def package_of(self, path: str) -> str | None:
        """The folder of the package ``path`` is in (the deepest holding a package.xml)."""
        folder = path.rpartition("/")[0]
        while True:
            if folder in self.packages:
                return folder
            if not folder:
                return None
            folder = folder.rpartition("/")[0]

    def _setting(self, node: str, parameter: str) -> list[Setting]:
        """The settings of ``parameter`` for the node ``node`` (``/ns/name``): by its fully
        qualified name, its name, or ``/**``."""
        if self._by_parameter is None:
            self._by_parameter = {}
            for setting in self.settings:
                self._by_parameter.setdefault(setting.parameter, []).append(setting)
        name = node.rsplit("/", 1)[-1]
        keys = {node, node.lstrip("/"), name, "/" + name, "/**", "**"}
        return [s for s in self._by_parameter.get(parameter, ()) if s.node in keys]

    def values_for(self, node: str, parameter: str) -> set[str]:
        """The values the parameter files give ``parameter`` of the node ``node``."""
        return {s.value for s in self._setting(node, parameter)}

    def setters(self, node: str, parameter: str) -> set[str]:
        """The parameter files that set ``parameter`` for ``node``."""
        return {s.path for s in self._setting(node, parameter)}


def read_tree(by_path: Mapping[str, FileFacts]) -> RosTree:
    """The ROS configuration of the tree whose files' facts are ``by_path``."""
    tree = RosTree()
    for path, facts in by_path.items():
        if facts.language == ConfigFormat.XML:
            _xml(tree, path, facts)
        elif facts.language == ConfigFormat.YAML:
            _parameters(tree, path, facts)
        elif facts.language == Language.PYTHON and PurePosixPath(path).name == "setup.py":
            _console_scripts(tree, path, facts)
    tree.launched = launched(by_path)
    return tree


def _xml(tree: RosTree, path: str, facts: FileFacts) -> None:
    for table in facts.tables:
        if table.keys == ("package", "name") and (name := table.get(TEXT)):
            tree.packages[path.rpartition("/")[0]] = name[0]
        elif table.keys[-1:] == ("class",) and table.keys[0] in ("library", "class_libraries"):
            kind = (table.get("type") or table.get("name") or ("",))[0]
            lookup = (table.get("name") or table.get("type") or ("",))[0]
            if kind:
                tree.aliases[lookup] = kind
                tree.descriptions.setdefault(kind, set()).add(path)


def _parameters(tree: RosTree, path: str, facts: FileFacts) -> None:
    for table in facts.tables:
        if PARAMETERS not in table.keys:
            continue
        at = table.keys.index(PARAMETERS)
        node = "/".join(table.keys[:at])
        prefix = table.keys[at + 1 :]
        for key, values in table.values:
            value = values[0] if len(values) == 1 else " ".join(values)
            tree.settings.append(Setting(path, node, ".".join((*prefix, key)), value))


def _console_scripts(tree: RosTree, path: str, facts: FileFacts) -> None:
    """``setup(entry_points={'console_scripts': ['talker = pkg.talker:main']})``."""
    folder = str(PurePosixPath(path).parent)
    folder = "" if folder == "." else folder
    for call in facts.call_sites:
        if call.callee not in ("setup", "setuptools.setup"):
            continue
        for argument in call.arguments:
            value = python_value(argument.text) if argument.keyword == "entry_points" else None
            scripts = value.get("console_scripts", ()) if isinstance(value, dict) else ()
            for script in scripts if isinstance(scripts, list | tuple) else ():
                name, _, target = str(script).partition("=")
                module = target.strip().partition(":")[0].replace(".", "/")
                if name.strip() and module:
                    file = f"{folder}/{module}.py" if folder else f"{module}.py"
                    tree.executables[(folder, name.strip())] = file


def configures(facts: FileFacts) -> bool:
    """Whether a file can be ROS configuration of other files (an XML or YAML file, a Python
    launch file, a ``setup.py``): a tree where one changes is coupled again whole."""
    if facts.language in (ConfigFormat.XML, ConfigFormat.YAML):
        return True
    if facts.language != Language.PYTHON:
        return False
    if PurePosixPath(facts.path).name == "setup.py":
        return True
    return any(d.target.split(".")[0] == "launch_ros" for d in facts.dependencies)
