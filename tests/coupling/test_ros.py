"""ROS computation graphs as dynamic coupling: golden trees of real C++, Python, launch,
parameter and plugin files through the real parsers and the shipped ros1/ros2 packs, each
expectation worked out by hand from the snippets (docs/metrics.md, "ROS computation graphs")."""

from __future__ import annotations

import textwrap
from collections.abc import Mapping

from archmetrics.app.coupling import configuration_files
from archmetrics.coupling import CouplingOptions, CouplingReport, LinkSite, measure_coupling
from archmetrics.coupling.index import build_index
from archmetrics.coupling.measure import link_tree
from archmetrics.coupling.model import LinkStatus
from archmetrics.facts import FileFacts
from archmetrics.parsers import LanguageTable, parse_source
from tests.coupling.trees import BUILTIN

_TABLE = LanguageTable.default(plugins=False)


def ros_facts(files: Mapping[str, str]) -> list[FileFacts]:
    """Facts of each file, its language by its ending or, for configuration, by the packs
    (inside a folder holding package.xml), as a scan selects them."""
    formats = configuration_files(BUILTIN).in_tree(files)
    found = []
    for path, source in files.items():
        language = _TABLE.language_of(path) or formats(path)
        assert language is not None, path
        data = textwrap.dedent(source).encode()
        facts = parse_source(path, data, language, _TABLE)
        assert facts.parsed, facts.warnings
        found.append(facts)
    return found


def ros(files: Mapping[str, str]) -> CouplingReport:
    return measure_coupling(ros_facts(files), CouplingOptions(), BUILTIN)


def sites(report: CouplingReport, path: str) -> list[tuple[int, str, str | None, str, str]]:
    """(line, rule, endpoint key, data type, status) of the sites in ``path``."""
    return [
        (s.line, s.rule, s.endpoint.key if s.endpoint else None, s.data_type, s.status.value)
        for s in report.of_file(path).link_sites
        if s.path == path
    ]


def site_at(report: CouplingReport, path: str, line: int) -> LinkSite:
    (found,) = [s for s in report.of_file(path).link_sites if s.path == path and s.line == line]
    return found


TALKER = """\
#include <rclcpp/rclcpp.hpp>
#include <rclcpp_components/register_node_macro.hpp>
#include <std_msgs/msg/string.hpp>
class Talker : public rclcpp::Node {
 public:
  Talker() : Node("talker") {
    topic_ = this->declare_parameter<std::string>("topic", "chatter");
    pub_ = this->create_publisher<std_msgs::msg::String>(topic_, 10);
    status_ = create_publisher<std_msgs::msg::String>("~/status", 10);
  }
  void tick() { pub_->publish(msg_); }
};
RCLCPP_COMPONENTS_REGISTER_NODE(talker_pkg::Talker)
"""

LISTENER = """\
import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class Listener(Node):
    def __init__(self):
        super().__init__('listener')
        self.sub = self.create_subscription(String, 'chatter', self.callback, 10)
"""

SETUP = """\
from setuptools import setup
setup(name='listener_pkg',
      entry_points={'console_scripts': ['listener = listener_pkg.listener:main']})
"""

WORKSPACE = {
    "talker_pkg/package.xml": "<package><name>talker_pkg</name></package>\n",
    "talker_pkg/src/talker.cpp": TALKER,
    "listener_pkg/package.xml": "<package><name>listener_pkg</name></package>\n",
    "listener_pkg/setup.py": SETUP,
    "listener_pkg/listener_pkg/listener.py": LISTENER,
}


