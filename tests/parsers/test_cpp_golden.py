"""Golden cases for the C++ parser: the C++ rows of the λ table, naming, decisions, calls."""

from __future__ import annotations

import textwrap

import pytest

from archmetrics.facts import FileFacts, Language, Span
from archmetrics.parsers import c_family
from tests.harness import complexities, facts_of, statement_kinds


def cpp(source: str) -> FileFacts:
    return facts_of(source, "cpp")


def kinds(source: str) -> list[str]:
    return statement_kinds(cpp(source))


# --- λ: C++ rows ----------------------------------------------------------------------------


def test_class_header_members_and_access_specifiers() -> None:
    source = """
    class Robot : public Base {
    public:
        Robot();
        ~Robot();
        int speed() const { return speed_; }
    private:
        int speed_;
    };
    """
    facts = cpp(source)
    assert [(s.kind, s.text) for s in facts.statements] == [
        ("class", "class Robot : public Base"),
        ("declaration", "Robot ( ) ;"),
        ("declaration", "~ Robot ( ) ;"),
        ("function", "int speed ( ) const"),
        ("return", "return speed_ ;"),
        ("field", "int speed_ ;"),
    ]


def test_nested_struct_member_counts_as_one_field_plus_its_fields() -> None:
    assert kinds("struct A { struct B { int x; } b; };") == ["struct", "field", "field"]


def test_namespace_and_extern_c_blocks_do_not_count() -> None:
    assert kinds('namespace ns { int a; }\nextern "C" { int b; }\n') == ["declaration"] * 2


def test_using_alias_and_namespace_alias_count() -> None:
    source = "using namespace std;\nusing std::string;\nusing Id = int;\nnamespace fs = std::fs;\n"
    assert kinds(source) == ["using", "using", "using", "namespace_alias"]


def test_template_counts_once_with_what_it_declares() -> None:
    facts = cpp("template <typename T>\nT twice(T x) {\n    return x + x;\n}\n")
    signature = facts.statements[0]
    assert (signature.kind, signature.span, signature.text) == (
        "function",
        Span(1, 2),
        "template < typename T > T twice ( T x )",
    )
    assert facts.loc == 2


def test_template_class_counts_once() -> None:
    assert kinds("template <class T>\nclass Box { T v; };\n") == ["class", "field"]


def test_static_assert_and_friend_count_once() -> None:
    source = """
    class A {
        static_assert(1, "x");
        friend class B;
        friend void f();
    };
    """
    assert kinds(source) == ["class", "static_assert", "friend", "friend"]


def test_defaulted_function_counts_but_is_not_a_measured_function() -> None:
    facts = cpp("struct A {\n    A() = default;\n};\n")
    assert statement_kinds(facts) == ["struct", "function"]
    assert facts.functions == ()


def test_try_does_not_count_each_catch_does_throw_does() -> None:
    source = """
    void f() {
        try {
            g();
        } catch (const std::exception& e) {
            throw;
        } catch (...) {
        }
    }
    """
    facts = cpp(source)
    assert [(s.kind, s.text) for s in facts.statements[1:]] == [
        ("expression", "g ( ) ;"),
        ("catch", "catch ( const std :: exception & e )"),
        ("throw", "throw ;"),
        ("catch", "catch ( ... )"),
    ]


def test_range_for_counts_once() -> None:
    facts = cpp("void f() { for (auto& x : xs) use(x); }")
    assert [(s.kind, s.text) for s in facts.statements[1:]] == [
        ("for", "for ( auto & x : xs )"),
        ("expression", "use ( x ) ;"),
    ]


def test_if_with_initializer_counts_once() -> None:
    assert kinds("void f() { if (int x = g(); x > 0) h(); }") == ["function", "if", "expression"]


def test_lambda_body_statements_count_and_are_cut_from_the_outer_text() -> None:
    facts = cpp("void f() {\n    auto g = [](int a) {\n        return a;\n    };\n}\n")
    assert [(s.kind, s.text, s.function) for s in facts.statements[1:]] == [
        ("declaration", "auto g = [ ] ( int a ) { } ;", "f"),
        ("return", "return a ;", "f"),
    ]


# --- functions and their names ----------------------------------------------------------------


