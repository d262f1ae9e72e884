"""Provider skeleton: serves the service on a bus by calling a typed implementation.

The module holds the implementation Protocol (what any implementation must offer), the
skeleton class (the provider-side CallProxy of thesis p. 65: payload in, typed call, payload
out), the adapter of the packaging form, and ``main`` to run the provider as a program.
Publish-subscribe and event services get a typed publisher class instead.
"""

from __future__ import annotations

from robosoa.descriptor import (
    ImplementationForm,
    Language,
    Operation,
    Packaging,
    Participant,
    Pattern,
    Profile,
    ServiceDescriptor,
)

from . import adapters
from .common import assemble, docstring, header, param_notes, types_imported
from .pytypes import call, def_line, field_from, keyword_lines, q, signature

_BUS_PATTERN = {Pattern.ONE_WAY: "oneway"}


def _protocol(d: ServiceDescriptor, name: str) -> list[str]:
    text = f"What an implementation of '{d.name}' offers: one method per operation."
    lines = [f"class {name}(Protocol):", *docstring("    ", text)]
    for op in d.operations:
        head = def_line("    ", op.name, signature(op.parameters, "self"), adapters.returns_of(op))
        lines += ["", *head]
        lines += docstring(
            "        ", op.definition or f"Serve '{op.name}'.", param_notes(op.parameters)
        )
    return lines


def _handler(op: Operation) -> list[str]:
    lines = [f"    def _serve_{op.name}(self, **payload: Any) -> dict[str, Any]:"]
    args = [f"{p.name}={field_from(p, 'payload')}" for p in op.parameters]
    invoke = f"self._impl.{op.name}({', '.join(args)})"
    if len(f"        result = {invoke}") > 99:
        inner = [
            line for p in op.parameters for line in keyword_lines("            ", p, "payload")
        ]
        invoke = "\n".join([f"self._impl.{op.name}(", *inner, "        )"])
    if not op.returns:
        return [*lines, f"        {invoke}", "        return {}"]
    lines.append(f"        result = {invoke}")
    if len(op.returns) == 1:
        return [*lines, f"        return {{{q(op.returns[0].name)}: to_wire(result)}}"]
    return [*lines, "        return payload_of(result)"]


def _skeleton(d: ServiceDescriptor, part: Participant, protocol: str) -> list[str]:
    name = part.naming.class_name
    text = f"Provider skeleton of '{d.name}' {d.version}: serves it by calling the implementation."
    entries = [f"{q(op.name)}: self._serve_{op.name}" for op in d.operations]
    table = [f"            {{{', '.join(entries)}}},"]
    if len(table[0]) > 99:
        table = ["            {", *(f"                {e}," for e in entries), "            },"]
    validator = "DESCRIPTOR.validator()" if part.profile is Profile.CHECKED else "None"
    lines = [f"class {name}:", *docstring("    ", text), ""]
    lines += [
        f"    def __init__(self, implementation: {protocol}) -> None:",
        "        self._impl = implementation",
        "",
        f"    def provide(self, bus: robosoa.Bus, group: str | None = {q(part.group)}) "
        "-> robosoa.ProviderHandle:",
        '        """Offer the service on ``bus``; close the returned handle to withdraw it."""',
        "        return bus.provide(",
        "            SERVICE,",
        *table,
        "            version=VERSION,",
        "            operations=OPERATIONS,",
        f"            pattern={q(_BUS_PATTERN.get(d.pattern, d.pattern.value))},",
        "            group=group,",
        f"            validator={validator},",
        *(["            idempotent=IDEMPOTENT,"] if d.pattern.has_replies else []),
        "        )",
    ]
    for op in d.operations:
        lines += ["", *_handler(op)]
    return lines


def _adapter(d: ServiceDescriptor, part: Participant, name: str) -> tuple[list[str], list[str]]:
    """The adapter class and the ``start`` lines of ``main`` for the participant's form."""
    impl = part.implementation
    assert impl is not None
    skeleton = part.naming.class_name
    if impl.form is ImplementationForm.EXECUTABLE:
        option = '"--cwd", default=None, help="directory the provider programs run in"'
        body = [*adapters.commands(d, impl), "", "", *adapters.executable(d, impl, name)]
        return body, [option, f"{skeleton}({name}(args.cwd))"]
    if part.language is Language.C:
        option = '"--library", default=LIBRARY, help="path of the C shared library"'
        body = [*adapters.library(impl), "", "", *adapters.c_library(d, impl, name)]
        return body, [option, f"{skeleton}({name}(args.library))"]
    option = '"--module", default=LIBRARY, help="implementation module"'
    body = [*adapters.library(impl), "", "", *adapters.python_library(d, impl, name)]
    return body, [option, f"{skeleton}({name}(args.module))"]


