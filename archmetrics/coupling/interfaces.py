"""ROS interface packages as static coupling: the ``.msg``, ``.srv`` and ``.action`` files of
the tree, and the includes and imports of the code generated from them.

rosidl generates, from ``geometry_msgs/msg/Twist.msg``, the C++ header
``geometry_msgs/msg/twist.hpp`` (the type's name in snake case; ROS 1's genmsg:
``geometry_msgs/Twist.h``) and the Python module ``geometry_msgs.msg`` holding ``Twist``.
An include or import of generated code that the tree does not hold depends, when the tree
holds the interface file, on that file (its element gets s_a): the interface is the contract
between the packages. Interface files are listed elements with λ = 0, as configuration files
are (docs/metrics.md, "ROS computation graphs").
"""

from __future__ import annotations

import re
from collections.abc import Iterable

KINDS = ("msg", "srv", "action")
_HEADER = re.compile(
    r"^(?P<package>[A-Za-z_]\w*)/(?P<kind>msg|srv|action)/(?:detail/)?(?P<name>[a-z0-9_]+?)"
    r"(?:__(?:struct|traits|builder|type_support|functions))?\.(?:hpp|h)$"
)
_ROS1_HEADER = re.compile(r"^(?P<package>[A-Za-z_]\w*)/(?P<name>[A-Z]\w*)\.h$")
_WORD = re.compile(r"[A-Z]+(?=[A-Z][a-z0-9])|[A-Z]?[a-z0-9]+|[A-Z]+")


def snake(name: str) -> str:
    """A type's name as rosidl names its header: ``PoseWithCovarianceStamped`` ->
    ``pose_with_covariance_stamped``, ``TFMessage`` -> ``tf_message``, ``SetBool`` ->
    ``set_bool``."""
    return "_".join(part.lower() for part in _WORD.findall(name))


class InterfaceIndex:
    """The tree's interface files by package, kind and type name."""

    def __init__(self, paths: Iterable[str]) -> None:
        self.by_type: dict[tuple[str, str, str], str] = {}
        self.by_snake: dict[tuple[str, str, str], str] = {}
        for path in paths:
            folder, _, file = path.rpartition("/")
            name, dot, kind = file.rpartition(".")
            parent, _, last = folder.rpartition("/")
            if not dot or kind not in KINDS or last != kind:
                continue
            package = parent.rpartition("/")[2]
            if not package:
                continue
            self.by_type.setdefault((package, kind, name), path)
            self.by_snake.setdefault((package, kind, snake(name)), path)

    def __bool__(self) -> bool:
        return bool(self.by_type)

    def include(self, target: str) -> str | None:
        """The interface file a generated header stands for (``geometry_msgs/msg/twist.hpp``,
        ``geometry_msgs/Twist.h``), or None."""
        if found := _HEADER.match(target):
            key = (found["package"], found["kind"], found["name"])
            return self.by_snake.get(key)
        if found := _ROS1_HEADER.match(target):
            for kind in ("msg", "srv"):
                path = self.by_type.get((found["package"], kind, found["name"]))
                if path is not None:
                    return path
        return None

    def module(self, target: str, name: str) -> str | None:
        """The interface file ``from <target> import <name>`` reads (``geometry_msgs.msg``,
        ``Twist``), or None."""
        package, dot, kind = target.rpartition(".")
        if not dot or kind not in KINDS or "." in package:
            return None
        return self.by_type.get((package, kind, name))
