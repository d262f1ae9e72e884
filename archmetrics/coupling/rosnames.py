"""ROS graph names and interface types, resolved as ROS resolves them (pure functions).

A topic, service, action or parameter name is *absolute* (``/cmd_vel``), *private*
(``~/state``, in ROS 1 also ``~state``: under the node's own name) or *relative*
(``cmd_vel``: under the node's namespace). rcl (ROS 2) and ros::names (ROS 1) resolve them
against the node's namespace (``/`` unless a launch file or the node's constructor sets one)
and name; a remapping then replaces a whole resolved name. Types are written
``geometry_msgs::msg::Twist`` in C++, ``geometry_msgs.msg.Twist`` in Python and
``geometry_msgs/msg/Twist`` by ROS's tools: they are compared in the last form.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

_TYPE_NOISE = re.compile(
    r"\b(?:const|typename|struct|class)\b|[&*\s]|::SharedPtr$|::ConstSharedPtr$"
)


@dataclass(frozen=True, slots=True)
class NodeName:
    """Where a node sits in the graph: its name (None when not known statically) and its
    namespace (absolute, ``/`` for the root)."""

    name: str | None
    namespace: str = "/"

    @property
    def fully_qualified(self) -> str | None:
        """``/ns/name``, or None without a name."""
        if self.name is None:
            return None
        return join(self.namespace, self.name)


class UnresolvedName(ValueError):
    """A name that cannot be resolved statically; the message says why."""


def join(namespace: str, name: str) -> str:
    """``namespace`` and a relative ``name`` as one absolute name (``/a`` + ``b`` = ``/a/b``)."""
    parts = [p for part in (namespace, name) for p in part.split("/") if p]
    return "/" + "/".join(parts)


def clean_namespace(text: str | None) -> str:
    """A namespace as given (``ns``, ``/ns/``, ``""``) made absolute (``/ns``, ``/``)."""
    return join("/", text or "")


UNKNOWN = "\x00"  # a ROS 1 NodeHandle's namespace that is computed at run time


def resolve(name: str, node: NodeName, handle: str | None = None) -> str:
    """The absolute name ``name`` stands for in ``node``. ``handle``: the namespace of the
    ROS 1 NodeHandle the name is given to, as written (``~`` private, ``foo`` relative,
    ``/foo`` absolute): a relative name resolves under it. Raises :class:`UnresolvedName`
    when that depends on what is not known statically."""
    text = name.strip()
    if not text:
        raise UnresolvedName("an empty name")
    if "{" in text or "$" in text:
        raise UnresolvedName(f"{text!r} holds a substitution")
    if text.startswith("~"):
        qualified = node.fully_qualified
        if qualified is None:
            raise UnresolvedName(f"private name {text!r}: the node's name is not known statically")
        return join(qualified, text[1:])
    if text.startswith("/"):
        return join("/", text)
    base = node.namespace
    if handle == UNKNOWN:
        raise UnresolvedName(f"{text!r} is given to a NodeHandle whose namespace is computed")
    if handle is not None and handle.strip():
        base = resolve(handle, node)
    return join(base, text)


_ADAPTER = re.compile(r"(?:rclcpp::)?(?:TypeAdapter<.*,|adapt_type<.*>::as<)([\w:]+)>")


def interface_type(written: str) -> str:
    """A message, service or action type as ROS's tools write it: ``pkg/msg/Name``
    (``geometry_msgs::msg::Twist``, ``geometry_msgs.msg.Twist``, ``std_msgs::String``); a
    type adapter by the ROS type it adapts to; one named in a string (a generic publisher's
    ``"std_msgs/msg/String"``) without its quotes."""
    text = _TYPE_NOISE.sub("", written.strip().strip("\"'")).lstrip(":")
    adapted = _ADAPTER.fullmatch(text)  # rclcpp::TypeAdapter<std::string, pkg::msg::T>
    if adapted:
        text = adapted.group(1)
    text = re.sub(r"<.*>$", "", text)
    text = text.replace("::", "/").replace(".", "/")
    return text


def qualified_type(text: str) -> bool:
    """Whether a type names its package (``std_msgs/msg/String``, ``std_msgs/String``):
    only such types are compared when two sites of one topic disagree."""
    return "/" in text
