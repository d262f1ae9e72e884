"""Python facts from the standard library: ``ast`` for the structure, ``tokenize``'s rules for
the text. The statement walk; expressions are in python_ast_expressions.py.

These are the same facts, to the token, as the libcst reader's (python_walk.py), which stays
the reader of files the running interpreter cannot parse (see python.py); the tests hold the
two to each other on real code. The rules are those of docs/metrics.md. ``ast`` says what
each statement is and where it starts and ends; its span and normalized text are a slice of
the token stream (python_lex.py). What ``ast`` gives no position (``else``, ``case``, the
``:`` that ends a header, the ``@`` of a decorator) is found among the tokens next to it.
"""

from __future__ import annotations

import ast
import unicodedata
from collections.abc import Callable

from archmetrics.facts import (
    Binding,
    Class,
    Decision,
    Dependency,
    DependencyKind,
    FileFacts,
    Function,
    Language,
    Span,
    Statement,
)
from archmetrics.parsers.python_ast_expressions import ExpressionReader, Frame
from archmetrics.parsers.python_ast_rules import (
    SIMPLE_KINDS,
    catch_all,
    docstring,
    statement_text,
)
from archmetrics.parsers.python_bindings import assignment_bindings, assignment_target
from archmetrics.parsers.python_lex import Unreadable
from archmetrics.parsers.python_shown import PendingCall


def read(path: str, source: str, tree: ast.Module) -> FileFacts:
    """Facts of one Python file that ``ast`` parsed (``generated`` is left to the registry).

    Raises :class:`Unreadable` where the tokens and the tree do not line up."""
    reader = _Reader(source)
    if not source.isascii() and _unnormalized_name(reader.tokens.text):
        raise Unreadable("a name not in NFKC form: ast normalizes it, libcst keeps it as written")
    reader.body(tree.body, None, docstrings=True)
    reader.calls.sort(key=lambda found: found[0])
    return FileFacts(
        path=path,
        language=Language.PYTHON,
        statements=tuple(reader.statements),
        functions=tuple(f for f in reader.functions if f is not None),
        classes=tuple(c for c in reader.classes if c is not None),
        dependencies=tuple(reader.dependencies),
        call_sites=tuple(
            call.site() if isinstance(call, PendingCall) else call for _, call in reader.calls
        ),
        bindings=tuple(reader.bindings),
        sloc=reader.sloc(),
    )


def parameters(args: ast.arguments) -> tuple[str, ...]:
    """A def's parameter names in the order written (``*args`` as ``args``)."""
    names = [a.arg for a in (*args.posonlyargs, *args.args)]
    names += [args.vararg.arg] if args.vararg else []
    names += [a.arg for a in args.kwonlyargs]
    names += [args.kwarg.arg] if args.kwarg else []
    return tuple(names)


def _unnormalized_name(tokens: list[str]) -> bool:
    """True when a name is written in characters Python reads as others (``ｗｗｗ`` is
    ``www``): facts keep names as written, and ``ast`` gives only their normal form."""
    return any(
        not token.isascii()
        and token[-1] not in "'\""  # not a string: a string ends with its quote
        and unicodedata.normalize("NFKC", token) != token
        for token in tokens
    )


