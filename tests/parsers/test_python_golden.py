"""Golden cases for the Python parser: one per row of the tables in docs/metrics.md.

Every case runs through both Python readers (``ast`` and libcst, tests/parsers/conftest.py).
"""

from __future__ import annotations

import textwrap

import pytest
from radon.complexity import cc_visit

from archmetrics.facts import Argument, Dependency, DependencyKind, FileFacts, Severity, Span
from archmetrics.parsers import LanguageTable, parse_source
from tests.harness import complexities, facts_of, statement_kinds

pytestmark = pytest.mark.usefixtures("python_reader")


def py(source: str) -> FileFacts:
    return facts_of(source, "python")


def kinds(source: str) -> list[str]:
    return statement_kinds(py(source))


def texts(source: str) -> list[str]:
    return [s.text for s in py(source).statements]


def decisions(source: str, function: str = "f") -> list[str]:
    (found,) = [f for f in py(source).functions if f.qualified_name == function]
    return [d.kind for d in found.decisions]


def radon_by_line(source: str) -> dict[int, int]:
    """radon's complexity per def line, closures and methods of (inner) classes flattened."""
    result: dict[int, int] = {}

    def visit(block: object) -> None:
        if hasattr(block, "methods"):
            for child in (*block.methods, *block.inner_classes):
                visit(child)
            return
        result[block.lineno] = block.complexity  # type: ignore[attr-defined]
        for closure in block.closures:  # type: ignore[attr-defined]
            visit(closure)

    for block in cc_visit(textwrap.dedent(source)):
        if hasattr(block, "methods") or not block.is_method:
            visit(block)
    return result


def ours_by_line(source: str) -> dict[int, int]:
    return {f.span.start: f.complexity for f in py(source).functions}


# --- λ: simple statements, one row each ------------------------------------------------------

SIMPLE_ROWS = [
    ("x = 1", "assign"),
    ("a = b = 1", "assign"),
    ("x += 1", "augassign"),
    ("x: int = 1", "annassign"),
    ("x: int", "annassign"),
    ("print(x)", "expr"),
    ("raise ValueError", "raise"),
    ("pass", "pass"),
    ("del x", "del"),
    ("assert x", "assert"),
    ("global g", "global"),
    ("import os", "import"),
    ("from os import path", "from_import"),
    ("type Alias = list[int]", "type_alias"),
]


@pytest.mark.parametrize(("source", "kind"), SIMPLE_ROWS)
def test_every_simple_statement_counts_once(source: str, kind: str) -> None:
    assert kinds(source + "\n") == [kind]


@pytest.mark.parametrize(
    ("body", "kind"),
    [("return 1", "return"), ("nonlocal n", "nonlocal"), ("yield 1", "expr")],
)
def test_function_only_statements_count(body: str, kind: str) -> None:
    assert kinds(f"def f():\n    {body}\n") == ["def", kind]


def test_break_and_continue_count() -> None:
    assert kinds("for i in x:\n    break\n    continue\n") == ["for", "break", "continue"]


# --- λ: compound statements count their header -----------------------------------------------


@pytest.mark.parametrize(
    ("source", "expected"),
    [
        ("if a:\n    pass\n", ["if", "pass"]),
        ("if a:\n    pass\nelif b:\n    pass\n", ["if", "pass", "elif", "pass"]),
        ("for i in x:\n    pass\n", ["for", "pass"]),
        ("async def f():\n    async for i in x:\n        pass\n", ["def", "for", "pass"]),
        ("while a:\n    pass\n", ["while", "pass"]),
        ("with a as b, c:\n    pass\n", ["with", "pass"]),
        ("async def f():\n    async with a:\n        pass\n", ["def", "with", "pass"]),
        ("try:\n    pass\nexcept E:\n    pass\n", ["try", "pass", "except", "pass"]),
        ("try:\n    pass\nexcept* E:\n    pass\n", ["try", "pass", "except", "pass"]),
        ("match x:\n    case 1:\n        pass\n", ["match", "case", "pass"]),
        ("class A:\n    pass\n", ["class", "pass"]),
        ("def f(a, b=1):\n    pass\n", ["def", "pass"]),
    ],
)
def test_compound_statement_counts_its_header(source: str, expected: list[str]) -> None:
    assert kinds(source) == expected