def test_qualified_names() -> None:
    source = """
    namespace outer { namespace inner {
    class Robot {
        void move() {}
        bool operator==(const Robot& o) const { return true; }
        operator bool() const { return true; }
        ~Robot() {}
    };
    void Robot::stop() {}
    Robot::Robot(int s) : speed_(s) {}
    } }
    namespace a::b { int g() { return 0; } }
    namespace { void hidden() {} }
    """
    assert [(f.name, f.qualified_name) for f in cpp(source).functions] == [
        ("move", "outer::inner::Robot::move"),
        ("operator==", "outer::inner::Robot::operator=="),
        ("operator bool", "outer::inner::Robot::operator bool"),
        ("~Robot", "outer::inner::Robot::~Robot"),
        ("stop", "outer::inner::Robot::stop"),
        ("Robot", "outer::inner::Robot::Robot"),
        ("g", "a::b::g"),
        ("hidden", "hidden"),
    ]


def test_lambda_is_part_of_its_function_as_in_lizard() -> None:
    facts = cpp(
        "int f(int a) {\n    auto g = [](int x) { return x ? 1 : 2; };\n    return g(a);\n}"
    )
    assert complexities(facts) == {"f": 2}


def test_local_class_methods_belong_to_the_enclosing_function_as_in_lizard() -> None:
    facts = cpp("void f() {\n    struct L { int m(int a) { if (a) return 1; return 0; } };\n}\n")
    assert complexities(facts) == {"f": 2}


# --- decisions ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("body", "kinds_found"),
    [
        ("try { g(); } catch (int) { } catch (...) { }", ["catch", "catch"]),
        ("for (auto x : xs) g();", ["for"]),
        ("if constexpr (A) g();", ["if"]),
        ("return a and b or c;", ["&&", "||"]),
        ("auto&& r = g();", []),
        ("std::forward<T&&>(x);", []),
        ("for (auto&& x : xs) g();", ["for"]),
    ],
)
def test_cpp_decision_points(body: str, kinds_found: list[str]) -> None:
    (function,) = cpp(f"int f() {{\n    {body}\n}}\n").functions
    assert sorted(d.kind for d in function.decisions) == sorted(kinds_found)


def test_and_or_keywords_count_unlike_lizard() -> None:
    """Disagreement class 2: lizard's token list has `&&`/`||` but not `and`/`or`."""
    assert complexities(cpp("bool f(bool a, bool b) { return a and not b; }")) == {"f": 2}


def test_rvalue_reference_is_no_decision_unlike_lizard() -> None:
    """Disagreement class 3: lizard counts `&&` in `for (auto&& x : v)`, we do not."""
    assert complexities(cpp("void f() { for (auto&& x : v) g(x); }")) == {"f": 2}


def test_decisions_in_signature_and_initializer_list_do_not_count_as_in_lizard() -> None:
    source = "struct A {\n    A(int x = y ? 1 : 2) : v(x ? 3 : 4) {}\n    int v;\n};\n"
    assert complexities(cpp(source)) == {"A::A": 1}


def test_function_try_block_counts_its_catch() -> None:
    """Disagreement class 4: lizard splits a function-try-block into two functions."""
    assert complexities(cpp("void f() try { g(); } catch (...) { h(); }")) == {"f": 2}


# --- classes ------------------------------------------------------------------------------------


def test_classes_structs_unions_with_qualified_names() -> None:
    source = """
    namespace ns {
    class Outer {
        struct Inner { int x; };
        union Any { int i; float f; };
    };
    class Forward;
    }
    """
    assert [(k.qualified_name, k.kind, k.span) for k in cpp(source).classes] == [
        ("ns::Outer", "class", Span(3, 6)),
        ("ns::Outer::Inner", "struct", Span(4, 4)),
        ("ns::Outer::Any", "union", Span(5, 5)),
    ]


# --- call sites ---------------------------------------------------------------------------------


def test_casts_rtti_and_qualified_calls() -> None:
    source = """
    void f(Base* b, Socket& sock, Socket* p) {
        Derived* d = dynamic_cast<Derived*>(b);
        if (typeid(*b) == typeid(Derived)) {}
        const char* home = std::getenv("HOME");
        auto prx = Ice::checkedCast<Demo::PrinterPrx>(base);
        sock.send(u8"hi");
        p->connect(R"(tcp://*:5555)");
        int n = static_cast<int>(sizeof(*b));
        g(nullptr, true, false);
    }
    """
    calls = [(k.callee, k.name, k.receiver) for k in cpp(source).call_sites]
    assert calls == [
        ("dynamic_cast", "dynamic_cast", None),
        ("typeid", "typeid", None),
        ("typeid", "typeid", None),
        ("std::getenv", "getenv", "std"),
        ("Ice::checkedCast", "checkedCast", "Ice"),
        ("sock.send", "send", "sock"),
        ("p->connect", "connect", "p"),
        ("static_cast", "static_cast", None),
        ("g", "g", None),
    ]
    by_callee = {k.callee: k for k in cpp(source).call_sites}
    assert by_callee["std::getenv"].arguments[0].value == "HOME"
    assert by_callee["sock.send"].arguments[0].value == "hi"
    assert by_callee["p->connect"].arguments[0].value == "tcp://*:5555"
    assert [(a.value, a.is_literal) for a in by_callee["g"].arguments] == [
        (None, True),
        (True, True),
        (False, True),
    ]
    assert {k.function for k in cpp(source).call_sites} == {"f"}


