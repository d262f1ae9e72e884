"""ROS interface packages as static coupling and elements grouped by ROS package or node:
golden trees through the real parsers, expectations worked out by hand from the snippets."""

from __future__ import annotations

from archmetrics.coupling import CouplingOptions, measure_coupling
from archmetrics.coupling.elements import group_elements
from archmetrics.coupling.interfaces import snake
from archmetrics.coupling.model import Resolution
from tests.coupling.test_ros import LISTENER, TALKER, WORKSPACE, ros, ros_facts
from tests.coupling.trees import BUILTIN

INTERFACES = {
    "common/geometry_msgs/package.xml": "<package><name>geometry_msgs</name></package>\n",
    "common/geometry_msgs/msg/Twist.msg": "Vector3 linear\nVector3 angular\n",
    "common/geometry_msgs/msg/PoseWithCovarianceStamped.msg": "std_msgs/Header header\n",
    "common/std_msgs/package.xml": "<package><name>std_msgs</name></package>\n",
    "common/std_msgs/msg/String.msg": "string data\n",
}


def test_rosidl_names_headers_in_snake_case() -> None:
    assert [snake(n) for n in ("Twist", "PoseWithCovarianceStamped", "TFMessage", "SetBool",
                               "Float64MultiArray", "Int32")] == [
        "twist", "pose_with_covariance_stamped", "tf_message", "set_bool",
        "float64_multi_array", "int32",
    ]  # fmt: skip


def test_generated_headers_and_modules_depend_on_the_interface_files() -> None:
    files = {
        **INTERFACES,
        **WORKSPACE,
        "nav/package.xml": "<package><name>nav</name></package>\n",
        "nav/src/amcl.cpp": (
            "#include <geometry_msgs/msg/pose_with_covariance_stamped.hpp>\n"
            "#include <geometry_msgs/Twist.h>\n"  # ROS 1's header
            "#include <nav_msgs/msg/odometry.hpp>\n"  # not in the tree: external
        ),
    }
    report = ros(files)
    amcl = {
        d.name: (d.resolution, d.target_file) for d in report.element("nav/src/amcl").dependencies
    }
    assert amcl == {
        "geometry_msgs/msg/pose_with_covariance_stamped.hpp": (
            Resolution.INTERNAL, "common/geometry_msgs/msg/PoseWithCovarianceStamped.msg"),
        "geometry_msgs/Twist.h": (Resolution.INTERNAL, "common/geometry_msgs/msg/Twist.msg"),
        "nav_msgs/msg/odometry.hpp": (Resolution.EXTERNAL, None),
    }  # fmt: skip
    listener = report.of_file("listener_pkg/listener_pkg/listener.py")
    imported = {d.name: d.target_file for d in listener.dependencies}
    assert imported["std_msgs.msg.String"] == "common/std_msgs/msg/String.msg"
    talker = report.of_file("talker_pkg/src/talker.cpp")
    string = report.of_file("common/std_msgs/msg/String.msg")
    # the talker's header and the listener's import: s_a 2; an interface is no code: λ 0
    assert sorted(string.dependents) == ["listener_pkg/listener_pkg/listener.py",
                                         "talker_pkg/src/talker"]  # fmt: skip
    assert (string.s_a, string.s_e, string.d_e) == (2, 0, 0)
    assert any(d.target_file == "common/std_msgs/msg/String.msg" for d in talker.dependencies)


def test_elements_grouped_by_package_and_by_node() -> None:
    paths = [
        "nav2_controller/package.xml",
        "nav2_controller/include/nav2_controller/controller_server.hpp",
        "nav2_controller/src/controller_server.cpp",
        "nav2_controller/src/main.cpp",
        "nav2_controller/launch/controller.launch.py",
        "tools/plot.py",
        "tools/util.c",
        "tools/util.h",
    ]
    by_package = {e.name: e.files for e in group_elements(paths, "package")}
    assert by_package == {
        "nav2_controller": tuple(sorted(paths[:5])),
        "tools/plot.py": ("tools/plot.py",),
        "tools/util": ("tools/util.c", "tools/util.h"),
    }
    by_node = {e.name: e.files for e in group_elements(paths, "node")}
    assert by_node == {
        "nav2_controller/controller_server": (paths[1], paths[2]),
        "nav2_controller/main": ("nav2_controller/src/main.cpp",),
        "nav2_controller/launch/controller.launch.py": (paths[4],),
        "nav2_controller/package.xml": (paths[0],),
        "tools/plot.py": ("tools/plot.py",),
        "tools/util": ("tools/util.c", "tools/util.h"),
    }


def test_a_package_element_links_as_its_files_do() -> None:
    facts = ros_facts(WORKSPACE)
    report = measure_coupling(facts, CouplingOptions(group="package"), BUILTIN)
    assert [e.element.name for e in report.elements] == ["listener_pkg", "talker_pkg"]
    assert report.element("listener_pkg").d_a == 2  # the talker's publisher and publish
    assert report.element("talker_pkg").d_e == 5
    assert TALKER and LISTENER