def test_else_and_finally_do_not_count() -> None:
    source = """
    try:
        x = 1
    except E:
        x = 2
    else:
        x = 3
    finally:
        x = 4
    if a:
        pass
    else:
        pass
    for i in y:
        pass
    else:
        pass
    """
    try_part = ["try", "assign", "except", "assign", "assign", "assign"]
    assert kinds(source) == [*try_part, "if", "pass", "pass", "for", "pass", "pass"]


def test_one_line_compound_counts_header_and_body() -> None:
    assert kinds("if a: x = 1; y = 2\n") == ["if", "assign", "assign"]


def test_two_statements_on_one_line_count_two() -> None:
    facts = py("a = 1; b = 2\n")
    assert [(s.kind, s.span, s.text) for s in facts.statements] == [
        ("assign", Span(1, 1), "a = 1"),
        ("assign", Span(1, 1), "b = 2"),
    ]


def test_statement_over_several_lines_counts_once() -> None:
    facts = py("total = (1 +\n         2 +\n         3)\nx = 1 + \\\n    2\n")
    assert [(s.kind, s.span) for s in facts.statements] == [
        ("assign", Span(1, 3)),
        ("assign", Span(4, 5)),
    ]


def test_comments_and_blank_lines_do_not_count() -> None:
    assert kinds("# a comment\n\n   \nx = 1  # trailing\n# another\n") == ["assign"]


def test_docstrings_do_not_count() -> None:
    source = '''
    """Module docstring."""
    class A:
        """Class docstring."""
        def f(self):
            """Function docstring."""
            return 1
    '''
    assert kinds(source) == ["class", "def", "return"]


def test_only_the_first_string_statement_is_a_docstring() -> None:
    assert kinds('"""doc"""\n"""not a docstring"""\nx = 1\n') == ["expr", "assign"]


def test_a_string_after_code_or_an_fstring_is_not_a_docstring() -> None:
    assert kinds('x = 1\n"text"\n') == ["assign", "expr"]
    assert kinds('def f():\n    f"{x}"\n') == ["def", "expr"]


def test_signature_with_decorators_is_one_statement() -> None:
    facts = py("@first\n@second(1,\n        2)\ndef f(a,\n      b=g()):\n    return a\n")
    (signature, body) = facts.statements
    assert signature.kind == "def"
    assert signature.span == Span(1, 5)
    assert signature.text == "@ first @ second ( 1 , 2 ) def f ( a , b = g ( ) ) :"
    assert body.kind == "return"
    (function,) = facts.functions
    assert function.span == Span(4, 6)  # from the def line, as radon reports it
    assert function.statements == 2


def test_lambda_is_part_of_its_statement() -> None:
    assert kinds("key = lambda x: x + 1\n") == ["assign"]


# --- Statement.text and Statement.function ---------------------------------------------------


def test_reformatting_and_comments_give_equal_text() -> None:
    assert texts("x=1\n") == texts("x = 1  # c\n") == ["x = 1"]
    one_line = texts("result = call(a, b, key=value)\n")
    spread = texts("result = call(  # why\n    a,\n    b,\n    key = value\n)\n")
    assert spread == one_line == ["result = call ( a , b , key = value )"]
    assert texts("x = 1 + \\\n    2\n") == texts("x = 1 + 2\n")


def test_compound_text_is_the_header_only() -> None:
    assert texts("if x>0:  # check\n    y = 1\n") == ["if x > 0 :", "y = 1"]
    assert texts("class A(B):\n    pass\n")[0] == "class A ( B ) :"
    assert texts("match p:\n    case [a, b] if a:\n        pass\n")[:2] == [
        "match p :",
        "case [ a , b ] if a :",
    ]


