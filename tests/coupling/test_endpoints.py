"""Endpoint reading and normalization, callee matching and rule choice (pure functions)."""

from __future__ import annotations

import pytest

from archmetrics.coupling.dynamic import (
    choose_rule,
    matches,
    normalize_callee,
    read_endpoint,
    requirement_met,
)
from archmetrics.coupling.endpoints import chain_lookup, constants_of, literal, normalize
from archmetrics.coupling.rules import EndpointSpec, FunctionHint, LinkKind, Role, Rule
from archmetrics.coupling.trace import plain_reader
from archmetrics.facts import Argument, CallSite, Span
from tests.harness import facts_of


@pytest.mark.parametrize(
    ("kind", "value", "key"),
    [
        ("address", "tcp://*:5555", "port:5555"),
        ("address", "tcp://localhost:5555", "port:5555"),
        ("address", "tcp://127.0.0.1:5555/", "port:5555"),
        ("address", "zmq://tcp://127.0.0.1:5570", "port:5570"),
        ("address", ("", 5555), "port:5555"),
        ("address", ("localhost", "5555"), "port:5555"),
        ("address", 5555, "port:5555"),
        ("address", "ipc:///tmp/feed", "address:ipc:///tmp/feed"),
        ("address", "INPROC://bus", "address:inproc://bus"),
        ("address", "inproc", "address:inproc"),
        ("port", "3490", "port:3490"),
        ("port", 3490, "port:3490"),
        ("port", 70000, None),
        ("port", True, None),
        ("library", "libdriver.so.1.2", "library:driver"),
        ("library", "/usr/lib/libzmq.so", "library:zmq"),
        ("library", "C:\\plugins\\camera.dll", "library:camera"),
        ("library", "libfoo.dylib", "library:foo"),
        ("ice", "SimplePrinter:default -p 10000", "port:10000"),
        ("ice", "tcp -h localhost -p 10000 -t 500", "port:10000"),
        ("ice", "Printer@PrinterAdapter", "ice:Printer"),
        ("interface", "POSITION2D", "interface:position2d"),
        ("topic", "pose", "topic:pose"),
        ("topic", b"pose", "topic:pose"),
        ("topic", "  ", None),
        ("service", 3.5, None),
    ],
)
def test_normalize(kind: str, value: object, key: str | None) -> None:
    assert normalize(kind, value) == key  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("text", "value"),
    [('"3490"', "3490"), ("(3490)", 3490), ("3490", 3490), ("'x'", "x"),
     ('( "localhost" , 80 )', ("localhost", 80)), ("argv[1]", None), ("PORT", None)],
)  # fmt: skip
def test_literal_reads_c_and_python_spellings(text: str, value: object) -> None:
    assert literal(text) == value


def test_constants_come_from_file_level_definitions_only() -> None:
    c = facts_of(
        """
        #define PORT "3490"
        #define ALIAS PORT
        #define MAX(a, b) ((a) > (b) ? (a) : (b))
        static const int BACKLOG = 10, QUEUE = 4;
        static const char *HOST = "localhost";
        int main(void) { int LOCAL = 1; return LOCAL; }
        """,
        "c",
    )
    assert constants_of(c.bindings) == {
        "PORT": "3490", "ALIAS": "3490", "BACKLOG": 10, "QUEUE": 4, "HOST": "localhost",
    }  # fmt: skip
    python = facts_of(
        "TOPIC = 'pose'\nPAIR: tuple = ('', 5555)\nclass K:\n    RATE = 10\n"
        "def f():\n    LOCAL = 1\n",
        "python",
    )
    assert constants_of(python.bindings) == {"TOPIC": "pose", "PAIR": ("", 5555), "RATE": 10}


@pytest.mark.parametrize(
    ("callee", "normalized"),
    [
        ("ctx . socket ( zmq . PUB ) . bind", "ctx.socket().bind"),
        ("::connect", "connect"),
        ("std::dynamic_pointer_cast<Laser>", "std.dynamic_pointer_cast"),
        ("client->sock.connect", "client.sock.connect"),
        ("IceStorm::TopicManagerPrx::checkedCast", "IceStorm.TopicManagerPrx.checkedCast"),
    ],
)
def test_normalize_callee(callee: str, normalized: str) -> None:
    assert normalize_callee(callee) == normalized


@pytest.mark.parametrize(
    ("pattern", "callee", "expected"),
    [
        ("connect", "connect", True),
        ("connect", "::connect", True),
        ("connect", "sock.connect", False),
        ("*.connect", "sock.connect", True),
        ("*.connect", "self.sock->connect", True),
        ("*.connect", "connect", False),
        ("*.connect", "sock.reconnect", False),
        ("socket.socket", "socket.socket", True),
        ("socket.socket", "s.socket", False),
        ("playerc_*_subscribe", "playerc_laser_subscribe", True),
        ("std.any_cast", "std::any_cast<int>", True),
    ],
)
def test_match_syntax(pattern: str, callee: str, expected: bool) -> None:
    assert matches(pattern, callee) is expected


def test_requires_matches_modules_and_include_paths() -> None:
    assert requirement_met([], [])
    assert requirement_met(["zmq"], ["os", "zmq.asyncio"])
    assert requirement_met(["sys/socket.h"], ["sys/socket.h"])
    assert requirement_met(["playerc.h"], ["libplayerc/playerc.h"])
    assert not requirement_met(["zmq"], ["zmqlike", "pyzmq"])
    assert not requirement_met(["socket.h"], ["mysocket.h"])


def _rule(rule_id: str, priority: int = 0, pattern: str = "*.send") -> Rule:
    return Rule("p", rule_id, ("python",), (pattern,), LinkKind.SOCKET, Role.INITIATE,
                priority=priority)  # fmt: skip


def test_the_highest_priority_wins_then_load_order() -> None:
    rules = [_rule("a"), _rule("b", 5), _rule("c", 5), _rule("d", 1, "other")]
    assert choose_rule("s.send", rules) == rules[1]
    assert choose_rule("s.recv", rules) is None


def _call(callee: str, *arguments: Argument, line: int = 1, function: str = "f") -> CallSite:
    name = callee.rsplit(".", 1)[-1]
    return CallSite(callee, name, None, Span(line, line), arguments, function)


def test_endpoint_by_keyword_position_constant_and_same_function() -> None:
    lookup = plain_reader(chain_lookup([{"TOPIC": "pose"}]))
    spec = EndpointSpec("topic", arg=0, keyword="topic")
    by_keyword = _call("bus.publish", Argument("{}"), Argument('"a"', "a", True, "topic"))
    by_constant = _call("bus.publish", Argument("TOPIC"))
    unreadable = _call("bus.publish", Argument("name + suffix"))
    found = [read_endpoint(c, spec, [], lookup)[0] for c in (by_keyword, by_constant, unreadable)]
    assert [(e.key, e.via) if e else None for e in found] == [
        ("topic:a", "argument"), ("topic:pose", "constant"), None,
    ]  # fmt: skip
    hinted = EndpointSpec("port", same_function=(FunctionHint("htons", 0),))
    send = _call("send", Argument("fd"), line=9)
    scope = [send, _call("htons", Argument("80", 80, True), line=3),
             _call("htons", Argument("81", 81, True), line=5, function="g")]  # fmt: skip
    endpoint, note = read_endpoint(send, hinted, scope, lookup)
    assert note == "" and endpoint is not None
    assert (endpoint.key, endpoint.via) == ("port:80", "same-function")
