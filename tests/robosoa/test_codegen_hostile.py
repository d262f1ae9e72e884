"""Descriptors written by a hostile stranger: refused, or generating code that holds nothing
but what the descriptor asks for. Regression cases first, then the properties."""

from __future__ import annotations

import ast
import keyword
import shlex

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from lxml import etree

from robosoa.codegen import generate, participants
from robosoa.codegen.common import doc_lines
from robosoa.codegen.pytypes import q
from robosoa.descriptor import DescriptorError, ServiceDescriptor, loads
from robosoa.descriptor.names import RESERVED
from tests.robosoa.codegen_spec import check_file, constant, descriptor_names, expected_files

PLANT = "PWNED"  # planted in every free-text field: must never reach code outside a string
BREAKS = ["\n", "\r", "\r\n", "\x0b", "\x0c", "\x1c", "\x1d", "\x1e", "\x85", "\u2028", "\u2029"]
FRAGMENTS = ['"""', '"""""', "'''", '"', "'", "\\", "\\N{", "\\x", "\\u", "#", ")", "}", "{",
             " ", "  ", "\t", "\n", "\r", "\x85", "\u2028", "\u2029", "\x7f", "\u200b", "é",
             "\U0001f916", f'__import__("os").system("{PLANT}")', f"{PLANT} = 1", PLANT]
SETTINGS = settings(max_examples=150, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])


def _xml_char(c: str) -> bool:
    return (c in "\t\n\r" or ord(c) >= 0x20) and c not in "\ufffe\uffff"


def free_text(max_size: int = 8) -> st.SearchStrategy[str]:
    """XML-compatible text full of quotes, backslashes, line breaks and would-be code."""
    chars = st.characters(codec="utf-8").filter(_xml_char)  # no surrogates
    piece = st.one_of(st.sampled_from(FRAGMENTS), st.text(chars, max_size=12),
                      st.just("x" * 120))
    return st.lists(piece, max_size=max_size).map("".join)


def file_names() -> st.SearchStrategy[str]:
    """Descriptor file names: anything, line breaks of every kind included."""
    piece = st.one_of(st.sampled_from([*BREAKS, "/", ".xml", "'", '"', PLANT, "\x00"]),
                      st.text(st.characters(codec="utf-8"), max_size=6))
    return st.lists(piece, min_size=1, max_size=6).map("".join)


SAFE = st.from_regex(r"[a-z][a-z0-9]{0,5}", fullmatch=True).filter(
    lambda n: not keyword.iskeyword(n) and n not in RESERVED)
HOSTILE_NAMES = ["None", "True", "class", "match", "type", "self", "payload_of", "SERVICE",
                 "main", "bind", "os", "sys", "robosoa", "Mapping", "from_payload", "to_payload",
                 "types", "client", "proxy", "impl", "provide", "QueryResult", "Row", "RowResult",
                 "XClient", "tuple", "dict", "str", "int", "list", "_x", "a-b", "a b", "é"]
NAMES = st.integers(0, 5).flatmap(  # one name in six is hostile
    lambda i: st.sampled_from(HOSTILE_NAMES) if i == 0 else SAFE)
PATTERNS = ["request-response", "publish-subscribe", "one-way", "event", "point-to-point"]
def enum(values: list[str]) -> st.SearchStrategy[str]:
    """One of ``values``, or now and then arbitrary text (which the schema must refuse)."""
    return st.integers(0, 7).flatmap(
        lambda i: free_text(2) if i == 0 else st.sampled_from(values))


def choice(names: st.SearchStrategy[str], values: list[str]) -> st.SearchStrategy[str]:
    """An enumerated value: noisy (``enum``) only where names are plain (SAFE)."""
    return enum(values) if names is SAFE else st.sampled_from(values)


PRIMITIVE_DEFAULTS = {"int": ["1", "-3", "1_0", "x", "9" * 30], "bool": ["true", "false", "1"],
                      "float": ["1.5", "nan", "inf", "-1e999", "1e-5"]}


