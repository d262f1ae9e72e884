"""The ROS graph through the real CLI on real git repositories: scan's link sites in JSON,
graph's computation view, diff's link changes per element, grouping by package; the JSON
checked against the shipped schemas."""

from __future__ import annotations

import json
import shutil
import subprocess
from importlib import resources
from pathlib import Path

import jsonschema
import pydot
import pytest

from archmetrics.cli import main
from tests.coupling.test_ros import LISTENER, TALKER, WORKSPACE
from tests.gitrepo import GitRepo

LAUNCH = """\
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([Node(package='talker_pkg', executable='talker')])
"""

SCAN_SUBSCRIBER = """\
from rclpy.node import Node
from sensor_msgs.msg import LaserScan
from geometry_msgs.msg import Twist


class Avoider(Node):
    def __init__(self):
        super().__init__('avoider')
        self.create_subscription(LaserScan, 'scan', self.on_scan, 10)
        self.cmd = self.create_publisher(Twist, 'cmd_vel', 10)
"""


def _schema(name: str) -> dict[str, object]:
    text = resources.files("archmetrics").joinpath("schemas", f"{name}.schema.json").read_text()
    return json.loads(text)  # type: ignore[no-any-return]


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> str:
    assert main(list(argv)) == 0
    out, _ = capsys.readouterr()
    return out


@pytest.fixture()
def repo(tmp_path: Path) -> GitRepo:
    repo = GitRepo(tmp_path / "ws")
    repo.commit("a talker and a listener", files={
        **WORKSPACE, "bringup/package.xml": "<package><name>bringup</name></package>\n",
        "bringup/launch/talk.launch.py": LAUNCH,
    })  # fmt: skip
    return repo


def test_scan_reports_graph_names_types_and_nodes(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    out = _run(capsys, "scan", str(repo.root), "--by", "link", "--format", "json", "-q",
               "--no-cache")  # fmt: skip
    document = json.loads(out)
    jsonschema.validate(document, _schema("scan-1"))
    sites = {(s["path"], s["line"]): s for e in document["elements"] for s in e["link_sites"]}
    publisher = sites[("talker_pkg/src/talker.cpp", 8)]
    fields = ("endpoint", "endpoint_type", "endpoint_name", "node", "status")
    assert [publisher[f] for f in fields] == [
        "topic:/chatter", "std_msgs/msg/String", "topic:chatter", "/talker", "resolved"
    ]
    launch = sites[("bringup/launch/talk.launch.py", 6)]
    assert (launch["endpoint"], launch["targets"]) == ("node:talker_pkg/talker",
                                                       ["talker_pkg/src/talker"])  # fmt: skip
    listener = next(e for e in document["elements"] if e["element"].endswith("listener.py"))
    assert (listener["d_a"], listener["d_e"]) == (2, 1)


def test_graph_draws_the_computation_graph(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    document = json.loads(_run(capsys, "graph", str(repo.root), "--format", "json",
                               "--no-cache"))  # fmt: skip
    jsonschema.validate(document, _schema("graph-1"))
    assert document["view"] == "computation"
    kinds = {n["name"]: (n["kind"], n["label"]) for n in document["nodes"]}
    assert kinds["topic:/chatter"] == ("topic", "/chatter")
    assert kinds["talker_pkg/src/talker"] == ("element", "/talker")
    assert kinds["listener_pkg/listener_pkg/listener.py"] == ("element", "/listener")
    flows = {(e["source"], e["target"], e["role"], e["weight"]) for e in document["edges"]}
    assert flows == {
        ("talker_pkg/src/talker", "topic:/chatter", "initiate", 2),  # publisher and publish
        ("talker_pkg/src/talker", "topic:/talker/status", "initiate", 1),
        ("topic:/chatter", "listener_pkg/listener_pkg/listener.py", "receive", 1),
    }
    dot = _run(capsys, "graph", str(repo.root), "--format", "dot", "--no-cache")
    [parsed] = pydot.graph_from_dot_data(dot)
    assert {e.get_source().strip('"') for e in parsed.get_edges()} >= {"talker_pkg/src/talker"}
    if shutil.which("dot"):
        done = subprocess.run(["dot", "-Tsvg"], input=dot, capture_output=True, text=True,
                              timeout=30)  # fmt: skip
        assert done.returncode == 0, done.stderr
    mermaid = _run(capsys, "graph", str(repo.root), "--format", "mermaid", "--no-cache")
    assert '["/chatter"]' in mermaid and '(["/talker"])' in mermaid
    elements = json.loads(_run(capsys, "graph", str(repo.root), "--view", "elements",
                               "--format", "json", "--no-cache"))  # fmt: skip
    assert elements["view"] == "elements"
    assert {n["kind"] for n in elements["nodes"]} == {"element"}


def test_diff_lists_each_elements_links_added_and_removed(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    repo.commit("v1", tag="v1")
    # the PR of the issue: a node subscribing to scan and publishing cmd_vel; the listener
    # stops listening
    repo.write({"avoid_pkg/package.xml": "<package><name>avoid_pkg</name></package>\n",
                "avoid_pkg/avoid_pkg/avoider.py": SCAN_SUBSCRIBER,
                "listener_pkg/listener_pkg/listener.py": LISTENER.replace(
                    "self.sub = self.create_subscription(String, 'chatter', self.callback, 10)",
                    "pass")})  # fmt: skip
    repo.commit("v2", tag="v2")
    out = _run(capsys, "diff", "-C", str(repo.root), "--base", "v1", "--head", "v2",
               "--format", "json", "--no-cache")  # fmt: skip
    document = json.loads(out)
    jsonschema.validate(document, _schema("diff-1"))
    by_name = {e["element"]: e for e in document["elements"]}
    avoider = by_name["avoid_pkg/avoid_pkg/avoider.py"]
    assert avoider["links_added"] == [
        {"role": "initiate", "endpoint": "topic:/cmd_vel", "count": 1},
        {"role": "receive", "endpoint": "topic:/scan", "count": 1},
    ]
    assert avoider["links_removed"] == []
    listener = by_name["listener_pkg/listener_pkg/listener.py"]
    assert listener["links_removed"] == [
        {"role": "receive", "endpoint": "topic:/chatter", "count": 1}
    ]
    assert document["locations"]["total"]["delta_d_e"] == 2 - 1 + 0  # +2 avoider, -1 listener
    assert by_name["talker_pkg/src/talker"]["links_added"] == []
    markdown = _run(capsys, "diff", "-C", str(repo.root), "--base", "v1", "--head", "v2",
                    "--format", "markdown", "--no-cache")  # fmt: skip
    assert "3 link changes" in markdown
    assert "| `avoid_pkg/avoid_pkg/avoider.py` | + | initiates | `topic:/cmd_vel` | 1 |" in markdown
    table = _run(capsys, "diff", "-C", str(repo.root), "--base", "v1", "--head", "v2",
                 "--no-cache")  # fmt: skip
    assert "links added and removed" in table and "topic:/scan" in table


def test_group_by_package_on_the_command_line(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    out = _run(capsys, "scan", str(repo.root), "--by", "element", "--format", "json", "-q",
               "--no-cache", "--group", "package")  # fmt: skip
    names = [e["element"] for e in json.loads(out)["elements"]]
    assert names == ["bringup", "listener_pkg", "talker_pkg"]
    assert TALKER
