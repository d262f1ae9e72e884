"""A link site's graph name, resolved, and its data type (rules with ``naming``, ``value``
or ``data_type`` in their endpoint; docs/metrics.md, "ROS: names and types").

The endpoint a rule reads (``topic:chatter``) is a name as written; with ``naming = "ros"``
it is resolved against the node and handle the call is made in (scopes.py):
``topic:/chatter``, ``topic:/talker/state`` for ``~/state``, ``parameter:/talker/rate`` for a
parameter. A name that cannot be resolved statically (a private name in a node whose name is
computed) leaves the site without an endpoint, its note saying why, its name kept. The data
type is read as written and spelled as ROS's tools spell it (``geometry_msgs/msg/Twist``);
in Python a type imported by name is read through its import, in C++ a type alias of the
same file (``using Msg = std_msgs::msg::String;``, ``using std_msgs::msg::Int32;``) through
the alias.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

from archmetrics.coupling.endpoints import normalize
from archmetrics.coupling.matching import constructed, member
from archmetrics.coupling.model import Endpoint, LinkSite
from archmetrics.coupling.rosnames import (
    UNKNOWN,
    NodeName,
    UnresolvedName,
    interface_type,
    resolve,
)
from archmetrics.coupling.rules import EndpointSpec, Place
from archmetrics.coupling.scopes import FileScopes
from archmetrics.coupling.values import pick
from archmetrics.facts import Binding, CallSite, Dependency, Statement
from archmetrics.parsers.c_family_calls import template_arguments, without_template_arguments

_DECLARED = re.compile(r"(?:const\s+)?([A-Za-z_][\w:]*)\s+([A-Za-z_]\w*)\s*;")
_TEMPLATED = re.compile(r"(?:const\s*)?([A-Za-z_][\w:]*<.*>)\s*([A-Za-z_]\w*)\s*;")
_SHARED = re.compile(r"(?:boost|std)::shared_ptr<(.+)>")
_CALLBACK_SUFFIX = re.compile(r"(?:::ConstPtr|::Ptr|ConstPtr|::Request|::Response)$")
_TYPE_NAME = re.compile(r"[A-Za-z_]\w*(?:::[A-Za-z_]\w*)*(?:<.*>)?")


def imported_names(dependencies: Sequence[Dependency]) -> dict[str, str]:
    """The names a Python file's imports bind, each to the dotted name it stands for
    (``Twist`` -> ``geometry_msgs.msg.Twist`` after ``from geometry_msgs.msg import Twist``)."""
    found: dict[str, str] = {}
    for dependency in dependencies:
        if dependency.level:
            continue
        if not dependency.names:
            for bound in dependency.bound:  # import a.b as c: c is a.b
                if bound != dependency.target.split(".")[0]:
                    found[bound] = dependency.target
            continue
        for name, bound in zip(dependency.names, dependency.bound, strict=False):
            found[bound] = f"{dependency.target}.{name}"
    return found


def qualified(callee: str, imports: Mapping[str, str]) -> str:
    """A Python callee with the name it starts with read through the file's imports
    (``Node`` -> ``launch_ros.actions.Node`` after ``from launch_ros.actions import Node``);
    as written when that name is no import."""
    head, dot, rest = callee.replace(" ", "").partition(".")
    found = imports.get(head)
    return f"{found}{dot}{rest}" if found else callee


class TypeAliases:
    """A C++ file's type aliases, read from its bindings when first asked: each name with
    the types it is given, in the function that gives it (None: at file, namespace or class
    level). Only a binding whose value is a plain (qualified) name is an alias. And its
    functions' signatures (``function`` statements), for the type a callback takes."""

    __slots__ = ("_bindings", "_found", "_statements")

    def __init__(self, bindings: Sequence[Binding], statements: Sequence[Statement] = ()) -> None:
        self._bindings = bindings
        self._statements = statements
        self._found: dict[str, dict[str | None, str]] | None = None

    def parameter_type(self, callback: str, function: str | None = None) -> str | None:
        """The type of the first parameter of the function ``callback`` names (``onScan``,
        ``&Node::onScan``) as written, without its reference, ``ConstPtr`` or ``Request``;
        else, for a plain name, the type a declaration in ``function`` gives it
        (``nav_msgs::GetMap map;``); None when the file says neither."""
        name = callback.replace(" ", "").lstrip("&").rpartition("::")[2]
        if not name.isidentifier():
            return None
        heads = [s.text for s in self._statements if s.kind == "function" and s.function
                 and (s.function == name or s.function.endswith("::" + name))]  # fmt: skip
        if not heads and name == callback.strip():
            return self._declared(name, function)
        if len(heads) != 1 or "(" not in heads[0]:
            return None
        first = heads[0].partition("(")[2].rpartition(")")[0].split(",")[0].split("=")[0]
        first = re.sub(r"\s*([:<>])\s*", r"\1", re.sub(r"\bconst\b", " ", first))
        words = first.replace("&", " ").replace("*", " ").split()
        if len(words) > 1 and words[-1].isidentifier():
            words = words[:-1]  # the parameter's name
        written = "".join(words)
        inner = _SHARED.fullmatch(written)
        written = inner.group(1) if inner else written
        return _CALLBACK_SUFFIX.sub("", written) or None

    def _declared(self, name: str, function: str | None) -> str | None:
        """The type ``T`` of the one declaration ``T name;`` in ``function``."""
        found = {
            declared.group(1)
            for s in self._statements
            if s.kind == "declaration" and s.function == function
            and (declared := _DECLARED.fullmatch(re.sub(r"\s*::\s*", "::", s.text)))
            and declared.group(2) == name
        }  # fmt: skip
        return found.pop() if len(found) == 1 else None

    def receiver_templates(self, receiver: str, function: str | None) -> tuple[str, ...]:
        """The template arguments of the type the object ``receiver`` is declared with, in
        ``function`` or as a member (``message_filters::Subscriber<T> sub_;``); () when none."""
        found = {
            declared.group(1)
            for s in self._statements
            if s.kind in ("field", "declaration") and s.function in (function, None)
            and (declared := _TEMPLATED.fullmatch(re.sub(r"\s*([:<>,])\s*", r"\1", s.text)))
            and declared.group(2) == receiver
        }  # fmt: skip
        return template_arguments(found.pop()) if len(found) == 1 else ()

    def get(self, name: str, function: str | None) -> str | None:
        """The type ``name`` stands for in ``function``: its alias there, else one given
        outside any function; None when there is none."""
        if self._found is None:
            found: dict[str, dict[str | None, str]] = {}
            for binding in self._bindings:
                value = binding.value.replace(" ", "")
                if _TYPE_NAME.fullmatch(value) and value != binding.name:
                    found.setdefault(binding.name, {})[binding.function] = value
            self._found = found
        given = self._found.get(name)
        if given is None:
            return None
        return given.get(function) or given.get(None)


