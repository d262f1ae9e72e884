"""Consumer call proxy: a class whose methods look like local calls (thesis p. 65, CallProxy).

One method per operation, shaped by the message exchange pattern: request-response and
point-to-point return the typed result, one-way returns how many providers took the message,
publish-subscribe and event subscribe a typed callback.
"""

from __future__ import annotations

from robosoa.descriptor import Operation, Participant, Pattern, Profile, ServiceDescriptor

from .common import assemble, docstring, header, param_notes, types_imported
from .pytypes import call, def_line, message_class, q, result_class, signature

_TYPES = ["DESCRIPTOR", "SERVICE", "VERSION"]


def _payload(op: Operation) -> str:
    items = ", ".join(f"{q(p.name)}: {p.name}" for p in op.parameters)
    return f"payload = payload_of({{{items}}})"


def _request(d: ServiceDescriptor, op: Operation, checked: bool) -> list[str]:
    returns = result_class(op) if op.returns else "None"
    lines = def_line("    ", op.name, signature(op.parameters, "self"), returns)
    lines += docstring(
        "        ", op.definition or f"Call '{op.name}'.", param_notes(op.parameters)
    )
    lines.append(f"        {_payload(op)}")
    if checked:
        lines.append(f"        self._check_request({q(op.name)}, payload)")
    if d.pattern is Pattern.POINT_TO_POINT:
        call = f"self._line().request({q(op.name)}, payload, timeout=self._timeout)"
    else:
        call = f"self._bus.request(SERVICE, {q(op.name)}, payload, **self._options)"
    if not op.returns:
        return [*lines, f"        {call}"]
    lines.append(f"        reply = {call}")
    if checked:
        lines.append(f"        self._check_reply({q(op.name)}, reply)")
    return [*lines, f"        return {returns}.from_payload(reply)"]


def _one_way(op: Operation, checked: bool) -> list[str]:
    lines = def_line("    ", op.name, signature(op.parameters, "self"), "int")
    text = op.definition or f"Send '{op.name}' without waiting."
    notes = ["Returns how many provider instances took the message.", *param_notes(op.parameters)]
    lines += docstring("        ", text, notes)
    lines.append(f"        {_payload(op)}")
    if checked:
        lines.append(f"        self._check_request({q(op.name)}, payload)")
    send = ["SERVICE", q(op.name), "payload", "to=self._delivery", "group=self._group"]
    send.append('version=self._options["version"]')
    return [*lines, *call("        ", "return self._bus.send", send)]


def _listen(d: ServiceDescriptor, op: Operation, checked: bool) -> list[str]:
    event = d.pattern is Pattern.EVENT
    kind = message_class(op) if op.parameters else ""
    args = ["self", f"callback: Callable[[{kind}], None]", "qos: robosoa.QoS | None = None"]
    lines = def_line("    ", f"on_{op.name}", args, "robosoa.Subscription")
    what = "event" if event else "topic"
    lines += docstring("        ", f"Call ``callback`` with each '{op.name}' {what} message; "
                       "``qos`` overrides the descriptor's.")
    lines.append("        def deliver(message: robosoa.Message) -> None:")
    if checked:
        lines.append(f"            self._check_request({q(op.name)}, message.payload)")
    value = f"{kind}.from_payload(message.payload)" if kind else ""
    lines += [f"            callback({value})", ""]
    listen = "on" if event else "subscribe"
    return [
        *lines,
        f"        chosen = qos if qos is not None else DESCRIPTOR.qos({q(op.name)})",
        *call("        ", f"return self._bus.{listen}",
              [f"SERVICE + {q('.' + op.name)}", "deliver", "qos=chosen"]),
    ]


def _init(d: ServiceDescriptor, part: Participant, checked: bool) -> list[str]:
    if d.pattern in (Pattern.PUBLISH_SUBSCRIBE, Pattern.EVENT):
        lines = ["    def __init__(self, bus: robosoa.Bus) -> None:", "        self._bus = bus"]
        return lines + (["        self._check_request = DESCRIPTOR.validator()"] if checked else [])
    args = ["self", "bus: robosoa.Bus", "timeout: float = 5.0"]
    args.append('version: str | None = f"^{VERSION}"')
    if d.pattern is Pattern.ONE_WAY:
        args += [f"delivery: str = {q(d.delivery)}", "group: str | None = None"]
    lines = def_line("    ", "__init__", args, "None")
    lines += [
        "        self._bus = bus",
        '        self._options: dict[str, Any] = {"timeout": timeout, "version": version}',
    ]
    if d.pattern is Pattern.ONE_WAY:
        lines += ["        self._delivery = delivery", "        self._group = group"]
    if d.pattern is Pattern.POINT_TO_POINT:
        lines.append("        self._timeout = timeout")
        lines.append("        self._channel: robosoa.Channel | None = None")
    if checked:
        lines.append("        self._check_request = DESCRIPTOR.validator()")
        if d.pattern.has_replies:
            lines.append("        self._check_reply = DESCRIPTOR.reply_validator()")
    if d.pattern is Pattern.POINT_TO_POINT:
        lines += [
            "",
            "    def _line(self) -> robosoa.Channel:",
            '        """The point-to-point channel to one provider instance, opened once."""',
            "        if self._channel is None:",
            '            version = self._options["version"]',
            "            self._channel = self._bus.channel(SERVICE, version=version)",
            "        return self._channel",
        ]
    return lines


def class_body(d: ServiceDescriptor, part: Participant) -> list[str]:
    """The proxy class named by the participant's naming."""
    checked = part.profile is Profile.CHECKED
    text = f"Call proxy of service '{d.name}' {d.version}: each method is one bus exchange."
    lines = [f"class {part.naming.class_name}:", *docstring("    ", text), ""]
    lines += _init(d, part, checked)
    for op in d.operations:
        lines.append("")
        if d.pattern.has_replies:
            lines += _request(d, op, checked)
        elif d.pattern is Pattern.ONE_WAY:
            lines += _one_way(op, checked)
        else:
            lines += _listen(d, op, checked)
    return lines


def _main(part: Participant) -> list[str]:
    return [
        "",
        "",
        "def main(argv: Sequence[str] | None = None) -> int:",
        '    """Call one operation from the command line: ``OPERATION name=value ...``."""',
        f"    return client_main(argv, DESCRIPTOR, {part.naming.class_name})",
        "",
        "",
        'if __name__ == "__main__":',
        "    sys.exit(main())",
    ]


def render_client(d: ServiceDescriptor, part: Participant) -> str:
    """``<module>.py`` of a consumer-source package: the typed call proxy."""
    summary = f"Consumer call proxy of service '{d.name}' {d.version} ({part.packaging})."
    body = class_body(d, part)
    if d.pattern is not Pattern.PUBLISH_SUBSCRIBE and d.pattern is not Pattern.EVENT:
        body += _main(part)
    groups: dict[str, list[str]] = {
        "sys": [],
        "collections.abc": ["Callable", "Sequence"],
        "typing": ["Any"],
        "robosoa": [],
        "robosoa.codegen.support": ["client_main", "payload_of"],
        ".types": [*_TYPES, *types_imported(d)],
    }
    if part.os.value != "any":
        groups["robosoa.codegen.support"].append("check_platform")
        body = [f"check_platform({q(part.os.value)})", "", "", *body]
    return assemble(header(d, summary, d.definition), groups, body)
