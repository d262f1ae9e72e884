"""Descriptor -> generated files, per participant and packaging form; writing them out."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from pathlib import Path

from robosoa.descriptor import Packaging, Participant, ServiceDescriptor
from robosoa.descriptor.errors import one_line
from robosoa.descriptor.names import camel, default_consumer

from .api import render_api, render_init
from .client import render_client
from .common import GeneratedFile, header, render_types
from .provider import render_provider


class CodegenError(ValueError):
    """The descriptor cannot produce what was asked (a form it does not declare...)."""


def _default_participant(d: ServiceDescriptor, packaging: Packaging) -> Participant:
    if packaging is not Packaging.CONSUMER_SOURCE:
        raise CodegenError(f"{one_line(d.source)}: declares no '{packaging}' participant")
    return default_consumer(d)


def participants(d: ServiceDescriptor, forms: Sequence[Packaging] = ()) -> list[Participant]:
    """The participants to generate: those of ``forms`` (all declared ones by default)."""
    if not forms:
        return list(d.participants) or [_default_participant(d, Packaging.CONSUMER_SOURCE)]
    return [d.participant(f) or _default_participant(d, f) for f in dict.fromkeys(forms)]


def _plain_init(d: ServiceDescriptor, part: Participant) -> str:
    summary = f"Generated {part.packaging} package of service '{d.name}' {d.version}."
    return "\n".join(header(d, summary)).rstrip() + "\n"


def generate_participant(d: ServiceDescriptor, part: Participant) -> list[GeneratedFile]:
    """The files of one participant's package."""
    root = part.naming.package.replace(".", "/")
    files = [GeneratedFile(f"{root}/types.py", render_types(d))]
    module = part.naming.module
    if part.packaging is Packaging.CONSUMER_NO_SOURCE:
        proxy = dataclasses.replace(
            part, naming=dataclasses.replace(part.naming, class_name=f"{camel(d.name)}Client")
        )
        proxy_module = "client" if module != "client" else "proxy"
        files.append(GeneratedFile(f"{root}/{proxy_module}.py", render_client(d, proxy)))
        api = render_api(d, part, proxy.naming.class_name, proxy_module)
        files.append(GeneratedFile(f"{root}/{module}.py", api))
        files.append(GeneratedFile(f"{root}/__init__.py", render_init(d, part, module)))
        return files
    files.append(GeneratedFile(f"{root}/__init__.py", _plain_init(d, part)))
    if part.packaging is Packaging.CONSUMER_SOURCE:
        files.append(GeneratedFile(f"{root}/{module}.py", render_client(d, part)))
    else:
        files.append(GeneratedFile(f"{root}/{module}.py", render_provider(d, part)))
    return files


def generate(d: ServiceDescriptor, forms: Sequence[Packaging] = ()) -> tuple[GeneratedFile, ...]:
    """All generated files for ``forms`` of ``d`` (pure: nothing is written)."""
    files: dict[str, GeneratedFile] = {}
    for part in participants(d, forms):
        for f in generate_participant(d, part):
            if f.path in files:
                raise CodegenError(f"{one_line(d.source)}: two participants generate {f.path}")
            files[f.path] = f
    return tuple(files.values())


def write(files: Sequence[GeneratedFile], out: str | Path) -> list[Path]:
    """Write ``files`` under directory ``out``; return the paths written."""
    written = []
    root = Path(out).resolve()
    for f in files:
        path = Path(out) / f.path
        if not path.resolve().is_relative_to(root):  # names are checked; this is a backstop
            raise CodegenError(f"{f.path}: outside the output directory {out}")
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(f.text, encoding="utf-8")
        written.append(path)
    return written