def through_alias(call: CallSite, aliases: TypeAliases | None) -> CallSite | None:
    """``call`` as made through the type alias its callee names (``MoveServer server(nh,
    "move_base")`` after ``typedef actionlib::SimpleActionServer<T> MoveServer;``): its
    callee the aliased class, its template arguments the alias's; None when it names none."""
    if aliases is None or call.receiver is not None or call.templates:
        return None
    given = aliases.get(call.callee, call.function)
    if given is None or given == call.callee:
        return None
    return call._replace(
        callee=without_template_arguments(given),
        name=without_template_arguments(given).rpartition("::")[2],
        templates=template_arguments(given) if "<" in given else (),
    )


def data_type(
    call: CallSite,
    place: Place | None,
    imports: Mapping[str, str],
    ros1: bool = False,
    aliases: TypeAliases | None = None,
) -> str:
    """The data type a call names at ``place`` (a template argument or an argument), as ROS
    spells it (ROS 1: ``std_msgs/String``, also for Python's ``std_msgs.msg.String``), read
    through ``aliases`` (C++); "" when it names none."""
    found = _data_type(call, place, imports, aliases)
    if ros1:
        package, _, rest = found.partition("/")
        kind, _, name = rest.partition("/")
        if name and kind in ("msg", "srv", "action"):
            return f"{package}/{name}"
    return found


