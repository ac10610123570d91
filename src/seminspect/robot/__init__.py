"""The simulated holonomic robot: ground and aerial modes, limits, collisions, trajectory log."""

from seminspect.robot.robot import Mode, MoveResult, Robot, RobotState, Trajectory

__all__ = ["Mode", "MoveResult", "Robot", "RobotState", "Trajectory"]
