"""Golden cases for C and C++ shaped by the preprocessor (docs/metrics.md, "Macros").

Each class of issue 13 is here in C and in C++ where both apply: the functions, their v_g
and their lines are what lizard reports for the same text, and no warning claims a loss
where nothing was lost.
"""

from __future__ import annotations

import pytest

from archmetrics.facts import FileFacts, Span
from archmetrics.parsers.c_family_macros import MacroNames, blank_macros
from tests.harness import complexities, facts_of


def spans(facts: FileFacts) -> dict[str, tuple[int, int]]:
    return {f.qualified_name: (f.span.start, f.span.end) for f in facts.functions}


def lost(facts: FileFacts) -> list[str]:
    return [w.message for w in facts.warnings]


# --- 1. a macro between class/struct/union and the name -------------------------------------


def test_export_macro_before_a_class_name_keeps_its_inline_methods() -> None:
    facts = facts_of(
        """
        class FOO_EXPORT Proxy : public Base {
          int Get() const { if (x) return x; return 0; }
        };
        struct PACKED Hdr { int f() { return 1; } };
        class LOCKABLE Mutex { void g() { while (a) b(); } };
        """,
        "cpp",
    )
    assert complexities(facts) == {"Proxy::Get": 2, "Hdr::f": 1, "Mutex::g": 2}
    assert [c.name for c in facts.classes] == ["Proxy", "Hdr", "Mutex"]
    assert facts.statements[0].text == "class FOO_EXPORT Proxy : public Base"  # as written
    assert not lost(facts)


def test_a_macro_with_arguments_and_a_macro_after_the_name() -> None:
    facts = facts_of(
        """
        class CAPABILITY("mutex") Mutex { void Lock() { if (a) b(); } };
        class Message PROTOBUF_FINAL : public Base { int size() const { return n ? 1 : 0; } };
        """,
        "cpp",
    )
    assert complexities(facts) == {"Mutex::Lock": 2, "Message::size": 2}


def test_an_export_macro_on_a_c_struct_keeps_the_functions_after_it() -> None:
    facts = facts_of(
        """
        struct PACKED hdr { int a; int b; };
        int f(int a) { if (a) return 1; return 2; }
        """,
        "c",
    )
    assert complexities(facts) == {"f": 2}
    assert [c.name for c in facts.classes] == ["hdr"]


def test_a_class_named_in_capitals_is_not_a_macro() -> None:
    facts = facts_of("class RGB { int r() { return 1; } };\nstruct XYZ : Base { };\n", "cpp")
    assert [c.name for c in facts.classes] == ["RGB", "XYZ"]
    assert complexities(facts) == {"RGB::r": 1}


# --- 3. a macro after a declarator ----------------------------------------------------------


def test_an_annotation_after_a_declarator_is_one_statement_and_not_the_name() -> None:
    facts = facts_of(
        """
        class M {
          void Lock() EXCLUSIVE_LOCKS_REQUIRED(mu_);
          void Unlock() RELEASE(mu_) { if (a) b(); }
          int Get() const OVERRIDE { return 1; }
        };
        """,
        "cpp",
    )
    assert spans(facts) == {"M::Unlock": (4, 4), "M::Get": (5, 5)}
    assert complexities(facts) == {"M::Unlock": 2, "M::Get": 1}
    assert [(s.kind, s.text) for s in facts.statements[1:3]] == [
        ("field", "void Lock ( ) EXCLUSIVE_LOCKS_REQUIRED ( mu_ ) ;"),  # one statement
        ("function", "void Unlock ( )"),
    ]


@pytest.mark.parametrize("language", ["c", "cpp"])
def test_a_c_annotation_after_a_prototype_keeps_the_next_function(language: str) -> None:
    facts = facts_of(
        """
        void fatal(const char *m) NORETURN_ATTR;
        int printf_like(const char *f, ...) PRINTF_FORMAT(1, 2);
        int g(int a) { if (a) return 1; return 2; }
        """,
        language,
    )
    assert complexities(facts) == {"g": 2}
    assert sum(1 for s in facts.statements if s.kind == "declaration") == 2


# --- 4. a macro that supplies syntax --------------------------------------------------------


@pytest.mark.parametrize("language", ["c", "cpp"])
def test_a_macro_that_supplies_the_parentheses_of_an_if(language: str) -> None:
    facts = facts_of(
        """
        #define EQ(s) (strcmp(x, s) == 0)
        int f(void) { if EQ("a") { return 1; } return 0; }
        int g(int a) { if (a) return 1; return 2; }
        """,
        language,
    )
    assert complexities(facts) == {"f": 2, "g": 2}


@pytest.mark.parametrize("language", ["c", "cpp"])
def test_a_namespace_or_diagnostic_macro_alone_on_its_line(language: str) -> None:
    facts = facts_of(
        """
        RAPIDJSON_NAMESPACE_BEGIN
        RAPIDJSON_DIAG_OFF(effc++)
        int f(int a) { if (a) return 1; return 2; }
        RAPIDJSON_DIAG_POP
        RAPIDJSON_NAMESPACE_END
        int g(int a) { while (a) a--; return 2; }
        """,
        language,
    )
    assert complexities(facts) == {"f": 2, "g": 2}


def test_an_enumerator_and_an_operand_in_capitals_are_not_blanked() -> None:
    source = b"enum c {\n  RED,\n  GREEN\n};\nint x = a +\n  MAXV\n;\n"
    assert blank_macros(source) == source


def test_blanking_keeps_every_offset_and_line() -> None:
    source = b"class FOO_API Proxy : Base {};\nvoid f() LOCKS(mu);\n"
    blanked = blank_macros(source, names=MacroNames(), first=False)
    assert len(blanked) == len(source)
    assert blanked.count(b"\n") == source.count(b"\n")
    assert b"FOO_API" not in blanked and b"LOCKS" not in blanked


def test_a_macro_inside_a_string_or_comment_is_left_alone() -> None:
    source = b'const char *s = "class FOO_API Proxy {";\n/* class BAR_API X { */\n'
    assert blank_macros(source, first=True) == source


def test_a_listed_attribute_macro_need_not_be_in_capitals() -> None:
    facts = facts_of("class my_export Proxy : Base { int f() { return 1; } };\n", "cpp")
    assert "Proxy::f" not in complexities(facts)  # not recognised without the list
    source = b"class my_export Proxy : Base { int f() { return 1; } };\n"
    blanked = blank_macros(source, names=MacroNames(attribute=("my_export",)), first=True)
    assert blanked.startswith(b"class           Proxy")


def test_no_lines_are_lost_to_the_blanking() -> None:
    facts = facts_of("class FOO_EXPORT A {\n  int f() {\n    return 1;\n  }\n};\n", "cpp")
    assert facts.functions[0].span == Span(2, 4)