def test_names_types_members_and_parameter_defaults_meet_across_languages() -> None:
    report = ros(WORKSPACE)
    talker = "talker_pkg/src/talker.cpp"
    assert sites(report, talker) == [
        (7, "ros2/declare-parameter", "parameter:/talker/topic", "", "external"),
        # the member topic_ holds the parameter's default, "chatter" (relative: /chatter)
        (8, "ros2/publisher", "topic:/chatter", "std_msgs/msg/String", "resolved"),
        (9, "ros2/publisher", "topic:/talker/status", "std_msgs/msg/String", "external"),
        # pub_ was made by the publisher of line 8: its topic and type
        (11, "ros2/publish", "topic:/chatter", "std_msgs/msg/String", "resolved"),
        (13, "ros2/component", "plugin:talker_pkg::Talker", "", "external"),
    ]
    publisher = site_at(report, talker, 8)
    named = (publisher.name, publisher.node, publisher.parameter)
    assert named == ("topic:chatter", "/talker", "topic")
    listener = "listener_pkg/listener_pkg/listener.py"
    assert sites(report, listener) == [
        (9, "ros2/py-subscription", "topic:/chatter", "std_msgs/msg/String", "resolved"),
    ]
    element = report.of_file(listener)
    # d_a: the publisher and the publish of the talker (p. 110: each occurrence)
    assert (element.d_a, element.d_e) == (2, 1)
    assert report.of_file(talker).d_e == 5


LAUNCH = """\
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    remaps = [('chatter', 'conversation')]
    return LaunchDescription([
        Node(package='talker_pkg', executable='talker', namespace='robot1', remappings=remaps),
        Node(package='listener_pkg', executable='listener', name='ear', namespace='robot1',
             remappings=[('chatter', 'conversation')]),
    ])
"""


def test_a_launch_file_renames_remaps_and_starts_its_nodes() -> None:
    files = {**WORKSPACE, "bringup/package.xml": "<package><name>bringup</name></package>\n",
             "bringup/launch/demo.launch.py": LAUNCH}  # fmt: skip
    report = ros(files)
    talker, listener = "talker_pkg/src/talker.cpp", "listener_pkg/listener_pkg/listener.py"
    assert [(line, key) for line, _, key, _, _ in sites(report, talker)] == [
        (7, "parameter:/robot1/talker/topic"),
        (8, "topic:/robot1/conversation"),  # /robot1/chatter, remapped
        (9, "topic:/robot1/talker/status"),
        (11, "topic:/robot1/conversation"),
        (13, "plugin:talker_pkg::Talker"),
    ]
    assert site_at(report, listener, 9).endpoint.key == "topic:/robot1/conversation"
    assert site_at(report, listener, 9).node == "/robot1/ear"  # renamed by the launch file
    launch = "bringup/launch/demo.launch.py"
    assert [(s.line, s.endpoint.key if s.endpoint else None, s.targets, s.status)
            for s in report.of_file(launch).link_sites] == [
        (8, "node:talker_pkg/talker", ("talker_pkg/src/talker",), LinkStatus.RESOLVED),  # node name
        (9, "node:listener_pkg/listener", (listener,), LinkStatus.RESOLVED),  # console_scripts
    ]  # fmt: skip
    # the talker receives its launch site without a site of its own: d_a 1 (the launch) + 0
    assert report.of_file(talker).d_a == 1
    assert report.of_file(listener).d_a == 3  # publisher, publish, launch


def test_two_launch_files_that_disagree_leave_the_code_names_and_say_so() -> None:
    other = LAUNCH.replace("robot1", "robot2")
    files = {
        **WORKSPACE,
        "bringup/package.xml": "<package><name>bringup</name></package>\n",
        "bringup/launch/one.launch.py": LAUNCH,
        "bringup/launch/two.launch.py": other,
    }
    report = ros(files)
    publisher = site_at(report, "talker_pkg/src/talker.cpp", 8)
    assert publisher.endpoint is not None and publisher.endpoint.key == "topic:/chatter"
    assert "started differently by launch files" in publisher.note


XML_LAUNCH = """\
<launch>
  <group>
    <push-ros-namespace namespace="arm"/>
    <node pkg="talker_pkg" exec="talker">
      <remap from="~/status" to="/diagnostics"/>
    </node>
  </group>
  <node_container pkg="rclcpp_components" exec="component_container" name="box" namespace="">
    <composable_node pkg="talker_pkg" plugin="talker_pkg::Talker"/>
  </node_container>
</launch>
"""

