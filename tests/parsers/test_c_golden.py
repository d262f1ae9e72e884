"""Golden cases for the C parser: one per row of the λ table in docs/metrics.md."""

from __future__ import annotations

import pytest

from archmetrics.facts import Argument, DependencyKind, FileFacts, Span
from tests.harness import complexities, facts_of, statement_kinds


def c(source: str) -> FileFacts:
    return facts_of(source, "c")


def kinds(source: str) -> list[str]:
    return statement_kinds(c(source))


def texts(source: str) -> list[str]:
    return [s.text for s in c(source).statements]


# --- λ: what is one statement -------------------------------------------------------------


def test_expression_statement_counts_once() -> None:
    assert kinds("void f(void) { x = 1; }") == ["function", "expression"]


def test_empty_statement_does_not_count() -> None:
    assert kinds("void f(void) { ; }") == ["function"]


def test_declaration_with_two_declarators_is_one_statement() -> None:
    assert kinds("int a, b;") == ["declaration"]


def test_statement_spread_over_lines_counts_once() -> None:
    facts = c("int total =\n    1 +\n    2;\n")
    assert [(s.kind, s.span) for s in facts.statements] == [("declaration", Span(1, 3))]


def test_two_statements_on_one_line_count_twice() -> None:
    facts = c("void f(void) {\n    a = 1; b = 2;\n}\n")
    assert [(s.text, s.span.start) for s in facts.statements[1:]] == [
        ("a = 1 ;", 2),
        ("b = 2 ;", 2),
    ]


def test_function_prototype_is_a_declaration() -> None:
    assert kinds("int f(int a);") == ["declaration"]


def test_function_signature_counts_once_even_over_several_lines() -> None:
    facts = c("static int\nadd(int a,\n    int b)\n{\n    return a + b;\n}\n")
    signature = facts.statements[0]
    assert (signature.kind, signature.span, signature.text) == (
        "function",
        Span(1, 3),
        "static int add ( int a , int b )",
    )
    assert facts.loc == 2


def test_return_break_continue_goto_count() -> None:
    source = """
    int f(int n) {
        while (n) { if (n > 5) break; if (n > 3) continue; n--; }
        goto out;
    out:
        return n;
    }
    """
    assert kinds(source) == [
        "function",
        "while",
        "if",
        "break",
        "if",
        "continue",
        "expression",
        "goto",
        "return",
    ]


def test_goto_label_itself_does_not_count() -> None:
    assert kinds("void f(void) {\nout:\n    x = 1;\n}\n") == ["function", "expression"]


def test_typedef_counts_with_its_fields() -> None:
    facts = c("typedef struct {\n    int x;\n    int y;\n} point;\n")
    assert [(s.kind, s.text) for s in facts.statements] == [
        ("typedef", "typedef struct { } point ;"),
        ("field", "int x ;"),
        ("field", "int y ;"),
    ]


def test_standalone_struct_definition_header_counts_once() -> None:
    facts = c("struct point {\n    int x;\n    int y;\n};\n")
    assert [(s.kind, s.text, s.span) for s in facts.statements] == [
        ("struct", "struct point", Span(1, 1)),
        ("field", "int x ;", Span(2, 2)),
        ("field", "int y ;", Span(3, 3)),
    ]


def test_struct_inside_a_declaration_counts_with_the_declaration_only() -> None:
    assert kinds("struct p { int x; } origin;") == ["declaration", "field"]


def test_forward_declaration_counts() -> None:
    assert kinds("struct p;\nunion u;") == ["struct", "union"]


def test_union_definition() -> None:
    assert kinds("union u { int i; float f; };") == ["union", "field", "field"]


def test_enum_counts_once_enumerators_do_not() -> None:
    facts = c("enum color {\n    RED,\n    GREEN = 2,\n};\n")
    assert [(s.kind, s.text, s.span) for s in facts.statements] == [
        ("enum", "enum color { RED , GREEN = 2 , }", Span(1, 4))
    ]


def test_if_header_counts_else_does_not_and_else_if_counts_as_its_if() -> None:
    source = """
    void f(int a) {
        if (a > 0) {
            a = 1;
        } else if (a < 0) {
            a = 2;
        } else {
            a = 3;
        }
    }
    """
    facts = c(source)
    assert [(s.kind, s.text) for s in facts.statements] == [
        ("function", "void f ( int a )"),
        ("if", "if ( a > 0 )"),
        ("expression", "a = 1 ;"),
        ("if", "if ( a < 0 )"),
        ("expression", "a = 2 ;"),
        ("expression", "a = 3 ;"),
    ]


