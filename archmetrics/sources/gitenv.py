"""The environment every git command archmetrics runs gets: read-only, offline, and with no
program the repository's configuration names.

A repository's ``.git/config`` can name programs git runs on its own: ``core.fsmonitor``
(run by every command that reads the index), the ``clean`` / ``smudge`` / ``process`` of a
filter driver (run when a work-tree file is hashed), hooks (``core.hooksPath``), a pager,
an askpass or ssh program, a credential helper. A tarball or CI artifact that carries its
``.git`` carries that file too, so each such setting is overridden for archmetrics's git
commands through ``GIT_CONFIG_COUNT`` / ``GIT_CONFIG_KEY_<n>`` / ``GIT_CONFIG_VALUE_<n>``
(git 2.31+), which outrank every configuration file (docs/security.md). Filter drivers have
names of the configuration's choosing: they are listed with ``git config --list`` (which
runs nothing) and each one's programs are set empty, which git takes as "no filter".
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence

READ_ONLY = {
    "GIT_OPTIONAL_LOCKS": "0",  # no index refresh, no index.lock
    "GIT_NO_LAZY_FETCH": "1",  # a partial clone's missing objects are not fetched (git 2.44+)
    "GIT_ALLOW_PROTOCOL": "",  # ... nor by older git: no transport is allowed at all
    "GIT_TERMINAL_PROMPT": "0",  # never wait for a password
    "GIT_ASKPASS": "",  # ... nor ask a program for one (empty: none; outranks core.askPass)
    "GIT_PAGER": "cat",  # outranks core.pager (never used without a terminal, all the same)
}
"""The environment variables of every git command archmetrics runs."""

SAFE_CONFIG: tuple[tuple[str, str], ...] = (
    ("core.fsmonitor", "false"),
    ("core.hooksPath", os.devnull),
    ("core.pager", "cat"),
    ("core.askPass", ""),
    ("core.sshCommand", "false"),
    ("credential.helper", ""),  # an empty value clears the list of helpers
    ("protocol.allow", "never"),
)
"""Settings that outrank the repository's: no program of its choosing is run."""

_DRIVER_PROGRAMS = {
    "filter": (("clean", ""), ("smudge", ""), ("process", ""), ("required", "false")),
    "diff": (("textconv", ""), ("command", "")),
}


def driver_overrides(names: Iterable[str]) -> list[tuple[str, str]]:
    """Overrides that disable every filter and diff driver among the configuration
    variable ``names`` (``filter.lfs.process``: the driver ``lfs``)."""
    drivers: dict[tuple[str, str], None] = {}
    for name in names:
        section, _, rest = name.partition(".")
        driver = rest.rpartition(".")[0]
        section = section.lower()
        if section in _DRIVER_PROGRAMS and driver:
            drivers[(section, driver)] = None
    return [
        (f"{section}.{driver}.{key}", value)
        for section, driver in drivers
        for key, value in _DRIVER_PROGRAMS[section]
    ]


def config_environment(
    pairs: Sequence[tuple[str, str]], outer: Mapping[str, str] | None = None
) -> dict[str, str]:
    """``pairs`` as ``GIT_CONFIG_*`` variables, after any the caller's environment
    (``outer``, default ``os.environ``) already holds, which stay in force."""
    outer = os.environ if outer is None else outer
    try:
        start = max(0, int(outer.get("GIT_CONFIG_COUNT", "0")))
    except ValueError:
        start = 0
    found = {"GIT_CONFIG_COUNT": str(start + len(pairs))}
    for offset, (key, value) in enumerate(pairs):
        found[f"GIT_CONFIG_KEY_{start + offset}"] = key
        found[f"GIT_CONFIG_VALUE_{start + offset}"] = value
    return found


def safe_environment(config_names: Iterable[str] = ()) -> dict[str, str]:
    """The variables every git command gets: :data:`READ_ONLY` and the overrides of
    :data:`SAFE_CONFIG` and of the drivers among ``config_names``."""
    pairs = [*SAFE_CONFIG, *driver_overrides(config_names)]
    return {**READ_ONLY, **config_environment(pairs)}