YAML_LAUNCH = """\
launch:
  - node:
      pkg: listener_pkg
      exec: listener
      namespace: arm
"""


def test_xml_and_yaml_launch_files_are_read_as_ros_does() -> None:
    files = {**WORKSPACE, "bringup/package.xml": "<package><name>bringup</name></package>\n",
             "bringup/launch/arm.launch.xml": XML_LAUNCH,
             "bringup/launch/ear.launch.yaml": YAML_LAUNCH}  # fmt: skip
    report = ros(files)
    xml = "bringup/launch/arm.launch.xml"
    assert [(s.line, s.rule, s.endpoint.key if s.endpoint else None, s.targets)
            for s in report.of_file(xml).link_sites] == [
        (4, "ros2/launch-file", "node:talker_pkg/talker", ("talker_pkg/src/talker",)),
        (9, "ros2/launch-file", "plugin:talker_pkg::Talker", ("talker_pkg/src/talker",)),
    ]  # fmt: skip
    yaml = "bringup/launch/ear.launch.yaml"
    assert [(s.line, s.endpoint.key if s.endpoint else None) for s in
            report.of_file(yaml).link_sites] == [(2, "node:listener_pkg/listener")]  # fmt: skip
    talker = "talker_pkg/src/talker.cpp"
    # the component and the node differ (no namespace, /arm): the code's names are kept
    assert site_at(report, talker, 9).endpoint.key == "topic:/talker/status"
    assert site_at(report, "listener_pkg/listener_pkg/listener.py", 9).endpoint.key == (
        "topic:/arm/chatter"
    )


PARAMS = """\
talker:
  ros__parameters:
    topic: news
/**:
  ros__parameters:
    use_sim_time: true
"""


def test_a_parameter_file_sets_the_name_and_receives_the_code_reading_it() -> None:
    files = {**WORKSPACE, "talker_pkg/config/talker_params.yaml": PARAMS}
    report = ros(files)
    talker = "talker_pkg/src/talker.cpp"
    declare = site_at(report, talker, 7)
    assert (declare.endpoint.key, declare.targets) == (
        "parameter:/talker/topic",
        ("talker_pkg/config/talker_params.yaml",),
    )
    # the file sets topic: news, so the publisher publishes on /news, not the default
    assert site_at(report, talker, 8).endpoint.key == "topic:/news"
    assert site_at(report, talker, 11).endpoint.key == "topic:/news"
    params = report.of_file("talker_pkg/config/talker_params.yaml")
    assert (params.d_a, params.d_e, params.element.files) == (
        1,
        0,
        ("talker_pkg/config/talker_params.yaml",),
    )


PLANNER = """\
#include "pluginlib/class_list_macros.hpp"
namespace planner_pkg { class Straight {}; }
PLUGINLIB_EXPORT_CLASS(planner_pkg::Straight, nav_core::Planner)
"""

SERVER = """\
#include <pluginlib/class_loader.hpp>
void load(pluginlib::ClassLoader<nav_core::Planner> & loader, const std::string & name) {
  auto straight = loader.createUniqueInstance("planner_pkg/Straight");
  auto chosen = loader.createUniqueInstance(name);
}
"""

DESCRIPTION = """\
<library path="planner_pkg">
  <class name="planner_pkg/Straight" type="planner_pkg::Straight"
         base_class_type="nav_core::Planner"><description>Straight lines.</description></class>
</library>
"""