def test_braceless_if_counts_header_and_body() -> None:
    assert kinds("void f(int a) { if (a) return; }") == ["function", "if", "return"]


def test_for_counts_once_not_its_inner_semicolons() -> None:
    facts = c("void f(void) { for (int i = 0; i < 3; i++) g(i); }")
    assert [(s.kind, s.text) for s in facts.statements[1:]] == [
        ("for", "for ( int i = 0 ; i < 3 ; i ++ )"),
        ("expression", "g ( i ) ;"),
    ]


def test_while_counts_once() -> None:
    assert kinds("void f(int n) { while (n) n--; }") == ["function", "while", "expression"]


def test_do_while_counts_once_on_its_while_line() -> None:
    facts = c("void f(int n) {\n    do {\n        n--;\n    } while (n > 0);\n}\n")
    do_while = facts.statements[1]
    assert (do_while.kind, do_while.text, do_while.span) == (
        "do_while",
        "do while ( n > 0 ) ;",
        Span(4, 4),
    )
    assert facts.loc == 3


def test_switch_case_and_default_labels_each_count() -> None:
    source = """
    void f(int n) {
        switch (n) {
        case 1:
        case 2:
            g();
            break;
        default:
            h();
        }
    }
    """
    facts = c(source)
    assert [(s.kind, s.text) for s in facts.statements[1:]] == [
        ("switch", "switch ( n )"),
        ("case", "case 1 :"),
        ("case", "case 2 :"),
        ("expression", "g ( ) ;"),
        ("break", "break ;"),
        ("default", "default :"),
        ("expression", "h ( ) ;"),
    ]


def test_bare_block_braces_do_not_count() -> None:
    assert kinds("void f(void) { { x = 1; } }") == ["function", "expression"]


def test_kr_parameter_declarations_are_part_of_the_signature() -> None:
    facts = c("int old(a)\n    int a;\n{\n    return a;\n}\n")
    assert [(s.kind, s.span) for s in facts.statements] == [
        ("function", Span(1, 2)),
        ("return", Span(4, 4)),
    ]


# --- λ: the preprocessor ------------------------------------------------------------------


def test_include_and_define_count() -> None:
    facts = c('#include <stdio.h>\n#include "x.h"\n#define N 10\n#define MAX(a, b) ((a) > (b))\n')
    assert [(s.kind, s.text) for s in facts.statements] == [
        ("include", "#include <stdio.h>"),
        ("include", '#include "x.h"'),
        ("define", "#define N 10"),
        ("define", "#define MAX ( a , b ) ( ( a ) > ( b ) )"),
    ]


def test_include_guard_does_not_count() -> None:
    source = "/* x.h */\n#ifndef X_H\n#define X_H\n\n#include <stddef.h>\nint x;\n\n#endif\n"
    assert kinds(source) == ["include", "declaration"]


def test_if_not_defined_include_guard_does_not_count() -> None:
    source = "#if !defined(X_H)\n#define X_H 1\nint x;\n#endif\n"
    assert kinds(source) == ["declaration"]


def test_pragma_once_does_not_count_other_pragmas_and_undef_do() -> None:
    facts = c("#pragma once\n#pragma pack(1)\n#undef N\n")
    assert [(s.kind, s.text) for s in facts.statements] == [
        ("directive", "#pragma pack ( 1 )"),
        ("directive", "#undef N"),
    ]


def test_guard_like_define_that_is_not_a_guard_counts() -> None:
    source = "#ifndef _GNU_SOURCE\n#define _GNU_SOURCE\n#endif\n#include <stdio.h>\n"
    assert kinds(source) == ["define", "include"]


def test_preprocessor_conditionals_do_not_count_but_both_branches_do() -> None:
    source = """
    #ifdef WIN32
    int a;
    #elif defined(UNIX)
    int b;
    #else
    int c;
    #endif
    #if 0
    int d;
    #endif
    """
    assert kinds(source) == ["declaration"] * 4


def test_directive_spacing_is_normalized() -> None:
    assert texts("#  define N 1\n") == ["#define N 1"]


# --- Statement.text and Statement.function --------------------------------------------------


