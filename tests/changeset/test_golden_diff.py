"""Golden statement diffs: real snippets through the real parsers (tests/harness.py facts_of).

Each case is a pre and a post snippet and the expected (Γ_A, Γ_R, Γ_M) of the file.
"""

from __future__ import annotations

import pytest

from archmetrics.changeset.statement_diff import Action, FileChange, diff_files
from tests.harness import facts_of


def change(pre: str, post: str, language: str) -> FileChange:
    return diff_files(facts_of(pre, language), facts_of(post, language))


def counts(pre: str, post: str, language: str) -> tuple[int, int, int]:
    c = change(pre, post, language)
    return c.added, c.removed, c.modified


PY_BASE = """\
import os

def area(w, h):
    # width times height
    if w > 0 and h > 0:
        return w * h
    return 0

def total(items):
    count = 0
    for item in items:
        count += area(item.w, item.h)
    print(count)
    return count
"""

PYTHON_CASES = {
    "reformat": (
        """\
import os


def area( w,h ):
  # width times height
  if w>0 and h>0:
      return w*h
  return 0
def total(items):
    count=0
    for item in items: count += area(item.w,  item.h)
    print( count )
    return count
""",
        (0, 0, 0),
    ),
    "comment edit": (
        PY_BASE.replace("# width times height", "# area in m^2 (was: w*h)  # todo"),
        (0, 0, 0),
    ),
    "edit a condition": (
        PY_BASE.replace("if w > 0 and h > 0:", "if w >= 0 and h > 0:"),
        (0, 0, 1),
    ),
    "split a call over lines": (
        PY_BASE.replace(
            "count += area(item.w, item.h)",
            "count += area(\n            item.w,\n            item.h\n        )",
        ),
        (0, 0, 0),
    ),
    "insert a statement": (
        PY_BASE.replace("    print(count)\n", "    print(count)\n    log(count)\n"),
        (1, 0, 0),
    ),
    "delete a statement": (PY_BASE.replace("    print(count)\n", ""), (0, 1, 0)),
    # count appears on 4 statements (assignment, augmented assignment, call, return)
    "rename a variable on several lines": (PY_BASE.replace("count", "n"), (0, 0, 4)),
    "reorder two statements": (
        PY_BASE.replace("print(count)\n    return count", "return count\n    print(count)"),
        (1, 1, 0),
    ),
    "edit an argument of a call split over lines": (
        PY_BASE.replace(
            "count += area(item.w, item.h)",
            "count += area(\n            item.w,\n            item.depth\n        )",
        ),
        (0, 0, 1),
    ),
    "docstring added": (
        PY_BASE.replace("def area(w, h):\n", 'def area(w, h):\n    """Area of a w x h box."""\n'),
        (0, 0, 0),
    ),
    "two statements joined on one line": (
        PY_BASE.replace("print(count)\n    return count", "print(count); return count"),
        (0, 0, 0),
    ),
}


@pytest.mark.parametrize("case", sorted(PYTHON_CASES))
def test_python(case: str) -> None:
    post, expected = PYTHON_CASES[case]
    assert counts(PY_BASE, post, "python") == expected


def test_python_modified_detail_has_spans_on_both_sides() -> None:
    post = PY_BASE.replace("    if w > 0 and h > 0:", "\n\n    if w >= 0 and h > 0:")
    (only,) = change(PY_BASE, post, "python").changes
    assert only.action is Action.MODIFIED
    assert only.pre is not None and only.post is not None
    assert (only.pre.span.start, only.post.span.start) == (5, 7)
    assert only.pre.function == "area"


def test_python_move_a_block() -> None:
    # `total` moves above `area`: the longest run (total's 6 statements) stays matched, so
    # area's 4 statements count as removed and re-added, each flagged as moved
    head, tail = PY_BASE.split("def total")
    moved = "import os\n\ndef total" + tail + head.replace("import os\n", "")
    c = change(PY_BASE, moved, "python")
    assert (c.added, c.removed, c.modified) == (4, 4, 0)
    assert all(x.moved for x in c.changes)
    assert sorted(x.pre.span.start for x in c.changes if x.pre) == [3, 5, 6, 7]


C_BASE = """\
#include <stdio.h>
#include "util.h"

static int area(int w, int h)
{
    /* width times height */
    if (w > 0 && h > 0) {
        return w * h;
    }
    return 0;
}

int total(const struct item *items, int n)
{
    int count = 0;
    for (int i = 0; i < n; i++) {
        count += area(items[i].w, items[i].h);
    }
    printf("%d\\n", count);
    return count;
}
"""

C_CASES = {
    "reformat": (
        """\
#include <stdio.h>
#include   "util.h"
static int
area(int w,
     int h) {
  if (w>0 && h>0)
    return w*h;
  return 0;
}
int total(const struct item* items, int n) {
  int count=0;
  for (int i=0; i<n; i++) count += area(items[i].w,items[i].h);
  printf("%d\\n",count); return count;
}
""",
        (0, 0, 0),
    ),
    "comment edit": (
        C_BASE.replace("/* width times height */", "// area, in m^2\n    /* w * h */"),
        (0, 0, 0),
    ),
    "edit a condition": (C_BASE.replace("if (w > 0 && h > 0)", "if (w > 0 || h > 0)"), (0, 0, 1)),
    "split a call over lines": (
        C_BASE.replace(
            "count += area(items[i].w, items[i].h);",
            "count += area(items[i].w,\n                      items[i].h);",
        ),
        (0, 0, 0),
    ),
    "insert a statement": (
        C_BASE.replace("    return count;", "    fflush(stdout);\n    return count;"),
        (1, 0, 0),
    ),
    "delete a statement": (C_BASE.replace('    printf("%d\\n", count);\n', ""), (0, 1, 0)),
    # count appears on 4 statements (declaration, compound assignment, printf, return)
    "rename a variable on several lines": (C_BASE.replace("count", "sum"), (0, 0, 4)),
    "reorder two statements": (
        C_BASE.replace(
            'printf("%d\\n", count);\n    return count;',
            'return count;\n    printf("%d\\n", count);',
        ),
        (1, 1, 0),
    ),
    "add a parameter to a signature": (
        C_BASE.replace("static int area(int w, int h)", "static int area(int w, int h, int scale)"),
        (0, 0, 1),
    ),
}


@pytest.mark.parametrize("case", sorted(C_CASES))
def test_c(case: str) -> None:
    post, expected = C_CASES[case]
    assert counts(C_BASE, post, "c") == expected


def test_c_move_a_function() -> None:
    # area (4 statements) moves below total (6): area's statements are removed and re-added
    head, tail = C_BASE.split("int total")
    includes, area = head.split("static int area")
    moved = includes + "int total" + tail + "\nstatic int area" + area
    c = change(C_BASE, moved, "c")
    assert (c.added, c.removed, c.modified) == (4, 4, 0)
    assert all(x.moved for x in c.changes)
    assert sorted(x.pre.span.start for x in c.changes if x.pre) == [4, 7, 8, 10]


def test_cpp_method_body_edit() -> None:
    pre = "int Store::get(int k) const {\n    auto it = m_.find(k);\n    return it->second;\n}\n"
    post = pre.replace("return it->second;", "return it == m_.end() ? -1 : it->second;")
    assert counts(pre, post, "cpp") == (0, 0, 1)