def test_a_plugin_load_meets_the_export_through_its_description() -> None:
    files = {
        "planner_pkg/package.xml": "<package><name>planner_pkg</name></package>\n",
        "planner_pkg/planner_plugins.xml": DESCRIPTION,
        "planner_pkg/src/straight.cpp": PLANNER,
        "server_pkg/package.xml": "<package><name>server_pkg</name></package>\n",
        "server_pkg/src/server.cpp": SERVER,
    }
    report = ros(files)
    load = site_at(report, "server_pkg/src/server.cpp", 3)
    assert (load.endpoint.key, load.targets) == (
        "plugin:planner_pkg::Straight",  # the lookup name, read through the description
        ("planner_pkg/planner_plugins.xml", "planner_pkg/src/straight"),
    )
    unknown = site_at(report, "server_pkg/src/server.cpp", 4)
    assert unknown.endpoint is None and unknown.status is LinkStatus.UNRESOLVED
    assert report.element("planner_pkg/src/straight").d_a == 1
    assert report.of_file("planner_pkg/planner_plugins.xml").d_a == 1


TF = {
    "frames_pkg/package.xml": "<package><name>frames_pkg</name></package>\n",
    "frames_pkg/frames.py": """\
        from rclpy.node import Node
        from tf2_ros.static_transform_broadcaster import StaticTransformBroadcaster
        class Frames(Node):
            def __init__(self):
                super().__init__('frames')
                self.broadcaster = StaticTransformBroadcaster(self)
            def send(self, t):
                self.broadcaster.sendTransform(t)
        """,
    "frames_pkg/follow.cpp": """\
        #include <tf2_ros/transform_listener.h>
        class Follow : public rclcpp::Node {
         public:
          Follow() : Node("follow") {
            listener_ = std::make_shared<tf2_ros::TransformListener>(buf_);
          }
        };
        """,
}


def test_a_tf_listener_receives_tf_and_tf_static() -> None:
    report = ros(TF)
    listener = site_at(report, "frames_pkg/follow.cpp", 5)
    assert (listener.endpoint.key, listener.endpoint.also) == ("topic:/tf", ("topic:/tf_static",))
    assert listener.status is LinkStatus.RESOLVED
    assert sites(report, "frames_pkg/frames.py") == [
        (6, "ros2/tf-static-broadcaster", "topic:/tf_static", "tf2_msgs/msg/TFMessage", "resolved"),
        (8, "ros2/send-transform", "topic:/tf_static", "tf2_msgs/msg/TFMessage", "resolved"),
    ]
    assert report.element("frames_pkg/follow").d_a == 2


def test_one_topic_with_two_types_is_noted_on_each_site() -> None:
    report = ros({
        "a/package.xml": "<package><name>a</name></package>\n",
        "a/pub.cpp": TALKER.replace('"~/status"', '"count"'),
        "a/sub.py": LISTENER.replace("'chatter'", "'count'").replace(
            "from std_msgs.msg import String", "from std_msgs.msg import Int32 as String"),
    })  # fmt: skip
    subscription = site_at(report, "a/sub.py", 9)
    assert subscription.data_type == "std_msgs/msg/Int32"
    clash = "/count carries several types: std_msgs/msg/Int32, std_msgs/msg/String"
    assert subscription.note == clash
    assert site_at(report, "a/pub.cpp", 9).note == subscription.note


ALIASES = """\
#include <rclcpp/rclcpp.hpp>
using std_msgs::msg::Int32;
typedef example_interfaces::srv::AddTwoInts Sum;
class Counter : public rclcpp::Node {
  using Twist = geometry_msgs::msg::Twist;
  using Vel = Twist;
  using Text = rclcpp::TypeAdapter<std::string, std_msgs::msg::String>;
 public:
  Counter() : Node("counter") {
    using Twist = geometry_msgs::msg::TwistStamped;
    a_ = create_publisher<Int32>("count", 1);
    b_ = create_publisher<Twist>("cmd_vel", 1);
    c_ = create_service<Sum>("sum", cb);
    d_ = create_publisher<Text>("text", 1);
    e_ = create_publisher<Pose>("pose", 1);
  }
  void more() { f_ = create_publisher<Vel>("vel", 1); }
};
"""