def test_text_survives_reformatting_and_comments() -> None:
    first = texts("int f(int a){int x=a+1;/* why */return x;}")
    second = texts("int f( int a )\n{\n    int x = a + 1;  // why\n    return x;\n}\n")
    assert first == second == ["int f ( int a )", "int x = a + 1 ;", "return x ;"]


def test_text_keeps_literals_as_written() -> None:
    assert texts('void f(void) { puts("a  b // c"); }')[1] == 'puts ( "a  b // c" ) ;'


def test_statement_function_names_the_enclosing_function() -> None:
    facts = c("int g = 1;\nint f(void) {\n    return g;\n}\n")
    assert [s.function for s in facts.statements] == [None, "f", "f"]


# --- McCabe decision points -------------------------------------------------------------------


@pytest.mark.parametrize(
    ("body", "kinds_found"),
    [
        ("if (a) x();", ["if"]),
        ("if (a) x(); else if (b) y(); else z();", ["if", "if"]),
        ("for (;;) x();", ["for"]),
        ("while (a) x();", ["while"]),
        ("do x(); while (a);", ["while"]),
        ("switch (a) { case 1: case 2: x(); default: y(); }", ["case", "case"]),
        ("x = a ? 1 : 2;", ["?"]),
        ("x = a && b;", ["&&"]),
        ("x = a || b;", ["||"]),
        ("if (a && (b || c)) x();", ["if", "&&", "||"]),
        ("x = a & b | c;", []),
    ],
)
def test_decision_points(body: str, kinds_found: list[str]) -> None:
    facts = c(f"void f(int a, int b, int c) {{\n    {body}\n}}\n")
    (function,) = facts.functions
    assert sorted(d.kind for d in function.decisions) == sorted(kinds_found)
    assert function.complexity == 1 + len(kinds_found)


def test_decision_lines_point_at_the_token() -> None:
    facts = c("int f(int a) {\n    if (a)\n        return 1;\n    return a ? 2 : 3;\n}\n")
    assert [(d.kind, d.line) for d in facts.functions[0].decisions] == [("if", 2), ("?", 4)]


def test_preprocessor_conditionals_in_a_body_are_decisions_as_in_lizard() -> None:
    source = """
    void f(void) {
    #ifdef A
        a();
    #elif defined(B) && defined(C)
        b();
    #endif
    #if X || Y
        c();
    #else
        d();
    #endif
    }
    """
    (function,) = c(source).functions
    # `&&`/`||` inside a directive's condition are not decisions: lizard reads the line as one token
    assert sorted(d.kind for d in function.decisions) == ["#elif", "#if", "#ifdef"]


def test_ifndef_in_a_body_counts_unlike_lizard() -> None:
    """Disagreement class 1: lizard counts #ifdef but not #ifndef; we count both."""
    source = "void f(void) {\n#ifndef A\n    a();\n#endif\n}\n"
    assert [d.kind for d in c(source).functions[0].decisions] == ["#ifndef"]


def test_and_before_an_assignment_counts_unlike_lizard() -> None:
    """Disagreement class 5: lizard takes a `&&` followed by a lone `=` (before any of
    `;{})`) for an rvalue reference `T&& x = ...` and does not count it; it is a logical
    and."""
    import lizard

    source = "void f(T *t) {\n  while (t && (x = next(t)) != 0)\n    g(x);\n}\n"
    assert [d.kind for d in c(source).functions[0].decisions] == ["while", "&&"]
    (theirs,) = lizard.analyze_file.analyze_source_code("f.c", source).function_list
    assert theirs.cyclomatic_complexity == 2  # the `&&` not counted


def test_a_conditional_between_angle_brackets_counts_unlike_lizard() -> None:
    """Disagreement class 6: lizard reads `i < 0 ? j >= k : ...` as template arguments
    `< 0 ? j >` and skips the `?` inside them (numpy's f2c loops); it is a decision."""
    import lizard

    source = "int f(int n, int a, int b) {\n  return n < 0 ? a >= b : a <= b;\n}\n"
    assert [d.kind for d in c(source).functions[0].decisions] == ["?"]
    (theirs,) = lizard.analyze_file.analyze_source_code("f.c", source).function_list
    assert theirs.cyclomatic_complexity == 1  # the `?` not counted


def test_preprocessor_conditionals_outside_functions_are_no_decisions() -> None:
    facts = c("#if A && B\nint f(void) { return 0; }\n#endif\n")
    assert complexities(facts) == {"f": 1}


