"""One scan link site in ROS terms: the single place where archmetrics's JSON meets the oracle.

Both the pinned slice (tests/coupling/test_ros_oracle_slice.py) and the full oracle
(benchmarks/ros_oracle.py) compare reported sites with hand-made expectations written in ROS
terms -- a kind (publisher, subscription, call, plugin-load, ...), a resolved name (/cmd_vel)
and a type (geometry_msgs/msg/Twist). ``ros_endpoint`` turns a ``link_sites`` entry of
``archmetrics scan --by link --format json`` into that triple; extra JSON fields are
tolerated, missing ones give None. The ROS rule packs' exact spelling of rule ids and
endpoints is decided where the packs are written: adjust this one function to it.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

#: The oracle's kinds by category (benchmarks/ros_oracle/README.md defines each kind).
CATEGORIES: dict[str, tuple[str, ...]] = {
    "communication": (
        "publisher", "subscription", "service-server", "service-client", "action-server",
        "action-client", "publish", "call", "send-goal", "tf-broadcaster", "tf-listener",
        "image-publisher", "image-subscriber", "mf-subscriber", "bond",
    ),
    "plugin": ("plugin-load", "plugin-export", "plugin-description", "component-register"),
    "parameter": (
        "param-declare", "param-get", "param-set", "param-client", "param-remote",
        "param-events", "dynamic-reconfigure",
    ),
    "launch": ("launch-node", "launch-component"),
}  # fmt: skip
KIND_CATEGORY = {kind: cat for cat, kinds in CATEGORIES.items() for kind in kinds}

#: Kinds that are one family for the comparison with a reported site: a tf broadcaster is a
#: publisher of /tf, an image_transport or message_filters subscriber a subscription.
_FAMILY = {
    "tf-broadcaster": "publisher", "image-publisher": "publisher",
    "tf-listener": "subscription", "image-subscriber": "subscription",
    "mf-subscriber": "subscription",
}  # fmt: skip

#: The kind family of each rule of the shipped ``ros2`` and ``ros1`` packs (rule ids as in
#: archmetrics/coupling/rules/ros2.toml and ros1.toml, after the ``pack/``): a tf broadcaster,
#: image_transport and message_filters rule is a publisher's or a subscription's.
_RULE_KINDS: dict[str, str] = {
    **dict.fromkeys(
        ("publisher", "publisher-function", "generic-publisher", "py-publisher", "advertise",
         "image-publisher", "image-advertise", "tf-broadcaster", "tf-static-broadcaster"),
        "publisher",
    ),
    **dict.fromkeys(
        ("subscription", "subscription-function", "generic-subscription", "py-subscription",
         "subscribe", "py-subscriber", "image-subscription", "image-subscribe",
         "filter-subscriber", "filter-subscribe", "py-filter-subscriber", "tf-listener"),
        "subscription",
    ),
    **dict.fromkeys(("twist-publisher",), "publisher"),
    **dict.fromkeys(("twist-subscription", "odom-subscription", "wait-for-message"),
                    "subscription"),
    **dict.fromkeys(("publish", "py-publish", "send-transform", "realtime-publish"), "publish"),
    "bond": "bond",
    **dict.fromkeys(("service", "service-function", "py-service", "advertise-service"),
                    "service-server"),
    **dict.fromkeys(("client", "client-function", "py-client", "service-client",
                     "py-service-proxy"), "service-client"),
    "camera-info-manager": "service-server", "lifecycle-client": "service-client",
    "lifecycle-call": "call", "dynamic-reconfigure": "dynamic-reconfigure",
    **dict.fromkeys(("call", "py-call", "service-call"), "call"),
    **dict.fromkeys(("action-server", "action-server-member", "py-action-server"),
                    "action-server"),
    **dict.fromkeys(("action-client", "action-client-member", "py-action-client"),
                    "action-client"),
    **dict.fromkeys(("send-goal", "py-send-goal"), "send-goal"),
    **dict.fromkeys(("declare-parameter", "declare-parameter-function", "declare-or-get-parameter",
                     "declare-or-get-parameter-function"), "param-declare"),
    **dict.fromkeys(("get-parameter", "parameter", "py-parameter", "parameter-file"),
                    "param-get"),
    **dict.fromkeys(("set-parameter", "py-set-parameter"), "param-set"),
    "parameters-client": "param-client", "transport-hints": "param-get",
    "remote-parameters": "param-remote", "parameter-events": "param-events",
    "plugin-export": "plugin-export", "component": "component-register",
    "plugin-load": "plugin-load", "plugin-description": "plugin-description",
    **dict.fromkeys(("launch-node", "launch-file", "launch-file-yaml"), "launch-node"),
    "launch-component": "launch-component",
}  # fmt: skip
#: A leading "topic:", "service:", ... on an endpoint; "demo::Talker" keeps its "::".
_SCHEME = re.compile(r"^[A-Za-z][\w-]*:(?!:)")


def kind_family(kind: str) -> str:
    """The family an oracle kind is compared in (``tf-listener`` -> ``subscription``)."""
    return _FAMILY.get(kind, kind)


def is_ros_site(site: Mapping[str, object]) -> bool:
    """A site found by a rule pack whose name starts with ``ros`` (``ros2/...``, ``ros1/...``)."""
    return str(site.get("rule", "")).split("/", 1)[0].startswith("ros")


def ros_endpoint(site: Mapping[str, object]) -> tuple[str, str | None, str | None]:
    """(kind family, resolved name or None, type or None) of one reported link site.

    The packs report the name resolved against its node (and launch file) as ``endpoint``
    (``topic:/chatter``), the name as written as ``endpoint_name`` and the interface as
    ``endpoint_type``. A ROS 2 parameter is named as declared (``endpoint_name`` without its
    ``~/``), as the oracle names it, and a plugin by the lookup name a load or description
    gives (``endpoint_name``, a description's ``endpoint_text``) rather than the C++ class it
    resolves to; a launch file's entry by the node it starts (``node``). A site whose
    ``status`` is ``unresolved`` has no name, but for a private name of a node named at run
    time (a controller's ``~/odom``), which the oracle writes as the code does.
    """
    pack, _, rule_id = str(site.get("rule", "")).partition("/")
    kind = _RULE_KINDS.get(rule_id)
    if kind is None:
        kind = "subscription" if site.get("role") == "receive" else "publish"
    endpoint = site.get("endpoint")
    if KIND_CATEGORY.get(kind) == "launch":  # named by the node it starts, typed by its code
        if str(endpoint).startswith("plugin:"):
            kind = "launch-component"
        return kind, str(site["node"]) if site.get("node") else None, None
    own = ("param-declare", "param-get", "param-set")  # a node's own parameter, as declared
    if pack == "ros2" and kind in own and site.get("endpoint_name"):
        endpoint = str(site["endpoint_name"]).replace(":~/", ":", 1)
    if kind == "plugin-description" and site.get("endpoint_text"):
        endpoint = f"plugin:{site['endpoint_text']}"  # its lookup name, as the oracle names it
    elif KIND_CATEGORY.get(kind) == "plugin" and site.get("endpoint_name"):
        endpoint = site["endpoint_name"]  # a pluginlib lookup name, as the oracle names it
    if rule_id in ("lifecycle-client", "lifecycle-call") and endpoint:  # the node's services
        method = str(site.get("callee", "")).rpartition(">")[2].rpartition(".")[2]
        endpoint = f"{endpoint}/{method if rule_id == 'lifecycle-call' else 'change_state'}"
    if kind == "param-remote" and endpoint:  # the node's parameter service the call names
        endpoint = f"{endpoint}/{str(site.get('callee', '')).rpartition('>')[2].rpartition('.')[2]}"
    named = endpoint and site.get("status") != "unresolved"
    name = _SCHEME.sub("", str(endpoint), count=1) if named else None
    written = _SCHEME.sub("", str(site.get("endpoint_name") or ""), count=1)
    if name is None and written.startswith("~"):
        # private to a node named at run time: the oracle keeps it as written (ROS 1: ~x)
        name = "~" + written[2:] if pack == "ros1" and written.startswith("~/") else written
    ros_type = site.get("endpoint_type")
    return kind, name, str(ros_type) if ros_type else None