def test_cpp_types_are_read_through_the_files_aliases() -> None:
    report = ros({"a/package.xml": "<package><name>a</name></package>\n", "a/c.cpp": ALIASES})
    assert [(line, kind) for line, _, _, kind, _ in sites(report, "a/c.cpp")] == [
        (11, "std_msgs/msg/Int32"),  # using std_msgs::msg::Int32;
        (12, "geometry_msgs/msg/TwistStamped"),  # the function's own alias first
        (13, "example_interfaces/srv/AddTwoInts"),  # typedef
        (14, "std_msgs/msg/String"),  # a type adapter: the ROS type it adapts to
        (15, "Pose"),  # no alias: as written
        (17, "geometry_msgs/msg/Twist"),  # an alias of an alias
    ]


ROS1 = """\
#include <ros/ros.h>
#include <geometry_msgs/Twist.h>
int main(int argc, char ** argv) {
  ros::init(argc, argv, "move_base");
  ros::NodeHandle private_nh("~");
  ros::NodeHandle nh;
  std::string planner;
  private_nh.param("base_global_planner", planner, std::string("navfn/NavfnROS"));
  ros::Publisher vel = nh.advertise<geometry_msgs::Twist>("cmd_vel", 1);
  ros::Publisher goal = private_nh.advertise<geometry_msgs::PoseStamped>("current_goal", 0);
  ros::ServiceClient client = nh.serviceClient<nav_msgs::GetPlan>("make_plan");
  client.call(srv);
  vel.publish(twist);
}
"""


def test_ros1_names_resolve_under_their_node_handles() -> None:
    report = ros({"move_base/package.xml": "<package><name>move_base</name></package>\n",
                  "move_base/src/move_base.cpp": ROS1})  # fmt: skip
    assert [(line, rule, key, kind) for line, rule, key, kind, _ in
            sites(report, "move_base/src/move_base.cpp")] == [
        (8, "ros1/parameter", "parameter:/move_base/base_global_planner", ""),
        (9, "ros1/advertise", "topic:/cmd_vel", "geometry_msgs/Twist"),
        (10, "ros1/advertise", "topic:/move_base/current_goal", "geometry_msgs/PoseStamped"),
        (11, "ros1/service-client", "service:/make_plan", "nav_msgs/GetPlan"),
        (12, "ros1/call", "service:/make_plan", "nav_msgs/GetPlan"),
        (13, "ros1/publish", "topic:/cmd_vel", "geometry_msgs/Twist"),
    ]  # fmt: skip


def test_a_computed_name_is_an_unresolved_site_with_a_note() -> None:
    source = TALKER.replace('"~/status"', "make_topic()").replace('Node("talker")', "Node(name)")
    report = ros({"p/package.xml": "<package><name>p</name></package>\n", "p/t.cpp": source})
    computed = site_at(report, "p/t.cpp", 9)
    assert computed.endpoint is None and computed.status is LinkStatus.UNRESOLVED
    assert computed.note.startswith("make_topic(): computed at run time")
    declared = site_at(report, "p/t.cpp", 7)  # the node's name is computed: so is /?/topic
    assert declared.endpoint is None
    assert "the node's name is not known statically" in declared.note


def test_the_index_counts_as_the_report_does_on_a_ros_tree() -> None:
    files = {**WORKSPACE, "talker_pkg/config/talker_params.yaml": PARAMS,
             "bringup/package.xml": "<package><name>bringup</name></package>\n",
             "bringup/launch/demo.launch.py": LAUNCH, **TF}  # fmt: skip
    facts = ros_facts(files)
    report = measure_coupling(facts, CouplingOptions(), BUILTIN)
    links = link_tree(facts, CouplingOptions(), BUILTIN)
    index = build_index(links, [f.path for f in facts])
    assert index.whole and index.receivers
    assert {name: values for name, values in index.values.items()} == {
        c.element.name: (c.s_a, c.s_e, c.d_a, c.d_e) for c in report.elements
    }