def test_method_call_on_a_call_result_keeps_the_whole_receiver() -> None:
    (outer, inner) = cpp("void f() { a.b(1).c(2); }").call_sites
    assert (outer.callee, outer.name, outer.receiver) == ("a.b(1).c", "c", "a.b(1)")
    assert inner.callee == "a.b"


def test_template_arguments_and_targets_of_calls() -> None:
    source = """
    void Talker::start() {
        pub_ = this->create_publisher<geometry_msgs::msg::Twist>("cmd_vel", 10);
        this->timer_ = create_wall_timer(period, cb);
        auto q = rclcpp::create_publisher<std::map<K, V>, Alloc>(node, "x", 10);
        topic_ = this->get_parameter("topic").as_string();
        sink(std::make_shared<tf2_ros::TransformBroadcaster>(this));
    }
    """
    calls = [(k.callee, k.templates, k.target) for k in cpp(source).call_sites]
    assert calls == [
        ("this->create_publisher", ("geometry_msgs::msg::Twist",), "pub_"),
        ("create_wall_timer", (), "this->timer_"),
        ("rclcpp::create_publisher", ("std::map<K,V>", "Alloc"), "q"),
        ('this->get_parameter("topic").as_string', (), "topic_"),
        ("this->get_parameter", (), "topic_"),  # the head of an accessor chain
        ("sink", (), None),
        ("std::make_shared", ("tf2_ros::TransformBroadcaster",), None),
    ]


def test_constructor_calls_without_a_call_expression_are_call_sites() -> None:
    source = """
    class Talker : public rclcpp::Node {
    public:
      Talker() : Node("talker"), as_(nh_, "fibonacci", false), pub_(make_pub("chatter")) {
        listener_ = new tf2_ros::TransformListener(buffer_);
        message_filters::Subscriber<Image> sub(this, "image"), other{this, "depth"};
      }
      actionlib::SimpleActionServer<FibonacciAction> as_;
    };
    """
    calls = [
        (k.callee, k.name, k.receiver, k.templates, k.target, [a.text for a in k.arguments])
        for k in cpp(source).call_sites
    ]
    assert calls == [
        ("Node", "Node", None, (), None, ['"talker"']),
        ("actionlib::SimpleActionServer", "SimpleActionServer", "actionlib",
         ("FibonacciAction",), "as_", ["nh_", '"fibonacci"', "false"]),
        ("pub_", "pub_", None, (), None, ['make_pub("chatter")']),  # type declared elsewhere
        ("make_pub", "make_pub", None, (), "pub_", ['"chatter"']),
        ("tf2_ros::TransformListener", "TransformListener", "tf2_ros", (), "listener_",
         ["buffer_"]),
        ("message_filters::Subscriber", "Subscriber", "message_filters", ("Image",), "sub",
         ["this", '"image"']),
        ("message_filters::Subscriber", "Subscriber", "message_filters", ("Image",), "other",
         ["this", '"depth"']),
    ]  # fmt: skip
    assert {k.function for k in cpp(source).call_sites} == {"Talker::Talker"}


def test_a_construction_read_as_a_function_declaration_is_a_call_site() -> None:
    source = """
    void f(int);
    int main() {
      tf2_ros::TransformListener listener(buffer);
      ros::NodeHandle child(nh, ns);
      int g(int);
      std::string h(std::string);
    }
    """
    calls = [
        (k.callee, k.span.start, k.target, [a.text for a in k.arguments])
        for k in cpp(source).call_sites
    ]
    assert calls == [
        ("tf2_ros::TransformListener", 4, "listener", ["buffer"]),
        ("ros::NodeHandle", 5, "child", ["nh", "ns"]),
    ]  # the declarations at file scope, of a primitive type or a qualified parameter stay


