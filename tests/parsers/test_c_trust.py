"""Golden cases: C/C++ shapes that tree-sitter cannot read, or reads as something else.

Each is a minimal reproduction of a construct seen in real code (docs/metrics.md,
"Warnings"). The facts must never hold a function the source does not define, must still
count the functions and decisions there (read from tokens, marked ``estimated``), and a
region whose facts were lost or estimated gets one warning that says what, in a reader's
words; a region that lost nothing gets none. Expected v_g values are counted by hand from
the snippets (as lizard counts: 1 + if, for, while, case, catch, ?, &&, ||, #if...).
"""

from __future__ import annotations

import pytest

from archmetrics.facts import FileFacts, Language
from archmetrics.parsers import c_family
from tests.harness import facts_of


def c(source: str) -> FileFacts:
    return facts_of(source, "c")


def cpp(source: str) -> FileFacts:
    return facts_of(source, "cpp")


def functions(facts: FileFacts) -> dict[str, tuple[int, int, int, bool]]:
    """qualified name -> (first line, last line, v_g, estimated)."""
    return {
        f.qualified_name: (f.span.start, f.span.end, f.complexity, f.estimated)
        for f in facts.functions
    }


def messages(facts: FileFacts) -> list[str]:
    return [w.message for w in facts.warnings]


# 1. A #define inside a brace initializer, a list macro, then #undef: tree-sitter read a
# function `OP` from the #define to the end of the file, with every function after it.
DEFINE_IN_INITIALIZER = """\
static const node_t stats_node[] = {
    {NAME("active"), CTL(stats_active)}};

#define OP(mtx) DATA_NODE(mutexes_##mtx)
ALL_MUTEXES
#undef OP

static const node_t mutexes_node[] = {
#define OP(mtx) {NAME(#mtx), CHILD(named, mutexes_##mtx)},
    ALL_MUTEXES
#undef OP
    {NAME("reset"), CTL(mutexes_reset)}};

static int
first_ctl(int a) {
    if (a > 1) {
        return 1;
    }
    return 0;
}

static int
second_ctl(int b) {
    while (b) b--;
    return b && a;
}
"""


def test_a_define_inside_an_initializer_makes_up_no_function() -> None:
    facts = c(DEFINE_IN_INITIALIZER)
    assert functions(facts) == {
        "first_ctl": (14, 20, 2, True),
        "second_ctl": (22, 26, 3, True),
    }
    assert messages(facts) == [
        "lines 10-26: 2 functions read from tokens only, v_g estimated; 'OP' read as a"
        " function by mistake, not reported (a #define inside an initializer)"
    ]


def test_the_tree_alone_made_up_that_function() -> None:
    # what the second reading corrects (c_family.parse(second_reading=False) is the tree's)
    from archmetrics.facts import Language
    from archmetrics.parsers import c_family

    tree = c_family.parse("x.c", DEFINE_IN_INITIALIZER, Language.C, second_reading=False)
    assert [f.name for f in tree.functions] == ["OP"]


# 2. A namespace-opening macro, a long comment, then `namespace detail {`: a function
# named `namespace`. An access-label macro before a commented method; a template macro
# before a class.
def test_a_namespace_macro_before_a_namespace_makes_no_function_named_namespace() -> None:
    facts = cpp(
        """\
        NLOHMANN_JSON_NAMESPACE_BEGIN
        /*!
        @brief detail namespace with internal helper functions

        This namespace collects functions that should not be exposed.
        */
        namespace detail
        {
        inline int f(int a)
        {
            if (a > 1) { return 2; }
            return a;
        }
        }  // namespace detail
        NLOHMANN_JSON_NAMESPACE_END
        """
    )
    assert functions(facts) == {"detail::f": (9, 13, 2, True)}
    assert messages(facts) == [
        "lines 1-14: 1 function read from tokens only, v_g estimated; 'namespace' read as a"
        " function by mistake, not reported (a macro read as a function's head)"
    ]


def test_an_access_label_macro_before_a_commented_method() -> None:
    facts = cpp(
        """\
        class iter_impl {
          public:
            int g(int a) { return a ? 1 : 2; }
          JSON_PRIVATE_UNLESS_TESTED:
            // a commented method
            int h(int b) {
                if (b) return 1;
                return 0;
            }
            int k(int c) { return c && b; }
        };
        """
    )
    assert functions(facts) == {
        "iter_impl::g": (3, 3, 2, False),
        "iter_impl::h": (6, 9, 2, False),
        "iter_impl::k": (10, 10, 2, False),
    }
    assert facts.warnings == ()


