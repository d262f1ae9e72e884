"""The thesis's dynamic-coupling cases (page 110), each on real source through the real parsers."""

from __future__ import annotations

from archmetrics.coupling import EdgeKind, LinkStatus
from tests.coupling.trees import measure

COMMON_H = """
#ifndef COMMON_H
#define COMMON_H
#define PORT "3490"
#define BACKLOG 10
#endif
"""

SERVER_C = r"""
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <netdb.h>
#include <sys/socket.h>
#include "common.h"

int main(void)
{
    struct addrinfo hints, *res;
    int fd, peer;
    char buf[100];
    memset(&hints, 0, sizeof hints);
    getaddrinfo(NULL, PORT, &hints, &res);
    fd = socket(res->ai_family, res->ai_socktype, res->ai_protocol);
    bind(fd, res->ai_addr, res->ai_addrlen);
    listen(fd, BACKLOG);
    while (1) {
        peer = accept(fd, NULL, NULL);
        recv(peer, buf, sizeof buf, 0);
        send(peer, "Hello, world!", 13, 0);
        send(peer, "bye", 3, 0);
    }
    return 0;
}
"""

CLIENT_C = r"""
#include <stdio.h>
#include <netdb.h>
#include <sys/socket.h>
#include "common.h"

int main(int argc, char *argv[])
{
    struct addrinfo hints, *info;
    char buf[100];
    getaddrinfo(argv[1], PORT, &hints, &info);
    int fd = socket(info->ai_family, info->ai_socktype, info->ai_protocol);
    connect(fd, info->ai_addr, info->ai_addrlen);
    send(fd, "hi", 2, 0);
    recv(fd, buf, sizeof buf, 0);
    return 0;
}
"""


def test_c_client_and_server_over_a_socket_on_the_well_known_port() -> None:
    report = measure({"net/common.h": COMMON_H, "net/server.c": SERVER_C, "net/client.c": CLIENT_C})
    server, client = report.element("net/server"), report.element("net/client")
    # d_e: every occurrence counts: bind, accept, recv, send, send (socket/listen are not links)
    assert [s.rule.split("/")[1] for s in server.link_sites] == [
        "c-bind", "c-accept", "c-recv", "c-send", "c-send",
    ]  # fmt: skip
    assert server.d_e == 5
    assert client.d_e == 3  # connect, send, recv
    # the port comes from getaddrinfo(.., PORT, ..) and #define PORT "3490" in common.h
    assert {s.endpoint.key for s in server.link_sites + client.link_sites if s.endpoint} == {
        "port:3490"
    }
    # d_a: initiating sites of the other element that reach a receiving site on the same port
    assert server.d_a == 2  # the client's connect and send
    assert client.d_a == 2  # the server's two sends
    assert [(s.path, s.callee) for s in server.incoming_sites] == [
        ("net/client.c", "connect"), ("net/client.c", "send"),
    ]  # fmt: skip
    # static coupling is what the thesis counted: includes other than stdio.h and stdlib.h
    assert (server.s_e, client.s_e) == (4, 3)  # string.h, netdb.h, sys/socket.h, common.h
    assert report.element("net/common").s_a == 2
    dynamic = {(e.source, e.target, e.label, e.weight) for e in report.graph.edges
               if e.kind is EdgeKind.DYNAMIC}  # fmt: skip
    assert dynamic == {
        ("net/client", "net/server", "port:3490", 2),
        ("net/server", "net/client", "port:3490", 2),
    }


def test_a_port_that_cannot_be_read_is_counted_and_listed_as_unresolved() -> None:
    client = CLIENT_C.replace("getaddrinfo(argv[1], PORT,", "getaddrinfo(argv[1], argv[2],")
    report = measure({"client.c": client})
    coupling = report.element("client")
    assert coupling.d_e == 3
    assert {s.status for s in coupling.link_sites} == {LinkStatus.UNRESOLVED}
    assert len(report.unresolved_sites) == 3


def test_htons_in_the_same_function_then_the_files_one_port() -> None:
    server = """
    #include <sys/socket.h>
    #include <netinet/in.h>
    void serve(int fd) {
        struct sockaddr_in a;
        a.sin_port = htons(8080);
        bind(fd, (struct sockaddr *)&a, sizeof a);
    }
    void other(int fd) { accept(fd, 0, 0); }
    """
    sites = measure({"srv.c": server}).element("srv").link_sites
    assert [(s.callee, s.endpoint.key, s.endpoint.via) for s in sites if s.endpoint] == [
        ("bind", "port:8080", "same-function"),
        ("accept", "port:8080", "same-file"),  # the one port the file's socket sites agree on
    ]


