"""Service descriptors (Hestand 2011, pp. 93-94): the XML service profile, loaded and checked.

``load(path)`` / ``loads(text)`` return a frozen :class:`ServiceDescriptor` or raise
:class:`DescriptorError` whose problems each read ``file:line: field: message``.
"""

from __future__ import annotations

from .errors import DescriptorError, Problem
from .loader import describe, load, loads, parse_type, schema
from .model import (
    PRIMITIVES,
    Actor,
    Command,
    Encoding,
    Function,
    Implementation,
    ImplementationForm,
    Language,
    Naming,
    OperatingSystem,
    Operation,
    Packaging,
    Parameter,
    Participant,
    Pattern,
    Profile,
    StreamQos,
    TypeDef,
    TypeRef,
)
from .payload import PayloadError, check_value, reply_validator, request_validator
from .service import ServiceDescriptor

__all__ = [
    "PRIMITIVES",
    "Actor",
    "Command",
    "DescriptorError",
    "Encoding",
    "Function",
    "Implementation",
    "ImplementationForm",
    "Language",
    "Naming",
    "OperatingSystem",
    "Operation",
    "Packaging",
    "Parameter",
    "Participant",
    "Pattern",
    "PayloadError",
    "Problem",
    "Profile",
    "ServiceDescriptor",
    "StreamQos",
    "TypeDef",
    "TypeRef",
    "check_value",
    "describe",
    "load",
    "loads",
    "parse_type",
    "reply_validator",
    "request_validator",
    "schema",
]
