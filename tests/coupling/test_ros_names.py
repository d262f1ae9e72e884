"""ROS sites named from elsewhere in their package: the node of the program making a class,
a member set from a parameter default outside the constructor (docs/metrics.md, "Names, as
ROS resolves them"). Real files through the real parsers and the shipped packs; every
expected name worked out by hand from the snippets."""

from __future__ import annotations

from tests.coupling.test_ros import ros, site_at

PACKAGE = "<package><name>mover</name></package>\n"

MOVER_HEADER = """\
#include <ros/ros.h>
namespace mover {
class Mover {
 public:
  Mover();
  void tick();
 private:
  ros::Publisher goal_pub_;
};
}
"""

MOVER = """\
#include "mover/mover.h"
namespace mover {
Mover::Mover() {
  ros::NodeHandle private_nh("~");
  goal_pub_ = private_nh.advertise<geometry_msgs::PoseStamped>("current_goal", 1);
}
void Mover::tick() { goal_pub_.publish(goal_); }
}
"""

MAIN = """\
#include "mover/mover.h"
int main(int argc, char ** argv) {
  ros::init(argc, argv, "mover_node");
  mover::Mover mover;
  ros::spin();
  return 0;
}
"""


def _mover(**more: str) -> dict[str, str]:
    return {
        "mover/package.xml": PACKAGE,
        "mover/include/mover/mover.h": MOVER_HEADER,
        "mover/src/mover.cpp": MOVER,
        **more,
    }


def test_a_class_takes_the_node_of_the_program_making_it_in_its_package() -> None:
    report = ros(_mover(**{"mover/src/mover_node.cpp": MAIN}))
    # ~current_goal on a "~" handle, in the node ros::init names in mover_node.cpp
    made = site_at(report, "mover/src/mover.cpp", 5)
    published = site_at(report, "mover/src/mover.cpp", 7)
    assert made.endpoint is not None and made.endpoint.key == "topic:/mover_node/current_goal"
    assert published.endpoint is not None
    assert published.endpoint.key == "topic:/mover_node/current_goal"
    assert made.node == "/mover_node"
    assert "mover/src/mover_node.cpp:4" in made.note


FACTORY = """\
#include "mover/mover.h"
mover::Mover * make_mover() { return new mover::Mover(); }
"""


def test_a_file_making_the_class_without_naming_a_node_says_nothing_of_its_node() -> None:
    files = {"mover/src/mover_node.cpp": MAIN, "mover/src/factory.cpp": FACTORY}
    made = site_at(ros(_mover(**files)), "mover/src/mover.cpp", 5)
    assert made.endpoint is not None and made.endpoint.key == "topic:/mover_node/current_goal"


def test_a_class_made_under_two_nodes_or_none_keeps_its_private_names_unresolved() -> None:
    other = MAIN.replace("mover_node", "other_node")
    report = ros(_mover(**{"mover/src/mover_node.cpp": MAIN, "mover/src/other.cpp": other}))
    made = site_at(report, "mover/src/mover.cpp", 5)
    assert made.endpoint is None and "not known statically" in made.note
    alone = ros(_mover())  # no program makes the class
    assert site_at(alone, "mover/src/mover.cpp", 5).endpoint is None


def test_a_plugin_class_keeps_its_loaders_node_unknown() -> None:
    exported = MOVER + "PLUGINLIB_EXPORT_CLASS(mover::Mover, nav_core::RecoveryBehavior)\n"
    exported = "#include <pluginlib/class_list_macros.h>\n" + exported
    report = ros(_mover(**{"mover/src/mover.cpp": exported, "mover/src/mover_node.cpp": MAIN}))
    made = site_at(report, "mover/src/mover.cpp", 6)  # one line lower: the include
    assert made.endpoint is None and "not known statically" in made.note