def test_a_template_macro_before_a_class() -> None:
    facts = cpp(
        """\
        NLOHMANN_BASIC_JSON_TPL_DECLARATION
        class basic_json
        {
          public:
            int size() const { if (x) return 1; return 0; }
            int empty() const { return x == 0 || y; }
        };
        """
    )
    assert functions(facts) == {
        "basic_json::size": (5, 5, 2, False),
        "basic_json::empty": (6, 6, 2, False),
    }


# 3. ASSERT_THROW with a declaration as its argument next to ASSERT_NO_THROW({ ... }).
def test_assert_throw_with_a_declaration_merges_no_tests() -> None:
    facts = cpp(
        """\
        TEST_F(NodeTest, Throws) {
          auto o = rclcpp::NodeOptions();
          ASSERT_THROW(const auto n = std::make_shared<Node>("x", o), std::invalid_argument);
          ASSERT_NO_THROW({
            auto m = std::make_shared<Node>("y", o);
            (void)m;
          });
        }

        TEST_F(NodeTest, Second) {
          if (a) {
            b();
          }
        }

        TEST_F(NodeTest, Third) {
          for (int i = 0; i < 3; ++i) {
            c(i);
          }
        }
        """
    )
    assert [(f.name, f.span.start, f.span.end, f.complexity) for f in facts.functions] == [
        ("TEST_F", 1, 8, 1),
        ("TEST_F", 10, 14, 2),
        ("TEST_F", 16, 20, 2),
    ]
    [warning] = facts.warnings  # the declaration inside the macro call: one statement
    assert warning.message.startswith("line 3: about 1 statement not counted")


# 4. A file-scope macro call without `;` right before a macro-made function.
def test_a_macro_call_without_semicolon_before_a_test() -> None:
    facts = cpp("DECLARE_THING(x)\n\nTEST(A, b) { if (x) y(); }\n")
    assert functions(facts) == {"TEST": (3, 3, 2, True)}
    assert len(facts.warnings) == 1


# 5. String literals juxtaposed with macro calls.
def test_string_literals_next_to_macro_calls() -> None:
    facts = c(
        """\
        static void check(LexState *ls, int c) {
          if (ls->t.token != c)
            err(ls, Q("=") " or " Q("in") " expected");
        }

        static int next(int a) {
          return a ? 1 : 0;
        }
        """
    )
    assert functions(facts) == {"check": (1, 4, 2, True), "next": (6, 8, 2, True)}
    [warning] = facts.warnings
    assert warning.message.startswith("lines 1-8: 2 functions read from tokens only")


# 6. MSVC inline assembly in a body.
def test_inline_assembly_does_not_swallow_the_next_function() -> None:
    facts = c(
        """\
        int cpuid(void) {
          int r;
          _asm {
            mov eax, 1
            cpuid
            mov r, edx
          }
          if (r) return 1;
          return 0;
        }

        int other(int a) {
          if (a) return 2;
          return 3;
        }
        """
    )
    assert functions(facts) == {"cpuid": (1, 10, 2, True), "other": (12, 15, 2, True)}
    [warning] = facts.warnings
    assert warning.message.startswith("lines 1-15: 2 functions read from tokens only")
    assert warning.message.endswith("(inline assembly)")


# 7. TEST_BEGIN(f) { ... } TEST_END with lowercase statement macros.
def test_test_begin_and_end_with_statement_macros() -> None:
    facts = c(
        """\
        TEST_BEGIN(test_one) {
            log_do_begin(x)
                if (y) z();
            log_do_end(x)
            expect_true(a && b, "msg");
        }
        TEST_END

        TEST_BEGIN(test_two) {
            for (int i = 0; i < 2; i++) w(i);
        }
        TEST_END

        int main(void) {
            return test(test_one, test_two);
        }
        """
    )
    assert [(f.name, f.span.end, f.complexity) for f in facts.functions] == [
        ("TEST_BEGIN", 6, 3),
        ("TEST_BEGIN", 11, 2),
        ("main", 16, 1),
    ]
    assert len(facts.warnings) == 1


# 8. A block comment on a continued #define line ended the directive for tree-sitter.
def test_a_comment_in_a_continued_define_keeps_the_define_whole() -> None:
    facts = c(
        """\
        #define CHECK(x) \\
          if (!(x)) { /* report */ \\
            fail(); \\
          }

        static int f(int a) {
          if (a > 2) return 1;
          return 0;
        }
        """
    )
    assert [(s.kind, s.span.start, s.span.end) for s in facts.statements[:2]] == [
        ("define", 1, 4),
        ("function", 6, 6),
    ]
    assert functions(facts) == {"f": (6, 9, 2, False)}
    assert facts.warnings == () and facts.sloc == 8


