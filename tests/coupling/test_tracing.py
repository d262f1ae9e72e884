"""Endpoints not written at the call: variables, parameters, module constants, the file's port."""

from __future__ import annotations

from archmetrics.coupling import LinkStatus
from tests.coupling.trees import measure

BEEJ_CLIENT = r"""
#include <stdlib.h>
#include <netdb.h>
#include <sys/socket.h>
#define PORT "3490"

static int connect_to(const char *host, const char *port)
{
    struct addrinfo hints, *info;
    getaddrinfo(host, port, &hints, &info);
    int fd = socket(info->ai_family, info->ai_socktype, info->ai_protocol);
    connect(fd, info->ai_addr, info->ai_addrlen);
    return fd;
}

static void talk(int fd, char *buf)
{
    send(fd, "GET", 3, 0);
    recv(fd, buf, 100, 0);
}

int main(int argc, char *argv[])
{
    const char *port = getenv("WDB_PORT") ? getenv("WDB_PORT") : PORT;
    if (argc > 2) port = argv[2];
    char buf[100];
    talk(connect_to(argv[1], port), buf);
    return 0;
}
"""


def _endpoints(report: object, element: str) -> list[tuple[str, str | None, str]]:
    sites = report.element(element).link_sites  # type: ignore[attr-defined]
    return [(s.callee, s.endpoint.key if s.endpoint else None, s.endpoint.via if s.endpoint
             else s.note) for s in sites]  # fmt: skip


def test_a_port_parameter_is_traced_to_the_callers_variable_and_its_constant() -> None:
    assert _endpoints(measure({"client.c": BEEJ_CLIENT}), "client") == [
        ("connect", "port:3490", "same-function"),  # getaddrinfo(.., port) <- main's port <- PORT
        ("send", "port:3490", "same-file"),  # talk() has no port: the file's one port
        ("recv", "port:3490", "same-file"),
    ]


def test_callers_giving_different_ports_leave_the_site_unresolved_with_a_note() -> None:
    source = BEEJ_CLIENT.replace(
        "talk(connect_to(argv[1], port), buf);",
        'talk(connect_to(argv[1], port), buf);\n    connect_to(argv[1], "4000");',
    )
    report = measure({"client.c": source})
    connect = report.element("client").link_sites[0]
    assert (connect.endpoint, connect.status) == (None, LinkStatus.UNRESOLVED)
    assert "several values" in connect.note and "'3490'" in connect.note
    # the file's other sites do not borrow a port from an ambiguous site
    assert [s.endpoint for s in report.element("client").link_sites] == [None, None, None]


def test_the_file_fallback_asks_the_same_role_first_and_refuses_two_ports() -> None:
    source = r"""
    #include <sys/socket.h>
    #include <netinet/in.h>
    void serve(int fd, struct sockaddr_in *a) { a->sin_port = htons(7000); bind(fd, 0, 0); }
    void call(int fd, struct sockaddr_in *a) { a->sin_port = htons(7001); connect(fd, 0, 0); }
    void reply(int fd) { send(fd, "x", 1, 0); }
    void take(int fd) { accept(fd, 0, 0); }
    """
    assert _endpoints(measure({"peer.c": source}), "peer") == [
        ("bind", "port:7000", "same-function"),
        ("connect", "port:7001", "same-function"),
        ("send", "port:7001", "same-file"),  # initiating, like connect
        ("accept", "port:7000", "same-file"),  # receiving, like bind
    ]


def test_python_port_from_a_variable_set_from_the_environment_or_a_constant() -> None:
    source = (
        "import os\nimport socket\n\nDEFAULT_PORT = 9000\n\n"
        "def serve():\n"
        "    port = int(os.environ.get('PORT', DEFAULT_PORT))\n"
        "    s = socket.socket()\n    s.bind(('', port))\n"
    )
    assert _endpoints(measure({"srv.py": source}), "srv.py") == [("s.bind", "port:9000", "traced")]
    source = source.replace("s.bind(('', port))", "s.bind(('', DEFAULT_PORT))")
    assert _endpoints(measure({"srv.py": source}), "srv.py") == [
        ("s.bind", "port:9000", "constant")
    ]
    source = source.replace("s.bind(('', DEFAULT_PORT))", "s.bind(('', int(sys.argv[1])))")
    assert _endpoints(measure({"srv.py": source}), "srv.py") == [("s.bind", None, "")]


def test_python_parameter_traced_through_a_method_call() -> None:
    source = (
        "import robosoa\n\nTOPIC = 'pose'\n\nclass Pub:\n"
        "    def announce(self, bus, topic):\n        bus.publish(topic, {})\n\n"
        "def main(bus):\n    Pub().announce(bus, TOPIC)\n"
    )
    assert _endpoints(measure({"pub.py": source}), "pub.py") == [
        ("bus.publish", "topic:pose", "traced")
    ]


def test_calls_through_a_module_name_are_static_and_module_constants_are_read() -> None:
    report = measure(
        {
            "proxy/__init__.py": "",
            "proxy/utils.py": (
                "import robosoa\n\nSERVICE = 'wdb'\n\n"
                "def request(bus, op, doc):\n    return bus.request(SERVICE, op, {'doc': doc})\n"
            ),
            "proxy/rep.py": (
                "import robosoa\nfrom proxy import utils as su\n\n"
                "def get(bus):\n    bus.wait_for(su.SERVICE)\n"
                "    return su.request(bus, 'get', '')\n"
            ),
            "service.py": "import robosoa\n\ndef serve(bus, h):\n    bus.provide('wdb', h)\n",
        }
    )
    rep = report.element("proxy/rep.py")
    assert _endpoints(report, "proxy/rep.py") == [("bus.wait_for", "service:wdb", "constant")]
    assert rep.d_e == 1  # su.request(...) is a call into proxy/utils.py, counted there
    assert report.element("service.py").d_a == 1  # utils' bus.request
