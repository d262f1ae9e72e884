"""Element grouping: Python modules, C/C++ header + implementation components, per-file."""

from __future__ import annotations

from pathlib import PurePosixPath

from hypothesis import given
from hypothesis import strategies as st

from archmetrics.coupling import Element, group_elements
from archmetrics.coupling.elements import component_name, suffix
from tests.coupling.trees import measure


def test_header_and_implementation_with_the_same_stem_form_one_component() -> None:
    elements = group_elements(["src/foo.c", "src/foo.h", "src/bar.cpp", "lib/foo.h", "a.py"])
    assert elements == (
        Element("a.py", ("a.py",), ("python",)),
        Element("lib/foo", ("lib/foo.h",), ("cpp",)),
        Element("src/bar", ("src/bar.cpp",), ("cpp",)),
        Element("src/foo", ("src/foo.c", "src/foo.h"), ("c", "cpp")),
    )


def test_name_does_not_depend_on_which_members_exist() -> None:
    before = {e.name for e in group_elements(["net/client.c"])}
    after = {e.name for e in group_elements(["net/client.c", "net/client.h"])}
    assert before == after == {"net/client"}


def test_per_file_makes_every_file_an_element_named_by_its_path() -> None:
    elements = group_elements(["src/foo.h", "src/foo.c", "x.py"], per_file=True)
    assert [(e.name, e.files) for e in elements] == [
        ("src/foo.c", ("src/foo.c",)),
        ("src/foo.h", ("src/foo.h",)),
        ("x.py", ("x.py",)),
    ]


def test_python_modules_are_not_grouped_with_c_files_of_the_same_stem() -> None:
    names = [e.name for e in group_elements(["m/x.py", "m/x.c", "m/x.h"])]
    assert names == ["m/x", "m/x.py"]


def test_a_stem_that_equals_another_files_path_falls_back_to_a_brace_name() -> None:
    names = [e.name for e in group_elements(["a/b.py", "a/b.py.c", "a/b.py.h"])]
    assert names == ["a/b.py", "a/b.py.{c,h}"]
    assert len(set(names)) == len(names)


def test_a_header_including_its_own_implementation_pair_is_not_counted() -> None:
    report = measure(
        {
            "src/queue.h": '#include "queue.c"\n#include "util.h"\nint q(void);\n',
            "src/queue.c": '#include "queue.h"\n#include <string.h>\nint q(void) { return 0; }\n',
            "src/util.h": "int u(void);\n",
        }
    )
    queue = report.element("src/queue")
    own = [d for d in queue.dependencies if d.target_element == "src/queue"]
    assert len(own) == 1 and not own[0].counted and "own element" in own[0].note
    assert queue.s_e == 2  # util.h and string.h
    assert report.element("src/util").s_a == 1


def test_per_file_counts_the_pair_include_as_coupling() -> None:
    files = {"src/queue.h": "int q(void);\n", "src/queue.c": '#include "queue.h"\nint x;\n'}
    report = measure(files, per_file=True)
    assert report.element("src/queue.c").s_e == 1
    assert report.element("src/queue.h").s_a == 1


_PART = st.text(alphabet="ab.c_-", min_size=1, max_size=6).filter(lambda p: p not in {".", ".."})


@given(st.lists(_PART, min_size=1, max_size=4).map("/".join))
def test_a_paths_ending_and_component_are_what_pathlib_gives(path: str) -> None:
    # read from the string (grouping asks every file, twice per diff), as PurePosixPath reads
    # a normalized git path: `.bashrc` and `a.` have no ending, `a.b.c` ends in `.c`
    pure = PurePosixPath(path)
    assert suffix(path) == pure.suffix
    assert component_name(path) == (str(pure.with_suffix("")) if pure.suffix else path)
