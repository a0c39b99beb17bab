"""Two hands in the simulator: the left hand is the right's mirror image, each plays its own half,
and the two never pass each other."""

import numpy as np
import pytest

from pianobot.env.piano import idle_pose
from pianobot.music.instrument import KeyboardSpec
from pianobot.sim.keyboard import KeyboardConfig, key_x
from pianobot.sim.world import PianoWorld, WorldConfig

PIANO = WorldConfig(keyboard=KeyboardConfig(spec=KeyboardSpec(21, 88)))
MIDDLE_MCP = 5  # a hand's action: index finger's 4 joints, then the middle finger's abduction, MCP, ...


def mirror(pitch: int) -> int:
    """The keyboard's black and white keys are symmetric about D4 (and G#): pitch p maps to 124 - p."""
    return 2 * 62 - pitch


@pytest.fixture(scope="module")
def world():
    world = PianoWorld(PIANO, hands=("right", "left"))
    yield world
    world.close()


def test_the_left_hand_is_the_right_hands_mirror_image(world):
    pose = np.tile(idle_pose(PIANO), 3)
    pose[[0, 4, 8]] = [0.3, -0.2, 0.1]  # abducted, differently for each finger
    right, left = 1.2, 0.6
    world.reset([right, left], pose)
    tips = world.tip_points(0), world.tip_points(1)
    for finger in (2, 3, 4):
        of_right, of_left = tips[0][finger], tips[1][finger]
        assert of_right[0] - right == pytest.approx(-(of_left[0] - left), abs=1e-6)
        assert of_right[1:] == pytest.approx(of_left[1:], abs=1e-6)
    world.reset([right, left], np.tile(idle_pose(PIANO), 3))
    tips = world.tip_points(0), world.tip_points(1)
    assert tips[0][2][0] < tips[0][3][0] < tips[0][4][0]  # right hand: index lowest
    assert tips[1][2][0] > tips[1][3][0] > tips[1][4][0]  # left hand: index highest


def test_each_hand_strikes_a_key_in_its_own_half_as_its_mirror_would(world):
    """The right middle finger over E5 and the left one over its mirror key C3 press alike: both
    keys sound, each credited to its own hand and finger, at nearly the same velocity."""
    keyboard = PIANO.keyboard
    high, low = 76, mirror(76)
    world.reset([key_x(keyboard, high), key_x(keyboard, low)], np.tile(idle_pose(PIANO), 3))
    action = np.zeros(26)
    action[MIDDLE_MCP] = action[13 + MIDDLE_MCP] = 0.6
    notes, hands, fingers = {}, {}, {}
    for _ in range(20):
        result = world.step(action)
        notes.update({e.pitch: e.velocity for e in result.events if e.on})
        hands.update(result.hands)
        fingers.update(result.fingers)
        if len(notes) == 2:
            break
    assert set(notes) == {high, low}
    assert hands == {high: 0, low: 1} and fingers == {high: 3, low: 3}
    assert abs(notes[high] - notes[low]) <= 3


def test_the_hands_cannot_pass_each_other(world):
    right, left = 0.9, 0.5
    world.reset([right, left], np.tile(idle_pose(PIANO), 3))
    action = np.zeros(26)
    action[12], action[25] = -1.0, 1.0  # both wrists towards each other at full speed
    for _ in range(20):
        world.step(action)
        gap = world.hand_state(0)[0] - world.hand_state(1)[0]
        assert gap >= world.min_separation - 0.005
    assert gap < world.min_separation + 0.01  # they did close in, as far as allowed
    with pytest.raises(ValueError, match="at least"):
        world.reset([0.5, 0.45], np.tile(idle_pose(PIANO), 3))