def test_file_complexity_is_the_sum_over_functions() -> None:
    facts = c("int f(int a) { return a ? 1 : 0; }\nint g(int a) { if (a) return 1; return 0; }\n")
    assert complexities(facts) == {"f": 2, "g": 2}
    assert facts.vg == 4


# --- functions --------------------------------------------------------------------------------


def test_function_span_name_and_statement_count() -> None:
    facts = c("static int\ncount(int n)\n{\n    int total = 0;\n    return total;\n}\n")
    (function,) = facts.functions
    assert (function.name, function.qualified_name, function.span) == ("count", "count", Span(1, 6))
    assert function.statements == 3  # signature, declaration, return


def test_function_returning_a_pointer_is_named_by_its_declarator() -> None:
    assert list(complexities(c("char *\nname(void) { return 0; }\n"))) == ["name"]


def test_macro_made_function_is_named_by_the_macro() -> None:
    facts = c("int before;\nMEM_STATIC ZSTD_t ZSTD_cpuid(void) {\n    return 0;\n}\n")
    assert [f.name for f in facts.functions] == ["ZSTD_cpuid"]


# --- classes ------------------------------------------------------------------------------------


def test_structs_and_unions_with_a_body_are_classes() -> None:
    facts = c(
        "struct a { int x; };\nunion b { int i; };\nstruct fwd;\n"
        "typedef struct { int y; } named;\nstruct c { union { int p; } u; };\n"
    )
    assert [(k.name, k.kind) for k in facts.classes] == [
        ("a", "struct"),
        ("b", "union"),
        ("named", "struct"),
        ("c", "struct"),
    ]


# --- dependencies ---------------------------------------------------------------------------


def test_includes_are_dependencies() -> None:
    facts = c('#include <stdio.h>\n#include "foo/bar.h"\n#include CONFIG_H\n')
    assert [(d.target, d.kind, d.span) for d in facts.dependencies] == [
        ("stdio.h", DependencyKind.INCLUDE_SYSTEM, Span(1, 1)),
        ("foo/bar.h", DependencyKind.INCLUDE, Span(2, 2)),
    ]
    assert facts.loc == 3  # the computed include still counts as a statement


# --- call sites -----------------------------------------------------------------------------


def test_call_sites_name_callee_receiver_and_function() -> None:
    source = """
    static int ready = init();
    void f(struct sock *p, struct sock s) {
        zmq_connect(p, "tcp://localhost:5555");
        s.send(1);
        p->connect(2);
    }
    """
    facts = c(source)
    assert [(k.callee, k.name, k.receiver, k.function) for k in facts.call_sites] == [
        ("init", "init", None, None),
        ("zmq_connect", "zmq_connect", None, "f"),
        ("s.send", "send", "s", "f"),
        ("p->connect", "connect", "p", "f"),
    ]


def test_call_site_literal_arguments() -> None:
    source = r"""
    void f(void) {
        g("a\tb\x41\101", "con" "cat", 0x1F, 017, 0b11, 10UL, 1.5, 2e3f,
          'c', '\n', -3, x, "x" NAME);
    }
    """
    (call,) = c(source).call_sites
    assert [(a.value, a.is_literal) for a in call.arguments] == [
        ("a\tbAA", True),
        ("concat", True),
        (31, True),
        (15, True),
        (3, True),
        (10, True),
        (1.5, True),
        (2000.0, True),
        ("c", True),
        ("\n", True),
        (-3, True),
        (None, False),
        (None, False),
    ]
    assert call.arguments[11] == Argument("x")
    assert call.arguments[1].text == '"con" "cat"'


def test_sizeof_is_not_a_call() -> None:
    assert [k.callee for k in c("int f(void) { return g(sizeof(int)); }").call_sites] == ["g"]


def test_call_through_function_pointer() -> None:
    (call,) = c("void f(void (*fp)(int)) { (*fp)(1); }").call_sites
    assert (call.callee, call.receiver) == ("(*fp)", None)


# --- SLOC -------------------------------------------------------------------------------------


def test_sloc_counts_lines_with_code_only() -> None:
    source = (
        "/* header\n"
        "   comment */\n"
        "\n"
        "#include <stdio.h>\n"
        "// line comment\n"
        "int x; /* trailing */\n"
        "/* start */ int y;\n"
        "int z = /* a\n"
        "   b */ 1;\n"
        'const char *s = "multi \\\n'
        'line";\n'
    )
    assert c(source).sloc == 7