# 9. A `throw` expression as a macro argument.
def test_a_throw_expression_as_a_macro_argument() -> None:
    facts = cpp(
        """\
        TEST(T, a) {
          EXPECT_THROW(throw 1, int);
        }

        TEST(T, b) {
          if (x) y();
        }
        """
    )
    assert [(f.span.start, f.span.end, f.complexity) for f in facts.functions] == [
        (1, 3, 1),
        (5, 7, 2),
    ]


# 10. CHECK_THROWS_AS with a comparison and a reference type as arguments.
def test_check_throws_as_with_a_comparison_and_a_reference_type() -> None:
    facts = cpp(
        """\
        TEST_CASE("a") {
          CHECK_THROWS_AS(a < b, "m", E&);
        }

        TEST_CASE("b") {
          if (x) y();
          while (z) w();
        }
        """
    )
    assert [(f.span.start, f.span.end, f.complexity, f.estimated) for f in facts.functions] == [
        (1, 3, 1, True),
        (5, 8, 3, True),
    ]
    assert len(facts.warnings) == 1


# 11. Statements as macro arguments: their `if`s are the function's decisions.
def test_statements_as_macro_arguments_count_their_decisions() -> None:
    facts = c(
        """\
        static void f(lua_State *L) {
          Protect( if (x) g(); );
          forEach(m, T, x, if (x->cb) { h(x); });
        }
        """
    )
    assert functions(facts) == {"f": (1, 4, 3, True)}
    [warning] = facts.warnings
    assert warning.message.startswith("lines 2-3: v_g of f estimated from tokens (+2)")


# 12. K&R definitions, one returning a pointer.
def test_a_kr_definition_with_a_pointer_return_type() -> None:
    facts = c(
        """\
        char *f(a)
        int a;
        {
          if (a) return 0;
          return "x";
        }

        int g(b)
        int b;
        {
          return b ? 1 : 0;
        }
        """
    )
    assert functions(facts) == {"f": (1, 6, 2, True), "g": (8, 12, 2, False)}
    [warning] = facts.warnings
    assert warning.message.startswith("lines 1-6: 1 function read from tokens only")


# 13. Statement macros without `;` before an `if`.
def test_statement_macros_without_semicolons_before_an_if() -> None:
    facts = c(
        """\
        static void f(int m) {
          EMIT(a)
          EMIT(b)
          if (m) {
            g();
          }
        }
        """
    )
    assert functions(facts) == {"f": (1, 7, 2, True)}
    assert len(facts.warnings) == 1


# 14. #if / #elif / #else branches that each reopen `} else {`.
def test_if_branches_that_each_reopen_an_else() -> None:
    facts = c(
        """\
        static int f(int a, int b) {
          int r = 0;
          if (a) {
            r = 1;
        #if defined(A)
          } else if (b) {
            r = 2;
        #elif defined(B)
          } else if (b > 1) {
            r = 3;
        #else
          } else {
            r = 4;
        #endif
          }
          if (r > 2) r = 0;
          return r;
        }

        static int g(int c) {
          while (c) c--;
          return c;
        }
        """
    )
    # if, #if, if, #elif, if, if: every branch as written, as lizard counts (v_g 7)
    assert functions(facts) == {"f": (1, 18, 7, False), "g": (20, 23, 2, False)}
    assert "directive" not in [s.kind for s in facts.statements]  # no stray #else
    assert facts.warnings == ()


# 15. An `if ... else` inside #ifdef, then `if (b) {` after #endif.
def test_an_else_in_an_ifdef_before_an_if() -> None:
    facts = c(
        """\
        static int f(int a, int b) {
          int r = 0;
        #ifdef X
          if (a)
            r = 1;
          else
        #endif
          if (b) {
            r = 2;
          }
          return r;
        }
        """
    )
    assert functions(facts) == {"f": (1, 12, 4, False)}  # #ifdef, if, if


# 16. `};  // comment` closing a class, then a TEST.
def test_a_class_closed_with_a_comment_then_a_test() -> None:
    facts = cpp(
        """\
        class Fixture : public ::testing::Test {
         public:
          int x;
        };  // comment
        TEST(A, b) {
          if (x) y();
        }
        """
    )
    assert functions(facts) == {"TEST": (5, 7, 2, False)}


# 17. A parenthesised name read as a cast loses the `&&` after it.
def test_a_parenthesised_name_called_keeps_the_and_after_it() -> None:
    facts = cpp("bool f(double a, double b) {\n  return (std::isnan)(a) && b > 0;\n}\n")
    assert functions(facts) == {"f": (1, 3, 2, False)}
    assert [d.kind for d in facts.functions[0].decisions] == ["&&"]


