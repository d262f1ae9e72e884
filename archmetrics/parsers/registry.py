"""The language seam: which parser reads which file ending."""

from __future__ import annotations

import functools
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from importlib import metadata

from archmetrics.facts import ConfigFormat, FileFacts, Language, ParseWarning, Severity
from archmetrics.parsers import text
from archmetrics.parsers.limits import DEFAULT_LIMITS, ParseLimits, too_large
from archmetrics.parsers.suppressions import with_suppressions

ParseFunction = Callable[[str, str], FileFacts]
"""(path, decoded source) -> facts. Decoding and binary checks happen before it is called."""
LimitedParseFunction = Callable[[str, str, ParseLimits], FileFacts]
"""(path, decoded source, limits) -> facts: a parser that keeps to the per-file limits."""

ENTRY_POINT_GROUP = "archmetrics.languages"

DEFAULT_EXTENSIONS: Mapping[str, str] = {
    ".py": Language.PYTHON,
    ".c": Language.C,
    ".h": Language.CPP,  # headers are C++ unless configured otherwise (C++ parses C headers too)
    ".cc": Language.CPP,
    ".cpp": Language.CPP,
    ".cxx": Language.CPP,
    ".c++": Language.CPP,
    ".hh": Language.CPP,
    ".hpp": Language.CPP,
    ".hxx": Language.CPP,
    ".h++": Language.CPP,
    ".ipp": Language.CPP,
    ".inl": Language.CPP,
}


class UnknownLanguage(ValueError):
    """A configured language has no parser."""


@dataclass(frozen=True, slots=True)
class LanguageSpec:
    """A language: its name and the function that turns its source into facts.

    ``parse_limited``, when given, is used instead of ``parse`` and is handed the per-file
    limits (``max_depth``, ``parse_seconds``); ``max_bytes`` holds for every language."""

    name: str
    parse: ParseFunction
    parse_limited: LimitedParseFunction | None = None

    def read(self, path: str, source: str, limits: ParseLimits) -> FileFacts:
        if self.parse_limited is not None:
            return self.parse_limited(path, source, limits)
        return self.parse(path, source)


