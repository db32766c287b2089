"""The robot model: Pinocchio's model of a URDF and the serial chain the commands drive,
where a description and its meshes come from (``sources``, ``xacro``), the robots
``--robot`` can name (``catalogue``), the link geometry to draw (``visuals``) and the
frame conversions every layer shares (``frames``).
"""

from .model import CONTINUOUS_LIMIT, ChainJoint, Robot
from .sources import RobotSource, load_source

__all__ = ["CONTINUOUS_LIMIT", "ChainJoint", "Robot", "RobotSource", "load_source"]