def test_fstring_text_keeps_its_literal_spacing() -> None:
    assert texts('x = f"a {b} c"\n') == ['x = f"a {b} c"']


def test_statement_function_is_the_innermost_function() -> None:
    source = """
    x = 1
    class A:
        y = 2
        def m(self):
            def inner():
                return 3
            return inner
    """
    owners = [(s.kind, s.function) for s in py(source).statements]
    assert owners == [
        ("assign", None),
        ("class", None),
        ("assign", None),
        ("def", "A.m"),
        ("def", "A.m.inner"),
        ("return", "A.m.inner"),
        ("return", "A.m"),
    ]
    statements = {f.qualified_name: f.statements for f in py(source).functions}
    assert statements == {"A.m": 2, "A.m.inner": 2}


def test_qualified_names_of_nested_definitions() -> None:
    source = """
    class Outer:
        class Inner:
            def method(self):
                pass
    def outer():
        def inner():
            pass
        class Local:
            def m(self):
                pass
    """
    facts = py(source)
    assert [f.qualified_name for f in facts.functions] == [
        "Outer.Inner.method",
        "outer",
        "outer.inner",
        "outer.Local.m",
    ]
    assert [(c.qualified_name, c.span) for c in facts.classes] == [
        ("Outer", Span(2, 5)),
        ("Outer.Inner", Span(3, 5)),
        ("outer.Local", Span(9, 11)),
    ]


# --- decision points: one row each, checked against radon as well --------------------------

DECISION_ROWS = [
    ("if a:\n        pass", ["if"]),
    ("if a:\n        pass\n    elif b:\n        pass\n    else:\n        pass", ["if", "elif"]),
    ("x = a if b else c", ["ifexp"]),
    ("for i in x:\n        pass", ["for"]),
    ("for i in x:\n        pass\n    else:\n        pass", ["for", "for_else"]),
    ("while a:\n        pass", ["while"]),
    ("while a:\n        pass\n    else:\n        pass", ["while", "while_else"]),
    ("async for i in x:\n        pass", ["for"]),
    (
        "try:\n        pass\n    except A:\n        pass\n    except B:\n        pass",
        ["except", "except"],
    ),
    (
        "try:\n        pass\n    except A:\n        pass\n    else:\n        pass",
        ["except", "try_else"],
    ),
    ("try:\n        pass\n    finally:\n        pass", []),
    ("with a:\n        pass", []),
    ("x = a and b and c or d", ["and", "and", "or"]),
    ("x = [i for i in y if i if i > 1]", ["comp_for", "comp_if", "comp_if"]),
    ("x = {k: v for k in a for v in b}", ["comp_for", "comp_for"]),
    ("x = (i async for i in y)", ["comp_for"]),
    ("assert a", ["assert"]),
    ("key = lambda v: v or 0", ["or"]),
    (
        "match x:\n        case 1:\n            pass\n        case 2:\n            pass",
        ["case", "case"],
    ),
    ("match x:\n        case 1:\n            pass\n        case _:\n            pass", ["case"]),
    (
        "match x:\n        case 1:\n            pass\n        case other:\n            pass",
        ["case"],
    ),
    ("match x:\n        case [a] if a or b:\n            pass", ["case", "or"]),
    ("return", []),
]


@pytest.mark.parametrize(("body", "expected"), DECISION_ROWS)
def test_decision_point(body: str, expected: list[str]) -> None:
    source = f"async def f():\n    {body}\n"
    assert decisions(source) == expected
    assert ours_by_line(source) == radon_by_line(source) == {1: 1 + len(expected)}


def test_decision_lines_are_where_the_construct_is() -> None:
    source = "def f():\n    if (a and\n            b):\n        pass\n"
    (function,) = py(source).functions
    assert [(d.kind, d.line) for d in function.decisions] == [("if", 2), ("and", 2)]