def _main(option: str, make: str) -> list[str]:
    return [
        "",
        "",
        "def main(argv: Sequence[str] | None = None) -> int:",
        '    """Run the provider as a program until interrupted: ``--bus URL``."""',
        "",
        "    def add_arguments(parser: argparse.ArgumentParser) -> None:",
        *call("        ", "parser.add_argument", option.split(", ")),
        "",
        "    def start(bus: robosoa.Bus, args: argparse.Namespace) -> object:",
        f"        return {make}.provide(bus)",
        "",
        '    return serve_main(argv, __doc__ or "", start, add_arguments)',
        "",
        "",
        'if __name__ == "__main__":',
        "    sys.exit(main())",
    ]


def _publisher(d: ServiceDescriptor, part: Participant) -> list[str]:
    verb = "emit" if d.pattern is Pattern.EVENT else "publish"
    text = f"Publisher of '{d.name}' {d.version}: one typed {verb}_* method per {verb}ed message."
    lines = [f"class {part.naming.class_name}:", *docstring("    ", text), ""]
    lines += ["    def __init__(self, bus: robosoa.Bus) -> None:", "        self._bus = bus"]
    if part.profile is Profile.CHECKED:
        lines.append("        self._check = DESCRIPTOR.validator()")
    event = ["event=True"] if d.pattern is Pattern.EVENT else []
    for op in d.operations:  # binds the PUB now and declares each stream's QoS
        args = [f"SERVICE + {q('.' + op.name)}", f"DESCRIPTOR.qos({q(op.name)})", *event]
        lines += call("        ", "bus.advertise", args)
    for op in d.operations:
        items = ", ".join(f"{q(p.name)}: {p.name}" for p in op.parameters)
        lines += [
            "",
            *def_line("    ", f"{verb}_{op.name}", signature(op.parameters, "self"), "None"),
        ]
        lines += docstring("        ", op.definition or f"{verb.title()} '{op.name}'.")
        lines.append(f"        payload = payload_of({{{items}}})")
        if part.profile is Profile.CHECKED:
            lines.append(f"        self._check({q(op.name)}, payload)")
        lines.append(f"        self._bus.{verb}(SERVICE + {q('.' + op.name)}, payload)")
    return lines


def render_provider(d: ServiceDescriptor, part: Participant) -> str:
    """``<module>.py`` of a provider package (provider-executable or provider-library)."""
    summary = f"Provider of service '{d.name}' {d.version} ({part.packaging})."
    if d.pattern in (Pattern.PUBLISH_SUBSCRIBE, Pattern.EVENT):
        body = _publisher(d, part)
    else:
        protocol = f"{part.naming.class_name}Implementation"
        form = "Executable" if part.packaging is Packaging.PROVIDER_EXECUTABLE else "Library"
        adapter, (option, make) = _adapter(d, part, f"{part.naming.class_name}{form}")
        body = [*_protocol(d, protocol), "", "", *_skeleton(d, part, protocol), "", ""]
        body += [*adapter, *_main(option, make)]
    groups: dict[str, list[str]] = {
        "argparse": [],
        "ctypes": [],
        "importlib": [],
        "sys": [],
        "collections.abc": ["Sequence"],
        "typing": ["Any", "Protocol"],
        "robosoa": [],
        "robosoa.codegen.support": ["ExecutableRunner", "payload_of", "serve_main", "to_wire"],
        ".types": ["DESCRIPTOR", "OPERATIONS", "SERVICE", "VERSION",
                   *(["IDEMPOTENT"] if d.pattern.has_replies else []), *types_imported(d)],
    }
    if part.os.value != "any":
        groups["robosoa.codegen.support"].append("check_platform")
        body = [f"check_platform({q(part.os.value)})", "", "", *body]
    return assemble(header(d, summary, d.definition), groups, body)
