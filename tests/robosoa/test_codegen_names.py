"""The reserved names are complete: generated code relies on no module-level or builtin name
that a descriptor could take (robosoa.descriptor.names.RESERVED)."""

from __future__ import annotations

import symtable

import pytest

from robosoa.codegen import generate
from robosoa.descriptor import loads
from robosoa.descriptor.names import RESERVED
from tests.robosoa.codegen_spec import descriptor_names, global_names
from tests.robosoa.conftest_codegen import descriptors


@pytest.mark.parametrize("case", sorted(descriptors()))
def test_generated_code_uses_only_reserved_or_declared_names(case: str) -> None:
    d = loads(descriptors()[case], source=case)
    declared = descriptor_names(d)
    unexpected = {}
    for f in generate(d):
        used = global_names(symtable.symtable(f.text, f.path, "exec"))
        extra = {n for n in used - declared - RESERVED
                 if not n.startswith("_")}  # descriptor names never start with "_"
        if extra:
            unexpected[f.path] = extra
    assert unexpected == {}