def test_closures_do_not_add_to_their_parent() -> None:
    source = """
    def outer(x):
        if x:
            pass
        def inner(y):
            return y if y else 0
        return inner
    """
    assert complexities(py(source)) == {"outer": 2, "outer.inner": 2}
    assert ours_by_line(source) == radon_by_line(source)


def test_methods_of_nested_classes_are_counted_like_radon() -> None:
    source = """
    class Outer:
        flag = a or b
        class Inner:
            def method(self):
                return [i for i in self]
    """
    assert complexities(py(source)) == {"Outer.Inner.method": 2}
    assert ours_by_line(source) == radon_by_line(source)


def test_methods_of_a_class_inside_a_class_are_measured_by_radon_not_printed_by_it() -> None:
    # radon's visitor measures them (under the outer class's `inner_classes`), but the
    # blocks `radon cc` prints are the top-level functions and classes and their own
    # methods: these are not among them. We report them (docs/metrics.md, "Disagreements
    # with radon"); they are no extra of ours, as methods of a class in a function are.
    source = """
    class Outer:
        def own(self, x):
            return x or 1
        class Inner:
            def method(self, y):
                if y:
                    return 1
                return 0
    """
    blocks = cc_visit(textwrap.dedent(source))
    printed = [b.name for b in blocks] + [m.name for b in blocks for m in getattr(b, "methods", ())]
    assert "method" not in printed
    (outer,) = [b for b in blocks if b.name == "Outer"]
    assert [(m.name, m.complexity) for c in outer.inner_classes for m in c.methods] == [
        ("method", 2)
    ]
    assert complexities(py(source)) == {"Outer.own": 2, "Outer.Inner.method": 2}


def test_signature_and_class_header_carry_no_decisions_like_radon() -> None:
    source = """
    @register(a or b)
    def f(x=1 if flag else 2, key=lambda v: v and v.y) -> (A or B):
        return x
    class C(A if flag else B):
        pass
    """
    assert complexities(py(source)) == {"f": 1}
    assert ours_by_line(source) == radon_by_line(source)


def test_decisions_inside_an_assert_are_not_counted_like_radon() -> None:
    source = "def f(a, b):\n    assert a and b or [x for x in a if x]\n"
    assert decisions(source) == ["assert"]
    assert ours_by_line(source) == radon_by_line(source) == {1: 2}


def test_module_level_decisions_belong_to_no_function() -> None:
    facts = py("if a:\n    x = b or c\n")
    assert facts.functions == ()
    assert facts.vg == 0


def test_deviation_except_star_counts_like_except() -> None:
    """radon 6 predates ``except*`` (its TryStar node counts 0); a handler is a handler."""
    source = """
    def f():
        try:
            pass
        except* A:
            pass
        except* B:
            pass
    """
    assert decisions(source) == ["except", "except"]
    assert ours_by_line(source) == {2: 3}
    assert radon_by_line(source) == {2: 1}


def test_deviation_methods_of_a_class_inside_a_function_are_reported() -> None:
    """radon drops classes defined in a function; they are code all the same."""
    source = """
    def factory():
        class Local:
            def m(self):
                return 1 if self else 2
        return Local
    """
    assert complexities(py(source)) == {"factory": 1, "factory.Local.m": 2}
    assert radon_by_line(source) == {2: 1}


def test_class_body_inside_a_function_gives_its_decisions_to_no_function() -> None:
    source = "def f():\n    class A:\n        x = a or b\n    return A\n"
    assert complexities(py(source)) == {"f": 1}
    assert ours_by_line(source) == radon_by_line(source)


# --- dependencies ------------------------------------------------------------------------


Imported = tuple[str, int, tuple[str, ...], tuple[str, ...]]


def deps(source: str) -> list[Imported]:
    return [(d.target, d.level, d.names, d.bound) for d in py(source).dependencies]


