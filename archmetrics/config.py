"""Settings from ``archmetrics.toml`` or ``[tool.archmetrics]`` in ``pyproject.toml``.

The files are read once, at the edge, into one frozen :class:`Settings`; the CLI lays its flags
over it. An unknown key or a value of the wrong type is an error naming the file and the key.
"""

from __future__ import annotations

import os
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from difflib import get_close_matches
from pathlib import Path
from typing import Any

from archmetrics.globs import BadPattern, compile_glob
from archmetrics.reading import TooLarge, read_regular

CONFIG_FILES = ("archmetrics.toml", "pyproject.toml")


class ConfigError(Exception):
    """A bad configuration file or value; the message is one line naming file and key."""


@dataclass(frozen=True, slots=True)
class LocationSettings:
    new: tuple[str, ...] = ()
    framework: tuple[str, ...] = ()
    base: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class CouplingSettings:
    per_file: bool = False
    group: str = "component"  # component | file | package | node (docs/metrics.md, Elements)
    include_dirs: tuple[str, ...] = ()
    ignore_includes: tuple[str, ...] = ("stdio.h", "stdlib.h")
    ignore_imports: tuple[str, ...] = ("__future__",)
    rule_packs: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class LimitSettings:
    """What one file may cost (docs/security.md, "Bounded work per file"; docs/metrics.md,
    "Limits"). A repository's configuration may lower or raise them, up to
    :data:`LIMIT_CEILINGS`."""

    file_seconds: float = 120.0  # wall-clock seconds to parse one file (the worker pool)
    worker_memory_mb: int = 4096  # MiB of address space a parser process may add
    file_mb: float = 16.0  # a larger file is not read (ParseLimits.max_bytes)
    nesting: int = 20_000  # the deepest syntax tree a reader builds (ParseLimits.max_depth)
    parse_seconds: float = 20.0  # tree-sitter's parse of one file (ParseLimits.parse_seconds)


LIMIT_CEILINGS: dict[str, float] = {
    "file-seconds": 3600,
    "worker-memory-mb": 65536,
    "file-mb": 1024,
    "nesting": 60_000,
    "parse-seconds": 3600,
}
"""The most a configuration may allow with ``--allow-raised-limits``: an untrusted
repository can make its own run slow, never endless. Without the flag a repository may only
lower a limit (app/settings.py)."""

LIMIT_FLOORS: dict[str, float] = {"file-mb": 0.001}
"""The least a limit may be where "more than 0" is not enough: ``file-mb = 1e-9`` would be
a limit of 0 bytes."""

_WHOLE_NUMBERS = {"worker-memory-mb", "nesting"}


def _limits(table: Mapping[str, Any], where: str) -> LimitSettings:
    _check_keys(table, set(LIMIT_CEILINGS), where)
    values: dict[str, Any] = {}
    for key, value in table.items():
        here, ceiling = f"{where}.{key}", LIMIT_CEILINGS[key]
        number_types = (int,) if key in _WHOLE_NUMBERS else (int, float)
        if not isinstance(value, number_types) or isinstance(value, bool):
            raise ConfigError(f"{here}: expected a number")
        floor = LIMIT_FLOORS.get(key)
        if not 0 < value <= ceiling or (floor is not None and value < floor):  # NaN fails too
            least = f"at least {floor:g}" if floor is not None else "more than 0"
            raise ConfigError(f"{here}: expected {least} and at most {ceiling:g}")
        values[key.replace("-", "_")] = value
    return LimitSettings(**values)


@dataclass(frozen=True, slots=True)
class MacroSettings:
    """C/C++ macros the parsers cannot tell from their place and spelling (docs/metrics.md,
    "Macros and #if"): ``attribute`` macros expand to nothing a metric counts (export and
    annotation macros, e.g. a lower-case ``my_export``); ``function`` macros head a
    function definition (``TEST(Suite, Name) { ... }``)."""

    attribute: tuple[str, ...] = ()
    function: tuple[str, ...] = ()


MAX_MACROS = 10_000
_MACRO_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,199}")


def _macros(table: Mapping[str, Any], where: str) -> MacroSettings:
    _check_keys(table, {"attribute", "function"}, where)
    values: dict[str, tuple[str, ...]] = {}
    for key, value in table.items():
        here = f"{where}.{key}"
        names = _strings(value, here)
        if len(names) > MAX_MACROS:
            raise ConfigError(f"{here}: more than {MAX_MACROS:,} names")
        for name in names:
            if not _MACRO_NAME.fullmatch(name):
                raise ConfigError(
                    f"{here}: {name[:40]!r} is not a C identifier (at most 200 characters)"
                )
        values[key] = tuple(sorted(set(names)))
    return MacroSettings(**values)