PUBLISHER_PY = """
import robosoa

def main():
    bus = robosoa.connect("inproc")
    bus.publish("pose", {"x": 1.0, "y": 2.0})
"""

SUBSCRIBER_PY = """
import robosoa

def on_pose(message):
    print(message.payload)

def main():
    bus = robosoa.connect("inproc")
    bus.subscribe("pose", on_pose)
"""


def test_python_publisher_and_subscriber_on_a_robosoa_topic() -> None:
    report = measure({"nav/publisher.py": PUBLISHER_PY, "nav/subscriber.py": SUBSCRIBER_PY})
    publisher, subscriber = report.element("nav/publisher.py"), report.element("nav/subscriber.py")
    assert subscriber.d_a == 1
    assert publisher.d_a == 0
    assert (publisher.d_e, subscriber.d_e) == (2, 2)  # connect + publish, connect + subscribe
    publish = next(s for s in publisher.link_sites if s.rule == "robosoa/publish")
    assert (publish.endpoint.key if publish.endpoint else None, publish.targets) == (
        "topic:pose",
        ("nav/subscriber.py",),
    )
    assert (publisher.s_e, subscriber.s_e) == (1, 1)  # robosoa, outside the tree
    assert [(e.source, e.target, e.label) for e in report.graph.edges] == [
        ("nav/publisher.py", "nav/subscriber.py", "topic:pose")
    ]


def test_python_request_resolves_to_the_provider_of_the_service() -> None:
    report = measure(
        {
            "wdb/service.py": (
                "import robosoa\n\ndef serve(bus, handler):\n"
                "    bus.provide('wdb', handler, operations=('get', 'put'))\n"
            ),
            "client/main.py": (
                "import robosoa\n\nSERVICE = 'wdb'\n\ndef run(bus):\n"
                "    bus.request(SERVICE, 'get', {'key': 1})\n"
                "    bus.request(service='wdb', operation='put', payload={})\n"
                "    bus.request('maps', 'get', {})\n"
            ),
        }
    )
    client = report.element("client/main.py")
    assert [(s.endpoint.key if s.endpoint else None, s.status) for s in client.link_sites] == [
        ("service:wdb", LinkStatus.RESOLVED),
        ("service:wdb", LinkStatus.RESOLVED),
        ("service:maps", LinkStatus.EXTERNAL),  # read, but nothing in the tree provides it
    ]
    assert report.element("wdb/service.py").d_a == 2


def test_pyzmq_publisher_and_subscriber_meet_at_the_port() -> None:
    report = measure(
        {
            "pub.py": (
                "import zmq\n\ndef main():\n    sock = zmq.Context().socket(zmq.PUB)\n"
                "    sock.bind('tcp://*:5556')\n    sock.send_string('pose 1')\n"
            ),
            "sub.py": (
                "import zmq\n\ndef main():\n    sock = zmq.Context().socket(zmq.SUB)\n"
                "    sock.connect('tcp://localhost:5556')\n    return sock.recv_string()\n"
            ),
        }
    )
    pub, sub = report.element("pub.py"), report.element("sub.py")
    assert (pub.d_e, sub.d_e) == (2, 2)
    assert pub.d_a == 1  # the subscriber's connect reaches the bound port
    assert sub.d_a == 1  # the publisher's send reaches the subscriber's recv on that port


def test_rtti_and_dynamic_loading_count_every_occurrence_without_linking() -> None:
    source = """
    #include <dlfcn.h>
    struct Base { virtual ~Base(); };
    struct Laser : Base {};
    void probe(Base *b) {
        if (dynamic_cast<Laser *>(b)) {}
        if (dynamic_cast<Laser *>(b)) {}
        void *h = dlopen("libdriver.so", RTLD_NOW);
        void *f = dlsym(h, "init");
    }
    """
    coupling = measure({"probe.cpp": source}).element("probe")
    assert coupling.d_e == 4
    assert coupling.d_a == 0
    assert [s.status for s in coupling.link_sites] == [
        LinkStatus.LOCAL, LinkStatus.LOCAL, LinkStatus.EXTERNAL, LinkStatus.LOCAL,
    ]  # fmt: skip
