"""The IK's refusal: how close the tool could get, beside the tolerance it missed."""

from __future__ import annotations

import math

from ..errors import C2rvizError

__all__ = ["Unreachable"]

_PROMISE_M = 1e-4  # the tolerances IkSettings promises: 0.1 mm ...
_PROMISE_RAD = math.radians(0.1)  # ... and 0.1 deg


class Unreachable(C2rvizError):
    """No chain values within the limits put the tool at the target.

    Attributes:
        distance_m: Position error of the closest tool pose found [m]; when
            ``reach_m`` is set, a lower bound on every pose's position error.
        angle_rad: Orientation error of that pose [rad]; 0 when the orientation
            was free, or when ``reach_m`` is set (no pose was searched).
        position_tolerance_m: The position error an answer may have [m].
        angle_tolerance_rad: The orientation error an answer may have [rad].
        orientation_free: The target was a point (``PointTarget``).
        reach_m: Set when the target is beyond the arm's reach, refused before
            any solve: the most the tool point can be from the first joint [m].
        from_first_joint_m: With ``reach_m``, the target's distance from the first joint [m].
    """

    def __init__(
        self,
        distance_m: float,
        angle_rad: float,
        position_tolerance_m: float = _PROMISE_M,
        angle_tolerance_rad: float = _PROMISE_RAD,
        *,
        orientation_free: bool = False,
        reach_m: float | None = None,
        from_first_joint_m: float | None = None,
    ) -> None:
        self.distance_m = distance_m
        self.angle_rad = angle_rad
        self.position_tolerance_m = position_tolerance_m
        self.angle_tolerance_rad = angle_tolerance_rad
        self.orientation_free = orientation_free
        self.reach_m = reach_m
        self.from_first_joint_m = from_first_joint_m
        tol_mm = position_tolerance_m * 1e3
        tol_deg = math.degrees(angle_tolerance_rad)
        away_mm = _figure(distance_m * 1e3, tol_mm)
        what = "point" if orientation_free else "pose"
        if reach_m is not None:
            where = from_first_joint_m if from_first_joint_m is not None else math.nan
            message = (
                f"{what} unreachable: the target is {where:.3f} m from the arm's first joint, "
                f"which reaches {reach_m:.3f} m at most: every tool {what} is at least "
                f"{away_mm} mm away, over the {tol_mm:g} mm tolerance"
            )
        elif orientation_free:
            message = (
                f"point unreachable: the closest reachable tool point is {away_mm} mm away, "
                f"over the {tol_mm:g} mm tolerance"
            )
        else:
            away_deg = _figure(math.degrees(angle_rad), tol_deg)
            message = (
                f"pose unreachable: the closest reachable tool pose is {away_mm} mm and "
                f"{away_deg} deg away, over the {tol_mm:g} mm / {tol_deg:g} deg tolerance"
            )
        super().__init__(message)


def _figure(value: float, tolerance: float) -> str:
    """``value`` to 0.1, with more decimals when that would not show it is over ``tolerance``."""
    decimals = 1
    while decimals < 6 and value > tolerance and round(value, decimals) <= tolerance:
        decimals += 1
    return f"{value:.{decimals}f}"