SERVER = """\
#include "nav2_ros_common/lifecycle_node.hpp"
#include <nav_msgs/msg/occupancy_grid.hpp>
namespace vo {
Server::Server(const rclcpp::NodeOptions & options)
: nav2::LifecycleNode("vo_server", "", options) {}
nav2::CallbackReturn Server::on_configure(const rclcpp_lifecycle::State & state) {
  obtainParams();
  map_pub_ = create_publisher<nav_msgs::msg::OccupancyGrid>(map_topic_, 1);
  return nav2::CallbackReturn::SUCCESS;
}
void Server::obtainParams() {
  auto node = shared_from_this();
  map_topic_ = nav2::declare_or_get_parameter(node, "map_topic", std::string{"vo_map"});
}
}
"""


def test_a_member_set_from_a_braced_parameter_default_in_another_method_names_the_site() -> None:
    files = {"vo/package.xml": "<package><name>vo</name></package>\n", "vo/src/server.cpp": SERVER}
    made = site_at(ros(files), "vo/src/server.cpp", 8)
    # map_topic_ = the default "vo_map" of map_topic (obtainParams), relative: /vo_map
    assert made.endpoint is not None
    assert (made.endpoint.key, made.endpoint.via) == ("topic:/vo_map", "parameter:map_topic")


def test_launch_files_that_disagree_leave_the_declared_default_not_a_parameter_file() -> None:
    from tests.coupling.test_ros import LAUNCH, PARAMS, WORKSPACE

    other = LAUNCH.replace("robot1", "robot2")
    files = {
        **WORKSPACE,
        "talker_pkg/config/talker_params.yaml": PARAMS,  # talker: topic: news
        "bringup/package.xml": "<package><name>bringup</name></package>\n",
        "bringup/launch/one.launch.py": LAUNCH,
        "bringup/launch/two.launch.py": other,
    }
    report = ros(files)
    # talker.cpp line 8: create_publisher(topic_), topic_ declared with the default "chatter";
    # the node runs as /robot1/talker and /robot2/talker: the code's names, the default's
    publisher = site_at(report, "talker_pkg/src/talker.cpp", 8)
    assert publisher.endpoint is not None and publisher.endpoint.key == "topic:/chatter"
    assert "started differently by launch files" in publisher.note
    # started by no launch file, the parameter file naming the node sets the name (news)
    alone = ros({**WORKSPACE, "talker_pkg/config/talker_params.yaml": PARAMS})
    assert site_at(alone, "talker_pkg/src/talker.cpp", 8).endpoint.key == "topic:/news"


SLOW = """\
#include <ros/ros.h>
#include <dynamic_reconfigure/Reconfigure.h>
int main(int argc, char ** argv) {
  ros::init(argc, argv, "slow");
  ros::NodeHandle private_nh("~");
  std::string planner_namespace;
  private_nh.param("planner_namespace", planner_namespace, std::string("DWAPlannerROS"));
  ros::NodeHandle planner_nh("~/" + planner_namespace);
  ros::ServiceClient client =
      planner_nh.serviceClient<dynamic_reconfigure::Reconfigure>("set_parameters", true);
  ros::Publisher pub = private_nh.advertise<std_msgs::String>(planner_namespace + "+x", 1);
}
"""


def test_a_concatenation_of_known_strings_names_a_handle_and_a_topic() -> None:
    files = {
        "slow/package.xml": "<package><name>slow</name></package>\n",
        "slow/src/slow.cpp": SLOW,
    }
    report = ros(files)
    # planner_nh is "~/" + the default "DWAPlannerROS": set_parameters under /slow/DWAPlannerROS
    client = site_at(report, "slow/src/slow.cpp", 10)  # the line of serviceClient
    assert client.endpoint is not None
    assert client.endpoint.key == "service:/slow/DWAPlannerROS/set_parameters"
    # a "+" inside a string literal is no concatenation: "DWAPlannerROS" + "+x", private
    publisher = site_at(report, "slow/src/slow.cpp", 11)
    assert publisher.endpoint is not None
    assert publisher.endpoint.key == "topic:/slow/DWAPlannerROS+x"
