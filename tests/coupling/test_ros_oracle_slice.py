"""The pinned ROS slice: every shape of call met in the oracle of public ROS code, scanned.

tests/coupling/ros_cases/ holds small ROS 2 and ROS 1 packages written for this test (one folder
per case; files end in ``.in`` so that no linter reads them) and cases.sites, the site each
holds, labelled by hand like the full oracle (benchmarks/ros_oracle/README.md). The cases are
copied, without the ``.in``, into one workspace that ``archmetrics scan --by link`` reads; the
reported sites of ``ros*`` packs must be exactly the rows (file, and line within
``[line - 2, end]``), each of the row's kind, each named as the row says when the name is
given statically (and never named wrongly when it is not), each communication site with the
row's message, service or action type. Parameter values in parameter and launch files are not
labelled (``judged``). ``ros_endpoint`` (ros_adapter.py) is the one place that reads a site's
JSON.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path

import pytest

from archmetrics.cli import main
from archmetrics.coupling import load_rule_packs
from tests.coupling.ros_adapter import KIND_CATEGORY, is_ros_site, kind_family, ros_endpoint
from tests.coupling.ros_rows import NAMED_STATIC, Row, judged, match_sites, parse_rows

if not any(pack.name.startswith("ros") for pack in load_rule_packs().packs):
    pytest.skip("no ROS rule pack (ros1, ros2) is loaded yet", allow_module_level=True)

CASES = Path(__file__).resolve().parent / "ros_cases"
ROWS = parse_rows((CASES / "cases.sites").read_text(encoding="utf-8"), "cases.sites")
NAMES = sorted(path.name for path in CASES.iterdir() if path.is_dir())

Site = Mapping[str, object]


@pytest.fixture(scope="module")
def reported(tmp_path_factory: pytest.TempPathFactory) -> list[Site]:
    """The ROS sites of one scan of the workspace made of every case."""
    root = tmp_path_factory.mktemp("ros_cases") / "ws"
    for snippet in CASES.rglob("*.in"):
        target = root / snippet.relative_to(CASES).with_suffix("")
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(snippet.read_bytes())
    out = root.parent / "scan.json"
    argv = ["scan", "--by", "link", "--format", "json", "-q", "--no-cache", "-o", str(out)]
    assert main([*argv, str(root)]) in (0, 1)
    document = json.loads(out.read_text(encoding="utf-8"))
    sites = [site for element in document["elements"] for site in element["link_sites"]]
    return [
        site
        for site in sites
        if is_ros_site(site) and judged(str(site["path"]), ros_endpoint(site)[0])
    ]


def _where(row: Row) -> str:
    return f"{row.file}:{row.line} {row.kind} {';'.join(row.names)}"


@pytest.mark.parametrize("case", NAMES)
def test_each_site_of_the_case_is_found_and_nothing_else(case: str, reported: list[Site]) -> None:
    rows = [row for row in ROWS if row.file.startswith(f"{case}/")]
    sites = [site for site in reported if str(site["path"]).startswith(f"{case}/")]
    match = match_sites(rows, sites, ros_endpoint)
    assert [_where(row) for row in match.missed] == [], "sites not found"
    assert [(s["path"], s["line"], s["rule"]) for s in match.extra] == [], "sites not in the table"
    for row, site in match.pairs:
        kind, name, ros_type = ros_endpoint(site)
        assert kind == kind_family(row.kind), _where(row)
        if row.given in NAMED_STATIC and row.names:
            assert row.accepts(name), f"{_where(row)}: reported {name!r}"
        else:
            assert name is None or row.accepts(name), f"{_where(row)}: reported {name!r}"
        if KIND_CATEGORY[row.kind] == "communication":
            assert ros_type in row.types, f"{_where(row)}: reported type {ros_type!r}"


@pytest.mark.parametrize(
    ("file", "line"),
    [
        ("rclcpp_topics/src/listener.cpp", 10),  # /chatter, published by talker and component
        ("generic/src/recorder.cpp", 25),  # /chatter through a generic subscription
        ("rclcpp_services_actions/src/clients.cpp", 14),  # /add_two_ints, served twice
        ("ros1_actionlib/scripts/move_client.py", 8),  # /move_base, served by move_server.cpp
    ],
)
def test_the_two_ends_of_one_name_meet(file: str, line: int, reported: list[Site]) -> None:
    [row] = [row for row in ROWS if (row.file, row.line) == (file, line)]
    [(_, site)] = match_sites([row], reported, ros_endpoint).pairs
    assert site["status"] == "resolved", _where(row)
