"""The single pass over a libcst module that turns it into facts.

One code-generation walk (see python_tokens.py) sees every node on entry and exit, in source
order. Statements, functions, classes, imports and calls are recorded as token ranges and
turned into lines and normalized text from the token lists. Decision points follow radon's
``ComplexityVisitor`` (docs/metrics.md, "Python decision points").
"""

from __future__ import annotations

from dataclasses import dataclass, field

import libcst as cst

from archmetrics.facts import (
    Binding,
    CallSite,
    Class,
    Decision,
    Dependency,
    Function,
    Span,
    Statement,
)
from archmetrics.parsers import python_calls as calls
from archmetrics.parsers import python_rules as rules
from archmetrics.parsers.python_bindings import (
    accessors_only,
    assignment_bindings,
    assignment_target,
)
from archmetrics.parsers.python_shown import PendingCall, Shown, call_site
from archmetrics.parsers.python_tokens import Hook, TokenState


@dataclass(slots=True)
class _Frame:
    """A function or class being walked; ``slot`` is its index in the output list."""

    name: str
    qualified_name: str
    slot: int
    start: int  # token index where its own syntax begins (after decorators)
    decisions: list[tuple[str, list[int]]] = field(default_factory=list)  # (kind, [line])
    statements: int = 0


class FactsWalker(TokenState):
    """Collects the facts of one module during ``module._codegen(walker)``."""

    def __init__(self) -> None:
        super().__init__()
        self.names: list[str] = []  # enclosing def/class names, for qualified names
        self.funcs: list[_Frame] = []  # enclosing functions (statements and calls go to [-1])
        self.targets: list[_Frame | None] = []  # decision target; a class body is None
        self.frames: list[_Frame] = []  # enclosing defs and classes
        self.suppress = 0  # > 0 where radon does not look (signatures, assert)
        self.header: tuple[str, int] | None = None  # compound header being read
        self.statements: list[Statement] = []
        self.functions: list[Function | None] = []
        self.classes: list[Class | None] = []
        self.dependencies: list[Dependency] = []
        self.bindings: list[Binding] = []
        self.calls: list[CallSite | PendingCall | None] = []
        self.call_ranges: list[tuple[int, int]] = []  # each call's first token and its ")"
        self.assigned: dict[int, tuple[str, int]] = {}  # as python_ast_expressions keeps it
        self.docstrings: set[int] = set()
        self.elifs: set[int] = set()
        self.else_kinds: dict[int, str] = {}
        self.catch_alls: set[int] = set()
        self.simple_starts: list[int] = []
        self.call_starts: list[tuple[int, int, list[int]]] = []  # (first token, slot, [line])
        self.arg_starts: dict[int, int] = {}
        self.syntax_starts: dict[int, int] = {}
        self.shown = Shown(self.toks, precise=True)  # call-site texts

    # -- helpers ----------------------------------------------------------------------------
    def span(self, first: int, end: int) -> Span:
        """Lines of tokens ``first:end``."""
        start = self.first_line(first)
        return Span(start, max(start, self.last_line(end)))

    def owner(self) -> str | None:
        """Qualified name of the innermost enclosing function (Statement/CallSite.function)."""
        return self.funcs[-1].qualified_name if self.funcs else None

    def add_statement(self, kind: str, first: int, end: int) -> None:
        """Record one logical line made of tokens ``first:end``."""
        span = self.span(first, end)
        self.statements.append(Statement(kind, span, self.text(first, end), self.owner()))
        if self.funcs:
            self.funcs[-1].statements += 1
        if kind == "assign" or kind == "annassign":
            found = assignment_bindings(kind, self.toks[first:end])
            self.bindings += [Binding(n, v, span.start, self.owner()) for n, v in found]
            assigned = assignment_target(kind, self.toks[first:end])
            if assigned is not None:
                name, start, stop = assigned
                self.assigned[first + start] = (name, first + stop)

    def decide(self, kind: str) -> None:
        """A decision point at the next token (its line: that token's, also inside an
        f-string), for the function whose body we are in."""
        if not self.suppress and self.targets and self.targets[-1] is not None:
            self.targets[-1].decisions.append((kind, self.next_line()))

    def open_header(self, kind: str) -> None:
        """A compound statement starts: its header runs until its body (or first case)."""
        self.close_header()
        self.header = (kind, len(self.toks))

    def close_header(self) -> None:
        """The body of the open header starts: record the header as one statement."""
        if self.header is None:
            return
        kind, first = self.header
        self.header = None
        self.add_statement(kind, first, len(self.toks))
        if kind in ("def", "class"):
            self.suppress -= 1

    def syntactic_start(self, node: cst.CSTNode) -> None:
        if type(node) is cst.FunctionDef or type(node) is cst.ClassDef:
            self.syntax_starts[id(node)] = len(self.toks)

    # -- scopes -----------------------------------------------------------------------------
    def open_scope(self, node: cst.FunctionDef | cst.ClassDef, kind: str) -> _Frame:
        """Enter a def or class: name it, reserve its output slot, note its docstring."""
        name = node.name.value
        self.names.append(name)
        slots = self.functions if kind == "def" else self.classes
        frame = _Frame(name, ".".join(self.names), len(slots), len(self.toks))
        slots.append(None)
        self.frames.append(frame)
        doc = rules.docstring(node.body)
        if doc is not None:
            self.docstrings.add(id(doc))
        self.open_header(kind)
        self.suppress += 1  # decorators, parameters, bases: radon visits only the body
        return frame

    def enter_def(self, node: cst.FunctionDef) -> None:
        frame = self.open_scope(node, "def")
        self.funcs.append(frame)
        self.targets.append(frame)

    def leave_def(self, node: cst.FunctionDef) -> None:
        frame = self.frames.pop()
        self.funcs.pop()
        self.targets.pop()
        self.names.pop()
        start = self.syntax_starts.pop(id(node), frame.start)
        decisions = tuple(Decision(kind, line) for kind, (line,) in frame.decisions)
        span = self.span(start, len(self.toks))
        self.functions[frame.slot] = Function(
            frame.name, frame.qualified_name, span, decisions, frame.statements, parameters(node)
        )

    def enter_class(self, node: cst.ClassDef) -> None:
        self.open_scope(node, "class")
        self.targets.append(None)

    def leave_class(self, node: cst.ClassDef) -> None:
        frame = self.frames.pop()
        self.targets.pop()
        self.names.pop()
        start = self.syntax_starts.pop(id(node), frame.start)
        self.classes[frame.slot] = Class(
            frame.name, frame.qualified_name, self.span(start, len(self.toks))
        )

    def enter_module(self, node: cst.Module) -> None:
        doc = rules.docstring(node.body)
        if doc is not None:
            self.docstrings.add(id(doc))

    def enter_body(self, node: cst.CSTNode) -> None:
        self.close_header()

    # -- simple statements ------------------------------------------------------------------
    def enter_simple(self, node: cst.CSTNode) -> None:
        self.simple_starts.append(len(self.toks))
        if id(node) in self.docstrings:
            self.skip_depth += 1

    def leave_simple(self, node: cst.CSTNode) -> None:
        first = self.simple_starts.pop()
        if id(node) in self.docstrings:
            self.skip_depth -= 1
            return
        end = len(self.toks)
        if end > first + 1 and self.toks[end - 1] == ";":
            end -= 1
        self.add_statement(rules.SIMPLE_KINDS[type(node)], first, end)
        if isinstance(node, rules.IMPORT_TYPES):
            self.dependencies.extend(rules.dependencies(node, self.span(first, end)))

    def enter_assert(self, node: cst.Assert) -> None:
        self.enter_simple(node)
        self.decide("assert")
        self.suppress += 1  # radon does not look inside an assert

    def leave_assert(self, node: cst.Assert) -> None:
        self.suppress -= 1
        self.leave_simple(node)

    # -- compound statements and decision points --------------------------------------------
    def enter_if(self, node: cst.If) -> None:
        kind = "elif" if id(node) in self.elifs else "if"
        if isinstance(node.orelse, cst.If):
            self.elifs.add(id(node.orelse))
        self.open_header(kind)
        self.decide(kind)

    def enter_loop(self, node: cst.For | cst.While) -> None:
        kind = "for" if isinstance(node, cst.For) else "while"
        if node.orelse is not None:
            self.else_kinds[id(node.orelse)] = kind + "_else"
        self.open_header(kind)
        self.decide(kind)

    def enter_try(self, node: cst.Try | cst.TryStar) -> None:
        if node.orelse is not None:
            self.else_kinds[id(node.orelse)] = "try_else"
        self.open_header("try")

    def enter_handler(self, node: cst.CSTNode) -> None:
        self.open_header("except")
        self.decide("except")

    def enter_else(self, node: cst.Else) -> None:
        kind = self.else_kinds.pop(id(node), None)
        if kind is not None:
            self.decide(kind)

    def enter_header(self, node: cst.CSTNode) -> None:
        self.open_header(rules.HEADER_KINDS[type(node)])

    def enter_match(self, node: cst.Match) -> None:
        catch_all = next((case for case in node.cases if rules.is_catch_all(case)), None)
        if catch_all is not None:
            self.catch_alls.add(id(catch_all))
        self.open_header("match")

    def enter_case(self, node: cst.MatchCase) -> None:
        self.open_header("case")
        if id(node) not in self.catch_alls:
            self.decide("case")

    # -- calls ----------------------------------------------------------------------------
    def enter_call(self, node: cst.Call) -> None:
        self.call_starts.append((len(self.toks), len(self.calls), self.next_line()))
        self.calls.append(None)
        self.call_ranges.append((-1, -1))

    def enter_arg(self, node: cst.Arg) -> None:
        self.arg_starts[id(node)] = len(self.toks)

    def leave_call(self, node: cst.Call) -> None:
        first, slot, (line,) = self.call_starts.pop()
        end = len(self.toks)
        starts = [self.arg_starts.pop(id(arg), first) for arg in node.args]
        long = False
        if self.fstring_depth:  # inside an f-string the tokens are glued: rebuild the text
            callee, receiver, arguments = calls.from_nodes(node)
        else:
            callee, receiver, arguments, open_, close = calls.from_tokens(
                self, node, first, end, starts
            )
            long = self.shown.note_call(first + len(node.lpar), open_, close + 1)
        name = node.func.attr.value if isinstance(node.func, cst.Attribute) else None
        span = Span(line, max(line, self.last_line(end)))
        made = PendingCall if long else call_site  # a long call's texts wait for all calls
        self.calls[slot] = made(self.shown, callee, name, receiver, span, arguments, self.owner())
        if not self.fstring_depth:
            self.call_ranges[slot] = (first + len(node.lpar), end - len(node.rpar) - 1)

    def give_targets(self) -> None:
        """Give each call whose value an assignment keeps (alone, or followed by accessors
        only) its target, as the ``ast`` reader does (python_bindings.assignment_target)."""
        for slot, (first, close) in enumerate(self.call_ranges):
            found = self.assigned.get(first)
            call = self.calls[slot]
            if found is None or call is None:
                continue
            name, stop = found
            if close + 1 == stop or accessors_only(self.toks[close + 1 : stop]):
                if isinstance(call, PendingCall):
                    call.target = name
                else:
                    self.calls[slot] = call._replace(target=name)


