"""The ROS oracle's row format and matching rule, and the committed oracle's own consistency."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

from tests.coupling.ros_adapter import (
    CATEGORIES,
    KIND_CATEGORY,
    is_ros_site,
    kind_family,
    ros_endpoint,
)
from tests.coupling.ros_rows import (
    LINE_SLACK,
    NAMED_STATIC,
    Row,
    is_test_path,
    judged,
    match_sites,
    parse_rows,
)

ORACLE = Path(__file__).resolve().parents[2] / "benchmarks" / "ros_oracle"
CASES = Path(__file__).resolve().parent / "ros_cases"
HEADER = "file|line|end|kind|name|type|from|written|launch|note"


def _rows(*lines: str) -> str:
    return "\n".join(["# a comment", HEADER, *lines])


def test_rows_are_read_with_their_launch_names_and_test_flag() -> None:
    [row, other] = parse_rows(
        _rows(
            'src/a.cpp|10|12|publisher|/chatter|std_msgs/msg/String|literal|"chatter"|'
            "/ns/chatter@launch/x.launch.py;/other@launch/y.xml|note",
            "pkg/test/t.py|3|3|subscription|/a;/b|std_msgs/msg/String|argument|topic||",
        ),
        "demo.sites",
    )
    assert (row.file, row.line, row.end, row.kind) == ("src/a.cpp", 10, 12, "publisher")
    assert row.launch_names == ("/ns/chatter", "/other") and not row.test
    assert row.accepts("/chatter") and row.accepts("/ns/chatter") and not row.accepts("/x")
    assert other.names == ("/a", "/b") and other.test and not other.accepts(None)


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("a.cpp|1|1|publisher|/x", "demo.sites:3: 5 columns"),
        ("a.cpp|1|1|publishr|/x|t|literal|w||", "demo.sites:3: unknown kind or from"),
        ("a.cpp|1|1|publisher|/x|t|guessed|w||", "demo.sites:3: unknown kind or from"),
    ],
)
def test_a_bad_row_names_its_line(line: str, message: str) -> None:
    with pytest.raises(ValueError, match=re.escape(message)):
        parse_rows(_rows(line), "demo.sites")


def test_sites_match_rows_nearest_first_within_the_slack() -> None:
    rows = parse_rows(
        _rows(
            "a.cpp|10|12|publisher|/p|t|literal|w||",
            "a.cpp|11|11|publish|/p|t|literal|w||",
            "a.cpp|30|30|subscription|/s|t|literal|w||",
        ),
        "demo.sites",
    )
    sites = [
        {"path": "a.cpp", "line": 11},  # nearest to the publish row (line 11), not the publisher
        {"path": "a.cpp", "line": 10 - LINE_SLACK},  # the statement's first line, for line 10
        {"path": "a.cpp", "line": 27},  # too far before line 30
        {"path": "b.cpp", "line": 1},
    ]
    match = match_sites(rows, sites)
    assert sorted((row.line, site["line"]) for row, site in match.pairs) == [(10, 8), (11, 11)]
    assert [row.line for row in match.missed] == [30]
    assert sorted((s["path"], s["line"]) for s in match.extra) == [("a.cpp", 27), ("b.cpp", 1)]


def test_equally_near_sites_pair_with_the_row_of_their_kind() -> None:
    rows = parse_rows(
        _rows(
            "r.py|10|10|subscription|/in|t|literal|w||",
            "r.py|10|10|publish|/out|t|literal|w||",
        ),
        "demo.sites",
    )
    sites = [
        {"path": "r.py", "line": 10, "kind": "publish"},
        {"path": "r.py", "line": 10, "kind": "subscription"},
    ]
    match = match_sites(rows, sites, lambda site: (str(site["kind"]), None, None))
    assert sorted((row.kind, site["kind"]) for row, site in match.pairs) == [
        ("publish", "publish"),
        ("subscription", "subscription"),
    ]


def test_two_sites_of_one_kind_on_a_line_pair_by_name() -> None:
    rows = parse_rows(
        _rows(
            "m.py|86|86|param-get|~warning_percentage||literal|w||",
            "m.py|86|86|param-get|~window||literal|w||",
        ),
        "demo.sites",
    )
    sites = [{"path": "m.py", "line": 86, "name": n} for n in ("~window", "~warning_percentage")]
    match = match_sites(rows, sites, lambda site: ("param-get", str(site["name"]), None))
    assert all(row.names == (site["name"],) for row, site in match.pairs)
    assert len(match.pairs) == 2


@pytest.mark.parametrize(
    ("path", "test"),
    [
        ("pkg/test/helper.cpp", True),
        ("pkg/tests/unit/x.py", True),
        ("pkg/launch_testing/check_msgs_launch_test.py", True),
        ("pkg/src/test_utils.cpp", True),
        ("pkg/src/contest.cpp", False),
        ("pkg/src/testing_node.cpp", False),
    ],
)
def test_test_files(path: str, test: bool) -> None:
    assert is_test_path(path) is test


@pytest.mark.parametrize(
    ("path", "kind", "expected"),
    [
        ("pkg/src/node.cpp", "param-declare", True),
        ("pkg/config/params.yaml", "param-get", False),
        ("pkg/config/params.yaml", "publisher", False),
        ("pkg/launch/robot.launch.yaml", "launch-node", True),
        ("pkg/launch/robot.launch.yaml", "param-set", False),
        ("pkg/launch/bringup_launch.py", "param-get", False),
        ("pkg/launch/bringup_launch.py", "launch-component", True),
        ("pkg/test/amcl.xml", "param-get", False),
        ("pkg/scripts/relay", "param-get", True),
    ],
)
def test_parameter_values_in_configuration_files_are_not_judged(
    path: str, kind: str, expected: bool
) -> None:
    assert judged(path, kind) is expected


def test_every_kind_has_one_category_and_a_family() -> None:
    kinds = [kind for group in CATEGORIES.values() for kind in group]
    assert len(kinds) == len(set(kinds)) == len(KIND_CATEGORY)
    assert kind_family("tf-listener") == "subscription" == kind_family("mf-subscriber")


def _oracle() -> list[tuple[str, str]]:
    document = tomllib.loads((ORACLE / "repos.toml").read_text(encoding="utf-8"))
    entries = [*document["repo"], *document["deb"]]
    return [(entry["name"], entry["sites"]) for entry in entries]


def test_the_oracle_pins_every_repository_to_a_commit() -> None:
    document = tomllib.loads((ORACLE / "repos.toml").read_text(encoding="utf-8"))
    names = [entry["name"] for entry in document["repo"]]
    assert len(names) == len(set(names)) >= 5
    assert {entry["ros"] for entry in document["repo"]} == {1, 2}
    for entry in document["repo"]:
        assert re.fullmatch(r"[0-9a-f]{40}", entry["commit"]), entry["name"]
        assert (ORACLE / entry["sites"]).is_file(), entry["sites"]
    assert sorted(p.name for p in ORACLE.glob("*.sites")) == sorted(s for _, s in _oracle())


def test_the_debian_packages_are_pinned_by_version_and_checksum() -> None:
    document = tomllib.loads((ORACLE / "repos.toml").read_text(encoding="utf-8"))
    for entry in document["deb"]:
        assert entry["packages"] and entry["paths"], entry["name"]
        for package in entry["packages"]:
            assert package["version"] and package["arch"] in ("all", "amd64"), package["name"]
            assert re.fullmatch(r"[0-9a-f]{64}", package["sha256"]), package["name"]


@pytest.mark.parametrize(("repo", "sites"), _oracle(), ids=[name for name, _ in _oracle()])
def test_the_oracle_rows_are_consistent(repo: str, sites: str) -> None:
    rows = parse_rows((ORACLE / sites).read_text(encoding="utf-8"), sites)
    assert rows, repo
    _consistent(rows, sites)


def _consistent(rows: list[Row], sites: str) -> None:
    for row in rows:
        where = f"{sites}: {row.file}:{row.line}"
        assert 1 <= row.line <= row.end, where
        communication = KIND_CATEGORY[row.kind] == "communication"
        if communication and row.given in NAMED_STATIC:
            assert row.names, f"{where}: a static name must be written down"
        if communication or row.kind.startswith("launch"):
            assert all(n.startswith(("/", "~")) for n in row.names + row.launch_names), where
    keys = [(row.file, row.line, row.kind, row.names) for row in rows]
    assert len(keys) == len(set(keys)), f"{sites}: a site is listed twice"


def test_a_site_becomes_kind_name_and_type() -> None:
    site = {
        "path": "src/a.cpp", "line": 3, "rule": "ros2/publisher", "kind": "messaging",
        "role": "initiate", "endpoint": "topic:/cmd_vel", "status": "external",
        "endpoint_type": "geometry_msgs/msg/Twist", "endpoint_name": "topic:cmd_vel",
        "node": "/teleop", "extra": [1],
    }  # fmt: skip
    assert is_ros_site(site) and not is_ros_site({**site, "rule": "zeromq/socket-connect"})
    assert ros_endpoint(site) == ("publisher", "/cmd_vel", "geometry_msgs/msg/Twist")
    tf = {**site, "rule": "ros2/tf-broadcaster", "endpoint": "topic:/tf"}
    assert ros_endpoint(tf)[:2] == ("publisher", "/tf")
    unresolved = {**site, "rule": "ros1/py-subscriber", "status": "unresolved",
                  "endpoint_type": None}  # fmt: skip
    assert ros_endpoint(unresolved) == ("subscription", None, None)
    assert ros_endpoint({"rule": "ros2/py-spin", "role": "receive"})[0] == "subscription"
    export = {"rule": "ros2/plugin-export", "endpoint": "plugin:demo::Talker", "status": "local"}
    assert ros_endpoint(export) == ("plugin-export", "demo::Talker", None)
    load = {"rule": "ros1/plugin-load", "endpoint": "plugin:navfn::NavfnROS",
            "endpoint_name": "plugin:navfn/NavfnROS", "status": "resolved"}  # fmt: skip
    assert ros_endpoint(load) == ("plugin-load", "navfn/NavfnROS", None)  # the lookup name
    described = {"rule": "ros2/plugin-description", "endpoint": "plugin:navfn::NavfnROS",
                 "endpoint_text": "navfn/NavfnROS", "status": "resolved"}  # fmt: skip
    assert ros_endpoint(described)[:2] == ("plugin-description", "navfn/NavfnROS")
    declared = {"rule": "ros2/declare-parameter", "endpoint": "parameter:/teleop/speed",
                "endpoint_name": "parameter:~/speed", "status": "external"}  # fmt: skip
    assert ros_endpoint(declared)[:2] == ("param-declare", "speed")  # as declared
    launched = {"rule": "ros2/launch-file", "endpoint": "plugin:demo::Talker",
                "node": "/robot1/talker", "status": "resolved"}  # fmt: skip
    assert ros_endpoint(launched) == ("launch-component", "/robot1/talker", None)


def test_the_slice_table_names_lines_of_its_snippets() -> None:
    rows = parse_rows((CASES / "cases.sites").read_text(encoding="utf-8"), "cases.sites")
    snippets = {p.relative_to(CASES).as_posix().removesuffix(".in") for p in CASES.rglob("*.in")}
    assert {row.file for row in rows} <= snippets
    for row in rows:
        lines = (CASES / f"{row.file}.in").read_text(encoding="utf-8").splitlines()
        assert 1 <= row.line <= row.end <= len(lines), f"{row.file}:{row.line}"
        assert lines[row.line - 1].strip(), f"{row.file}:{row.line} is blank"
    _consistent(rows, "cases.sites")
    assert {KIND_CATEGORY[row.kind] for row in rows} == set(CATEGORIES)
    assert not any(row.test for row in rows)