def test_import_gives_one_dependency_per_module() -> None:
    facts = py("import a.b as c, d.e\n")
    assert facts.dependencies == (
        Dependency("a.b", DependencyKind.IMPORT, Span(1, 1), bound=("c",)),
        Dependency("d.e", DependencyKind.IMPORT, Span(1, 1), bound=("d",)),
    )


@pytest.mark.parametrize(
    ("source", "expected"),
    [
        ("from x.y import p, q as r", [("x.y", 0, ("p", "q"), ("p", "r"))]),
        ("from ..m import n", [("m", 2, ("n",), ("n",))]),
        ("from . import m", [("", 1, ("m",), ("m",))]),
        ("from x import *", [("x", 0, ("*",), ("*",))]),
        (
            "from __future__ import annotations",
            [("__future__", 0, ("annotations",), ("annotations",))],
        ),
        ("from .a.b import (c,\n    d as e)", [("a.b", 1, ("c", "d"), ("c", "e"))]),
    ],
)
def test_from_import_forms(source: str, expected: list[Imported]) -> None:
    assert deps(source + "\n") == expected


def test_import_inside_a_function_is_a_dependency_too() -> None:
    facts = py("def f():\n    import json\n")
    assert [(d.target, d.span) for d in facts.dependencies] == [("json", Span(2, 2))]


def test_multiline_import_spans_its_lines() -> None:
    (dep,) = py("from x import (\n    a,\n    b,\n)\n").dependencies
    assert dep.span == Span(1, 4)


# --- call sites ---------------------------------------------------------------------------


def calls(source: str) -> list[tuple[str, str, str | None]]:
    return [(c.callee, c.name, c.receiver) for c in py(source).call_sites]


@pytest.mark.parametrize(
    ("source", "expected"),
    [
        ("f()", [("f", "f", None)]),
        ("bus.request()", [("bus.request", "request", "bus")]),
        (
            "importlib.import_module('m')",
            [("importlib.import_module", "import_module", "importlib")],
        ),
        ("socket.socket.fromfd(1)", [("socket.socket.fromfd", "fromfd", "socket.socket")]),
        ("''.join(x)", [("'' . join", "join", "''")]),
        ("self.items[0].send(x)", [("self . items [ 0 ] . send", "send", "self . items [ 0 ]")]),
        ("(a.b)(1)", [("a.b", "b", "a")]),
    ],
)
def test_callee_name_and_receiver(source: str, expected: list[tuple[str, str, str | None]]) -> None:
    assert calls(source + "\n") == expected


def test_calls_are_listed_in_source_order_with_their_function() -> None:
    source = "@deco(1)\ndef f():\n    return g(h(1), k())\nx = m()\n"
    facts = py(source)
    assert [(c.callee, c.function, c.span) for c in facts.call_sites] == [
        ("deco", "f", Span(1, 1)),
        ("g", "f", Span(3, 3)),
        ("h", "f", Span(3, 3)),
        ("k", "f", Span(3, 3)),
        ("m", None, Span(4, 4)),
    ]


def arguments(source: str) -> tuple[Argument, ...]:
    (site,) = py(source).call_sites
    return site.arguments


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ('"tcp://*:5555"', "tcp://*:5555"),
        ("'a' 'b'", "ab"),
        ("('a'\n   'b')", "ab"),
        ('f"plain {{x}}"', "plain {x}"),
        ("42", 42),
        ("0x10", 16),
        ("2.5", 2.5),
        ("-1", -1),
        ("-2.5", -2.5),
        ("True", True),
        ("False", False),
        ("None", None),
        ('b"raw"', "raw"),
    ],
)
def test_literal_arguments(text: str, value: object) -> None:
    (argument,) = arguments(f"connect({text})\n")
    assert argument.is_literal is True
    assert argument.value == value
    assert type(argument.value) is type(value)