def _python(path: str, source: str, limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    from archmetrics.parsers import python

    return python.parse(path, source, limits)


def _c(path: str, source: str, limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    from archmetrics.parsers import c_family

    return c_family.parse(path, source, Language.C, limits)


def _cpp(path: str, source: str, limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    from archmetrics.parsers import c_family

    return c_family.parse(path, source, Language.CPP, limits)


def _toml(path: str, source: str, limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    from archmetrics.parsers import config_toml

    return config_toml.parse(path, source, limits)


def _xml(path: str, source: str, limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    from archmetrics.parsers import config_xml

    return config_xml.parse(path, source, limits)


def _yaml(path: str, source: str, limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    from archmetrics.parsers import config_yaml

    return config_yaml.parse(path, source, limits)


def _rosidl(path: str, source: str, limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    """A ROS interface definition: no executable code, no table; listed so that the
    includes and imports of the code generated from it depend on it (coupling/interfaces.py)."""
    return FileFacts(path=path, language=ConfigFormat.ROSIDL.value)


BUILTIN_LANGUAGES: tuple[LanguageSpec, ...] = (
    LanguageSpec(Language.PYTHON, _python, _python),
    LanguageSpec(Language.C, _c, _c),
    LanguageSpec(Language.CPP, _cpp, _cpp),
    # configuration formats: no file ending maps to them; the rule packs say which files
    # are configuration (docs/metrics.md, "Configuration links")
    LanguageSpec(ConfigFormat.TOML, _toml, _toml),
    LanguageSpec(ConfigFormat.XML, _xml, _xml),
    LanguageSpec(ConfigFormat.YAML, _yaml, _yaml),
    LanguageSpec(ConfigFormat.ROSIDL, _rosidl, _rosidl),
)


def _plugin_languages() -> tuple[LanguageSpec, ...]:
    """The languages plugins announce, read once per import path: scanning the installed
    distributions' entry points costs tens of milliseconds, and a history builds its
    language table for every commit (a path added later, as a test does, is read then)."""
    return _plugins_on(tuple(sys.path))


@functools.lru_cache(maxsize=8)
def _plugins_on(path: tuple[str, ...]) -> tuple[LanguageSpec, ...]:
    found = []
    for entry in metadata.entry_points(group=ENTRY_POINT_GROUP):
        spec = entry.load()
        if not isinstance(spec, LanguageSpec):
            raise TypeError(
                f"entry point {entry.name!r} in group {ENTRY_POINT_GROUP} must be a LanguageSpec,"
                f" got {type(spec).__name__}"
            )
        found.append(spec)
    return tuple(found)


@dataclass(frozen=True, slots=True)
class LanguageTable:
    """File endings mapped to languages, and languages to parsers."""

    extensions: tuple[tuple[str, str], ...]
    languages: tuple[LanguageSpec, ...]
    _by_ending: dict[str, str] = field(init=False, repr=False, compare=False, hash=False)

    def __post_init__(self) -> None:
        by_ending = dict(reversed(self.extensions))  # the first of an ending listed twice
        object.__setattr__(self, "_by_ending", by_ending)

    @classmethod
    def default(
        cls, overrides: Mapping[str, str] | None = None, plugins: bool = True
    ) -> LanguageTable:
        """The built-in table, with ``overrides`` (ending -> language, "" to drop) applied."""
        languages = {spec.name: spec for spec in BUILTIN_LANGUAGES}
        if plugins:
            languages.update({spec.name: spec for spec in _plugin_languages()})
        extensions = dict(DEFAULT_EXTENSIONS)
        for ending, language in (overrides or {}).items():
            ending = ending if ending.startswith(".") else "." + ending
            if not language:
                extensions.pop(ending.lower(), None)
                continue
            if language not in languages:
                known = ", ".join(sorted(languages))
                raise UnknownLanguage(f"no parser for language {language!r} (known: {known})")
            extensions[ending.lower()] = language
        return cls(tuple(sorted(extensions.items())), tuple(languages.values()))

    def language_of(self, path: str) -> str | None:
        """The language of ``path`` by its ending, or None when it is not source we measure.
        The ending is what ``PurePosixPath(path).suffix`` gives (none for ``.bashrc`` or
        ``a.``), found without building a path: a diff asks for every file of two trees."""
        name = path.rstrip("/").rpartition("/")[2]
        dot = name.rfind(".")
        if dot <= 0 or dot == len(name) - 1:
            return None
        return self._by_ending.get(name[dot:].lower())

    def spec(self, language: str) -> LanguageSpec:
        for spec in self.languages:
            if spec.name == language:
                return spec
        raise UnknownLanguage(f"no parser for language {language!r}")


def parse_source(
    path: str,
    data: bytes,
    language: str,
    table: LanguageTable,
    limits: ParseLimits = DEFAULT_LIMITS,
) -> FileFacts:
    """Facts for one file's bytes. Never raises for bad input: problems become warnings,
    and a file over one of the ``limits`` comes back not measured, saying which."""
    if len(data) > limits.max_bytes:
        return too_large(path, language, len(data), limits)
    if text.is_binary(data):
        return FileFacts(
            path=path,
            language=language,
            parsed=False,
            warnings=(ParseWarning(path, 1, "binary file with a source ending; not measured"),),
        )
    source, decode_warning = text.decode(path, data)
    facts = with_suppressions(table.spec(language).read(path, source, limits), source)
    extra: list[ParseWarning] = [decode_warning] if decode_warning else []
    generated = facts.generated or text.declares_generated(source)
    if not extra and generated == facts.generated:
        return facts
    from dataclasses import replace

    return replace(facts, warnings=tuple(extra) + facts.warnings, generated=generated)


__all__ = [
    "DEFAULT_EXTENSIONS",
    "DEFAULT_LIMITS",
    "LanguageSpec",
    "LanguageTable",
    "ParseLimits",
    "ParseWarning",
    "Severity",
    "UnknownLanguage",
    "parse_source",
]
