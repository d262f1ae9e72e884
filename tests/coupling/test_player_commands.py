"""Player commands sent with playerc_client_write are dynamic links (thesis p. 110), one a call.

libplayerc's own proxies send every command this way (e.g. playerc_position2d_set_cmd_vel), and
so do the study's Pragmatics interface plugins: before the rule existed, a proxy function added
for a new message added no dynamic efferent coupling at all.
"""

from __future__ import annotations

from pathlib import Path

from archmetrics.coupling import LinkStatus
from tests.coupling.trees import measure

STUDY = Path(__file__).resolve().parents[2] / "fixtures" / "study" / "pragmatics" / "player"

PROXY_C = """\
#include <string.h>
#include <libplayerc/playerc.h>

int drive(playerc_device_t *device, double distance)
{
  struct { double distance; } cmd;
  memset(&cmd, 0, sizeof cmd);
  cmd.distance = distance;
  return playerc_client_write(device->client, device, PLAYER_MURIPRAGINTERF_CMD_DRIVE, &cmd, NULL);
}

int stop(playerc_device_t *device)
{
  return playerc_client_write(device->client, device, PLAYER_MURIPRAGINTERF_CMD_STOP, NULL, NULL);
}
"""


def test_each_command_write_is_one_link_to_its_interface() -> None:
    proxy = measure({"proxy.c": PROXY_C}).element("proxy")
    writes = [s for s in proxy.link_sites if s.rule == "player/client-write"]
    assert len(writes) == 2
    assert proxy.d_e == 2
    assert {s.endpoint.key for s in writes if s.endpoint} == {"interface:muripraginterf"}
    assert {s.status for s in writes} != {LinkStatus.UNRESOLVED}


def test_without_libplayerc_a_function_named_alike_is_no_link() -> None:
    source = PROXY_C.replace("#include <libplayerc/playerc.h>\n", "")
    assert measure({"proxy.c": source}).element("proxy").d_e == 0


def test_the_study_proxies_count_one_link_per_command_function() -> None:
    """Each stage of the Pragmatics subject adds one command function to two proxies."""
    counts = []
    for stage in ("baseline", "first", "second"):
        path = STUDY / stage / "interfaces" / "muribackendinterf" / "muribackendinterf_client.c"
        source = path.read_text(encoding="utf-8")
        proxy = measure({"muribackendinterf_client.c": source}).element("muribackendinterf_client")
        writes = [s for s in proxy.link_sites if s.rule == "player/client-write"]
        assert len(writes) == source.count("playerc_client_write(")
        counts.append(len(writes))
    assert counts == [counts[0], counts[0] + 1, counts[0] + 2]


def test_write_to_a_file_descriptor_just_opened_is_no_socket_link() -> None:
    from archmetrics.coupling import load_rule_packs, measure_coupling
    from tests.harness import facts_of

    source = """\
        #include <sys/socket.h>
        #include <stdlib.h>
        #include <unistd.h>
        int spool(const char *s) {
            char p[] = "/tmp/xXXXXXX";
            int fd = mkstemp(p);
            return (int) write(fd, s, 1);
        }
        int reply(int sock, const char *s) { return (int) write(sock, s, 1); }
        """
    facts = facts_of(source, "c", "srv.c")
    report = measure_coupling([facts], None, load_rule_packs(plugins=False))
    [element] = report.elements
    assert [(s.line, s.rule) for s in element.link_sites] == [(9, "posix-sockets/c-write")]
