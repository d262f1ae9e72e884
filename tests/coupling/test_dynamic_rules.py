"""How rules apply in real files: requires, priority between packs, definitions, element scope."""

from __future__ import annotations

from archmetrics.coupling import LinkStatus
from tests.coupling.trees import measure


def test_c_read_and_write_count_only_in_files_that_use_sockets() -> None:
    body = "int copy(int fd, char *b) { read(fd, b, 1); return write(fd, b, 1); }\n"
    plain = measure({"io.c": "#include <unistd.h>\n" + body}).element("io")
    sockets = measure({"io.c": "#include <sys/socket.h>\n" + body}).element("io")
    assert (plain.d_e, sockets.d_e) == (0, 2)


def test_requires_sees_includes_through_headers_of_the_tree() -> None:
    report = measure(
        {
            "net/net.h": "#include <sys/socket.h>\n#define PORT 7000\n",
            "app/main.c": (
                '#include "../net/net.h"\n'
                "void go(int fd, struct sockaddr *a) { int p = htons(PORT); connect(fd, a, 16); }\n"
            ),
        }
    )
    sites = report.element("app/main").link_sites
    assert [(s.callee, s.endpoint.key if s.endpoint else None) for s in sites] == [
        ("connect", "port:7000")
    ]


def test_python_rules_need_the_library_imported() -> None:
    source = "def go(s):\n    s.connect(('localhost', 80))\n    s.send(b'x')\n"
    assert measure({"a.py": source}).element("a.py").d_e == 0
    assert measure({"a.py": "import socket\n" + source}).element("a.py").d_e == 2


def test_a_call_matches_one_rule_and_library_packs_win_over_plain_sockets() -> None:
    source = (
        "import socket\nimport zmq\nimport robosoa\n\n"
        "def go(sock, bus):\n"
        "    sock.connect('tcp://localhost:5555')\n"
        "    bus.send('motors', 'stop', {})\n"
    )
    sites = measure({"a.py": source}).element("a.py").link_sites
    assert [s.rule for s in sites] == ["zeromq/py-connect", "robosoa/send"]


def test_player_client_subscribes_into_the_driver_matching_its_interface() -> None:
    report = measure(
        {
            "client/bot.c": (
                "#include <libplayerc/playerc.h>\n"
                "int main(void) {\n"
                '    playerc_client_t *c = playerc_client_create(NULL, "localhost", 6665);\n'
                "    playerc_client_connect(c);\n"
                "    playerc_position2d_t *p = playerc_position2d_create(c, 0);\n"
                "    playerc_position2d_subscribe(p, PLAYER_OPEN_MODE);\n"
                "    playerc_client_read(c);\n"
                "    return 0;\n"
                "}\n"
            ),
            "driver/base.cc": (
                "#include <libplayercore/playercore.h>\n"
                "int Base::ProcessMessage(QueuePointer &q, player_msghdr *hdr, void *data) {\n"
                "    if (Message::MatchMessage(hdr, PLAYER_MSGTYPE_CMD, PLAYER_POSITION2D_CMD_VEL,"
                " device_addr)) { return 0; }\n"
                "    return -1;\n"
                "}\n"
                "void Base::Main() {\n"
                "    Publish(device_addr, PLAYER_MSGTYPE_DATA, PLAYER_POSITION2D_DATA_STATE,"
                " &data, sizeof data, NULL);\n"
                "}\n"
            ),
        }
    )
    client, driver = report.element("client/bot"), report.element("driver/base")
    assert [s.rule.split("/")[1] for s in client.link_sites] == [
        "client-connect", "device-subscribe", "client-read",
    ]  # fmt: skip
    assert [s.rule.split("/")[1] for s in driver.link_sites] == [
        "process-message", "match-message", "driver-publish",
    ]  # fmt: skip
    subscribe = client.link_sites[1]
    assert subscribe.targets == ("driver/base",)
    assert driver.d_a == 1
    assert client.link_sites[0].endpoint is not None
    assert client.link_sites[0].endpoint.key == "port:6665"
    assert client.link_sites[0].status is LinkStatus.EXTERNAL  # the Player server is not here


def test_a_site_never_links_into_its_own_element() -> None:
    report = measure(
        {
            "bus/loop.py": (
                "import robosoa\n\ndef run(bus, cb):\n"
                "    bus.subscribe('tick', cb)\n    bus.publish('tick', {})\n"
            ),
        }
    )
    loop = report.element("bus/loop.py")
    assert (loop.d_e, loop.d_a) == (2, 0)
    assert [s.status for s in loop.link_sites] == [LinkStatus.EXTERNAL, LinkStatus.EXTERNAL]
