"""A C or C++ file's facts do not depend on its line endings (docs/metrics.md, "Line
endings"): a CRLF checkout (git's ``core.autocrlf``, a ``.gitattributes`` text rule) holds
other bytes than its LF blob, and both must read alike -- as a compiler and lizard read them."""

from __future__ import annotations

from pathlib import Path

import pytest

from archmetrics.facts import Language
from tests.harness import facts_of

# numpy's vendored x86-simd-sort (x86simdsort-avx2.cpp), cut down: macro calls alone on
# their lines in a namespace, which the macro rules blank (a line of a macro and nothing
# else); with CRLF they were read as twelve statements in one file and as a region that
# could not be parsed in another
NAMESPACE_MACROS = """#include "x86simdsort-internal.h"

#define DEFINE_ALL_METHODS(type) \\
    template <> \\
    void qsort(type *arr, size_t arrsize) \\
    { \\
        x86simdsortStatic::qsort(arr, arrsize); \\
    }

namespace xss {
namespace avx2 {
    DEFINE_ALL_METHODS(uint32_t)
    DEFINE_ALL_METHODS(int32_t)
} // namespace avx2
} // namespace xss
"""


@pytest.mark.parametrize("ending", ["\r\n", "\r"])
def test_crlf_and_lone_cr_read_as_lf(ending: str) -> None:
    lf = facts_of(NAMESPACE_MACROS, Language.CPP, "a.cpp")
    other = facts_of(NAMESPACE_MACROS.replace("\n", ending), Language.CPP, "a.cpp")
    assert other == lf
    assert [s.kind for s in lf.statements] == ["include", "define"]
    assert not lf.warnings


def _sources(folder: Path) -> list[Path]:
    return sorted(p for p in folder.rglob("*") if p.suffix in {".c", ".h", ".cc"} and p.is_file())


@pytest.mark.slow
def test_a_real_library_reads_alike_with_either_ending() -> None:
    """Brotli's C sources (the pinned oracle corpus) checked out with CRLF."""
    from tests.parsers.test_c_oracle import _corpus_dir, _unpacked

    folder = _corpus_dir()
    folder.mkdir(parents=True, exist_ok=True)
    root = _unpacked(folder, "brotli-1.1.0.tar.gz", "Brotli==1.1.0") / "c"
    files = _sources(root)
    assert len(files) > 80
    for path in files:
        source = path.read_text("utf-8", "replace").replace("\r\n", "\n")
        language = Language.C if path.suffix == ".c" else Language.CPP
        lf = facts_of(source, language, path.name)
        assert facts_of(source.replace("\n", "\r\n"), language, path.name) == lf, path
