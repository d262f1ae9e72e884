"""XML configuration files to facts: every element as a table (a ROS launch file's ``<node>``
and its ``<remap>``, a plugin description's ``<class>``, a ``package.xml``).

Read with the standard library's expat, set for untrusted input (docs/security.md): a
document that declares an entity is refused before any is expanded (no entity-expansion bomb,
no external entity: nothing is ever fetched or opened), parameter entities and external DTDs
are never read, and a reference to an undeclared entity is an error; a file over
:data:`MAX_BYTES`, nested deeper than :data:`MAX_DEPTH` elements or with more than
:data:`MAX_ELEMENTS` elements is not measured. Each element is one :class:`ConfigTable`: its
keys the tags from the root to it (namespace prefixes dropped), its line, its attributes in
the order written (``xmlns`` declarations left out) and, under ``#text``, its text before its
first child when it has any; ``parent`` is the index of its parent element's table. Nothing
is executed or resolved: ``$(find pkg)`` stays as written.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from xml.parsers import expat

from archmetrics.facts import ConfigFormat, ConfigTable, FileFacts
from archmetrics.parsers.limits import DEFAULT_LIMITS, ParseLimits, not_measured

MAX_ELEMENTS = 50_000
"""A file with more elements than this is not measured (a launch file or plugin description
holds tens; a larger XML file is data, not hand-written configuration)."""
MAX_DEPTH = 256  # elements nested deeper than this: not measured
MAX_BYTES = 10 << 20  # a larger XML file (10 MiB) is not read as configuration

TEXT = "#text"  # the key an element's text is kept under


class _Refused(Exception):
    """The document breaks a bound: not measured, with the reason."""


@dataclass(slots=True)
class _Element:
    keys: tuple[str, ...]
    line: int
    values: list[tuple[str, tuple[str, ...]]]
    parent: int
    text: list[str] = field(default_factory=list)
    closed_text: bool = False  # a child started: later text is not the element's own


def _local(name: str) -> str:
    """A tag or attribute name without its namespace prefix (``x:tag`` -> ``tag``)."""
    return name.rpartition(":")[2]


class _Reader:
    """expat's callbacks, building the elements in document order."""

    def __init__(self, parser: expat.XMLParserType) -> None:
        self.parser = parser
        self.elements: list[_Element] = []
        self.open: list[int] = []

    def start(self, name: str, attributes: list[str]) -> None:
        if len(self.open) >= MAX_DEPTH:
            raise _Refused(f"nested deeper than {MAX_DEPTH} elements; not read as configuration")
        if len(self.elements) >= MAX_ELEMENTS:
            raise _Refused(f"more than {MAX_ELEMENTS:,} elements; not read as configuration")
        parent = self.open[-1] if self.open else -1
        if parent >= 0:
            self.elements[parent].closed_text = True
        above = self.elements[parent].keys if parent >= 0 else ()
        pairs = zip(attributes[::2], attributes[1::2], strict=True)
        values: list[tuple[str, tuple[str, ...]]] = [
            (_local(k), (v,)) for k, v in pairs if k != "xmlns" and not k.startswith("xmlns:")
        ]
        line = self.parser.CurrentLineNumber
        self.elements.append(_Element((*above, _local(name)), max(line, 1), values, parent))
        self.open.append(len(self.elements) - 1)

    def end(self, name: str) -> None:
        self.open.pop()

    def characters(self, data: str) -> None:
        if self.open and not (element := self.elements[self.open[-1]]).closed_text:
            element.text.append(data)

    def tables(self) -> tuple[ConfigTable, ...]:
        found = []
        for element in self.elements:
            text = "".join(element.text).strip()
            values = (*element.values, (TEXT, (text,))) if text else tuple(element.values)
            found.append(ConfigTable(element.keys, element.line, values, element.parent))
        return tuple(found)


def _declared(*_: object) -> None:
    raise _Refused("not valid XML: declares an entity (refused: entities are never expanded)")


def parse(path: str, source: str, limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    """The elements of an XML document, each with its line; never raises for bad input."""
    language = ConfigFormat.XML.value
    if len(source) > min(MAX_BYTES, limits.max_bytes):
        message = f"larger than {min(MAX_BYTES, limits.max_bytes):,} characters; not read"
        return not_measured(path, language, 1, message)
    parser = expat.ParserCreate(encoding="utf-8")  # the text is decoded: its own encoding
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    parser.ordered_attributes = True
    parser.buffer_text = True
    reader = _Reader(parser)
    parser.StartElementHandler = reader.start
    parser.EndElementHandler = reader.end
    parser.CharacterDataHandler = reader.characters
    parser.EntityDeclHandler = _declared
    parser.UnparsedEntityDeclHandler = _declared
    try:
        parser.Parse(source.encode("utf-8", "surrogatepass"), True)
    except expat.ExpatError as error:
        line = error.lineno if error.lineno > 0 else 1
        return not_measured(path, language, line, f"not valid XML: {expat.ErrorString(error.code)}")
    except _Refused as refused:
        return not_measured(path, language, max(parser.CurrentLineNumber, 1), str(refused))
    except (ValueError, UnicodeError, RecursionError) as error:
        return not_measured(path, language, 1, f"not valid XML: {error}")
    return FileFacts(path=path, language=language, tables=reader.tables())