class _Reader(ExpressionReader):
    def __init__(self, source: str):
        super().__init__(source)
        self.names: list[str] = []  # enclosing def/class names, for qualified names
        self.statements: list[Statement] = []
        self.functions: list[Function | None] = []
        self.classes: list[Class | None] = []
        self.dependencies: list[Dependency] = []
        self.bindings: list[Binding] = []
        self.docstrings: list[tuple[int, int]] = []  # token ranges

    def statement_start(self, node: ast.stmt) -> int:
        """A statement's first token: the ``@`` of its first decorator, if it has one."""
        decorators = getattr(node, "decorator_list", None)
        if decorators:
            return self.tokens.before(self.first(decorators[0]), "@")
        return self.first(node)

    def add_statement(self, kind: str, first: int, end: int, node: ast.stmt | None = None) -> None:
        text = statement_text(self.tokens, first, end, node)
        span = self.span(first, end)
        self.statements.append(Statement(kind, span, text, self.owner()))
        if self.funcs:
            self.funcs[-1].statements += 1
        if kind == "assign" or kind == "annassign":
            found = assignment_bindings(kind, self.tokens.text[first:end])
            self.bindings += [Binding(n, v, span.start, self.owner()) for n, v in found]
            assigned = assignment_target(kind, self.tokens.text[first:end])
            if assigned is not None:
                name, start, stop = assigned
                self.assigned[first + start] = (name, first + stop)

    # -- blocks and simple statements -------------------------------------------------------
    def body(self, statements: list[ast.stmt], target: Frame | None, docstrings: bool) -> None:
        """Statements of a block; ``target`` takes the decisions (None in a class body)."""
        for index, node in enumerate(statements):
            if index == 0 and docstrings and docstring(node):
                first, end = self.first(node), self.end(node)
                if end < len(self.tokens) and self.tokens.text[end] == ";":
                    end += 1  # libcst counts the ";" as the docstring's
                self.docstrings.append((first, end))
                continue
            kind = type(node)
            simple = SIMPLE_KINDS.get(kind)
            if simple is None:
                handler = _COMPOUND.get(kind)
                if handler is None:
                    raise Unreadable(f"statement {kind.__name__} at line {node.lineno}")
                handler(self, node, target)
                continue
            first, end = self.first(node), self.end(node)
            self.add_statement(simple, first, end, node)
            if kind is ast.Assert:
                self.decide(target, "assert", first)
                self.expressions([node], None)  # radon does not look inside an assert
                continue
            if kind is ast.Import or kind is ast.ImportFrom:
                self.imports(node, self.span(first, end))  # type: ignore[arg-type]
            self.expressions([node], target)

    def imports(self, node: ast.Import | ast.ImportFrom, span: Span) -> None:
        if type(node) is ast.Import:
            for alias in node.names:
                local = alias.asname or alias.name.split(".")[0]
                self.dependencies.append(
                    Dependency(alias.name, DependencyKind.IMPORT, span, bound=(local,))
                )
            return
        names = tuple(alias.name for alias in node.names)
        bound = tuple(alias.asname or alias.name for alias in node.names)
        level = node.level or 0  # type: ignore[union-attr]
        module = node.module or ""  # type: ignore[union-attr]
        self.dependencies.append(
            Dependency(module, DependencyKind.IMPORT, span, level, names, bound)
        )

    # -- compound statements ----------------------------------------------------------------
    def header(self, kind: str, first: int, after: int, target: Frame | None) -> None:
        """A compound header from token ``first`` to the ``:`` found from ``after`` on,
        with its decision point (``target`` None: it has none)."""
        self.add_statement(kind, first, self.tokens.colon(after) + 1)
        self.decide(target, kind, first)

    def else_(self, orelse: list[ast.stmt], target: Frame | None, kind: str | None) -> None:
        """An ``else:`` block; ``kind`` names its decision point, if it is one."""
        if orelse:
            if kind is not None:
                keyword = self.tokens.before(self.statement_start(orelse[0]), "else")
                self.decide(target, kind, keyword)
            self.body(orelse, target, docstrings=False)

    def if_(self, node: ast.If, target: Frame | None) -> None:
        """An ``if`` and its ``elif`` chain, in a loop: ``ast`` nests each ``elif`` in the
        ``orelse`` of the one before, and generated chains run to thousands."""
        text = self.tokens.text
        first = self.first(node)
        kind = "elif" if text[first] == "elif" else "if"
        while True:
            self.header(kind, first, self.end(node.test), target)
            self.expressions([node.test], target)
            self.body(node.body, target, docstrings=False)
            orelse = node.orelse
            if len(orelse) != 1 or type(orelse[0]) is not ast.If:
                break
            first = self.first(orelse[0])
            if text[first] != "elif":
                break  # `else:` holding an `if`: an indented block, read as one
            node, kind = orelse[0], "elif"
        self.else_(orelse, target, None)

    def loop(self, node: ast.For | ast.AsyncFor | ast.While, target: Frame | None) -> None:
        if type(node) is ast.While:
            kind, parts = "while", [node.test]
        else:
            kind, parts = "for", [node.target, node.iter]  # type: ignore[union-attr]
        self.header(kind, self.first(node), self.end(parts[-1]), target)
        self.expressions(parts, target)  # type: ignore[arg-type]
        self.body(node.body, target, docstrings=False)
        self.else_(node.orelse, target, kind + "_else")

    def with_(self, node: ast.With | ast.AsyncWith, target: Frame | None) -> None:
        parts = [part for item in node.items for part in (item.context_expr, item.optional_vars)]
        last = max(self.end(part) for part in parts if part is not None)
        first, text = self.first(node), self.tokens.text
        opening = first + 1 if text[first] == "with" else first + 2  # after "async with"
        if text[opening] == "(" and self.tokens.closing.get(opening) == self.tokens.colon(last) - 1:
            self.tokens.statement_parens.add(opening)  # `with (a, b):`: the statement's own
        self.header("with", first, last, None)
        self.expressions(parts, target)  # type: ignore[arg-type]
        self.body(node.body, target, docstrings=False)

    def try_(self, node: ast.Try, target: Frame | None) -> None:
        first = self.first(node)
        self.header("try", first, first, None)
        self.body(node.body, target, docstrings=False)
        for handler in node.handlers:
            start = self.first(handler)
            after = self.end(handler.type) if handler.type is not None else start
            self.header("except", start, after, target)
            self.expressions([handler.type], target)
            self.body(handler.body, target, docstrings=False)
        self.else_(node.orelse, target, "try_else")
        self.body(node.finalbody, target, docstrings=False)

    def match(self, node: ast.Match, target: Frame | None) -> None:
        first = self.first(node)
        self.tokens.soft_keywords.add(first)
        self.header("match", first, self.end(node.subject), None)
        self.expressions([node.subject], target)
        default = catch_all(node.cases)
        for case in node.cases:
            start = self.tokens.before(self.first(case.pattern), "case")
            self.tokens.soft_keywords.add(start)
            last = case.guard if case.guard is not None else case.pattern
            self.header("case", start, self.end(last), None if case is default else target)
            self.expressions([case.guard], target)
            self.body(case.body, target, docstrings=False)

    def scope(self, node: ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef) -> None:
        """A def or class: its signature, its header's expressions (no decision points
        there, as radon), its body; a def's statements and calls are its own."""
        syntax = self.first(node)
        is_def = type(node) is not ast.ClassDef
        self.names.append(node.name)
        frame = Frame(".".join(self.names))
        slot = len(self.functions if is_def else self.classes)
        (self.functions if is_def else self.classes).append(None)
        if is_def:
            self.funcs.append(frame)
        returns = getattr(node, "returns", None)
        after = self.end(returns) if returns is not None else syntax
        kind = "def" if is_def else "class"
        self.add_statement(kind, self.statement_start(node), self.tokens.colon(after) + 1)
        header = [*node.decorator_list, *getattr(node, "type_params", ())]
        if is_def:
            header += [node.args, returns]  # type: ignore[union-attr]
        else:
            header += [*node.bases, *node.keywords]  # type: ignore[union-attr]
        self.expressions(header, None)
        self.body(node.body, frame if is_def else None, docstrings=True)
        span = self.span(syntax, self.end(node))
        self.names.pop()
        if not is_def:
            self.classes[slot] = Class(node.name, frame.qualified_name, span)
            return
        self.funcs.pop()
        frame.decisions.sort(key=lambda found: found[0])
        decisions = tuple(Decision(kind, line) for _, kind, line in frame.decisions)
        self.functions[slot] = Function(
            node.name,
            frame.qualified_name,
            span,
            decisions,
            frame.statements,
            parameters(node.args),  # type: ignore[union-attr]
        )

    # -- SLOC -------------------------------------------------------------------------------
    def sloc(self) -> int:
        """Lines holding a token outside docstrings; a multi-line token's non-blank lines."""
        tokens = self.tokens
        lines: set[int] = set()
        start = 0
        skipped: set[int] = set()
        for first, end in self.docstrings:
            lines.update(tokens.starts[start:first])
            lines.update(tokens.ends[start:first])
            skipped.update(range(first, end))
            start = end
        lines.update(tokens.starts[start:])
        lines.update(tokens.ends[start:])
        for index in tokens.multiline:
            if index not in skipped:
                for line in range(tokens.starts[index] + 1, tokens.ends[index]):
                    if self.offset.line_text(line).strip():
                        lines.add(line)
        return len(lines)


def _scope(reader: _Reader, node: ast.AST, target: Frame | None) -> None:
    reader.scope(node)  # type: ignore[arg-type]


_COMPOUND: dict[type[ast.AST], Callable[[_Reader, ast.AST, Frame | None], None]] = {
    ast.If: _Reader.if_,  # type: ignore[dict-item]
    ast.For: _Reader.loop,  # type: ignore[dict-item]
    ast.AsyncFor: _Reader.loop,  # type: ignore[dict-item]
    ast.While: _Reader.loop,  # type: ignore[dict-item]
    ast.With: _Reader.with_,  # type: ignore[dict-item]
    ast.AsyncWith: _Reader.with_,  # type: ignore[dict-item]
    ast.Try: _Reader.try_,  # type: ignore[dict-item]
    ast.Match: _Reader.match,  # type: ignore[dict-item]
    ast.FunctionDef: _scope,
    ast.AsyncFunctionDef: _scope,
    ast.ClassDef: _scope,
}
if hasattr(ast, "TryStar"):
    _COMPOUND[ast.TryStar] = _Reader.try_  # type: ignore[assignment]
