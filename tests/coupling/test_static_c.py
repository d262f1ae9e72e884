"""Static coupling in C/C++: include resolution, the ignore list, s_e and s_a."""

from __future__ import annotations

from archmetrics.coupling import Resolution
from tests.coupling.trees import measure


def _deps(report: object, element: str) -> dict[str, tuple[Resolution, str | None]]:
    coupling = report.element(element)  # type: ignore[attr-defined]
    return {d.name: (d.resolution, d.target_element) for d in coupling.dependencies}


def test_quoted_include_resolves_relative_to_the_including_file() -> None:
    report = measure(
        {
            "app/main.c": '#include "../lib/list.h"\n#include "local.h"\nint main(void);\n',
            "lib/list.h": "int list(void);\n",
            "app/local.h": "int local;\n",
            "other/local.h": "int other;\n",
        }
    )
    assert _deps(report, "app/main") == {
        "../lib/list.h": (Resolution.INTERNAL, "lib/list"),
        "local.h": (Resolution.INTERNAL, "app/local"),
    }
    assert report.element("lib/list").s_a == 1
    assert report.element("other/local").s_a == 0


def test_include_dirs_are_searched_after_the_files_own_folder() -> None:
    files = {
        "src/main.c": '#include "proto/msg.h"\nint main(void) { return 0; }\n',
        "include/proto/msg.h": "struct msg { int x; };\n",
        "vendor/proto/msg.h": "struct msg { int y; };\n",
    }
    assert _deps(measure(files, include_dirs=("include",)), "src/main") == {
        "proto/msg.h": (Resolution.INTERNAL, "include/proto/msg"),
    }
    # without the include dir the suffix is ambiguous: reported, not guessed
    unresolved = measure(files).element("src/main").dependencies[0]
    assert unresolved.resolution is Resolution.UNRESOLVED
    assert "ambiguous" in unresolved.note


def test_a_unique_path_suffix_resolves_quoted_and_angled_includes() -> None:
    report = measure(
        {
            "client/robot.c": (
                '#include <libplayerc/playerc.h>\n#include "geometry.h"\n#include <math.h>\n'
                "int main(void) { return 0; }\n"
            ),
            "player_stub/libplayerc/playerc.h": "int playerc_client_connect(void *c);\n",
            "common/include/geometry.h": "double dist(double a, double b);\n",
        }
    )
    assert _deps(report, "client/robot") == {
        "libplayerc/playerc.h": (Resolution.INTERNAL, "player_stub/libplayerc/playerc"),
        "geometry.h": (Resolution.INTERNAL, "common/include/geometry"),
        "math.h": (Resolution.EXTERNAL, None),
    }


def test_an_unfound_quoted_include_is_unresolved_not_dropped() -> None:
    report = measure({"a.c": '#include "missing.h"\n#include <zmq.h>\nint x;\n'})
    coupling = report.element("a")
    assert _deps(report, "a") == {
        "missing.h": (Resolution.UNRESOLVED, None),
        "zmq.h": (Resolution.EXTERNAL, None),
    }
    assert coupling.s_e == 2  # both count: the thesis counts include files referenced
    assert [d.name for d in report.unresolved_dependencies] == ["missing.h"]


def test_stdio_and_stdlib_are_ignored_by_default_and_the_list_is_configurable() -> None:
    source = "#include <stdio.h>\n#include <stdlib.h>\n#include <string.h>\nint x;\n"
    assert measure({"a.c": source}).element("a").s_e == 1
    assert measure({"a.c": source}, ignore_includes=()).element("a").s_e == 3
    assert measure({"a.c": source}, ignore_includes=("string.h",)).element("a").s_e == 2


def test_s_e_counts_distinct_targets_once_across_the_files_of_an_element() -> None:
    report = measure(
        {
            "m/motor.h": '#include <stdint.h>\n#include "bus.h"\nint motor(void);\n',
            "m/motor.c": (
                '#include "motor.h"\n#include "bus.h"\n#include <stdint.h>\n#include <math.h>\n'
                "int motor(void) { return 0; }\n"
            ),
            "m/bus.h": "int bus;\n",
        }
    )
    motor = report.element("m/motor")
    assert motor.s_e == 3  # stdint.h, bus.h (the m/bus element), math.h
    bus = next(d for d in motor.dependencies if d.target_element == "m/bus")
    assert [(s.path, s.line) for s in bus.sites] == [("m/motor.c", 2), ("m/motor.h", 2)]


def test_s_a_counts_distinct_dependent_elements() -> None:
    report = measure(
        {
            "lib/log.h": "void log(const char *m);\n",
            "lib/log.c": '#include "log.h"\nvoid log(const char *m) {}\n',
            "a.c": '#include "lib/log.h"\nint a;\n',
            "b.cpp": '#include "lib/log.h"\n#include "lib/log.h"\nint b;\n',
        }
    )
    log = report.element("lib/log")
    assert (log.s_a, log.dependents) == (2, ("a", "b"))
