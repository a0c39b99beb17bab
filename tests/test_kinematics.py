"""The fingers' inverse kinematics: the scripted pianist's every motion goes through it."""

import math

import numpy as np
import pytest

from pianobot.sim.hand import TILT_RANGE, FingerGeometry, finger_ik, lowest_point_in_finger_plane


def reference_ik(geometry: FingerGeometry, reach: float, drop: float, tilt: float) -> np.ndarray | None:
    """finger_ik as a plain loop over the tilts, nearest first, the larger first of two equally near."""
    for k in range(99):
        offset = 0.0 if k == 0 else 0.02 * ((k + 1) // 2) * (1 if k % 2 else -1)
        phi = tilt + offset
        if not TILT_RANGE[0] <= phi <= TILT_RANGE[1]:
            continue
        l3 = geometry.distal - geometry.tip_radius
        x = reach - l3 * math.cos(phi) - geometry.base_to_mcp
        z = drop - geometry.tip_radius - l3 * math.sin(phi)
        cosine = (x * x + z * z - geometry.proximal**2 - geometry.middle**2) / (2 * geometry.proximal * geometry.middle)
        if abs(cosine) > 1:
            continue
        pip = math.acos(cosine)
        mcp = math.atan2(z, x) - math.atan2(
            geometry.middle * math.sin(pip), geometry.proximal + geometry.middle * math.cos(pip)
        )
        q = np.array([mcp, pip, phi - mcp - pip])
        if all(lo <= a <= hi for a, (lo, hi) in zip(q, geometry.flexion_limits)):
            return q
    return None


def test_finger_ik_picks_the_tilt_the_plain_loop_picks_everywhere_in_and_out_of_reach():
    geometry = FingerGeometry()
    found = missed = 0
    for reach in np.linspace(0.0, 0.14, 36):
        for drop in np.linspace(-0.03, 0.13, 33):
            for tilt in (0.5, 0.6, 0.9, 1.1, 1.3, 1.57, 1.7):
                expected = reference_ik(geometry, reach, drop, tilt)
                got = finger_ik(geometry, reach, drop, tilt)
                if expected is None:
                    assert got is None, (reach, drop, tilt)
                    missed += 1
                    continue
                found += 1
                np.testing.assert_array_equal(got, expected)  # the same arithmetic: the same bits
                assert lowest_point_in_finger_plane(geometry, got) == pytest.approx((reach, drop), abs=1e-9)
    assert found > 1000 and missed > 1000  # the grid covers both reachable and unreachable points