@dataclass(frozen=True, slots=True)
class Settings:
    """Everything configurable, with its defaults. ``source`` names the file it came from."""

    source: str = "(defaults)"
    languages: tuple[tuple[str, str], ...] = ()  # file ending -> language ("" drops the ending)
    exclude: tuple[str, ...] = ()
    include_generated: bool = False
    locations: LocationSettings = field(default_factory=LocationSettings)
    coupling: CouplingSettings = field(default_factory=CouplingSettings)
    gates: tuple[str, ...] = ()
    cache_path: str | None = None
    cache: bool = True
    jobs: int = 0  # 0: one worker per core
    limits: LimitSettings = field(default_factory=LimitSettings)
    macros: MacroSettings = field(default_factory=MacroSettings)
    gate_lines: tuple[int, ...] = ()  # the line of ``source`` each of ``gates`` is written on
    notices: tuple[str, ...] = ()  # what the reader should know of how this was read, and
    # what the run changed of these settings: said on stderr
    revision: str | None = None  # the git revision they (and their rule packs) were read
    # from; None: files on disk


def _strings(value: Any, where: str) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ConfigError(f"{where}: expected a list of strings")
    return tuple(value)


def _bool(value: Any, where: str) -> bool:
    if not isinstance(value, bool):
        raise ConfigError(f"{where}: expected true or false")
    return value


def _table(value: Any, where: str) -> Mapping[str, Any]:
    if not isinstance(value, dict):
        raise ConfigError(f"{where}: expected a table")
    return value


def _check_keys(table: Mapping[str, Any], allowed: set[str], where: str) -> None:
    for key in table:
        if key not in allowed:
            raise ConfigError(f"{where}: unknown key {key!r} (known: {', '.join(sorted(allowed))})")


def _globs(value: Any, where: str) -> tuple[str, ...]:
    """A list of path globs, each checked now, so a bad one is named with its file and key."""
    globs = _strings(value, where)
    for glob in globs:
        try:
            compile_glob(glob)
        except BadPattern as error:
            raise ConfigError(f"{where}: {error}") from None
    return globs


def _locations(table: Mapping[str, Any], where: str) -> LocationSettings:
    _check_keys(table, {"new", "framework", "base"}, where)
    return LocationSettings(
        **{key: _globs(value, f"{where}.{key}") for key, value in table.items()}
    )


def _coupling(table: Mapping[str, Any], where: str) -> CouplingSettings:
    names = {"per-file", "include-dirs", "ignore-includes", "ignore-imports", "rule-packs", "group"}
    _check_keys(table, names, where)
    values: dict[str, Any] = {}
    for key, value in table.items():
        here = f"{where}.{key}"
        if key == "group":
            values[key] = _choice(value, here, GROUPINGS)
            continue
        values[key.replace("-", "_")] = (
            _bool(value, here) if key == "per-file" else _strings(value, here)
        )
    return CouplingSettings(**values)


GROUPINGS = ("component", "file", "package", "node")  # coupling/elements.py


