"""Implementation adapters of a provider: one class per implementation form (thesis p. 94).

Each adapter offers one typed method per operation and reaches the real implementation: a
program run per request (provider as executable), a Python module, or a C shared library
through ctypes (provider as library).
"""

from __future__ import annotations

from robosoa.descriptor import Implementation, Operation, Parameter, ServiceDescriptor

from .common import docstring
from .pytypes import annotation, def_line, field_from, literal_lines, q, result_class, signature

_CTYPES = {"int": "ctypes.c_int64", "float": "ctypes.c_double", "bool": "ctypes.c_bool"}
_CTYPES["string"] = "ctypes.c_char_p"


def returns_of(op: Operation) -> str:
    """What an implementation method returns: None, the single value, or the result class."""
    if not op.returns:
        return "None"
    if len(op.returns) == 1:
        only = op.returns[0]
        return annotation(only.type) if only.required else f"{annotation(only.type)} | None"
    return result_class(op)


def _method_head(op: Operation) -> list[str]:
    return def_line("    ", op.name, signature(op.parameters, "self"), returns_of(op))


def _from_reply(op: Operation) -> str:
    if len(op.returns) == 1:
        return field_from(op.returns[0], "reply")
    return f"{result_class(op)}.from_payload(reply)"


def executable(d: ServiceDescriptor, impl: Implementation, name: str) -> list[str]:
    """Adapter running the provider programs; requests on stdin, results from stdout."""
    text = f"Implementation running the provider programs ({impl.encoding} on stdin/stdout)."
    lines = [f"class {name}:", *docstring("    ", text), ""]
    lines += [
        "    def __init__(self, cwd: str | None = None) -> None:",
        f"        self._runner = ExecutableRunner(DESCRIPTOR, {q(impl.encoding.value)}, "
        f"{q(impl.timeout)}, cwd)",
    ]
    for op in d.operations:
        command = impl.command(op.name)
        argv = command.argv if command is not None else ""
        items = ", ".join(f"{q(p.name)}: {p.name}" for p in op.parameters)
        lines += ["", *_method_head(op)]
        lines += docstring("        ", f"Run ``{argv}`` for one '{op.name}' request.")
        lines.append(f"        payload = payload_of({{{items}}})")
        run = f"self._runner.run({q(op.name)}, COMMANDS[{q(op.name)}], payload)"
        if op.returns:
            lines += [f"        reply = {run}", f"        return {_from_reply(op)}"]
        else:
            lines.append(f"        {run}")
    return lines


def commands(d: ServiceDescriptor, impl: Implementation) -> list[str]:
    """The ``COMMANDS`` table: operation -> command line of its program."""
    lines = ["COMMANDS: dict[str, str] = {"]
    for op in d.operations:
        command = impl.command(op.name)
        lines += literal_lines(f"    {q(op.name)}: ", command.argv if command else "", ",")
    return [*lines, "}"]


def library(impl: Implementation) -> list[str]:
    """The ``LIBRARY`` constant: the module or shared library the adapter loads by default."""
    return literal_lines("LIBRARY = ", impl.library or "")


def python_library(d: ServiceDescriptor, impl: Implementation, name: str) -> list[str]:
    """Adapter calling the functions of a Python module given by dotted path."""
    module = impl.library or ""
    text = f"Implementation calling the functions of Python module '{module}'."
    lines = [f"class {name}:", *docstring("    ", text), ""]
    lines += [
        "    def __init__(self, module: str = LIBRARY) -> None:",
        "        self._module = importlib.import_module(module)",
    ]
    for op in d.operations:
        args = ", ".join(f"{p.name}={p.name}" for p in op.parameters)
        lines += ["", *_method_head(op)]
        lines += docstring("        ", f"Call ``{module}.{impl.symbol(op.name)}``.")
        call = f"self._module.{impl.symbol(op.name)}({args})"
        if op.returns:
            lines += [f"        result: {returns_of(op)} = {call}", "        return result"]
        else:
            lines.append(f"        {call}")
    return lines


def _c_argument(p: Parameter) -> str:
    return f"{p.name}.encode()" if p.type.name == "string" else p.name


def c_library(d: ServiceDescriptor, impl: Implementation, name: str) -> list[str]:
    """Adapter calling a C shared library through ctypes, argument types from the descriptor."""
    path = impl.library or ""
    text = f"Implementation calling C library '{path}' through ctypes."
    lines = [f"class {name}:", *docstring("    ", text), ""]
    lines += [
        "    def __init__(self, path: str = LIBRARY) -> None:",
        "        self._lib = ctypes.CDLL(path)",
    ]
    for op in d.operations:
        symbol = f"self._lib.{impl.symbol(op.name)}"
        argtypes = ", ".join(_CTYPES[p.type.name] for p in op.parameters)
        restype = _CTYPES[op.returns[0].type.name] if op.returns else "None"
        lines += [
            f"        {symbol}.argtypes = [{argtypes}]",
            f"        {symbol}.restype = {restype}",
        ]
    for op in d.operations:
        symbol = f"self._lib.{impl.symbol(op.name)}"
        args = ", ".join(_c_argument(p) for p in op.parameters)
        lines += ["", *_method_head(op)]
        lines += docstring("        ", f"Call C function ``{impl.symbol(op.name)}``.")
        if not op.returns:
            lines.append(f"        {symbol}({args})")
        elif op.returns[0].type.name == "string":
            lines += [
                f"        raw: bytes | None = {symbol}({args})",
                '        return (raw or b"").decode()',
            ]
        else:
            lines += [
                f"        result: {returns_of(op)} = {symbol}({args})",
                "        return result",
            ]
    return lines
