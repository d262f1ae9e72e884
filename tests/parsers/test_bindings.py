"""Bindings and parameters: what the parsers say names are given (facts.Binding) and what
functions take (Function.parameters), for C, C++ and both Python readers."""

from __future__ import annotations

import textwrap

from hypothesis import given
from hypothesis import strategies as st

from archmetrics.facts import Binding
from archmetrics.parsers import python
from archmetrics.parsers.python_bindings import assignment_bindings
from tests.harness import facts_of


def _bound(source: str, language: str) -> list[tuple[str, str, int, str | None]]:
    return [tuple(b) for b in facts_of(source, language).bindings]  # type: ignore[misc]


def test_c_macros_initializers_and_assignments_bind_their_names() -> None:
    source = """
    #define PORT "3490"
    #define GUARD
    #define MAX(a, b) ((a) > (b) ? (a) : (b))
    static const char *HOST = "x", *P2 = PORT;
    int table[] = {1, 2};
    int main(int argc, char **argv)
    {
        int fd = (int) open(p, 1);
        if ((rv = getaddrinfo(NULL, PORT, &h, &s)) != 0) return 1;
        x += 2;
        s->port = 7;
        return 0;
    }
    """
    assert _bound(source, "c") == [
        ("PORT", '"3490"', 2, None),
        ("HOST", '"x"', 5, None),
        ("P2", "PORT", 5, None),
        ("fd", "( int ) open ( p , 1 )", 9, "main"),
        ("rv", "getaddrinfo ( NULL , PORT , & h , & s )", 10, "main"),
    ]


def test_cpp_members_references_and_brace_initializers() -> None:
    source = """
    namespace n { const int kPort = 5; class C { static constexpr int P = 7; }; }
    void g() { auto &r = x; std::string s("a"); int y{3}; int z = 4; }
    void C::h() { this->topic_ = "cmd_vel"; other->x = 1; }
    """
    assert _bound(source, "cpp") == [
        ("kPort", "5", 2, None),
        ("P", "7", 2, None),
        ("r", "x", 3, "g"),
        ("z", "4", 3, "g"),
        ("this->topic_", '"cmd_vel"', 4, "C::h"),  # a member of this; other->x is not bound
    ]


def test_cpp_type_aliases_bind_their_names_to_the_types() -> None:
    source = """
    using Msg = std_msgs::msg::String;
    using std_msgs::msg::Int32;
    using namespace std;
    using namespace a::b;
    typedef a::B C;
    typedef void (*F)(int);
    void g() { using T = q::R<int>; }
    """
    assert _bound(source, "cpp") == [
        ("Msg", "std_msgs :: msg :: String", 2, None),
        ("Int32", "std_msgs :: msg :: Int32", 3, None),
        ("C", "a :: B", 6, None),  # a typedef of one plain name; F binds nothing
        ("T", "q :: R < int >", 8, "g"),
    ]
    assert _bound("typedef struct s s_t;\n", "c") == []  # C has no type aliases here


def test_c_parameters_are_named_through_their_declarators() -> None:
    source = """
    int listen_on(const char *port, int n, void (*cb)(int), char buf[], ...) { return 0; }
    int none(void) { return 1; }
    int unnamed(struct sockaddr_in *a, int) { return 1; }
    """
    functions = facts_of(source, "c").functions
    assert [f.parameters for f in functions] == [("port", "n", "cb", "buf"), (), ("a",)]
    cpp = facts_of("void C::m(const std::string &host, int port = 5) {}\n", "cpp")
    assert [f.parameters for f in cpp.functions] == [("host", "port")]


PYTHON = """
PORT = 5555
A = B = (1, 2)
f = lambda x=1: x
self.x = 3
a, b = 1, 2
class K:
    X: int = 3
    Y: int
def g(self, a, b=2, /, c=3, *args, d, **kw):
    fd = os.open(p, 1)
    n += 1
"""


def test_python_assignments_bind_plain_names_in_both_readers() -> None:
    expected = [
        Binding("PORT", "5555", 2),
        Binding("A", "( 1 , 2 )", 3),
        Binding("B", "( 1 , 2 )", 3),
        Binding("f", "lambda x = 1 : x", 4),
        Binding("self.x", "3", 5),  # a member of the object at hand
        Binding("X", "3", 8),
        Binding("fd", "os . open ( p , 1 )", 11, "g"),
    ]
    facts = facts_of(PYTHON, "python")
    assert list(facts.bindings) == expected
    through_libcst = python.parse_with_libcst("snippet.py", textwrap.dedent(PYTHON))
    assert list(through_libcst.bindings) == expected
    assert through_libcst.functions == facts.functions
    assert [f.parameters for f in facts.functions] == [("self", "a", "b", "c", "args", "d", "kw")]


@given(st.lists(st.sampled_from(["x", "y", "=", "(", ")", "lambda", ":", "1", ",", "[", "]"])))
def test_assignment_bindings_never_raise_and_bind_names(tokens: list[str]) -> None:
    for kind in ("assign", "annassign", "expr"):
        for name, value in assignment_bindings(kind, tokens):
            assert name.removeprefix("self.").isidentifier() and value
