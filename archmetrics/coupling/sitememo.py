"""One file's link sites, kept by content: the key says all that decides them, the record holds
them; a tree that shares a file and its reach with one measured before reads them back instead
of matching rules and tracing endpoints again (docs/performance.md, "Link sites by content").

A file's sites (before ``resolve`` gives them status and targets) are decided by: its facts;
for each file it reaches by includes or imports, in order, their facts (the constants a name
is looked up in, the dependencies that make a rule usable); the facts of its element's files
(the same); where its own dependencies resolve (the module bindings); and, the same for every
file of a tree, this archmetrics's code, the parser settings, the coupling options and the rule
packs (``context``). Facts are named by content (``identity``: a blob and a language). The key
is a SHA-256 of all of it; a record is JSON, checked field by field when read back (the store,
a cache file, is not trusted: anything it did not write reads as missing)."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from archmetrics.coupling.model import Endpoint, LinkSite, LinkStatus
from archmetrics.coupling.rules import LinkKind, Role

RECORD = "link-sites/2"


class SiteStore(Protocol):
    """Where records are kept: bytes by key, many at a time."""

    def get_many(self, keys: Sequence[str]) -> Mapping[str, bytes]: ...

    def put_many(self, items: Mapping[str, bytes]) -> None: ...


@dataclass(frozen=True, slots=True)
class SiteMemo:
    """A store, what decides every file's sites alike (``context``: a digest the caller makes
    of the code, the parser settings, the options and the packs) and each file's content id."""

    store: SiteStore
    context: str
    identity: Mapping[str, str]  # path -> content (blob and language)


def site_key(
    memo: SiteMemo,
    path: str,
    reach: Sequence[str],
    element_files: Sequence[str],
    bindings: Sequence[tuple[str, str | None]],
) -> str | None:
    """The key of ``path``'s sites, or None when a file it depends on has no known content.
    ``reach``: the files it reaches, itself first, in order; ``bindings``: its dependencies'
    names and the tree files they resolve to. Paths and content ids hold no NUL (git's paths
    cannot), so joining them with NULs is unambiguous; the bindings are JSON."""
    identity = memo.identity
    parts = [RECORD, memo.context, path]
    for group in (reach, element_files):
        parts.append(str(len(group)))
        for p in group:
            content = identity.get(p)
            if not content:
                return None
            parts.append(p)
            parts.append(content)
    parts.append(json.dumps(bindings, separators=(",", ":")))
    text = "\0".join(parts)
    return RECORD + ":" + hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()


def encode_sites(path: str, sites: Sequence[LinkSite]) -> bytes | None:
    """The record of one file's unresolved sites, or None if one is not such a site."""
    rows: list[list[Any]] = []
    for s in sites:
        if s.path != path or s.status is not LinkStatus.UNRESOLVED or s.targets:
            return None
        endpoint = None
        if s.endpoint is not None:
            point = s.endpoint
            endpoint = [point.key, point.text, point.via, list(point.also)]
        rows.append(
            [s.line, s.rule, s.kind.value, s.role.value, s.callee, endpoint, s.function, s.note,
             s.name, s.node, s.data_type, s.parameter]
        )  # fmt: skip
    return json.dumps(rows, separators=(",", ":")).encode()  # ASCII: any text survives


def decode_sites(path: str, data: bytes) -> tuple[LinkSite, ...] | None:
    """The sites ``encode_sites`` wrote, or None for anything else."""
    try:
        rows = json.loads(data)
    except ValueError:
        return None
    if not isinstance(rows, list):
        return None
    sites = []
    for row in rows:
        site = _site(path, row)
        if site is None:
            return None
        sites.append(site)
    return tuple(sites)


def _site(path: str, row: object) -> LinkSite | None:
    if not (isinstance(row, list) and len(row) == 12):
        return None
    line, rule, kind, role, callee, endpoint, function, note, *names = row
    if not (
        type(line) is int
        and line >= 0
        and all(isinstance(t, str) for t in (rule, kind, role, callee, note, *names))
        and (function is None or isinstance(function, str))
        and kind in _KINDS
        and role in _ROLES
    ):
        return None
    point = None
    if endpoint is not None:
        if not (
            isinstance(endpoint, list)
            and len(endpoint) == 4
            and all(isinstance(t, str) for t in endpoint[:3])
            and isinstance(endpoint[3], list)
            and all(isinstance(t, str) for t in endpoint[3])
        ):
            return None
        key, text, via, also = endpoint
        point = Endpoint(key, text, via, tuple(also))
    name, node, data_type, parameter = names
    return LinkSite(
        path, line, rule, LinkKind(kind), Role(role), callee, point, LinkStatus.UNRESOLVED,
        (), function, note, name, node, data_type, parameter,
    )  # fmt: skip


_KINDS = frozenset(kind.value for kind in LinkKind)
_ROLES = frozenset(role.value for role in Role)
