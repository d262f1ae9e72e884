"""Dead-reckoning odometry for a differential-drive robot base."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass
class Pose:
    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0


class Odometry:
    """Integrates wheel encoder ticks into a pose."""

    def __init__(self, ticks_per_metre: float, wheel_base: float) -> None:
        if ticks_per_metre <= 0 or wheel_base <= 0:
            raise ValueError("ticks_per_metre and wheel_base must be positive")
        self.ticks_per_metre = ticks_per_metre
        self.wheel_base = wheel_base
        self.pose = Pose()

    def update(self, left_ticks: int, right_ticks: int) -> Pose:
        left = left_ticks / self.ticks_per_metre
        right = right_ticks / self.ticks_per_metre
        distance = (left + right) / 2.0
        turn = (right - left) / self.wheel_base
        if abs(turn) < 1e-9:
            self.pose.x += distance * math.cos(self.pose.yaw)
            self.pose.y += distance * math.sin(self.pose.yaw)
        else:
            radius = distance / turn
            self.pose.x += radius * (math.sin(self.pose.yaw + turn) - math.sin(self.pose.yaw))
            self.pose.y -= radius * (math.cos(self.pose.yaw + turn) - math.cos(self.pose.yaw))
        self.pose.yaw = normalize(self.pose.yaw + turn)
        return self.pose

    def reset(self, x: float = 0.0, y: float = 0.0, yaw: float = 0.0) -> None:
        self.pose = Pose(x, y, normalize(yaw))


def normalize(angle: float) -> float:
    """Wrap an angle into [-pi, pi)."""
    while angle >= math.pi:
        angle -= 2 * math.pi
    while angle < -math.pi:
        angle += 2 * math.pi
    return angle