@pytest.mark.parametrize("text", ['f"{host}:1"', "x", "1 + 2", "[1]", "'a' f'{b}'", "-x"])
def test_non_literal_arguments(text: str) -> None:
    (argument,) = arguments(f"connect({text})\n")
    assert (argument.is_literal, argument.value) == (False, None)


def test_argument_text_keyword_and_stars() -> None:
    found = arguments("call(a.b, key = 'v', *rest, **options)\n")
    assert found == (
        Argument("a . b"),
        Argument("'v'", "v", True, "key"),
        Argument("* rest"),
        Argument("** options"),
    )


def test_calls_inside_fstrings_are_found() -> None:
    facts = py("x = f\"{render(item, 'wide')}!\"\n")
    (site,) = facts.call_sites
    assert (site.callee, site.arguments) == (
        "render",
        (Argument("item"), Argument("'wide'", "wide", True)),
    )


def test_arguments_keep_the_order_they_are_written_in() -> None:
    found = arguments("call(a, *b, c=1, *d, **e)\n")
    assert [(a.text, a.keyword) for a in found] == [
        ("a", None),
        ("* b", None),
        ("1", "c"),
        ("* d", None),
        ("** e", None),
    ]


@pytest.mark.parametrize(
    ("source", "texts"),
    [
        ("f(lambda a=1, b=2: a, 3)", ["lambda a = 1 , b = 2 : a", "3"]),
        ("f(x for x, y in z)", ["x for x , y in z"]),
        ("f((x for x in y), 1,)", ["( x for x in y )", "1"]),
        ("f((a), {b: c, d: e}, [g, h])", ["( a )", "{ b : c , d : e }", "[ g , h ]"]),
    ],
)
def test_argument_texts_hold_their_own_commas(source: str, texts: list[str]) -> None:
    assert [a.text for a in arguments(source + "\n")] == texts


def test_true_false_and_none_are_names_to_a_callee() -> None:
    assert calls("True.__index__()\n") == [("True.__index__", "__index__", "True")]


def test_a_call_assigned_alone_or_before_accessors_has_its_target() -> None:
    source = """
    class Talker(Node):
        def __init__(self):
            self.pub = self.create_publisher(String, 'chatter', 10)
            topic = self.declare_parameter('topic', 'chatter').value
            t: str = (self.get_parameter('t').get_parameter_value().string_value)
            a = b = make(2)
            y = h(1).k(2)
            self.pub.publish(String(data='hi'))
    """
    facts = py(source)
    found = [(c.callee, c.target) for c in facts.call_sites]
    assert found == [
        ("self.create_publisher", "self.pub"),
        ("self.declare_parameter", "topic"),
        ("self . get_parameter ( 't' ) . get_parameter_value", "t"),
        ("self.get_parameter", "t"),
        ("make", "b"),  # the last target of a chain of them
        ("h ( 1 ) . k", "y"),
        ("h", None),  # k's argument makes it no accessor
        ("self.pub.publish", None),
        ("String", None),
    ]


def test_a_call_in_parentheses_spans_them() -> None:
    (site,) = py("x = (\n    connect(1)\n)\n").call_sites
    assert site.span == Span(1, 3)


@pytest.mark.parametrize(
    ("source", "line"),
    [
        ("    with (\n        a if b else c\n    ):\n        pass\n", 3),  # the statement's
        ("    with (\n        a if b else c\n    ) as d:\n        pass\n", 2),  # the item's
    ],
)
def test_parentheses_of_a_with_statement_are_its_own(source: str, line: int) -> None:
    (function,) = py("def f():\n" + source).functions
    assert [(d.kind, d.line) for d in function.decisions] == [("ifexp", line)]


def test_parentheses_after_a_soft_keyword_are_the_subjects_own() -> None:
    source = "match (\n    f(x)\n):\n    case _:\n        match(y)\n"
    assert [(c.callee, c.span) for c in py(source).call_sites] == [
        ("f", Span(1, 3)),
        ("match", Span(5, 5)),
    ]