# 18. ACTION_TEMPLATE with template parameters that tree-sitter cannot read.
def test_action_template() -> None:
    facts = cpp(
        """\
        ACTION_TEMPLATE(ReturnGiant,
                        HAS_2_TEMPLATE_PARAMS(typename, T1,
                                              template <typename T> class, T2),
                        AND_1_VALUE_PARAMS(value)) {
          if (value) return T2<T1>(value);
          return 0;
        }

        TEST(ActionTemplateTest, Works) {
          EXPECT_TRUE(a || b);
        }
        """
    )
    assert [(f.name, f.span.start, f.span.end, f.complexity) for f in facts.functions] == [
        ("ACTION_TEMPLATE", 1, 7, 2),
        ("TEST", 9, 11, 2),
    ]
    assert messages(facts) == [
        "lines 1-7: 1 function read from tokens only, v_g estimated (a macro it cannot"
        " know? 'ACTION_TEMPLATE(ReturnGiant,')",
        "line 9: the head of TEST read as 'ACTION_TEMPLATE' (a macro it cannot know?"
        " 'TEST(ActionTemplateTest, Works) {')",
    ]


# --- what the checks themselves must not do ------------------------------------------------


def test_macro_calls_before_a_function_head_do_not_name_it() -> None:
    facts = c(
        "GENERATE_TEST(dict)\nGENERATE_TEST(types)\n\nint\nmain(void) {\n\treturn t(a, b);\n}\n"
    )
    assert functions(facts) == {"main": (4, 7, 1, False)}
    assert messages(facts) == [
        "lines 1-5: the head of main read as 'GENERATE_TEST' (macro calls without their ';'"
        " read as a function's head)"
    ]


def test_a_declaration_in_another_if_branch_does_not_name_the_function() -> None:
    # f2c.c's pow_zi: a K&R head in one #if branch, a declaration and the prototype head in
    # the other; the token reading, reading both branches' tokens, named the function after
    # the declared `twice`, and the tree's right name was replaced by it
    facts = c(
        """\
        #ifdef KR_headers
        void power(p, b)
         int *p; int b;
        #else
        extern void twice(int *);
        void power(int *p, int b)
        #endif
        {
        \tif (b > 0)
        \t\ttwice(p);
        }
        """
    )
    assert [(f.name, f.span.end, f.complexity) for f in facts.functions] == [("power", 11, 2)]
    assert not any("read as" in message for message in messages(facts))


def test_an_operator_named_with_other_spaces_is_not_renamed() -> None:
    # gmock's matchers: a damaged typedef in the body of `operator Matcher<Container>()`; the
    # token reading spells the name `operator Matcher< Container>`, the same name
    facts = cpp(
        """\
        class Holder {
         public:
          template <typename Container>
          // a comment
          operator Matcher<Container>() const {
            typedef REMOVE_CONST_(Container) Raw;
            return Matcher<Container>(value_);
          }
        };
        """
    )
    assert functions(facts) == {"Holder::operator Matcher<Container>": (5, 8, 1, False)}
    assert messages(facts) == []


RULE_MACROS = """\
#define RULE(x)
#define RULEX(x)
#define RULEF(name)\tstatic int CALLCONV rule_##name(State *s)
/* -- rules for numbers -- */

RULE(ADD NUM NUM)
RULE(SUB NUM NUM)
RULE(MUL NUM NUM)
RULEF(numarith)
{
  number a = left;
  number y = a > 0 ? arith(a, s->op) : 0;
  return knum(s, y);
}

RULE(NEG NUM LOAD)
RULEF(numneg)
{
  if (a) return 2;
  return 0;
}
"""


def test_a_function_named_after_an_empty_macro_takes_the_head_macros_name() -> None:
    # LuaJIT's lj_opt_fold.c: `#define LJFOLD(x)` (empty) tags the function that
    # `LJFOLDF(name)` declares; tree-sitter read the tags and the head as one head named
    # after the first tag, a macro whose body is no function head
    tree = c_family.parse("x.c", RULE_MACROS, Language.C, second_reading=False)
    assert [(f.name, f.span.start) for f in tree.functions] == [("RULE", 6)]
    facts = c(RULE_MACROS)
    assert [
        (f.name, f.span.start, f.span.end, f.complexity, f.estimated) for f in facts.functions
    ] == [
        ("RULEF", 9, 14, 2, False),
        ("RULEF", 17, 21, 2, True),
    ]
    assert messages(facts) == [
        "lines 6-10: the head of RULEF read as 'RULE' (macro calls without their ';' read as"
        " a function's head)",
        "lines 17-21: 1 function read from tokens only, v_g estimated (a block outside any"
        " function (a K&R definition or a macro?))",
    ]


