"""Node-type tables for the C and C++ walker: what is a statement, a decision, a body.

Everything language-specific about C and C++ lives here as data; ``c_family`` is the one
walker that reads these tables. docs/metrics.md explains each row (thesis page 103 for
statements, lizard's defaults for decisions).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from enum import Enum


class Shape(Enum):
    """Which part of a statement node is the statement's own text and span."""

    WHOLE = "whole"  # the node, nested bodies cut out: `x = f ( [ ] { } ) ;`
    HEADER = "header"  # up to the body (field below): `if ( x > 0 )`, a function signature
    LABEL = "label"  # `case 1 :` / `default :` without the statements that follow
    DO_WHILE = "do_while"  # `do ... while ( c ) ;`: the trailer holds the terminating `;`


@dataclass(frozen=True, slots=True)
class StatementRule:
    """One row of the λ table: a node type that is one statement."""

    kind: str
    shape: Shape = Shape.WHOLE
    body_field: str = "body"


_W = Shape.WHOLE
_H = Shape.HEADER

#: Node types that are one logical line each, in both languages (thesis p. 103).
C_STATEMENTS: Mapping[str, StatementRule] = {
    "expression_statement": StatementRule("expression"),  # an empty `;` is dropped
    "declaration": StatementRule("declaration"),  # one `;`: `int a, b;` is one
    "type_definition": StatementRule("typedef"),
    "field_declaration": StatementRule("field"),
    "return_statement": StatementRule("return"),
    "break_statement": StatementRule("break"),
    "continue_statement": StatementRule("continue"),
    "goto_statement": StatementRule("goto"),
    "function_definition": StatementRule("function", _H),  # the signature, once
    "if_statement": StatementRule("if", _H, "consequence"),  # `else` adds nothing
    "for_statement": StatementRule("for", _H),  # the `;`s in its parentheses do not count
    "while_statement": StatementRule("while", _H),
    "do_statement": StatementRule("do_while", Shape.DO_WHILE),
    "switch_statement": StatementRule("switch", _H),
    "case_statement": StatementRule("case", Shape.LABEL),  # kind "default" for default:
    "struct_specifier": StatementRule("struct", _H),  # only where it stands alone
    "union_specifier": StatementRule("union", _H),
    "enum_specifier": StatementRule("enum"),  # enumerators are part of it
    "preproc_include": StatementRule("include"),
    "preproc_def": StatementRule("define"),  # not an include guard's
    "preproc_function_def": StatementRule("define"),
    "preproc_call": StatementRule("directive"),  # #undef, #pragma (not `once`), #error
}

#: Extra rows for C++.
CPP_STATEMENTS: Mapping[str, StatementRule] = {
    **C_STATEMENTS,
    "class_specifier": StatementRule("class", _H),
    "for_range_loop": StatementRule("for", _H),
    "catch_clause": StatementRule("catch", _H),
    "throw_statement": StatementRule("throw"),
    "co_return_statement": StatementRule("co_return"),
    "co_yield_statement": StatementRule("co_yield"),
    "alias_declaration": StatementRule("using"),
    "using_declaration": StatementRule("using"),
    "namespace_alias_definition": StatementRule("namespace_alias"),
    "static_assert_declaration": StatementRule("static_assert"),
    "friend_declaration": StatementRule("friend"),
    "concept_definition": StatementRule("concept"),
    "template_instantiation": StatementRule("declaration"),
}

#: Type specifiers count only where they stand alone (`struct S { ... };`, `class C;`);
#: inside a declaration, typedef or field the enclosing statement already counts their `;`.
SPECIFIERS = ("struct_specifier", "union_specifier", "enum_specifier", "class_specifier")
SPECIFIER_CONTAINERS = (
    "translation_unit",
    "declaration_list",
    "field_declaration_list",
    "compound_statement",
    "template_declaration",
    "linkage_specification",
    "preproc_if",
    "preproc_ifdef",
    "preproc_else",
    "preproc_elif",
    "preproc_elifdef",
)