def parameters(node: cst.FunctionDef) -> tuple[str, ...]:
    """A def's parameter names in the order written (``*args`` as ``args``)."""
    params = node.params
    names = [p.name.value for p in (*params.posonly_params, *params.params)]
    if isinstance(params.star_arg, cst.Param):
        names.append(params.star_arg.name.value)
    names += [p.name.value for p in params.kwonly_params]
    if params.star_kwarg is not None:
        names.append(params.star_kwarg.name.value)
    return tuple(names)


def _decision(kind: str) -> Hook:
    def hook(walker: FactsWalker, node: cst.CSTNode) -> None:
        walker.decide(kind)

    return hook


FactsWalker.enter = {
    cst.Module: FactsWalker.enter_module,
    cst.FunctionDef: FactsWalker.enter_def,
    cst.ClassDef: FactsWalker.enter_class,
    cst.IndentedBlock: FactsWalker.enter_body,
    cst.SimpleStatementSuite: FactsWalker.enter_body,
    **{kind: FactsWalker.enter_simple for kind in rules.SIMPLE_KINDS},
    cst.Assert: FactsWalker.enter_assert,
    cst.If: FactsWalker.enter_if,
    cst.For: FactsWalker.enter_loop,
    cst.While: FactsWalker.enter_loop,
    cst.Try: FactsWalker.enter_try,
    cst.TryStar: FactsWalker.enter_try,
    cst.ExceptHandler: FactsWalker.enter_handler,
    cst.ExceptStarHandler: FactsWalker.enter_handler,
    cst.Else: FactsWalker.enter_else,
    cst.With: FactsWalker.enter_header,
    cst.Match: FactsWalker.enter_match,
    cst.MatchCase: FactsWalker.enter_case,
    cst.IfExp: _decision("ifexp"),
    cst.And: _decision("and"),
    cst.Or: _decision("or"),
    cst.CompFor: _decision("comp_for"),
    cst.CompIf: _decision("comp_if"),
    cst.Call: FactsWalker.enter_call,
    cst.Arg: FactsWalker.enter_arg,
}
FactsWalker.leave = {
    cst.FunctionDef: FactsWalker.leave_def,
    cst.ClassDef: FactsWalker.leave_class,
    **{kind: FactsWalker.leave_simple for kind in rules.SIMPLE_KINDS},
    cst.Assert: FactsWalker.leave_assert,
    cst.Call: FactsWalker.leave_call,
}