def _choice(value: Any, where: str, allowed: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value not in allowed:
        raise ConfigError(f"{where}: expected one of {', '.join(allowed)}")
    return value


def _int(value: Any, where: str) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or value < 0:
        raise ConfigError(f"{where}: expected a non-negative integer")
    return value


def parse_settings(table: Mapping[str, Any], source: str) -> Settings:
    """Settings from the archmetrics table of a config file (already TOML-decoded)."""
    known = {
        "languages",
        "exclude",
        "include-generated",
        "locations",
        "coupling",
        "gates",
        "cache-path",
        "cache",
        "jobs",
        "limits",
        "macros",
    }
    _check_keys(table, known, source)
    values: dict[str, Any] = {"source": source}
    for key, value in table.items():
        here = f"{source}: {key}"
        if key == "languages":
            langs = _table(value, here)
            for ending, language in langs.items():
                if not isinstance(language, str):
                    raise ConfigError(f"{here}.{ending}: expected a language name")
            values["languages"] = tuple(sorted(langs.items()))
        elif key == "exclude":
            values[key] = _globs(value, here)
        elif key == "gates":
            values[key] = _strings(value, here)
        elif key in ("include-generated", "cache"):
            values[key.replace("-", "_")] = _bool(value, here)
        elif key == "locations":
            values["locations"] = _locations(_table(value, here), here)
        elif key == "coupling":
            values["coupling"] = _coupling(_table(value, here), here)
        elif key == "limits":
            values["limits"] = _limits(_table(value, here), here)
        elif key == "macros":
            values["macros"] = _macros(_table(value, here), here)
        elif key == "cache-path":
            if not isinstance(value, str) or "\0" in value:
                raise ConfigError(f"{here}: expected a path (without a NUL character)")
            values["cache_path"] = value
        else:
            values["jobs"] = _int(value, here)
    return Settings(**values)


MAX_CONFIG_BYTES = 1 << 20
"""A configuration file larger than this (1 MiB) is refused rather than read."""


def read_document(path: Path) -> tuple[dict[str, Any], str]:
    """The TOML document at ``path`` and its text; ConfigError for anything that is not
    one, however odd (a huge file, a FIFO or device, nesting deep enough to exhaust the
    parser's recursion, a bad encoding)."""
    try:
        data = read_regular(path, MAX_CONFIG_BYTES)
    except TooLarge:
        raise ConfigError(f"{path}: larger than {MAX_CONFIG_BYTES} bytes; not read") from None
    except OSError as error:
        raise ConfigError(f"{path}: cannot read: {error.strerror or error}") from error
    return parse_toml(data, str(path)), data.decode("utf-8", "replace")


def parse_toml(data: bytes, source: str) -> dict[str, Any]:
    """The TOML document in ``data`` (read from ``source``, which errors name)."""
    try:
        return tomllib.loads(data.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise ConfigError(f"{source}: not valid TOML: {error}") from error
    except RecursionError:
        raise ConfigError(f"{source}: not valid TOML: nested too deeply") from None


def _inside(root: Path, path: Path) -> bool:
    """Whether ``path``, its symbolic links followed, lies in ``root`` (likewise)."""
    real_root = os.path.realpath(root)
    return os.path.commonpath([real_root, os.path.realpath(path)]) == real_root


def load_settings(root: Path) -> Settings:
    """Settings from ``archmetrics.toml``, else ``pyproject.toml``'s table, in ``root``. A
    configuration file that is a symbolic link leading out of ``root``, a FIFO or a device
    is an error, never read.

    What the reader should know comes as ``notices``: both files configure archmetrics (the
    first is read, the other ignored), or pyproject.toml has a ``[tool.NAME]`` table whose
    name is close to ``archmetrics`` (a typo that would otherwise be silently ignored)."""
    found: list[tuple[Path, Settings]] = []
    notices: list[str] = []
    for name in CONFIG_FILES:
        path = root / name
        if not os.path.lexists(path):
            continue
        if not _inside(root, path):
            raise ConfigError(f"{path}: a symbolic link leading out of the repository; not read")
        document, text = read_document(path)
        tool = document.get("tool", {})
        if name == "pyproject.toml" and isinstance(tool, dict):
            notices += _near_misses(tool, path)
        settings = settings_from_document(document, name, str(path), text)
        if settings is not None:
            found.append((path, settings))
    if not found:
        return Settings(notices=tuple(notices))
    path, settings = found[0]
    if len(found) > 1:
        notices.append(
            f"{path} and [tool.archmetrics] in {found[1][0]} both configure archmetrics: "
            f"{path.name} is read, pyproject.toml's table is ignored"
        )
    return replace(settings, notices=tuple(notices))


def settings_from_document(
    document: Mapping[str, Any], name: str, source: str, text: str = ""
) -> Settings | None:
    """The settings in the TOML ``document`` of the configuration file ``name`` (read from
    ``source``; ``text``, its text, gives each gate's line), or None for a
    ``pyproject.toml`` without a ``[tool.archmetrics]`` table."""
    tool = document.get("tool", {})
    if not isinstance(tool, dict):
        raise ConfigError(f"{source}: tool: expected a table")
    if name == "pyproject.toml":
        table = tool.get("archmetrics")
        if table is None:
            return None
    else:
        table = tool.get("archmetrics", document)
    settings = parse_settings(_table(table, f"{source}: tool.archmetrics"), source)
    lines = tuple(_line_of(text, gate) for gate in settings.gates)
    return replace(settings, gate_lines=lines)


def _near_misses(tool: Mapping[str, Any], path: Path) -> list[str]:
    """A notice for each ``[tool.NAME]`` whose NAME is close to ``archmetrics`` but not it."""
    names = [name for name in tool if name != "archmetrics" and isinstance(name, str)]
    close = [n for n in names if get_close_matches("archmetrics", [n.lower()], cutoff=0.8)]
    return [
        f"{path}: [tool.{name}] is not read by archmetrics: did you mean [tool.archmetrics]?"
        for name in close
    ]


def _line_of(text: str, value: str) -> int:
    """The first line of ``text`` holding ``value`` as written (1 when none does)."""
    for number, line in enumerate(text.splitlines(), start=1):
        if value in line:
            return number
    return 1
