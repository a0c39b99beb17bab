"""The keyboard: velocity calibration, the MIDI-like key sensor, and a physical key press."""

import numpy as np
import pytest

from pianobot.music.instrument import KeyboardSpec
from pianobot.sim.keyboard import KeyboardConfig, KeySensor, VelocityCurve, key_boxes, keyboard_width


def test_velocity_curve_is_monotone_and_its_inverse_round_trips():
    curve = VelocityCurve()
    speeds = np.geomspace(0.005, 2.0, 200)
    velocities = curve.velocity(speeds)
    assert np.all(np.diff(velocities) >= 0)
    assert velocities[0] == 1 and velocities[-1] == 127
    for v in range(1, 128):
        assert curve.velocity(curve.speed(v)) == v


def test_key_layout_is_two_octaves_of_real_sized_keys():
    config = KeyboardConfig()
    boxes = key_boxes(config)
    assert len(boxes) == 24 and sum(b.black for b in boxes) == 10
    assert keyboard_width(config) == pytest.approx(14 * 0.0235)
    white = [b for b in boxes if not b.black]
    assert np.allclose(np.diff([b.center[0] for b in white]), 0.0235)
    black = [b for b in boxes if b.black]
    assert all(
        b.half[0] * 2 == pytest.approx(0.0137) and b.center[2] + b.half[2] == pytest.approx(0.0127) for b in black
    )
    # C#4 lies between C4 and D4
    assert white[0].center[0] < boxes[1].center[0] < white[1].center[0]
    assert not any(b.black for b in key_boxes(KeyboardConfig(spec=KeyboardSpec(62, 1))))


def test_key_sensor_sends_note_on_with_velocity_and_note_off_with_hysteresis():
    config = KeyboardConfig(spec=KeyboardSpec(60, 2))
    sensor = KeySensor(config)
    full = config.geometry.max_angle
    speed = np.array([0.0, 0.0])
    assert sensor.update(0.0, np.array([0.5 * full, 0.0]), speed) == []  # not yet at the strike depth
    fast = VelocityCurve().speed(100) / config.geometry.white_length
    events = sensor.update(0.1, np.array([0.7 * full, 0.0]), np.array([fast, 0.0]))
    assert [(e.pitch, e.on, e.velocity) for e in events] == [(60, True, 100)]
    assert sensor.update(0.2, np.array([0.9 * full, 0.0]), speed) == []  # held: no second note-on
    assert sensor.update(0.3, np.array([0.5 * full, 0.0]), speed) == []  # between release and strike: still on
    events = sensor.update(0.4, np.array([0.2 * full, 0.0]), speed)
    assert [(e.pitch, e.on) for e in events] == [(60, False)]
    assert not sensor.sounding.any()


def test_slow_press_is_soft_and_fast_press_is_loud():
    """A finger pressing a key through the physics: the key's speed sets the velocity."""
    from pianobot.env.piano import idle_pose
    from pianobot.sim.world import PianoWorld, WorldConfig

    world = PianoWorld(WorldConfig())
    velocities = []
    for speed in (0.15, 0.6):
        world.reset(world.boxes[4].center[0], np.tile(idle_pose(world.config), 3))  # middle finger over E4
        action = np.zeros(13)
        action[5] = speed  # the middle finger's knuckle (MCP) flexes
        notes = []
        for _ in range(20):
            result = world.step(action)
            notes += [e.velocity for e in result.events if e.on]
            if notes:
                break
        assert len(notes) == 1
        velocities.append(notes[0])
        angles, _ = world.key_state()
        assert angles.max() <= 1.3 * world.config.keyboard.geometry.max_angle  # the key stops at the keybed
    world.close()
    assert velocities[0] + 20 < velocities[1]


@pytest.mark.parametrize("control", ["velocity"])
def test_finger_joints_stay_within_their_limits_at_full_command(control):
    """(Under torque control, fingers jammed into the keys at full torque still overshoot by up to
    0.6 rad: see docs/simulator.md.)"""
    from pianobot.env.piano import idle_pose
    from pianobot.sim.world import PianoWorld, WorldConfig

    world = PianoWorld(WorldConfig(control=control))
    world.reset(world.width / 2, np.tile(idle_pose(world.config), 3))
    low, high = world.joint_limits
    for sign in (1.0, -1.0):
        action = np.zeros(13)
        action[:12] = sign
        for _ in range(30):
            world.step(action)
            angles = world.hand_state()[2]
            assert np.all(angles >= low - 0.15) and np.all(angles <= high + 0.15)
    world.close()


def _press(keyboard: KeyboardSpec, pitch: int, speed: float) -> tuple[list[tuple[int, int]], np.ndarray, np.ndarray]:
    """The middle finger, over ``pitch``, flexes its knuckle at ``speed`` until a key sounds: the
    note-ons (pitch, velocity), and every key's angle and the angle of each key the world read."""
    from pianobot.env.piano import idle_pose
    from pianobot.sim.bullet import p
    from pianobot.sim.world import PianoWorld, WorldConfig

    world = PianoWorld(WorldConfig(keyboard=KeyboardConfig(spec=keyboard)))
    world.reset(world.boxes[keyboard.index(pitch)].center[0], np.tile(idle_pose(world.config), 3))
    action = np.zeros(13)
    action[5] = speed
    notes = []
    for _ in range(20):
        notes += [(e.pitch, e.velocity) for e in world.step(action).events if e.on]
        if notes:
            break
    read, _ = world.key_state()
    actual = np.array([p.getJointState(body, 0, physicsClientId=world.client)[0] for body in world.keys])
    world.close()
    return notes, read, actual


def test_a_key_sounds_the_same_on_a_whole_piano_and_only_the_pressed_key_moves():
    """Each key is a body of its own, asleep while at rest: the same press on E4 gives the same note
    on the paper's 24 keys and on 88 (A0-C8), the keys beside it (the black keys overlap the white
    ones' boxes) do not move, and the key states the world reports are the keys' own."""
    paper, piano = KeyboardSpec(), KeyboardSpec(21, 88)
    notes, read, actual = _press(paper, 64, 0.6)
    assert len(notes) == 1 and notes[0][0] == 64
    assert _press(piano, 64, 0.6)[0] == notes
    assert np.allclose(read, actual, atol=1e-4)
    others = np.delete(actual, paper.index(64))
    assert np.abs(others).max() < 1e-4


def test_every_finger_follows_a_large_commanded_move_within_one_step():
    """What the 50 solver iterations bought: each finger's joints, the ring finger's (the last)
    included, move by what a control step's speeds command (at 15 iterations the ring finger
    fell 0.08 rad short of a 0.4 rad move)."""
    from pianobot.env.piano import idle_pose
    from pianobot.sim.world import PianoWorld, WorldConfig

    world = PianoWorld(WorldConfig())
    world.reset(world.width / 2, np.tile(idle_pose(world.config), 3))
    step = 1 / world.config.control_hz
    for move in ([0.0, 0.2, -0.3, 0.4], [0.0, -0.08, 0.3, -0.18], [0.1, 0.15, -0.25, -0.1]):  # rad, within the limits
        before = world.hand_state()[2]
        action = np.zeros(13)
        action[:12] = np.tile(move, 3) / (world.config.hand.max_joint_speed * step)
        world.step(action)
        assert np.abs(world.hand_state()[2] - before - np.tile(move, 3)).max() < 0.005
    world.close()