@st.composite
def typed(draw: st.DrawFn, tag: str, names: st.SearchStrategy[str],
          structs: list[str]) -> etree._Element:
    element = etree.Element(tag, name=draw(names))
    kind = draw(st.sampled_from(["int", "float", "bool", "string", *structs]))
    element.set("type", f"list[{kind}]" if draw(st.booleans()) else kind)
    if draw(st.booleans()):
        element.set("definition", draw(free_text(4)))
    if element.get("type") == "string" and draw(st.booleans()):
        element.set("default", draw(free_text(4)))
    elif kind in PRIMITIVE_DEFAULTS and "[" not in element.get("type", "") and draw(
            st.booleans()):
        element.set("default", draw(st.sampled_from(PRIMITIVE_DEFAULTS[kind])))
    return element


def _definition(draw: st.DrawFn, parent: etree._Element) -> None:
    if draw(st.booleans()):
        etree.SubElement(parent, "definition").text = draw(free_text())


@st.composite
def participant(draw: st.DrawFn, pattern: str, ops: list[str],
                names: st.SearchStrategy[str]) -> etree._Element:
    replies = pattern in ("request-response", "point-to-point")
    forms = ["provider-library", "consumer-source"]
    forms += ["provider-executable", "consumer-no-source"] if replies or pattern == "one-way" \
        else []
    packaging = draw(st.sampled_from(forms))
    element = etree.Element("participant", actor=packaging.split("-")[0], packaging=packaging)
    if draw(st.booleans()):
        element.set("group", draw(names))
    c = packaging == "provider-library" and replies and draw(st.booleans())
    etree.SubElement(element, "target", language="c" if c else "python",
                     os=draw(choice(names, ["any", "posix", "linux"])))
    if packaging == "provider-executable":
        impl = etree.SubElement(element, "implementation", form="executable",
                                encoding=draw(choice(names, ["json", "xml"])))
        words = draw(st.lists(free_text(3), min_size=1, max_size=3))
        etree.SubElement(impl, "command").text = shlex.join(words) or "prog"
    elif packaging != "consumer-source" and (replies or pattern == "one-way"):
        impl = etree.SubElement(element, "implementation", form="library",
                                library=draw(st.one_of(free_text(3), names)) or "lib")
        for op in draw(st.lists(st.sampled_from(ops), max_size=2, unique=True)):
            etree.SubElement(impl, "function", operation=op, symbol=draw(names))
    etree.SubElement(element, "codegen", profile=draw(choice(names, ["checked", "unchecked"])))
    naming = etree.SubElement(element, "naming")
    for attribute in ("package", "module", "class"):
        if draw(st.booleans()):
            naming.set(attribute, draw(names))
    return element


@st.composite
def descriptors(draw: st.DrawFn, names: st.SearchStrategy[str]) -> tuple[str, str]:
    """(descriptor text, file name) of a descriptor with every field drawn."""
    pattern = draw(st.sampled_from(PATTERNS))
    version = draw(choice(names, ["1.0.0", "2.10.3"]))
    root = etree.Element("service", name=draw(names), version=version)
    _definition(draw, root)
    etree.SubElement(root, "pattern").text = draw(choice(names, [pattern]))
    structs = draw(st.lists(names, max_size=2, unique=True))
    if structs:
        types = etree.SubElement(root, "types")
        for name in structs:
            struct = etree.SubElement(types, "struct", name=name)
            _definition(draw, struct)
            others = [s for s in structs if s != name]
            for field in draw(st.lists(typed("field", names, others), min_size=1, max_size=2)):
                struct.append(field)
    ops = draw(st.lists(names, min_size=1, max_size=3, unique=True))
    for name in ops:
        op = etree.SubElement(root, "operation", name=name)
        _definition(draw, op)
        for param in draw(st.lists(typed("param", names, structs), max_size=3)):
            op.append(param)
        if pattern in ("request-response", "point-to-point"):
            for ret in draw(st.lists(typed("return", names, structs), max_size=2)):
                op.append(ret)
    for part in draw(st.lists(participant(pattern, ops, names), max_size=3)):
        root.append(part)
    return etree.tostring(root, encoding="unicode"), draw(file_names())


def check_generated(d: ServiceDescriptor) -> None:
    """Every generated file passes ``check_file``; planted text stays inside strings."""
    expected = expected_files(d)
    files = generate(d)
    assert {f.path for f in files} == set(expected)
    declared = descriptor_names(d)
    for f in files:
        tree = check_file(f, expected[f.path], PLANT, declared)
        if f.path.endswith("/types.py"):
            assert constant(tree, "DESCRIPTOR_XML") == d.text
            doc = ast.get_docstring(tree, clean=False) or ""
            assert "".join(d.definition.split()) in "".join(doc.split())