def test_a_macro_called_alone_between_declarations_is_a_call_site() -> None:
    source = """
    #include "pluginlib/class_list_macros.hpp"
    namespace nav2_navfn_planner { void plan() {} }
    PLUGINLIB_EXPORT_CLASS(nav2_navfn_planner::NavfnPlanner, nav2_core::GlobalPlanner)
    RCLCPP_COMPONENTS_REGISTER_NODE(composition::Talker);
    SET_NAME("x")
    """
    calls = [
        (k.callee, k.span.start, k.function, [(a.text, a.value) for a in k.arguments])
        for k in cpp(source).call_sites
    ]
    assert calls == [
        ("PLUGINLIB_EXPORT_CLASS", 4, None,
         [("nav2_navfn_planner::NavfnPlanner", None), ("nav2_core::GlobalPlanner", None)]),
        ("RCLCPP_COMPONENTS_REGISTER_NODE", 5, None, [("composition::Talker", None)]),
        ("SET_NAME", 6, None, [('"x"', "x")]),
    ]  # fmt: skip


# --- headers and robustness ---------------------------------------------------------------------


def test_header_include_guard_and_pragma_once() -> None:
    source = "#pragma once\n#ifndef A_HPP\n#define A_HPP\n#include <vector>\nclass A;\n#endif\n"
    assert kinds(source) == ["include", "class"]


def test_unparseable_cpp_still_measures_the_rest() -> None:
    source = "int ok() { return 1; }\nQ_OBJECT_MAGIC(x) y z {\nint later() { return 2; }\n"
    facts = cpp(source)
    assert facts.parsed
    assert [w.message for w in facts.warnings] == [
        "lines 2-3: the brackets from line 2 on never close (a statement read as a function"
        " definition (a macro call without its ';'?))"
    ]
    assert "ok" in complexities(facts)


def test_coroutine_statements_count() -> None:
    source = "task<int> f() {\n    co_yield 1;\n    co_return 2;\n}\n"
    assert kinds(source) == ["function", "co_yield", "co_return"]


def test_concept_counts_once_with_its_template() -> None:
    facts = cpp("template <class T>\nconcept Small = sizeof(T) < 4;\n")
    assert [(s.kind, s.span) for s in facts.statements] == [("concept", Span(1, 2))]


def test_explicit_instantiation_counts_without_a_warning() -> None:
    facts = cpp("template class Box<int>;\n")
    assert (statement_kinds(facts), facts.warnings) == (["declaration"], ())


def test_declaration_in_a_while_condition_is_part_of_the_header() -> None:
    facts = cpp("void f() { while (T* p = next()) use(p); }")
    assert [(s.kind, s.text) for s in facts.statements[1:]] == [
        ("while", "while ( T * p = next ( ) )"),
        ("expression", "use ( p ) ;"),
    ]


@pytest.mark.parametrize("language", ["c", "cpp"])
def test_extern_c_guard_idiom_parses_cleanly_and_counts_nothing(language: str) -> None:
    source = """\
        #ifndef API_H
        #define API_H
        #ifdef __cplusplus
        extern "C" {
        #endif
        int api_open(const char *name);
        #ifdef __cplusplus
        }
        #endif
        #endif
        """
    facts = facts_of(source, language, "api.h")
    assert facts.warnings == ()
    assert [(s.kind, s.span.start) for s in facts.statements] == [("declaration", 6)]


@pytest.mark.parametrize("language", ["c", "cpp"])
def test_extern_c_guard_idiom_with_comments_after_its_braces_is_hidden_too(language: str) -> None:
    # protobuf's upb headers close the block as `}  /* extern "C" */`: tree-sitter sees a
    # `}` that closes nothing unless those lines are blanked like the bare idiom's
    source = """\
        #ifdef __cplusplus
        extern "C" {  // C linkage
        #endif
        int api_open(const char *name);
        #ifdef __cplusplus
        }  /* extern "C" */
        #endif
        """
    data = c_family.hide_extern_c_guards(textwrap.dedent(source).encode())
    lines = data.decode().splitlines()
    assert (lines[1].strip(), lines[5].strip()) == ("", "")
    assert not c_family.grammar(Language(language)).parser.parse(data).root_node.has_error
    facts = facts_of(source, language, "api.h")
    # 7 lines, the two blanked ones not source lines
    assert (facts.sloc, facts.warnings) == (5, ())
    assert [(s.kind, s.span.start) for s in facts.statements] == [("declaration", 4)]
