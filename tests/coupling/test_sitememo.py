"""Each file's link sites kept by content (coupling/sitememo.py): a tree measured with the memo
reports what it reports without; a file whose reach changed is found again, the others are
read back; a record the store did not write is recomputed."""

from __future__ import annotations

import hashlib
from collections.abc import Mapping, Sequence

import pytest

from archmetrics.coupling import CouplingOptions, CouplingReport, LinkStatus, measure_coupling
from archmetrics.coupling.model import Endpoint, LinkSite
from archmetrics.coupling.rules import LinkKind, Role
from archmetrics.coupling.sitememo import SiteMemo, decode_sites, encode_sites
from tests.coupling.test_tracing import BEEJ_CLIENT
from tests.coupling.trees import BUILTIN, tree_facts

PORT_H = '#define PORT "3490"\n'
CLIENT = BEEJ_CLIENT.replace('#define PORT "3490"\n', '#include "net/port.h"\n')
SERVER = r"""
#include <sys/socket.h>
#include <netinet/in.h>
void serve(int fd, struct sockaddr_in *a) { a->sin_port = htons(3490); bind(fd, 0, 0); }
"""
PLAIN = "def helper(a):\n    return a\n"


class Store:
    """A store in memory that counts what it is asked and what it serves."""

    def __init__(self) -> None:
        self.data: dict[str, bytes] = {}
        self.served = 0

    def get_many(self, keys: Sequence[str]) -> Mapping[str, bytes]:
        found = {k: self.data[k] for k in keys if k in self.data}
        self.served += len(found)
        return found

    def put_many(self, items: Mapping[str, bytes]) -> None:
        self.data.update(items)


def _tree(port_h: str = PORT_H) -> dict[str, str]:
    return {"net/port.h": port_h, "client.c": CLIENT, "server.c": SERVER, "util.py": PLAIN}


def _measure(files: dict[str, str], store: Store | None = None) -> CouplingReport:
    facts = tree_facts(files)
    memo = None
    if store is not None:
        identity = {
            f.path: hashlib.sha256(files[f.path].encode()).hexdigest() + ":" + f.language
            for f in facts
        }
        memo = SiteMemo(store, "context", identity)
    return measure_coupling(facts, CouplingOptions(), BUILTIN, memo)


def _endpoints(report: CouplingReport) -> list[tuple[str, str, str | None, LinkStatus]]:
    return [
        (s.path, s.callee, s.endpoint.key if s.endpoint else None, s.status)
        for e in report.elements
        for s in e.link_sites
    ]


def test_a_tree_measured_again_reads_every_files_sites_back() -> None:
    plain = _measure(_tree())
    assert ("client.c", "connect", "port:3490", LinkStatus.RESOLVED) in _endpoints(plain)
    store = Store()
    assert _measure(_tree(), store) == plain
    # one record per file a rule names a callee of (client.c, server.c), all computed; the
    # header and util.py call nothing a rule names: no sites, nothing to keep
    assert len(store.data) == 2 and store.served == 0
    assert _measure(_tree(), store) == plain
    assert store.served == 2


def test_a_changed_header_finds_again_the_files_that_reach_it_only() -> None:
    store = Store()
    _measure(_tree(), store)
    changed = _tree('#define PORT "4000"\n')
    served = store.served
    report = _measure(changed, store)
    assert report == _measure(changed)
    assert ("client.c", "connect", "port:4000", LinkStatus.EXTERNAL) in _endpoints(report)
    # the server read back; the client, which includes the header, found again
    assert store.served - served == 1
    assert len(store.data) == 3


@pytest.mark.parametrize(
    "record",
    [
        b"not json",
        b"{}",
        b"[[1]]",
        b'[[1,"r","socket","nope","c","",null,""]]',
        b'[[true,"r","socket","initiate","c",null,null,""]]',
        b'[[1,"r","socket","initiate","c",["k","t"],null,""]]',
    ],
    ids=["not-json", "not-a-list", "short-row", "unknown-role", "bool-line", "short-endpoint"],
)
def test_a_record_the_store_did_not_write_is_found_again(record: bytes) -> None:
    plain = _measure(_tree())
    store = Store()
    _measure(_tree(), store)
    store.data = dict.fromkeys(store.data, record)
    assert _measure(_tree(), store) == plain


def test_a_file_of_unknown_content_is_found_and_not_kept() -> None:
    files = _tree()
    facts = tree_facts(files)
    store = Store()
    identity = {f.path: "x:" + f.language for f in facts if f.path != "net/port.h"}
    report = measure_coupling(facts, CouplingOptions(), BUILTIN, SiteMemo(store, "c", identity))
    assert report == _measure(files)
    # the client, which reaches the header, is not kept; the server is (the header and
    # util.py have no sites to keep)
    assert len(store.data) == 1


def test_records_round_trip_every_field() -> None:
    sites = (
        LinkSite("a.c", 3, "posix/connect", LinkKind.SOCKET, Role.INITIATE, "connect",
                 Endpoint("port:1", "PORT", "constant"), LinkStatus.UNRESOLVED, (), "main",
                 "note \u00e9 \ud800"),
        LinkSite("a.c", 9, "dl/dlopen", LinkKind.DYNAMIC_LOAD, Role.USE, "dlopen", None,
                 LinkStatus.UNRESOLVED),
    )  # fmt: skip
    record = encode_sites("a.c", sites)
    assert record is not None and record.isascii()
    assert decode_sites("a.c", record) == sites
    resolved = (sites[1].__class__(*[*_fields(sites[1])[:7], LinkStatus.LOCAL]),)
    assert encode_sites("a.c", resolved) is None  # only sites not yet resolved are kept
    assert encode_sites("b.c", sites) is None  # nor another file's


def _fields(site: LinkSite) -> list[object]:
    return [getattr(site, name) for name in site.__slots__]  # type: ignore[attr-defined]