def test_a_function_read_as_a_declaration_with_a_brace_initializer() -> None:
    # gevent's libev.h: `static void f(struct s* p, t* w) {};` in a header, which
    # tree-sitter-cpp reads as a declaration of f with a brace initializer, silently
    facts = cpp(
        """\
        static void start_child(struct ev_loop* loop, child_t* w) {};

        static int stop_child(int a) { return a ? 1 : 0; }
        """
    )
    assert functions(facts) == {"start_child": (1, 1, 1, True), "stop_child": (3, 3, 2, False)}
    assert messages(facts) == [
        "line 1: 1 function read from tokens only, v_g estimated (a function's body read as"
        " a brace initializer)"
    ]


def test_a_comparison_inside_template_arguments_of_a_return_type() -> None:
    # Catch2: `std::enable_if_t<sizeof(R) >= sizeof(T), T> fill(G& g) {` is an ERROR for
    # tree-sitter, and the token reading took `>=` for the closing `>` and an initializer's
    # `=`: the function was lost under no warning
    facts = cpp(
        """\
        template <typename T, typename G>
            std::enable_if_t<sizeof(typename G::result_type) >= sizeof(T),
            T> fill(G& gen) {
            return gen() > 0 ? 1 : 0;
        }
        """
    )
    assert functions(facts) == {"fill": (1, 5, 2, True)}
    [warning] = messages(facts)
    assert warning.startswith("lines 1-5: 1 function read from tokens only, v_g estimated")


def test_a_damaged_function_head_that_lost_nothing_is_not_warned_about() -> None:
    # zlib: `ZEXPORT` between the type and the name is an ERROR for tree-sitter; the
    # function, its statements and decisions are read all the same
    facts = c(
        "uLong ZEXPORT adler32(uLong adler, const Bytef *buf) {\n"
        "    if (buf == Z_NULL) return 1L;\n    return adler;\n}\n"
    )
    assert functions(facts) == {"adler32": (1, 4, 2, False)}
    assert facts.warnings == ()


def test_a_method_of_a_class_inside_a_function_is_no_suspect() -> None:
    facts = cpp(
        "int f(int a) {\n  struct L { int m(int b) { return b ? 1 : 0; } };\n"
        "  return L().m(a);\n}\n"
    )
    assert functions(facts) == {"f": (1, 4, 2, False)}
    assert facts.warnings == ()


@pytest.mark.parametrize("language", ["c", "cpp"])
def test_braces_that_never_close_are_warned_about(language: str) -> None:
    facts = facts_of(
        "int ok() { return 1; }\nMAGIC(x) y z {\nint later() { return 2; }\n", language
    )
    assert "ok" in [f.name for f in facts.functions]
    assert any("never close" in message for message in messages(facts))


@pytest.mark.parametrize("language", ["c", "cpp"])
def test_a_wrapper_macro_around_a_head_names_no_function(language: str) -> None:
    # libuv: `#define UV_UNUSED(declaration) __attribute__((unused)) declaration`; the
    # function is the one its argument declares (tree-sitter reads it cleanly, as a
    # function named UV_UNUSED with one parameter that declares a function)
    facts = facts_of(
        """\
        UV_UNUSED(static void update_time(uv_loop_t* loop)) {
          if (loop) loop->time = 1;
        }

        HEAP_EXPORT(void heap_init(struct heap* heap, int n)) {
          heap->min = n ? NULL : heap;
        }
        """,
        language,
    )
    assert [(f.name, f.complexity) for f in facts.functions] == [
        ("update_time", 2),
        ("heap_init", 2),
    ]
    if language == "cpp":  # read as a function definition: its parameters are known
        assert [f.parameters for f in facts.functions] == [("loop",), ("heap", "n")]


def test_a_qualified_name_in_capitals_in_a_file_read_from_tokens() -> None:
    # re2's pcre.cc: `PCRE::PCRE(...)` (a class named in capitals) crashed the token
    # reading, and the whole file went unmeasured
    facts = cpp(
        """\
        int broken(int a) { @ if (a) return 1; return 0; }

        PCRE::PCRE(const char* pattern) {
          if (pattern) Init(pattern);
        }
        """
    )
    assert facts.parsed
    assert [(f.qualified_name, f.complexity) for f in facts.functions] == [
        ("broken", 2),
        ("PCRE::PCRE", 2),
    ]
