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

# (a piece of the rule id, the kind family it names); the first piece found wins. Written for
# ids like "ros2/cpp-create-publisher" or "ros1/py-service-proxy".
_RULE_KINDS: tuple[tuple[str, str], ...] = (
    ("param-set", "param-set"), ("set-param", "param-set"), ("param-client", "param-client"),
    ("parameters-client", "param-client"), ("param-remote", "param-remote"),
    ("param-event", "param-events"), ("parameter-event", "param-events"),
    ("reconfigure", "dynamic-reconfigure"), ("bond", "bond"),
    ("goal", "send-goal"), ("action-server", "action-server"),
    ("action-client", "action-client"), ("create-service", "service-server"),
    ("advertise-service", "service-server"), ("service-server", "service-server"),
    ("service-proxy", "service-client"), ("service-client", "service-client"),
    ("create-client", "service-client"), ("send-request", "call"), ("call", "call"),
    ("broadcaster", "publisher"), ("send-transform", "publish"), ("listener", "subscription"),
    ("publisher", "publisher"), ("advertise", "publisher"), ("publish", "publish"),
    ("subscri", "subscription"), ("message-filter", "subscription"),
    ("declare", "param-declare"), ("param", "param-get"),
    ("class-loader", "plugin-load"), ("instance", "plugin-load"), ("plugin-load", "plugin-load"),
    ("plugin-description", "plugin-description"), ("plugin-xml", "plugin-description"),
    ("export", "plugin-export"), ("launch-component", "launch-component"),
    ("launch", "launch-node"), ("component", "component-register"),
)  # fmt: skip
#: A leading "topic:", "service:", ... on an endpoint; "demo::Talker" keeps its "::".
_SCHEME = re.compile(r"^[A-Za-z][\w-]*:(?!:)")
_TYPE_KEYS = ("type", "msg_type", "message_type", "interface_type", "ros_type")


def kind_family(kind: str) -> str:
    """The family an oracle kind is compared in (``tf-listener`` -> ``subscription``)."""
    return _FAMILY.get(kind, kind)


def is_ros_site(site: Mapping[str, object]) -> bool:
    """A site found by a rule pack whose name starts with ``ros`` (``ros2/...``, ``ros1/...``)."""
    return str(site.get("rule", "")).split("/", 1)[0].startswith("ros")


def ros_endpoint(site: Mapping[str, object]) -> tuple[str, str | None, str | None]:
    """(kind family, resolved name or None, type or None) of one reported link site.

    A site whose ``status`` is ``unresolved`` has no name, whatever its ``endpoint`` says.
    """
    rule_id = str(site.get("rule", "")).split("/", 1)[-1].replace("_", "-").lower()
    kind = next((k for piece, k in _RULE_KINDS if piece in rule_id), None)
    if kind is None:
        kind = "subscription" if site.get("role") == "receive" else "publish"
    endpoint = site.get("endpoint")
    named = endpoint and site.get("status") != "unresolved"
    name = _SCHEME.sub("", str(endpoint), count=1) if named else None
    ros_type = next((str(site[k]) for k in _TYPE_KEYS if site.get(k)), None)
    return kind, name, ros_type
