"""The gymnasium environment: spaces, determinism, truncation, reward terms, registration."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from pianobot.env.piano import EnvConfig, PianoEnv, finger_targets
from pianobot.env.rewards import RewardConfig
from pianobot.music.piece import Note, Piece
from pianobot.music.tensor import FINGER, NOTE, VELOCITY

PHRASE = Piece((Note(0.0, 60, 0.5, 70, 2), Note(0.5, 62, 1.0, 90, 3)), bpm=60)


def rollout(env, seed, steps=30):
    observation, _ = env.reset(seed=seed)
    rng = np.random.default_rng(1)
    trace = []
    for _ in range(steps):
        observation, reward, terminated, truncated, info = env.step(rng.uniform(-1, 1, env.action_space.shape))
        trace.append((reward, observation))
        if truncated:
            break
    return trace


def same(a, b):
    return all(ra == rb and all(np.array_equal(oa[k], ob[k]) for k in oa) for (ra, oa), (rb, ob) in zip(a, b))


def test_gymnasium_check_env_passes():
    check_env(PianoEnv(piece=PHRASE), skip_render_check=True)
    check_env(PianoEnv(task="chord", config=EnvConfig(tactile=False)), skip_render_check=True)


def test_observation_layout_matches_the_paper():
    env = PianoEnv(piece=PHRASE)
    observation, _ = env.reset(seed=0)
    assert observation["score"].shape == (11, 24, 5)  # current step + 10 lookahead, L x 5
    assert observation["tactile"].shape == (2, 3, 15, 20) and observation["tactile"].dtype == np.uint8
    assert observation["joints"].shape == (12,) and observation["joint_velocities"].shape == (12,)
    assert observation["wrist"].shape == (2,)
    assert "keys" not in observation
    assert env.action_space.shape == (13,)
    full = PianoEnv(piece=PHRASE, config=EnvConfig(tactile_pool=None, key_observations=True, lookahead=0))
    observation, _ = full.reset(seed=0)
    assert observation["tactile"].shape == (2, 3, 60, 80)
    assert observation["score"].shape == (1, 24, 5)
    assert observation["keys"].shape == (24,) and observation["key_velocities"].shape == (24,)
    assert "tactile" not in PianoEnv(piece=PHRASE, config=EnvConfig(tactile=False)).reset(seed=0)[0]


def test_the_score_window_slides_one_step_per_step():
    env = PianoEnv(piece=PHRASE, config=EnvConfig(tactile=False))
    observation, _ = env.reset(seed=0)
    lead = env.lead_steps
    assert lead == 20  # 1 s lead-in at 20 Hz
    assert observation["score"][lead - 10 :, 0, 0].sum() == 0  # C4 lies beyond the 10-step lookahead
    for _ in range(lead - 10):
        observation, *_ = env.step(np.zeros(13))
    assert observation["score"][10, 0, 0] == 1  # C4's onset has just come into view
    assert observation["score"][10, 0, 1] == pytest.approx(70 / 127)
    assert observation["score"][10, 0, 2:].tolist() == [1, 0, 0]  # index finger


def test_deterministic_for_a_seed_and_independent_of_earlier_episodes():
    env = PianoEnv(piece=PHRASE)
    first = rollout(env, seed=7)
    rollout(env, seed=8)
    assert same(first, rollout(env, seed=7))
    assert same(first, rollout(PianoEnv(piece=PHRASE), seed=7))
    start = [PianoEnv(piece=PHRASE).reset(seed=s)[0]["wrist"][0] for s in (1, 2)]
    assert start[0] != start[1]  # the hand starts at a random place


def test_the_phrase_end_is_truncated_not_terminated():
    env = PianoEnv(piece=PHRASE, config=EnvConfig(tactile=False))
    env.reset(seed=0)
    flags = []
    for _ in range(env.horizon):
        _, _, terminated, truncated, _ = env.step(np.zeros(13))
        flags.append((terminated, truncated))
    assert flags[-1] == (False, True)
    assert not any(t for t, _ in flags) and not any(tr for _, tr in flags[:-1])
    assert env.horizon == 20 + 25  # lead-in + 1.0 s of music + 0.25 s tail


@pytest.mark.parametrize("kind", ["linear", "squared", "wasserstein"])
def test_reward_terms_in_info_sum_to_the_reward(kind):
    env = PianoEnv(piece=PHRASE, config=EnvConfig(tactile=False, reward=RewardConfig(kind=kind)))
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    for _ in range(40):
        _, reward, _, _, info = env.step(rng.uniform(-1, 1, 13))
        assert sum(info["reward_terms"].values()) == pytest.approx(reward)


def test_idle_hand_touches_nothing():
    env = PianoEnv(piece=PHRASE, config=EnvConfig(tactile=True))
    observation, _ = env.reset(seed=3)
    for _ in range(10):
        observation, reward, _, _, info = env.step(np.zeros(13))
        assert info["events"] == [] and observation["tactile"].max() == 0
        assert reward == pytest.approx(1.0)  # nothing asked for yet, nothing played


def test_torque_control_and_discrete_wrist_run():
    from pianobot.sim.world import WorldConfig

    for world in (WorldConfig(control="torque"), WorldConfig(discrete_wrist=True)):
        env = PianoEnv(piece=PHRASE, config=EnvConfig(world=world, tactile=False))
        trace = rollout(env, seed=0, steps=10)
        assert len(trace) == 10 and all(np.isfinite(r) for r, _ in trace)
    env = PianoEnv(piece=PHRASE, config=EnvConfig(world=WorldConfig(discrete_wrist=True), tactile=False))
    env.reset(seed=0)
    action = np.zeros(13)
    action[-1] = -1.0
    for _ in range(15):
        observation, *_ = env.step(action)
    assert observation["wrist"][0] == pytest.approx(2 * env.world.boxes[0].center[0] / env.world.width - 1, abs=0.01)


def test_registered_ids():
    env = gym.make("pianobot/OneNote-v1", config=EnvConfig(tactile=False))
    observation, _ = env.reset(seed=0)
    assert observation["score"].shape == (11, 24, 5)
    assert gym.make("pianobot/Piano-v1", piece=PHRASE).unwrapped.piece == PHRASE
    assert {"pianobot/ThreeNote-v1", "pianobot/SixNote-v1", "pianobot/Rhythmic-v1", "pianobot/Chord-v1"} <= set(
        gym.registry
    )


def test_unplayable_phrase_is_refused():
    from pianobot.errors import PianobotError

    with pytest.raises(PianobotError, match="outside the keyboard"):
        PianoEnv(piece=Piece((Note(0, 40, 1, 80, 2),)))


def test_frozen_joints_shrink_the_action_and_hold_still():
    env = PianoEnv(piece=PHRASE, config=EnvConfig(tactile=False, actuated=("mcp", "pip")))
    assert env.action_space.shape == (7,)  # 2 joints x 3 fingers + wrist
    observation, _ = env.reset(seed=0)
    start = observation["joints"].reshape(3, 4).copy()
    action = np.zeros(7)
    action[[0, 2, 4]] = -0.1  # lift the knuckles (no key is touched)
    for _ in range(5):
        observation, *_ = env.step(action)
    joints = observation["joints"].reshape(3, 4)
    assert np.allclose(joints[:, [0, 3]], start[:, [0, 3]], atol=0.02)  # abduction and DIP did not move
    assert np.all(joints[:, 1] < start[:, 1] - 0.1)  # MCP did
    with pytest.raises(ValueError):
        PianoEnv(piece=PHRASE, config=EnvConfig(actuated=("elbow",)))


def test_finger_targets_tell_a_held_note_from_the_next_strike_of_the_same_key():
    keys, fingers = 24, (2, 3, 4)
    tips = {f: np.zeros(3) for f in fingers}
    points = np.arange(keys * 3, dtype=float).reshape(keys, 3) * 0.001
    window = np.zeros((11, keys, 5), np.float32)
    window[0:4, 3, [NOTE, FINGER]] = 1.0  # the index finger holds key 3 for 4 more steps ...
    window[0:4, 3, VELOCITY] = 0.5
    window[5:9, 3, [NOTE, FINGER]] = 1.0  # ... then strikes it again, louder
    window[5:9, 3, VELOCITY] = 0.8
    previous = window[0].copy()  # the held note started before this window
    held = finger_targets(window, tips, points, fingers, velocity=True, previous=previous)
    assert held.shape == (3, 6)
    assert held[0, 3] == pytest.approx(1 - 5 / 11)  # the next strike, not the held note
    assert held[0, 4] == pytest.approx(0.8)
    assert held[0, 5] == pytest.approx(4 / 11)  # how much longer to hold
    assert np.allclose(held[0, :3], points[3] / 0.1)
    strike = finger_targets(window[5:], tips, points, fingers, velocity=True, previous=window[4])
    assert strike[0, 3] == 1.0 and strike[0, 4] == pytest.approx(0.8) and strike[0, 5] == 0.0
    assert not held[1:].any() and not strike[1:].any()
    # without onsets (policies before them) the held note reads as one to strike now
    old = finger_targets(window, tips, points, fingers, velocity=True)
    assert old.shape == (3, 5) and old[0, 3] == 1.0 and old[0, 4] == pytest.approx(0.5)


def test_finger_targets_point_from_each_fingertip_to_its_next_key():
    env = PianoEnv(piece=PHRASE, config=EnvConfig(tactile=False))
    observation, _ = env.reset(seed=3)
    assert observation["targets"].shape == (3, 6)
    assert not observation["targets"].any()  # nothing in the 0.5 s window yet
    for _ in range(env.lead_steps - 5):
        observation, *_ = env.step(np.zeros(13))
    targets = observation["targets"]
    tips = env.world.tip_points()
    # finger 2 plays C4 (key 0) 5 steps ahead, finger 3 D4 (key 2) 15 steps ahead: beyond the window
    expected = np.clip((env.strike_points[0] - tips[2]) / 0.1, -5, 5)
    assert np.allclose(targets[0, :3], expected, atol=1e-5)
    assert targets[0, 3] == pytest.approx(1 - 5 / 11)
    assert targets[0, 4] == pytest.approx(PHRASE.notes[0].velocity / 127)  # how loud
    assert targets[0, 5] == 0  # holds nothing
    assert not targets[1].any() and not targets[2].any()
    older = PianoEnv(
        piece=PHRASE, config=EnvConfig(tactile=False, target_velocity=False, target_onsets=False)
    )  # as policies before them
    assert older.reset(seed=3)[0]["targets"].shape == (3, 4)
    without = PianoEnv(piece=PHRASE, config=EnvConfig(tactile=False, target_observations=False))
    assert "targets" not in without.reset(seed=0)[0]


def test_each_strike_of_a_repeated_note_is_announced_once_and_the_hold_between_them_is_not():
    piece = Piece([Note(0.0, 60, 0.5, 80, 2), Note(0.5, 60, 1.0, 80, 2)])  # C4 twice, index finger
    env = PianoEnv(piece=piece, config=EnvConfig(tactile=False, random_start=False))
    observation, _ = env.reset(seed=0)
    now, holding = [], []
    while True:
        now.append(observation["targets"][0, 3] == 1.0)
        holding.append(observation["targets"][0, 5] > 0)
        observation, _, terminated, truncated, _ = env.step(np.zeros(env.action_space.shape))
        if terminated or truncated:
            break
    strikes = [env.lead_steps, env.lead_steps + 10]  # 20 Hz: the onsets' steps
    assert [t for t, flag in enumerate(now) if flag] == strikes
    assert all(holding[strikes[0] + 1 : strikes[1] - 1]) and not holding[strikes[0]] and not holding[strikes[1] - 1]


def test_render_honours_the_render_mode():
    """Issue 36, item 5: a frame with render_mode='rgb_array'; None and gymnasium's warning without
    one; another mode refused. gymnasium's checker passes with rendering checked."""
    import warnings

    rendering = PianoEnv(piece=PHRASE, config=EnvConfig(tactile=False), render_mode="rgb_array")
    rendering.reset(seed=0)
    frame = rendering.render()
    assert frame.ndim == 3 and frame.shape[2] == 3 and frame.dtype == np.uint8 and frame.any()
    check_env(rendering)
    rendering.close()
    quiet = PianoEnv(piece=PHRASE, config=EnvConfig(tactile=False))
    quiet.reset(seed=0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert quiet.render() is None
    assert any("render_mode" in str(w.message) for w in caught)
    quiet.close()
    with pytest.raises(ValueError, match="render_mode 'human'"):
        PianoEnv(piece=PHRASE, render_mode="human")