@settings(SETTINGS, max_examples=200)
@given(descriptors(NAMES))
def test_hostile_descriptors_are_refused_or_generate_only_what_they_declare(
        case: tuple[str, str]) -> None:
    text, source = case
    try:
        d = loads(text, source=source)
    except DescriptorError:
        event("refused")
        return
    event("accepted")
    check_generated(d)


def _plain(text: str) -> str:
    """The descriptor with every free-text field replaced by a plain word."""
    root = etree.fromstring(text)
    for element in root.iter():
        if element.tag in ("definition", "command"):
            element.text = "t"
        if element.get("definition") is not None:
            element.set("definition", "t")
        if element.get("type") == "string" and element.get("default") is not None:
            element.set("default", "t")
    return etree.tostring(root, encoding="unicode")


def _problems(text: str, source: str) -> frozenset[str] | ServiceDescriptor:
    try:
        return loads(text, source=source)
    except DescriptorError as exc:  # lines move with line breaks in the text: fields only
        return frozenset(p.field for p in exc.problems)


@SETTINGS
@given(descriptors(SAFE))
def test_free_text_never_decides_acceptance_and_reaches_code_verbatim(
        case: tuple[str, str]) -> None:
    # definitions, documentation, string defaults, command lines and file names are data:
    # a descriptor is refused exactly when the same descriptor with plain text is
    text, source = case
    outcome, plain = _problems(text, source), _problems(_plain(text), "plain.xml")
    if not isinstance(outcome, ServiceDescriptor):
        event("refused")
        assert outcome == plain
        return
    event("accepted")
    assert isinstance(plain, ServiceDescriptor)
    check_generated(outcome)
    for f in generate(outcome):
        tree = ast.parse(f.text)
        names = {t.id for n in tree.body if isinstance(n, ast.Assign | ast.AnnAssign)
                 for t in (n.targets if isinstance(n, ast.Assign) else [n.target])
                 if isinstance(t, ast.Name)}
        part = next(p for p in participants(outcome)
                    if f.path.startswith(p.naming.package.replace(".", "/") + "/"))
        impl = part.implementation
        if "COMMANDS" in names and impl is not None:
            commands = {op.name: impl.command(op.name) for op in outcome.operations}
            assert constant(tree, "COMMANDS") == {
                name: command.argv for name, command in commands.items() if command}
        if "LIBRARY" in names and impl is not None:
            assert constant(tree, "LIBRARY") == impl.library


@settings(max_examples=200, deadline=None, derandomize=True, database=None)
@given(st.text(), st.integers(1, 100))
def test_docstring_lines_never_end_the_docstring(text: str, width: int) -> None:
    lines = doc_lines(text, width)
    assert all(len(line) <= max(width, 10) for line in lines)
    body = "\n".join(lines)
    value = ast.literal_eval(f'"""{body}"""')
    assert "".join(value.split()) == "".join(text.split())


@settings(max_examples=200, deadline=None, derandomize=True, database=None)
@given(st.text())
def test_string_literals_are_repr_exact(text: str) -> None:
    assert ast.literal_eval(q(text)) == text
    assert "\n" not in q(text) and "\r" not in q(text)


WDB_LIKE = """\
<service name="svc" version="1.0.0">
  <pattern>request-response</pattern>
  <operation name="op">
    <definition>{definition}</definition>
    <param name="x" type="string" default="{default}" definition="{param}"/>
    <return name="r" type="int"/>
  </operation>
  <participant actor="consumer" packaging="consumer-source">{naming}</participant>
</service>
"""


def _service(definition: str = "d", default: str = "v", param: str = "p",
             naming: str = "") -> str:
    return WDB_LIKE.format(definition=definition, default=default, param=param,
                           naming=naming)


PAYLOAD = ";__import__('os').system('PWNED') #"
NO_PARAMS = """\
<service name="svc" version="1.0.0"><definition>{service}</definition>
  <pattern>request-response</pattern>
  <types><struct name="Row"><definition>{struct}</definition>
    <field name="n" type="int"/></struct></types>
  <operation name="op"><definition>{op}</definition><return name="r" type="Row"/></operation>
</service>
"""


