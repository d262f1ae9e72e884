"""XML configuration files to facts: every element as a table (a ROS launch file's ``<node>``
and its ``<remap>``, a plugin description's ``<class>``, a ``package.xml``).

Read with lxml (libxml2) set for untrusted input (docs/security.md): entities are not
expanded (``resolve_entities=False``: an external entity is never fetched, an entity-expansion
bomb is refused by libxml2's amplification limit), nothing is fetched over the network, no DTD
is loaded, and ``huge_tree`` stays off, so libxml2 refuses a document nested deeper than 256
elements or with text nodes over 10 MB. Each element is one :class:`ConfigTable`: its keys
the tags from the root to it (namespace prefixes dropped), its line, its attributes in the
order written and, under ``#text``, its text when it has any; ``parent`` is the index of
its parent element's table. Nothing is executed or resolved: ``$(find pkg)`` stays as written.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from archmetrics.facts import ConfigFormat, ConfigTable, FileFacts
from archmetrics.parsers.limits import DEFAULT_LIMITS, ParseLimits, not_measured

MAX_ELEMENTS = 50_000
"""A file with more elements than this is not measured (a launch file or plugin description
holds tens; a larger XML file is data, not hand-written configuration)."""

TEXT = "#text"  # the key an element's text is kept under

if TYPE_CHECKING:
    from lxml import etree


def _parser() -> etree.XMLParser:
    from lxml import etree  # imported when an XML file is read (coupling only reads TEXT)

    return etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        huge_tree=False,
        remove_comments=True,
        remove_pis=True,
        encoding="utf-8",
    )


def _local(tag: str) -> str:
    """A tag without its namespace (``{uri}name`` -> ``name``)."""
    return tag.rpartition("}")[2]


def parse(path: str, source: str, limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    """The elements of an XML document, each with its line; never raises for bad input."""
    from lxml import etree

    language = ConfigFormat.XML.value
    try:
        root = etree.fromstring(source.encode("utf-8", "surrogatepass"), _parser())
    except etree.XMLSyntaxError as error:
        line = error.lineno if isinstance(error.lineno, int) and error.lineno > 0 else 1
        return not_measured(path, language, line, f"not valid XML: {error.msg}")
    except (ValueError, UnicodeError) as error:
        return not_measured(path, language, 1, f"not valid XML: {error}")
    tables: list[ConfigTable] = []
    pending: list[tuple[etree._Element, tuple[str, ...], int]] = [(root, (), -1)]
    while pending:  # depth first, in document order, without recursion
        element, above, parent = pending.pop()
        if not isinstance(element.tag, str):
            continue  # an entity reference left unexpanded
        keys = (*above, _local(element.tag))
        values = [(_local(str(name)), (str(value),)) for name, value in element.attrib.items()]
        text = (element.text or "").strip()
        if text:
            values.append((TEXT, (text,)))
        index = len(tables)
        written: object = element.sourceline  # None when libxml2 lost count
        line = written if isinstance(written, int) and written > 0 else 1
        tables.append(ConfigTable(keys, line, tuple(values), parent))
        if len(tables) > MAX_ELEMENTS:
            message = f"more than {MAX_ELEMENTS:,} elements; not read as configuration"
            return not_measured(path, language, 1, message)
        pending.extend((child, keys, index) for child in reversed(element))
    return FileFacts(path=path, language=language, tables=tuple(tables))
