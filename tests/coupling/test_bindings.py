"""Names a Python file binds to modules, read from the imports the parser found."""

from __future__ import annotations

from archmetrics.coupling.bindings import module_bindings
from tests.harness import facts_of


def bindings(source: str, submodules: tuple[str, ...] = ()) -> frozenset[str]:
    return module_bindings(facts_of(source, "python").dependencies, submodules)


def test_import_binds_its_first_name_or_its_alias() -> None:
    source = "import os.path\nimport numpy as np, json\ndef f():\n    import robosoa.bus as rb\n"
    assert bindings(source) == {"os", "np", "json", "rb"}


def test_from_import_binds_only_what_resolved_to_a_submodule() -> None:
    source = "from proxy import service_utilities as su, CONSTANT\nfrom . import (helpers,)\n"
    assert bindings(source) == frozenset()
    assert bindings(source, ("proxy.service_utilities", ".helpers")) == {"su", "helpers"}
    assert bindings("from .. import *\n", (".",)) == frozenset()
