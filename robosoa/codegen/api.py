"""Consumer without source: an existing library's API re-exposed over the bus (thesis p. 94).

The generated package has the library's function names and signatures, so a consumer that
imported the library imports the package instead; each function forwards to the service
through the package's call proxy.
"""

from __future__ import annotations

from robosoa.descriptor import Operation, Participant, ServiceDescriptor

from .adapters import returns_of
from .common import assemble, docstring, header, param_notes, types_imported
from .pytypes import def_line, q, signature


def _function(op: Operation, symbol: str) -> list[str]:
    lines = ["", "", *def_line("", symbol, signature(op.parameters), returns_of(op))]
    lines += docstring(
        "    ", op.definition or f"Call '{op.name}' over the bus.", param_notes(op.parameters)
    )
    args = ", ".join(f"{p.name}={p.name}" for p in op.parameters)
    call = f"_client().{op.name}({args})"
    if not op.returns:
        return [*lines, f"    {call}"]
    if len(op.returns) == 1:
        return [*lines, f"    return {call}.{op.returns[0].name}"]
    return [*lines, f"    return {call}"]


def render_api(d: ServiceDescriptor, part: Participant, proxy: str, proxy_module: str) -> str:
    """``<module>.py``: one module-level function per operation, named as in the library."""
    impl = part.implementation
    library = impl.library if impl is not None and impl.library else part.naming.package
    summary = f"API of '{library}' re-exposed over the bus as service '{d.name}' {d.version}."
    body = [
        "_state: dict[str, " + proxy + "] = {}",
        "",
        "",
        "def bind(bus: robosoa.Bus, timeout: float = 5.0) -> None:",
        '    """Send this module\'s calls over ``bus`` (default: connect to $ROBOSOA_BUS)."""',
        f'    _state["proxy"] = {proxy}(bus, timeout=timeout)',
        "",
        "",
        f"def _client() -> {proxy}:",
        '    if "proxy" not in _state:',
        '        bind(robosoa.connect(os.environ.get("ROBOSOA_BUS", "inproc")))',
        '    return _state["proxy"]',
    ]
    for op in d.operations:
        symbol = impl.symbol(op.name) if impl is not None else op.name
        body += _function(op, symbol)
    groups: dict[str, list[str]] = {
        "os": [],
        "robosoa": [],
        f".{proxy_module}": [proxy],
        ".types": types_imported(d),
    }
    return assemble(header(d, summary, d.definition), groups, body)


def render_init(d: ServiceDescriptor, part: Participant, module: str) -> str:
    """``__init__.py`` re-exporting the API so ``import <package>`` replaces the library."""
    impl = part.implementation
    names = ["bind", *(impl.symbol(op.name) if impl else op.name for op in d.operations)]
    summary = f"Drop-in bus replacement of '{part.naming.package}' for service '{d.name}'."
    body = ["__all__ = [", *(f"    {q(n)}," for n in sorted(names)), "]"]
    return assemble(header(d, summary), {f".{module}": names}, body)
