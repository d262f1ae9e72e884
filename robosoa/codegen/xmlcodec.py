"""The XML request/result documents exchanged with provider executables (encoding="xml").

A request is ``<request service="wdb" operation="query"><x>1</x></request>``; a result is
``<result><rows><item><key>a</key></item></rows></result>``. Lists hold ``<item>`` children,
structs hold one child per field, booleans are ``true``/``false``, bytes are base64 text
(``robosoa.codegen.textual``). Decoding is driven by the
descriptor's types, so the provider program writes plain text.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from lxml import etree

from robosoa.codegen.textual import from_base64, to_text
from robosoa.descriptor import Parameter, ServiceDescriptor, TypeRef


def _fill(element: etree._Element, value: object) -> None:
    if isinstance(value, Mapping):
        for key, item in value.items():
            if item is not None:
                _fill(etree.SubElement(element, str(key)), item)
    elif isinstance(value, list | tuple):
        for item in value:
            _fill(etree.SubElement(element, "item"), item)
    elif isinstance(value, bool):
        element.text = "true" if value else "false"
    elif isinstance(value, bytes | bytearray | memoryview):
        element.text = to_text(value)
    else:
        element.text = str(value)


def encode_request(service: str, operation: str, payload: Mapping[str, Any]) -> bytes:
    """The XML request document for one call."""
    root = etree.Element("request", service=service, operation=operation)
    _fill(root, payload)
    return bytes(etree.tostring(root, xml_declaration=True, encoding="UTF-8"))


def _value(d: ServiceDescriptor, t: TypeRef, element: etree._Element, path: str) -> Any:
    if t.item is not None:
        return [_value(d, t.item, child, f"{path}[{i}]") for i, child in enumerate(element)]
    text = element.text or ""
    try:
        if t.name == "int":
            return int(text)
        if t.name == "float":
            return float(text)
    except ValueError:
        raise ValueError(f"{path}: '{text}' is not a {t.name}") from None
    if t.name == "bool":
        if text.strip() not in ("true", "false", "1", "0"):
            raise ValueError(f"{path}: '{text}' is not a bool")
        return text.strip() in ("true", "1")
    if t.name == "string":
        return text
    if t.name == "bytes":
        return from_base64(text.strip(), path)
    struct = d.type(t.name)
    fields = struct.fields if struct is not None else ()
    return _fields(d, fields, element, f"{path}.")


def _fields(
    d: ServiceDescriptor, fields: Sequence[Parameter], element: etree._Element, prefix: str
) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for f in fields:
        child = element.find(f.name)
        if child is not None:
            out[f.name] = _value(d, f.type, child, f"{prefix}{f.name}")
    return out


def decode_result(
    d: ServiceDescriptor, returns: Sequence[Parameter], document: bytes
) -> dict[str, Any]:
    """The reply payload read from a program's XML result document."""
    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False,
                             huge_tree=False)
    try:
        root = etree.fromstring(document, parser)
    except etree.XMLSyntaxError as exc:
        raise ValueError(f"result is not XML: {exc}") from None
    if root.getroottree().docinfo.internalDTD is not None:
        raise ValueError("result has a DTD: not allowed")
    return _fields(d, returns, root, "")