#: Statement nodes that sit inside another statement's header and so add nothing.
NOT_STATEMENTS = (
    "(for_statement (declaration) @skip)",  # for (int i = 0; ...)
    "(condition_clause (declaration) @skip)",  # if (auto x = f())
    "(init_statement (_) @skip)",  # if (int x = f(); x > 0)
    "(function_definition (declaration) @skip)",  # K&R parameter declarations
    "(friend_declaration (declaration) @skip)",  # friend void f();
)

#: Decision points (+1 to v_g), as lizard counts them by default, keyed by token.
DECISIONS: Mapping[str, str] = {
    "if": "if",
    "for": "for",
    "while": "while",  # do-while's while too
    "case": "case",  # each label; `default` is not a decision
    "catch": "catch",
    "?": "?",
    "&&": "&&",
    "||": "||",
    "and": "&&",
    "or": "||",
    "#if": "#if",
    "#ifdef": "#ifdef",
    "#ifndef": "#ifndef",
    "#elif": "#elif",
    "#elifdef": "#elifdef",
    "#elifndef": "#elifndef",
}

#: A `catch` clause cut from its `try` by an #if (`} catch (A&) {} / #ifdef X / catch (B&)
#: {} / #endif`): tree-sitter reads a function named `catch`; in a body it is the clause.
CATCH_READ_AS_FUNCTION = (
    "(function_definition declarator: (function_declarator declarator: (identifier) @catch))"
    # (every such name is captured; c_family.py keeps those spelled `catch`)
)

#: `&&` tokens that are rvalue references, not logical and.
NOT_DECISIONS = (
    '(reference_declarator "&&" @nodecision)',
    '(abstract_reference_declarator "&&" @nodecision)',
    '(ref_qualifier "&&" @nodecision)',
)

#: Preprocessor conditions: lizard reads a directive line as one token, so the `&&`, `||`
#: and `?` inside `#if A && B` are not decisions (the `#if` itself is).
DIRECTIVE_CONDITIONS = (
    "(preproc_if condition: (_) @directive)",
    "(preproc_elif condition: (_) @directive)",
)

#: A block where no statement may stand (between declarations): tree-sitter read the head
#: before it as something else (a K&R definition with a pointer return type, a macro).
#: (Patterns name only parents that do not nest deeply: c_family_grammar.py.)
STRAY_BLOCKS = (
    "(translation_unit (compound_statement) @stray)",
    "(declaration_list (compound_statement) @stray)",
    # in an #if branch: only those outside every function body are stray (c_family_facts)
    "[(preproc_if (compound_statement) @stray) (preproc_ifdef (compound_statement) @stray)"
    " (preproc_else (compound_statement) @stray) (preproc_elif (compound_statement) @stray)]",
    # `static void f(struct s *p, t *w) {};`: tree-sitter-cpp reads a declaration with a
    # brace initializer, which no function declarator can have: the body of a definition
    "(declaration declarator: (init_declarator declarator: (function_declarator)"
    " value: (initializer_list) @braced))",
)

#: A function head with calls or words after its parameter list (``GENERATE_TEST(a)`` /
#: ``GENERATE_TEST(b)`` / ``int main(void) {``: macro calls without their `;` read as one
#: head, named after the first; ``char *f(a) int a; {`` read likewise).
MISREAD_HEAD = (
    "(function_definition declarator: (function_declarator parameters: (parameter_list) ."
    " [(identifier) (call_expression)]) body: (_) @misread)"
)

#: `(std::isnan)(a) && b > 0`: tree-sitter takes `(a)` for a cast and `&& b` for two
#: address-of operators; the outer one is captured and counted where it is spelled `&&`.
CAST_AND = (
    "(cast_expression type: (type_descriptor type: (type_identifier) !declarator)"
    " value: (pointer_expression argument: (pointer_expression)) @castand)"
)

#: Bodies whose contents are statements of their own: cut out of a statement's text.
BODIES = ("compound_statement", "field_declaration_list", "declaration_list")

#: Scopes that qualify a name (`ns::Class::method`).
NAMESPACE = "namespace_definition"
CLASSES: Mapping[str, str] = {
    "struct_specifier": "struct",
    "class_specifier": "class",
    "union_specifier": "union",
}

FUNCTION = "function_definition"
TEMPLATE = "template_declaration"