# --- robustness -----------------------------------------------------------------------------


def test_a_macro_error_that_loses_nothing_is_not_warned_about() -> None:
    source = """
    int before(void) { return 1; }
    static int table[] = { ENTRY(a) ENTRY(b) };
    int after(int x) { if (x) return 2; return 3; }
    """
    facts = c(source)
    assert facts.warnings == ()  # tree-sitter's ERROR there cost no statement, call or decision
    assert [site.name for site in facts.call_sites] == ["ENTRY", "ENTRY"]
    assert complexities(facts) == {"before": 1, "after": 2}
    assert facts.parsed


def test_a_region_that_loses_facts_is_warned_about_once_with_its_lines_and_losses() -> None:
    source = """
    template <typename T> class A {
      int f(int a) { if (a) return 1; return 2; }
      DECLARE_THING(x) = [](int y) { if (y) return k(y); return 0; }

      int g(int a) { MACRO(int, x) while (a) a--; return h(a, MACRO(long, y)); }
    };
    """
    facts = facts_of(source, "cpp")
    # line 4: the lambda at class scope holds no function's decision, and its call `k(y)`
    # was read: nothing lost there. Line 6: the first macro call, a type among its
    # arguments, is not read (the second is)
    assert [(site.callee, site.span.start) for site in facts.call_sites] == [
        ("k", 4),
        ("h", 6),
        ("MACRO", 6),
    ]
    [warning] = facts.warnings
    assert warning.line == 6
    assert warning.message == (
        "line 6: about 1 call site not counted (a macro it cannot know? 'int g(int a) {"
        " MACRO(int, x) while (a) a')"
    )
    assert complexities(facts) == {"A::f": 2, "A::g": 2}  # the rest is measured


@pytest.mark.parametrize(
    "source",
    ["}}}{{{", "/* unterminated", '"unterminated', "int f( {", "#if\n#else\n", "\x01\x02", ""],
)
def test_bad_input_never_raises(source: str) -> None:
    facts = c(source)
    assert facts.sloc >= 0 and facts.loc >= 0 and facts.vg >= 0


def test_sloc_counts_each_line_of_a_continued_macro() -> None:
    source = "#define TWICE(x) \\\n    ((x) + \\\n     (x))\n\\\n\nint y;\n"
    facts = c(source)
    assert (facts.sloc, facts.loc) == (4, 2)  # the lone `\` line holds no token


# --- determinism ----------------------------------------------------------------------------


def test_nodes_starting_together_are_ordered_outer_first_whatever_the_capture_order() -> None:
    # tree-sitter's query cursor returns captures that start at the same byte in an order
    # that depends on what the process parsed before (seen on numpy's _rational_tests.c);
    # in_order must give one answer for every order it is handed.
    from tree_sitter import QueryCursor

    from archmetrics.facts import Language
    from archmetrics.parsers.c_family import grammar
    from archmetrics.parsers.c_family_names import in_order

    source = b"void f(void) { g(a)(b)(c); }\n"
    built = grammar(Language.C)
    calls = QueryCursor(built.query).captures(built.parser.parse(source).root_node)["call"]
    texts = {source[n.start_byte : n.end_byte].decode() for n in calls}
    assert texts == {"g(a)(b)(c)", "g(a)(b)", "g(a)"}
    for order in (calls, calls[::-1], sorted(calls, key=lambda n: n.end_byte)):
        ordered = in_order(order)
        assert [source[n.start_byte : n.end_byte].decode() for n in ordered] == [
            "g(a)(b)(c)",
            "g(a)(b)",
            "g(a)",
        ]


def test_a_region_is_reported_once_in_any_capture_order() -> None:
    # `@(void)` is an ERROR holding an ERROR that starts at the same byte: one region,
    # whichever order the query cursor hands them over in.
    from tree_sitter import QueryCursor

    from archmetrics.facts import Language
    from archmetrics.parsers.c_family import grammar
    from archmetrics.parsers.c_family_facts import suspect_regions

    source = b"@(void) if (a) f(b);\n"
    built = grammar(Language.C)
    found = QueryCursor(built.query).captures(built.parser.parse(source).root_node)
    errors = found["error"]
    assert len(errors) > 1
    for order in (errors, errors[::-1]):
        regions = suspect_regions({"error": list(order)}, source, [], [], [], [])
        assert regions == [(0, len(source) - 1, "damage")]