def _data_type(
    call: CallSite, place: Place | None, imports: Mapping[str, str], aliases: TypeAliases | None
) -> str:
    if place is None:
        return ""
    if place.value is not None:
        return interface_type(place.value)
    written: str | None = None
    if place.template is not None:
        _, templates = constructed(call)
        if not templates and call.receiver and aliases is not None:  # sub_.subscribe(...)
            templates = aliases.receiver_templates(member(call.receiver), call.function)
        written = templates[place.template] if place.template < len(templates) else None
    elif place.arg is not None or place.keyword is not None:
        argument = pick(call.arguments, place)
        written = argument.text if argument is not None else None
    if not written and place.callback is not None and aliases is not None:
        positional = [a for a in call.arguments if a.keyword is None]
        if place.callback < len(positional):
            written = aliases.parameter_type(positional[place.callback].text, call.function)
    if not written:
        return ""
    written = written.replace(" ", "")
    head, dot, rest = written.partition(".")
    if head in imports:
        written = imports[head] + dot + rest
    elif aliases is not None:
        seen = {written}
        while (given := aliases.get(written, call.function)) and given not in seen:
            seen.add(given)  # using A = B; using B = pkg::msg::C;
            written = given
    return interface_type(written)


@dataclass(frozen=True, slots=True)
class Named:
    """What the graph-name reading adds to a site."""

    endpoint: Endpoint | None
    note: str
    name: str = ""
    node: str = ""


def graph_endpoint(
    spec: EndpointSpec, call: CallSite, found: Endpoint | None, note: str, scopes: FileScopes
) -> Named:
    """The site's endpoint with its names resolved (``spec.naming``), or fixed
    (``spec.value``): the first name is the endpoint, the others keys it also receives on."""
    names = list(spec.value)
    if not names and found is not None:
        names = [found.key.partition(":")[2]]
    if not names:
        return Named(None, note)
    if spec.naming is None:
        keys = [key for name in names if (key := normalize(spec.type, name))]
        text = found.text if found is not None else names[0]
        via = found.via if found is not None else "fixed"
        return Named(Endpoint(keys[0], text, via, tuple(keys[1:])) if keys else None, note)
    if spec.type == "parameter" and spec.naming == "ros":  # a ROS 2 node's own parameter
        names = [f"~/{name.lstrip('/~')}" for name in names]
    node, handle = scopes.context(call)
    written = f"{spec.type}:{folded(names[0], handle)}"
    qualified = node.fully_qualified or ""
    try:
        resolved = [_resolved(spec, name, node, handle) for name in names]
    except UnresolvedName as why:
        return Named(None, note or str(why), written, qualified)
    text = found.text if found is not None else names[0]
    via = found.via if found is not None else "fixed"
    point = Endpoint(resolved[0], text, via, tuple(resolved[1:]))
    return Named(point, note, written, qualified)


def folded(name: str, handle: str | None) -> str:
    """``name`` as it reads without the ROS 1 NodeHandle it was given to (``scan`` on a
    handle made with ``"~"`` is ``~/scan``), so that it resolves alike later (rosgraph.py)."""
    if handle is None or not handle.strip() or handle == UNKNOWN or name.startswith(("/", "~")):
        return name
    return f"{handle.rstrip('/')}/{name}"


def _resolved(spec: EndpointSpec, name: str, node: NodeName, handle: str | None) -> str:
    return f"{spec.type}:{resolve(name, node, handle)}"


def completed(site: LinkSite, named: Named, kind_of_data: str, parameter: str) -> LinkSite:
    """``site`` with what the graph-name reading found."""
    return replace(
        site,
        endpoint=named.endpoint,
        note=named.note,
        name=named.name,
        node=named.node,
        data_type=kind_of_data,
        parameter=parameter,
    )