def test_calls_and_decisions_inside_fstrings_have_their_own_lines() -> None:
    source = (
        'def f():\n    s = f"""{\n        a if b else c} {g(\n        1)}"""\n'
        '    t = f"{x or y}"\n    return s + t\n'
    )
    facts = py(source)
    (function,) = facts.functions
    assert [(d.kind, d.line) for d in function.decisions] == [("ifexp", 3), ("or", 5)]
    assert [(c.callee, c.span) for c in facts.call_sites] == [("g", Span(3, 4))]


def test_an_fstring_in_parentheses_is_one_token_without_them() -> None:
    assert texts('x = (\n    f"{a}"  # note\n)\n') == ['x = ( f"{a}" )']


def test_an_fstring_keeps_its_text_as_written_over_lines() -> None:
    source = 'def f(d):\n    c = f"""{\n        g(1,\n          2) if d else 0\n    }"""\n'
    assert texts(source)[1] == 'c = f"""{\n        g(1,\n          2) if d else 0\n    }"""'


def test_relative_import_text_names_each_dot() -> None:
    assert texts("from ... import x\nfrom .... import y\n") == [
        "from . . . import x",
        "from . . . . import y",
    ]


# --- SLOC ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("source", "sloc"),
    [
        ("x = 1\n", 1),
        ("\n\n   \nx = 1\n\n", 1),
        ("# comment\nx = 1  # trailing comment\n", 1),
        ('"""Module\n\ndocstring."""\nx = 1\n', 1),
        ('def f():\n    """Doc\n    string."""\n    return 1\n', 2),
        ('def f(): """doc"""\n', 1),
        ('x = """\nline\n\nline\n"""\n', 4),
        ("x = (1,\n     2)\n", 2),
        ("x = 1 + \\\n    2\n", 2),
        ('class A:\n    "doc"\n    x = 1\n', 2),
        ("", 0),
    ],
)
def test_sloc(source: str, sloc: int) -> None:
    assert py(source).sloc == sloc


# --- bad input ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("source", "line"),
    [
        ("x = 1\ny = (\n", 2),
        ("x = 1\ndef f(:\n    pass\n", 2),
        ("if x:\npass\n", 2),
        ("x = 'open\n", 1),
    ],
)
def test_syntax_error_is_reported_not_guessed(source: str, line: int) -> None:
    facts = py(source)
    assert facts.parsed is False
    assert (facts.statements, facts.functions, facts.call_sites, facts.loc) == ((), (), (), 0)
    (warning,) = facts.warnings
    assert warning.severity is Severity.ERROR
    assert warning.line == line
    assert warning.message.startswith("Python syntax error: ")
    assert warning.path == "snippet.py"


def test_non_utf8_bytes_are_measured_with_a_warning() -> None:
    data = b"x = 1\n# caf\xe9\ny = 'na\xefve'\n"
    facts = parse_source("legacy.py", data, "python", LanguageTable.default(plugins=False))
    assert facts.parsed is True
    assert [w.line for w in facts.warnings] == [2]
    assert "Latin-1" in facts.warnings[0].message
    assert statement_kinds(facts) == ["assign", "assign"]
    assert facts.sloc == 2


def test_binary_file_is_not_measured() -> None:
    facts = parse_source(
        "blob.py", b"x = 1\n\x00\x01\x02", "python", LanguageTable.default(plugins=False)
    )
    assert facts.parsed is False
    assert facts.loc == 0
    assert "binary" in facts.warnings[0].message


def test_windows_and_old_mac_newlines_give_the_same_lines() -> None:
    unix = py("x = 1\n\ndef f():\n    return 2\n")
    for newline in ("\r\n", "\r"):
        other = facts_of("x = 1\n\ndef f():\n    return 2\n".replace("\n", newline), "python")
        assert other.statements == unix.statements
        assert other.functions == unix.functions
        assert other.sloc == unix.sloc == 3