# Before the fix, textwrap cut the escaped quotes of a long word between a backslash and its
# quote: the backslash then continued the line and the quotes that followed closed the
# docstring. The widths are those of a method (88), a class (92) and a module (96) docstring.
@pytest.mark.parametrize("text", [
    "a" * 83 + '"""""' + PAYLOAD, "a" * 77 + '"' * 8 + PAYLOAD,
    "a" * 87 + '"""""' + PAYLOAD, "a" * 91 + '"""""' + PAYLOAD,
    '"', "\\", 'ends with a quote"', "ends with a backslash\\", '"""' * 40,
    "x" * 95 + "\\" + '"""' + "x" * 95,
])
def test_definitions_that_close_the_docstring_stay_text(text: str) -> None:
    xml = text.replace("&", "&amp;").replace("<", "&lt;")
    d = loads(NO_PARAMS.format(service=xml, struct=xml, op=xml))
    check_generated(d)
    squeezed = "".join(text.split())
    for f in generate(d):
        tree = ast.parse(f.text)
        assert "__import__" not in {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.ClassDef) and node.name in ("op", "Row"):
                assert "".join((ast.get_docstring(node) or "").split()) == squeezed


@pytest.mark.parametrize("breaker", BREAKS)
def test_a_line_break_in_the_file_name_stays_in_the_marker_comment(breaker: str) -> None:
    source = f"evil{breaker}import os{breaker}os.system('PWNED'){breaker}.xml"
    d = loads(_service(), source=source)
    check_generated(d)
    for f in generate(d):
        assert f.text.splitlines()[1].startswith('"""'), f.path
        assert repr(source) in f.text.splitlines()[0]


@pytest.mark.parametrize(("attributes", "message"), [
    ('class="None"', "'None' is a reserved word (a Python keyword)"),
    ('class="SERVICE"', "'SERVICE' is a reserved word (generated code defines or uses it)"),
    ('class="OpResult"', "generated name 'OpResult' is taken twice"),
    ('module="types"', "'types' is the types module"),
    ('module="class"', "'class' is a reserved word (a Python keyword)"),
    ('package="a.None.b"', "package 'a.None.b' is not a dotted name of identifiers"),
    ('package="os"', "package 'os' would hide the module 'os'"),
])
def test_naming_that_cannot_compile_is_refused_with_its_line(attributes: str,
                                                             message: str) -> None:
    text = _service(naming=f"<naming {attributes}/>")
    with pytest.raises(DescriptorError) as caught:
        loads(text, source="svc.xml")
    assert "svc.xml:8: participant 'consumer-source' naming: " in str(caught.value)
    assert message in str(caught.value)


@pytest.mark.parametrize(("body", "message"), [
    ('<param name="payload_of" type="int"/>', "operation 'op' parameter 'payload_of': "
     "'payload_of' is a reserved word"),
    ('<param name="True" type="int"/>', "'True' is a reserved word (a Python keyword)"),
    ('<param name="OpResult" type="int"/><return name="r" type="int"/>',
     "'OpResult' is also the name of a class"),
    ('<param name="x" type="float" default="inf"/>', "default 'inf' is not a valid float"),
    ('<param name="x" type="float" default="1e999"/>', "default '1e999' is not a valid float"),
])
def test_names_and_defaults_that_break_generated_code_are_refused(body: str,
                                                                  message: str) -> None:
    text = ('<service name="svc" version="1.0.0"><pattern>request-response</pattern>'
            f'<operation name="op">{body}</operation></service>')
    with pytest.raises(DescriptorError, match=message.replace("(", r"\(").replace(")", r"\)")):
        loads(text, source="svc.xml")


def test_quotes_in_every_string_round_trip() -> None:
    nasty = "a\"b'c\\\\d\"\"\"e'''f&#10;g&#13;h&#x2028;i"
    text = _service(definition=nasty, default=nasty.replace('"', "&quot;"),
                    param=nasty.replace('"', "&quot;"))
    d = loads(text)
    check_generated(d)
    client = next(f for f in generate(d) if f.path.endswith("/client.py"))
    method = next(n for n in ast.walk(ast.parse(client.text))
                  if isinstance(n, ast.FunctionDef) and n.name == "op")
    default = method.args.defaults[0]
    param = d.operations[0].parameters[0]
    assert ast.literal_eval(default) == param.default
